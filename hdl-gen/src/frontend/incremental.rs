//! The incremental I0 (`--fe-i0 incremental`, issue 27): no product per row. The walker keeps,
//! per *source* of the span's left end (column 0, and each edge), the quotient and remainder of
//! the plane's numerator over `2A` at that source's column, and steps them by adds with the
//! row (`golden::frontend::incremental`, the model this is bit for bit).
//!
//! A source is *started* at the first row where it gives the left end of a span with pixels:
//! there one shared engine (one multiplier, `FrontEnd::start_clocks` clocks) evaluates today's
//! reciprocal formula at that pixel, which is covered, so in range and exact, and divides the
//! source's row steps by `2A` with the same reciprocal (only when their quotient is within
//! `[-2^IW, 2^IW)`: a step it cannot take leaves the source unstarted, to start again at its
//! next use). The walker waits for the engine (`ie_wait`): about one start a triangle, a few
//! more beside slivers. The span path then only carries the span to the output register.

use super::hw::{slit, Hw};
use super::stager::Stager;
use crate::verilog::{assign, comment, lit, reg, set, sext, sreg, swire, wire, zext, Item, Stmt};
use golden::frontend::{I0Form, Widths};

// A start at an edge runs from the clock it begins (t0) to the one that writes the source
// (t9), one product a step (golden's `incremental::EDGE_PRODUCTS`): to the pixel, the exact
// step product, the modular one, and three reciprocal evaluations (the start, the step without
// and with the DDA's carry) of two products each, chained where their operands allow. Column 0
// has one step (`COL0_PRODUCTS`). A product takes one clock on the K x RW multiplier, RW on the
// HX8K's shift-add one (`FrontEnd::start_product_clocks`); a walker's start holds the walker
// for `FrontEnd::start_clocks`.
use golden::frontend::incremental::{COL0_PRODUCTS, EDGE_PRODUCTS};

pub(super) fn on(hw: &Hw) -> bool {
    hw.fe.i0 == I0Form::Incremental
}

/// Exact plane widths: CALC's oriented `Nx` and `Ny` (signed).
fn plane_widths(hw: &Hw) -> (u32, u32) {
    hw.plane_widths()
}

/// The set-up result's extra registers: the exact plane, for the steps' range checks.
pub(super) fn setup_regs(hw: &Hw, body: &mut Vec<Item>) {
    let (nx_w, ny_w) = plane_widths(hw);
    body.push(comment("Incremental I0: the exact plane, for the range checks of the sources' steps."));
    body.extend([sreg("s_nx", nx_w), sreg("s_ny", ny_w), reg("s_a", hw.fe.widths().aw)]);
}

/// CALC's last clock loads them with the rest of the set-up result.
pub(super) fn setup_load(st: &Stager) -> Vec<Stmt> {
    vec![set("s_nx", st.at("onx")), set("s_ny", st.at("ony")), set("s_a", st.at("aabs"))]
}

/// A set-up result is held for the walker: the parallel set-up's `HOLD`, an engine's queue head.
fn held(hw: &Hw) -> &'static str {
    if hw.engine_form() {
        "q_ne"
    } else {
        "st == HOLD"
    }
}

/// The smallest of three signed signals, compared side by side (the walker's form).
fn min3(side: &str) -> String {
    let c = |i: u32, j: u32| format!("{side}{i} <= {side}{j}");
    format!("({} && {}) ? {side}0 : ({}) ? {side}1 : {side}2", c(0, 1), c(0, 2), c(1, 2))
}

/// Before the walker's `emit`: the sources' state, which source gives the row's left end, and
/// whether the walker waits for its start. `px` is the row's pixel test.
pub(super) fn select(hw: &Hw, body: &mut Vec<Item>) {
    let Widths { aw, gw: bound_w, .. } = hw.fe.widths();
    let iw = hw.fe.cfg.iw();
    let (nx_w, ny_w) = plane_widths(hw);
    let end_w = bound_w + 1;
    body.push(comment("Incremental I0: per source j (0 column 0, 1 + k edge k) started, I0's quotient q and"));
    body.push(comment("remainder r (normalised, against 2 An) at the source's column on this row, and its steps"));
    body.push(comment("a row (s0: edge without its DDA's carry, s1: with it; v: in range)."));
    body.extend([sreg("w_nx", nx_w), sreg("w_ny", ny_w), reg("w_a", aw), reg("w_fresh", 1)]);
    for j in 0..4 {
        body.extend([reg(&format!("ie_v{j}"), 1), reg(&format!("ie_q{j}"), iw), reg(&format!("ie_r{j}"), aw + 1)]);
        let steps: &[&str] = if j == 0 { &["s0"] } else { &["s0", "s1"] };
        for s in steps {
            body.extend([reg(&format!("ie_{s}v{j}"), 1), reg(&format!("ie_{s}q{j}"), iw), reg(&format!("ie_{s}r{j}"), aw + 1)]);
        }
    }
    body.push(comment("The start the engine made for the next triangle's first row (its source, I0, steps)."));
    body.extend([reg("ie_pv", 1), reg("ie_psrc", 2), reg("ie_pq", iw), reg("ie_pr", aw + 1)]);
    for s in ["p0", "p1"] {
        body.extend([reg(&format!("ie_{s}v"), 1), reg(&format!("ie_{s}q"), iw), reg(&format!("ie_{s}r"), aw + 1)]);
    }
    body.push(comment("The left end's candidates: column 0 when no left edge is inside it, each left edge at it."));
    body.push(wire("ie_c0", 1, format!("mg == {}", slit(end_w, 0))));
    for k in 0..3 {
        body.push(wire(&format!("ie_c{}", k + 1), 1, format!("in{k} && !w_right{k} && gg{k} == mg")));
    }
    for j in 0..4 {
        body.push(wire(&format!("ie_sc{j}"), 1, format!("ie_c{j} && ie_v{j}")));
    }
    body.push(comment("A started candidate if there is one (golden's order), else the first candidate."));
    body.push(wire(
        "ie_sel",
        2,
        "ie_sc0 ? 2'd0 : ie_sc1 ? 2'd1 : ie_sc2 ? 2'd2 : ie_sc3 ? 2'd3 : ie_c0 ? 2'd0 : ie_c1 ? 2'd1 : ie_c2 ? 2'd2 : 2'd3",
    ));
    body.push(wire("ie_wait", 1, "px && !(ie_sc0 || ie_sc1 || ie_sc2 || ie_sc3)"));
    body.push(wire("ie_i0", iw, "ie_sel == 2'd0 ? ie_q0 : ie_sel == 2'd1 ? ie_q1 : ie_sel == 2'd2 ? ie_q2 : ie_q3"));
    body.push(comment("The next triangle is taken once its first row's start is made (ie_pv)."));
    body.push(assign("take", format!("{} && ie_pv && adv && !ie_wait && (!w_valid || w_end)", held(hw))));
}

/// The widths the start engine works in.
#[derive(Clone, Copy)]
struct Ew {
    aw: u32,
    bound_w: u32,
    sum_w: u32,
    recip_w: u32,
    xw: u32,
    iw: u32,
    frac: u32,
    nx_w: u32,
    ny_w: u32,
    a_w: u32,
    b_w: u32,
    p_w: u32,
    e_w: u32,
    y_w: u32,
    cmp_w: u32,
    c_w: u32,
    end_w: u32,
}

impl Ew {
    fn new(hw: &Hw) -> Ew {
        let Widths { aw, gw: bound_w, k: sum_w, rw: recip_w, .. } = hw.fe.widths();
        let (xw, iw, frac) = (hw.fe.cfg.xbits, hw.fe.cfg.iw(), hw.fe.cfg.frac);
        let (nx_w, ny_w) = plane_widths(hw);
        let (a_w, b_w) = (sum_w, recip_w);
        // The highest bit read is the quotient estimate's, K + IW.
        let p_w = sum_w + iw + 1;
        let e_w = nx_w + bound_w + 1;
        let y_w = ny_w.max(e_w) + 2;
        let cmp_w = y_w.max(aw + frac) + 1;
        let c_w = aw + 2;
        let end_w = bound_w + 1;
        Ew { aw, bound_w, sum_w, recip_w, xw, iw, frac, nx_w, ny_w, a_w, b_w, p_w, e_w, y_w, cmp_w, c_w, end_w }
    }
}

/// After the walker: the shared engine, and the sources' state stepped with the walker's row.
pub(super) fn engine(hw: &Hw, body: &mut Vec<Item>) {
    let ew = Ew::new(hw);
    let Ew { aw, bound_w, sum_w, xw, iw, nx_w, a_w, b_w, p_w, e_w, c_w, .. } = ew;
    let (start, col0) = hw.fe.start_clocks();
    let m = hw.fe.start_product_clocks();
    assert!(
        xw <= b_w && bound_w <= b_w && iw < b_w && nx_w <= a_w && c_w <= a_w && e_w - 1 <= p_w,
        "the engine's operands fit its multiplier"
    );
    body.push(Item::Blank);
    if m == 1 {
        body.push(comment(format!(
            "Incremental I0: the start engine, one {a_w} x {b_w} multiplier, {start} clocks a start ({col0} at column 0):"
        )));
    } else {
        body.push(comment(format!(
            "Incremental I0: the start engine, one shift-add multiplier ({a_w} x {b_w}, {m} clocks a product), {start} clocks a start ({col0} at column 0):"
        )));
        body.push(comment("each step below is its product's first clock (ie_k == 0), the product is ready at the next step's."));
    }
    body.push(comment("t0 Gxn lo; t1 S2n, |Nx Qs|; t2 S2n Rn; t3 q~ 2An; t4 I0 and its remainder, Gxn |Qs|; t5 the"));
    body.push(comment("step's numerator X0 = ((512 (Ny - Nx Qs)) << s) + (2An << IW), its range, X0 Rn; t6 q~ 2An; t7 the"));
    body.push(comment("step, X1 = X0 - 2 Gxn, X1 Rn; t8 q~ 2An; t9 X1's step (edges only). It serves the walker's start"));
    body.push(comment("(ie_wait) first; otherwise it starts the held triangle's first row from the set-up's result."));
    body.extend([
        reg("ie_busy", 1),
        reg("ie_pre", 1),
        reg("ie_t", 4),
        reg("ie_src", 2),
        reg("ie_p", p_w),
        reg("ie_u", sum_w),
        reg("ie_qt", iw + 1),
        sreg("ie_e", e_w),
        reg("ie_rq", iw),
        reg("ie_rr", aw + 1),
        reg("ie_aq", iw),
        reg("ie_ar", aw + 1),
        reg("ie_av", 1),
        reg("ie_ok0", 1),
        reg("ie_ok1", 1),
    ]);
    if m > 1 {
        body.push(comment("The shift-add multiplier: the multiplicand shifted up and the multiplier down a bit a clock."));
        body.extend([reg("ie_k", hw.start_count_bits()), reg("ie_sa", p_w), reg("ie_sb", b_w)]);
    }
    first_row(hw, &ew, body);
    body.push(comment("The walker's start goes first: it takes the engine from a first-row start, which starts again."));
    body.push(wire("ie_go", 1, "ie_wait ? (!ie_busy || ie_pre) : (!ie_busy && ie_pneed)"));
    body.push(wire("ie_tt", 4, format!("ie_go ? {} : ie_t", lit(4, 0))));
    operands(hw, &ew, body);
    let prog = program(&ew);
    let walk = source_steps(&ew, body);
    let load = first_row_load();
    // A product's first clock: the whole product, or the shift-add's first partial product.
    let issue = if m == 1 {
        vec![set("ie_p", format!("{} * {}", zext("ie_ma", a_w, p_w), zext("ie_mb", b_w, p_w)))]
    } else {
        vec![
            set("ie_p", format!("ie_mb[0] ? {} : {}", zext("ie_ma", a_w, p_w), lit(p_w, 0))),
            set("ie_sa", format!("{} << 1", zext("ie_ma", a_w, p_w))),
            set("ie_sb", "ie_mb >> 1"),
            set("ie_k", lit(hw.start_count_bits(), 1)),
        ]
    };
    let mut go =
        vec![set("ie_busy", "1'b1"), set("ie_pre", "!ie_wait"), set("ie_t", lit(4, 1)), set("ie_src", "ie_wait ? ie_sel : ie_psel")];
    go.extend(issue.clone());
    let mut busy = issue;
    busy.extend(prog);
    if m > 1 {
        let kw = hw.start_count_bits();
        // The last step issues no product: the engine idles with its clock count at 0.
        busy.push(Stmt::If("ie_last".into(), vec![set("ie_k", lit(kw, 0))], vec![]));
        let add = vec![
            set("ie_p", format!("ie_p + (ie_sb[0] ? ie_sa : {})", lit(p_w, 0))),
            set("ie_sa", "ie_sa << 1"),
            set("ie_sb", "ie_sb >> 1"),
            set("ie_k", format!("ie_k == {} ? {} : ie_k + {}", lit(kw, (m - 1) as u64), lit(kw, 0), lit(kw, 1))),
        ];
        busy = vec![Stmt::If(format!("ie_k != {}", lit(kw, 0)), add, busy)];
    }
    let mut reset = vec![set("ie_busy", "1'b0"), set("ie_t", lit(4, 0)), set("ie_pv", "1'b0")];
    if m > 1 {
        reset.push(set("ie_k", lit(hw.start_count_bits(), 0)));
    }
    body.push(Item::Always(vec![Stmt::If(
        "rst".into(),
        reset,
        vec![
            Stmt::If("ie_go".into(), go, vec![Stmt::If("ie_busy".into(), busy, vec![])]),
            Stmt::If("take".into(), load, vec![Stmt::If("adv && w_valid && !ie_wait".into(), walk, vec![])]),
        ],
    )]));
    body.push(Item::Blank);
}

/// The held triangle's first row: its left end and the source giving it.
fn first_row(hw: &Hw, ew: &Ew, body: &mut Vec<Item>) {
    let Ew { bound_w, end_w, .. } = *ew;
    body.push(comment("The held triangle's first row: its left end and the source giving it (none started yet)."));
    for k in 0..3 {
        body.push(wire(&format!("pin{k}"), 1, format!("s_act{k} && s_rs{k} <= s_first && s_first <= s_re{k}")));
        body.push(swire(&format!("pgg{k}"), end_w, sext(&format!("r_g{k}"), bound_w, end_w)));
        body.push(swire(&format!("plg{k}"), end_w, format!("(pin{k} && !s_right{k} && pgg{k} < lo0) ? pgg{k} : lo0")));
    }
    body.push(swire("pmg", end_w, min3("plg")));
    body.push(comment("verilator lint_off UNUSEDSIGNAL"));
    body.push(swire("plo", end_w, "-pmg"));
    body.push(comment("verilator lint_on UNUSEDSIGNAL"));
    body.push(wire("ie_pc0", 1, format!("pmg == {}", slit(end_w, 0))));
    // Edge 2 is the source when none before it is a candidate.
    for k in 0..2 {
        body.push(wire(&format!("ie_pc{}", k + 1), 1, format!("pin{k} && !s_right{k} && pgg{k} == pmg")));
    }
    body.push(wire("ie_psel", 2, "ie_pc0 ? 2'd0 : ie_pc1 ? 2'd1 : ie_pc2 ? 2'd2 : 2'd3"));
    body.push(wire("ie_pneed", 1, format!("{} && !ie_pv", held(hw))));
}

/// The engine's operands and its arithmetic around the one product.
fn operands(hw: &Hw, ew: &Ew, body: &mut Vec<Item>) {
    let Ew { aw, bound_w, sum_w, recip_w, xw, iw, frac, nx_w, ny_w, a_w, b_w, e_w, y_w, cmp_w, c_w, .. } = *ew;
    body.push(comment("Operands: the set-up's result for a first-row start, the walker's otherwise."));
    body.push(wire("ie_su", 1, "ie_go ? !ie_wait : ie_pre"));
    let x = |name: &str, w: u32, su: &str, wk: &str, signed: bool| {
        let v = format!("ie_su ? {su} : {wk}");
        if signed {
            swire(name, w, v)
        } else {
            wire(name, w, v)
        }
    };
    body.extend([
        x("x_lo", xw, &format!("plo[{}:0]", xw - 1), "lo_u", false),
        x("x_gxn", sum_w, "s_gxn", "w_gxn", false),
        x("x_tn", sum_w, "s_tn", "w_tn", false),
        x("x_dyn", sum_w, "s_dyn", "w_dyn", false),
        x("x_an", aw, "s_an", "w_an", false),
        x("x_rn", recip_w, if hw.engine_form() { "r_rn" } else { "drn_q" }, "w_rn", false),
        x("x_nx", nx_w, "s_nx", "w_nx", true),
        x("x_ny", ny_w, "s_ny", "w_ny", true),
        x("x_a", aw, "s_a", "w_a", false),
    ]);
    for k in 0..3 {
        body.push(x(&format!("x_qs{k}"), bound_w, &format!("r_qs{k}"), &format!("w_qs{k}"), true));
    }
    let pick = |f: &dyn Fn(usize) -> String| {
        format!("ie_src == 2'd1 ? {} : ie_src == 2'd2 ? {} : ie_src == 2'd3 ? {} : {}", f(0), f(1), f(2), f(3))
    };
    body.push(swire("ie_qs", bound_w, pick(&|k| if k < 3 { format!("x_qs{k}") } else { slit(bound_w, 0) })));
    body.push(wire("ie_qneg", 1, format!("ie_qs[{}]", bound_w - 1)));
    body.push(wire("ie_qa", bound_w, "ie_qneg ? -ie_qs : ie_qs"));
    body.push(wire("ie_nxneg", 1, format!("x_nx[{}]", nx_w - 1)));
    body.push(wire("ie_nxa", nx_w, "ie_nxneg ? -x_nx : x_nx"));
    body.push(wire("ie_an2", aw + 1, "{x_an, 1'b0}"));
    body.push(wire("ie_qtp", iw + 1, format!("ie_p[{}:{sum_w}]", sum_w + iw)));
    body.push(wire("ie_pm", sum_w, format!("ie_qneg ? -ie_p[{}:0] : ie_p[{}:0]", sum_w - 1, sum_w - 1)));
    body.push(wire("ie_u0", sum_w, format!("((x_dyn - ie_pm) << 1) + ({} << {iw})", zext("ie_an2", aw + 1, sum_w))));
    body.push(wire("ie_u1", sum_w, "ie_u - (x_gxn << 1)"));
    let is = |ts: &[u32]| ts.iter().map(|t| format!("ie_tt == {}", lit(4, *t as u64))).collect::<Vec<_>>().join(" || ");
    body.push(wire(
        "ie_ma",
        a_w,
        format!(
            "({}) ? x_gxn : ({}) ? {} : ({}) ? {} : ({}) ? ie_u0 : ({}) ? ie_u1 : ie_u",
            is(&[0, 4]),
            is(&[1]),
            zext("ie_nxa", nx_w, a_w),
            is(&[3, 6, 8]),
            zext("ie_an2", aw + 1, a_w),
            is(&[5]),
            is(&[7]),
        ),
    ));
    body.push(wire(
        "ie_mb",
        b_w,
        format!(
            "({}) ? {} : ({}) ? {} : ({}) ? {} : x_rn",
            is(&[0]),
            zext("x_lo", xw, b_w),
            is(&[1, 4]),
            zext("ie_qa", bound_w, b_w),
            is(&[3, 6, 8]),
            zext("ie_qtp", iw + 1, b_w)
        ),
    ));
    body.push(comment("The correction: c = U - q~ 2An (mod 2^(AW+2)), the quotient q~ + (c >= 2An), the remainder."));
    body.push(comment("verilator lint_off UNUSEDSIGNAL"));
    body.push(wire("ie_c", c_w, format!("ie_u[{}:0] - ie_p[{}:0]", c_w - 1, c_w - 1)));
    body.push(wire("ie_ge", 1, format!("ie_c >= {}", zext("ie_an2", aw + 1, c_w))));
    body.push(wire("ie_cq", iw + 1, format!("ie_qt + {}", zext("ie_ge", 1, iw + 1))));
    body.push(wire("ie_cr", c_w, format!("ie_ge ? ie_c - {} : ie_c", zext("ie_an2", aw + 1, c_w))));
    body.push(comment("verilator lint_on UNUSEDSIGNAL"));
    body.push(swire("ie_y0", y_w, format!("{} - {}", sext("x_ny", ny_w, y_w), sext("ie_e", e_w, y_w))));
    body.push(swire("ie_y1", y_w, format!("ie_y0 - {}", sext("x_nx", nx_w, y_w))));
    body.push(wire("ie_lim", cmp_w, format!("{} << {frac}", zext("x_a", aw, cmp_w))));
    for c in 0..2 {
        body.push(wire(&format!("ie_ya{c}"), y_w, format!("ie_y{c}[{}] ? -ie_y{c} : ie_y{c}", y_w - 1)));
    }
    body.push(wire(
        "ie_last",
        1,
        format!("ie_t == {} || (ie_src == 2'd0 && ie_t == {})", lit(4, EDGE_PRODUCTS as u64), lit(4, COL0_PRODUCTS as u64)),
    ));
    let cq = format!("ie_cq[{}:0]", iw - 1);
    let cr = format!("ie_cr[{}:0]", aw);
    body.push(comment("What the last clock writes: the start, the step without the carry, the step with it."));
    body.push(wire("ie_d0v", 1, "ie_src == 2'd0 ? ie_ok0 : ie_av"));
    body.push(wire("ie_d0q", iw, format!("ie_src == 2'd0 ? {cq} : ie_aq")));
    body.push(wire("ie_d0r", aw + 1, format!("ie_src == 2'd0 ? {cr} : ie_ar")));
}

/// The engine's program, one step a clock (the go clock is t0).
fn program(ew: &Ew) -> Vec<Stmt> {
    let Ew { aw, sum_w, iw, e_w, y_w, cmp_w, .. } = *ew;
    let (cq, cr) = (format!("ie_cq[{}:0]", iw - 1), format!("ie_cr[{}:0]", aw));
    // The program, one step a clock; the go clock is t0.
    let at = |t: u32, then: Vec<Stmt>| Stmt::If(format!("ie_t == {}", lit(4, t as u64)), then, vec![]);
    let mut prog = vec![
        set("ie_t", format!("ie_t + {}", lit(4, 1))),
        at(1, vec![set("ie_u", format!("((x_tn + ie_p[{}:0]) << 1) + {}", sum_w - 1, zext("x_an", aw, sum_w)))]),
        at(
            2,
            vec![set(
                "ie_e",
                format!(
                    "(ie_nxneg ^ ie_qneg) ? -{} : {}",
                    zext(&format!("ie_p[{}:0]", e_w - 2), e_w - 1, e_w),
                    zext(&format!("ie_p[{}:0]", e_w - 2), e_w - 1, e_w)
                ),
            )],
        ),
        at(3, vec![set("ie_qt", "ie_qtp")]),
        at(4, vec![set("ie_rq", cq.clone()), set("ie_rr", cr.clone())]),
        at(
            5,
            vec![
                set("ie_u", "ie_u0"),
                set("ie_ok0", format!("{} < ie_lim", zext("ie_ya0", y_w, cmp_w))),
                set("ie_ok1", format!("{} < ie_lim", zext("ie_ya1", y_w, cmp_w))),
            ],
        ),
        at(6, vec![set("ie_qt", "ie_qtp")]),
        at(7, vec![set("ie_aq", cq.clone()), set("ie_ar", cr.clone()), set("ie_av", "ie_ok0"), set("ie_u", "ie_u1")]),
        at(8, vec![set("ie_qt", "ie_qtp")]),
    ];
    // The last clock writes the source's state (started, I0 here, its steps), or for a first
    // row the held start.
    let mut own = Vec::new();
    for j in 0..4 {
        let mut w = vec![set(format!("ie_v{j}"), "1'b1"), set(format!("ie_q{j}"), "ie_rq"), set(format!("ie_r{j}"), "ie_rr")];
        w.extend([set(format!("ie_s0v{j}"), "ie_d0v"), set(format!("ie_s0q{j}"), "ie_d0q"), set(format!("ie_s0r{j}"), "ie_d0r")]);
        if j > 0 {
            w.extend([set(format!("ie_s1v{j}"), "ie_ok1"), set(format!("ie_s1q{j}"), cq.clone()), set(format!("ie_s1r{j}"), cr.clone())]);
        }
        own.push(Stmt::If(format!("ie_src == {}", lit(2, j as u64)), w, vec![]));
    }
    let held = vec![
        set("ie_pv", "1'b1"),
        set("ie_psrc", "ie_src"),
        set("ie_pq", "ie_rq"),
        set("ie_pr", "ie_rr"),
        set("ie_p0v", "ie_d0v"),
        set("ie_p0q", "ie_d0q"),
        set("ie_p0r", "ie_d0r"),
        set("ie_p1v", "ie_ok1"),
        set("ie_p1q", cq.clone()),
        set("ie_p1r", cr.clone()),
    ];
    prog.push(Stmt::If(
        "ie_last".into(),
        vec![set("ie_busy", "1'b0"), set("ie_t", lit(4, 0)), Stmt::If("ie_pre".into(), held, own)],
        vec![],
    ));

    prog
}

/// The sources stepped with the walker's row; a first row with no pixel drops the held start.
fn source_steps(ew: &Ew, body: &mut Vec<Item>) -> Vec<Stmt> {
    let Ew { aw, iw, .. } = *ew;
    // The sources step with the walker's row: edge k's by its DDA's carry this row.
    let mut walk = Vec::new();
    for j in 0..4 {
        let cond = if j == 0 { "1'b1".to_string() } else { format!("w_act{k} && w_row >= w_rs{k}", k = j - 1) };
        let field = |f: &str| if j == 0 { format!("ie_s0{f}0") } else { format!("(cy{} ? ie_s1{f}{j} : ie_s0{f}{j})", j - 1) };
        body.push(wire(&format!("ie_sv{j}"), 1, field("v")));
        body.push(wire(
            &format!("ie_sr{j}"),
            aw + 2,
            format!("{} + {}", zext(&format!("ie_r{j}"), aw + 1, aw + 2), zext(&field("r"), aw + 1, aw + 2)),
        ));
        body.push(wire(&format!("ie_cy{j}"), 1, format!("ie_sr{j} >= {}", zext("{w_an, 1'b0}", aw + 1, aw + 2))));
        body.push(comment("verilator lint_off UNUSEDSIGNAL"));
        body.push(wire(&format!("ie_rn{j}"), aw + 2, format!("ie_cy{j} ? ie_sr{j} - {} : ie_sr{j}", zext("{w_an, 1'b0}", aw + 1, aw + 2))));
        body.push(comment("verilator lint_on UNUSEDSIGNAL"));
        walk.push(Stmt::If(
            cond,
            vec![Stmt::If(
                format!("ie_v{j} && ie_sv{j}"),
                vec![
                    set(format!("ie_r{j}"), format!("ie_rn{j}[{aw}:0]")),
                    set(format!("ie_q{j}"), format!("ie_q{j} + {} + {}", field("q"), zext(&format!("ie_cy{j}"), 1, iw))),
                ],
                vec![set(format!("ie_v{j}"), "1'b0")],
            )],
            vec![],
        ));
    }
    // A first row with no pixel starts nothing: the held start (at a column that may be far off
    // the triangle, where the reciprocal is not exact) is dropped.
    walk.push(Stmt::If("w_fresh && !px".into(), (0..4).map(|j| set(format!("ie_v{j}"), "1'b0")).collect(), vec![]));
    walk.push(set("w_fresh", "1'b0"));
    walk
}

/// The walker's load: the held start into its source.
fn first_row_load() -> Vec<Stmt> {
    let mut load = vec![set("w_nx", "s_nx"), set("w_ny", "s_ny"), set("w_a", "s_a"), set("w_fresh", "1'b1"), set("ie_pv", "1'b0")];
    for j in 0..4 {
        let mut w = vec![set(format!("ie_v{j}"), "1'b1"), set(format!("ie_q{j}"), "ie_pq"), set(format!("ie_r{j}"), "ie_pr")];
        w.extend([set(format!("ie_s0v{j}"), "ie_p0v"), set(format!("ie_s0q{j}"), "ie_p0q"), set(format!("ie_s0r{j}"), "ie_p0r")]);
        if j > 0 {
            w.extend([set(format!("ie_s1v{j}"), "ie_p1v"), set(format!("ie_s1q{j}"), "ie_p1q"), set(format!("ie_s1r{j}"), "ie_p1r")]);
        }
        load.push(Stmt::If(format!("ie_psrc == {}", lit(2, j as u64)), w, vec![set(format!("ie_v{j}"), "1'b0")]));
    }
    load
}

/// The span path of the incremental form: the walker's span (I0 included) carried through the
/// same register stages as the reciprocal form's, so latency and the properties are the same.
pub(super) fn span_path(hw: &Hw) -> Stager {
    let fe = &hw.fe;
    let Widths { yw: row_w, .. } = fe.widths();
    let (xw, iw, dw) = (fe.cfg.xbits, fe.cfg.iw(), fe.cfg.dw());
    let mut sp = Stager::new("p", golden::pipeline::i0_registers(hw.pipeline).to_vec());
    for (n, ww, src) in [
        ("y", row_w, "w_row".to_string()),
        ("x", xw, "lo_u".into()),
        ("len", xw + 1, format!("len_w[{xw}:0]")),
        ("di", dw, "w_di".into()),
        ("i0w", iw, "ie_i0".into()),
    ] {
        sp.input_as(n, ww, false, &src);
    }
    for _ in 1..golden::pipeline::I0_STAGES.len() {
        sp.cut();
    }
    sp.note(comment("Incremental I0: the span path carries the walker's span to the output register."));
    let i0w = sp.at("i0w");
    sp.def("i0", iw, false, i0w);
    sp
}
