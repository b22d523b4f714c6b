//! `tri_fe_edge`: one edge of the triangle, instanced three times by a `generate` loop in
//! `tri_frontend`. From CALC's values for the edge to its bound on the walked row: the set-up
//! result (its rows, its divisor, and its two divisions, the first bound and the step), then the
//! walker's integer DDA (a compare and two adds side by side a row).

use super::divider::counter_width;
use super::divider::{Div, DivConns};
use super::hw::Hw;
use crate::verilog::{comment, reg, set, sext, sreg, swire, wire, zext, Item, Module, Port, Stmt};
use crate::Names;
use golden::frontend::Widths;

/// The widths one edge works in.
/// D = 256 |dy| and rs256 = 256 Rs: both end in this many zero bits, so the remainder's low bits
/// never move nor carry (the lean DDA holds the rest, [`EdgeWidths::high_w`]).
const SCALE_BITS: u32 = 8;

struct EdgeWidths {
    row_w: u32,
    vy_w: u32,
    bound_w: u32,
    ediv_w: u32,
    /// The span's ends: a bound and one bit.
    end_w: u32,
    /// The dividends of the first bound and of the step.
    pw_init: u32,
    pw_step: u32,
    cnt_w: u32,
    /// The walked row's place among the edge's rows held in registers, moved with the row
    /// (behind the row stages, [`Hw::row_stage`]), and the walker's load and step taken apart
    /// from its stall: see [`dda`].
    tracked: bool,
    /// The lean DDA behind the sequential span path (the iCE40 forms): see [`dda`].
    lean: bool,
    /// The engine forms the DDA's start, `thr` and `t` (golden's `Plan::edge_t`): the edge
    /// loads them as they come, without `D` and `rem` (see [`dda`]).
    engine_t: bool,
}

impl EdgeWidths {
    fn new(hw: &Hw) -> EdgeWidths {
        let wd = hw.fe.widths();
        let Widths { yw: row_w, cy: vy_w, gw: bound_w, dw_edge: ediv_w, .. } = wd;
        assert_eq!(ediv_w, vy_w + 8, "an edge's divisor is |dy| in sub-pixels, 8 fraction bits");
        // g's distance to the screen's right bound fits the bounds' width (see `dda`).
        assert!(u64::from(hw.fe.screen.width) <= 1 << (bound_w - 1), "the screen is wider than 2^(GW-1)");
        EdgeWidths {
            row_w,
            vy_w,
            bound_w,
            ediv_w,
            end_w: bound_w + 1,
            pw_init: bound_w + ediv_w,
            pw_step: bound_w + vy_w,
            cnt_w: counter_width(&wd),
            tracked: hw.row_stage(),
            lean: hw.engine_form() && hw.fe.span_seq().is_some() && !hw.row_stage(),
            engine_t: hw.row_stage() && hw.fe.setup.plan().is_some_and(|p| p.edge_t),
        }
    }

    /// The lean DDA's width: the divisor's bits above [`SCALE_BITS`].
    fn high_w(&self) -> u32 {
        self.ediv_w - SCALE_BITS
    }

    /// The width the edge takes and holds `D`, `rem` and `rs256` in: their bits above
    /// [`SCALE_BITS`] behind the row stages (see [`dda`]), else whole.
    fn held_w(&self) -> u32 {
        if self.tracked {
            self.high_w()
        } else {
            self.ediv_w
        }
    }
}

/// How many low bits of `D`, `rem` and `rs256` the edges never read: the set-up result leaves
/// them out (`engine::result::fields`). Behind the row stages the DDA holds the high bits alone.
pub(super) fn dropped_low_bits(hw: &Hw) -> u32 {
    let e = EdgeWidths::new(hw);
    e.ediv_w - e.held_w()
}

/// Whether the edges take the DDA's start `thr` and `t` from the engine, in place of `D` and
/// `rem` (`engine::result::fields`).
pub(super) fn start_from_engine(hw: &Hw) -> bool {
    EdgeWidths::new(hw).engine_t
}

/// The per-edge values CALC hands on and the edges' bounds the walker reads: buses of three lanes,
/// edge k in lane k (`name[k*w +: w]`).
pub(super) struct EdgeBuses {
    /// `(port, bus, lane width)` per input, in port order.
    pub inputs: Vec<(&'static str, &'static str, u32)>,
}

/// The buses into the edges: `(port, bus name, lane width)`; the caller declares them.
pub(super) fn input_buses(hw: &Hw) -> EdgeBuses {
    let e = EdgeWidths::new(hw);
    if hw.engine_form() {
        // The shared engine's result: the edge's set-up complete, divisions made.
        let dw = e.held_w();
        let (d, rem) = if e.engine_t { (("thr", "e_thr", dw), ("t", "e_t", dw + 1)) } else { (("d", "e_d", dw), ("rem", "e_rem", dw)) };
        return EdgeBuses {
            inputs: vec![
                ("act", "e_act", 1),
                ("right", "e_right", 1),
                ("rs", "e_rs", e.row_w),
                ("re", "e_re", e.row_w),
                d,
                ("g", "e_g", e.bound_w),
                rem,
                ("qs", "e_qs", e.bound_w),
                ("rs256", "e_rs256", dw),
            ],
        };
    }
    EdgeBuses {
        inputs: vec![
            ("n", "e_n", e.pw_init),
            ("sn", "e_sn", e.pw_step),
            ("ady", "e_ady", e.vy_w),
            ("act", "e_act", 1),
            ("right", "e_right", 1),
            ("rs", "e_rs", e.row_w),
            ("re", "e_re", e.row_w),
        ],
    }
}

/// The signed width of an edge's bound on the walked row (`lg`, `ha`).
pub(super) fn end_width(hw: &Hw) -> u32 {
    EdgeWidths::new(hw).end_w
}

/// A quotient `q` offset by B = 2^(w-1) as the signed `q - B`: its top bit inverted.
fn offset_to_signed(q: &str, w: u32) -> String {
    if w == 1 {
        format!("~{q}")
    } else {
        format!("{{~{q}[{}], {q}[{}:0]}}", w - 1, w - 2)
    }
}

/// What the incremental I0 (`--fe-i0 incremental`, `super::incremental`) or the left slots'
/// running sums (`Hw::run_sums`, `super::sums`) read of each edge, as extra outputs `(port,
/// width, signed, the edge's signal, tri_frontend's name of lane k)`: the walker's state and the
/// held set-up result. None in the default form.
pub(super) fn state_outputs(hw: &Hw) -> Vec<(&'static str, u32, bool, String, &'static str)> {
    let e = EdgeWidths::new(hw);
    if hw.run_sums() {
        // The walker's left slots step their running sums with the edge's DDA: whether it
        // steps on the next row and whether it carries.
        let on = if e.tracked { "w_act && w_ge" } else { "w_act && row >= w_rs" };
        return vec![("x_on", 1, false, on.into(), "e_on"), ("x_cy", 1, false, "cy".into(), "e_cy")];
    }
    if !super::incremental::on(hw) {
        return Vec::new();
    }
    let flip = |q: &str| offset_to_signed(q, e.bound_w);
    // Behind an engine the held set-up result is the queue head, the edge's inputs.
    let engine = hw.engine_form();
    let held = |parallel: String, input: &str| if engine { input.to_string() } else { parallel };
    vec![
        ("x_in", 1, false, "in_rows".into(), "in"),
        ("x_right", 1, false, "w_right".into(), "w_right"),
        ("x_g", e.end_w, true, "gg".into(), "gg"),
        ("x_act", 1, false, "w_act".into(), "w_act"),
        ("x_rs", e.row_w, false, "w_rs".into(), "w_rs"),
        ("x_qs", e.bound_w, true, "w_qs".into(), "w_qs"),
        ("x_cy", 1, false, "cy".into(), "cy"),
        ("x_sact", 1, false, held("s_act".into(), "act"), "s_act"),
        ("x_sright", 1, false, held("s_right".into(), "right"), "s_right"),
        ("x_srs", e.row_w, false, held("s_rs".into(), "rs"), "s_rs"),
        ("x_sre", e.row_w, false, held("s_re".into(), "re"), "s_re"),
        ("x_rg", e.bound_w, true, held(flip("ei_q"), "g"), "r_g"),
        ("x_rqs", e.bound_w, true, held(flip("es_q"), "qs"), "r_qs"),
    ]
}

/// The ports of [`state_outputs`].
fn state_ports(hw: &Hw) -> Vec<Port> {
    let reader = if hw.run_sums() { "walker's running sums" } else { "incremental I0" };
    let out = |(port, w, signed, _, name): (&str, u32, bool, String, &str)| {
        let p = Port::output(port, w, if signed { "signed integer" } else { "" }, &format!("for the {reader}: the edge's {name}"));
        if signed {
            p.signed()
        } else {
            p
        }
    };
    state_outputs(hw).into_iter().map(out).collect()
}

/// The `generate` loop of the three edges in `tri_frontend`: each lane of the input buses into
/// its edge, each edge's outputs for the span's ends into `e_<port>` ([`end_ports`]).
pub(super) fn instances(hw: &Hw, names: &Names, buses: &EdgeBuses) -> Item {
    let e = EdgeWidths::new(hw);
    let lane = |bus: &str, w: u32| if w == 1 { format!("{bus}[k]") } else { format!("{bus}[k*{w} +: {w}]") };
    let engine = hw.engine_form();
    let walker: &[(&str, &str)] = if e.tracked {
        &[("go", "adv"), ("next", "w_next"), ("more", "w_more"), ("first", "s_first")]
    } else {
        &[("take", "w_load"), ("step", "w_step")]
    };
    // Loaded a field a clock from the walk memory: each edge's nine bits of e_ld.
    let walker: &[(&str, &str)] = if hw.edges_in_walk_ram() { &[("ld", "e_ld[k*9 +: 9]"), ("step", "w_step")] } else { walker };
    let mut conns: Vec<(String, String)> = [("clk", "clk"), ("calc_go", "calc_go"), ("div_run", "div_run"), ("div_cnt", "div_cnt")]
        .iter()
        .chain(walker)
        .chain(&[("row", "w_row"), ("lo", "lo0"), ("hi", "hi0")])
        .filter(|(p, _)| !engine || !["calc_go", "div_run", "div_cnt"].contains(p))
        .map(|(p, s)| (p.to_string(), s.to_string()))
        .collect();
    conns.extend(buses.inputs.iter().map(|(port, bus, w)| (port.to_string(), lane(bus, *w))));
    conns.extend(end_ports(hw).iter().map(|(p, w)| (p.to_string(), lane(&format!("e_{p}"), *w))));
    conns.extend(state_outputs(hw).iter().map(|(port, w, ..)| (port.to_string(), lane(&format!("e_{port}"), *w))));
    Item::ForGenerate {
        var: "k".into(),
        count: 3,
        label: "g_edge".into(),
        body: vec![Item::Instance { module: names.fe_edge.clone(), name: "u_edge".into(), params: vec![], conns }],
    }
}

/// The set-up dividers of one edge: its first bound and its step.
pub(super) fn dividers(hw: &Hw) -> [Div; 2] {
    let e = EdgeWidths::new(hw);
    [Div { name: "u_ei", pw: e.pw_init, qb: e.bound_w }, Div { name: "u_es", pw: e.pw_step, qb: e.bound_w }]
}

/// `tri_fe_edge`.
pub(super) fn module(hw: &Hw, names: &Names) -> Module {
    if hw.engine_form() {
        return module_engine(hw, names);
    }
    let e = EdgeWidths::new(hw);
    let EdgeWidths { row_w, vy_w, bound_w, ediv_w, end_w, pw_init, pw_step, cnt_w, .. } = e;
    let header = vec![
        format!("{} — one edge of {}'s triangle (edge k from vertex k+1 to vertex k+2; three instances).", names.fe_edge, names.frontend),
        "Generated by segshade hdl-gen; do not edit.".into(),
        String::new(),
        "Set-up (calc_go, CALC's last clock): the edge's rows rs..re, its side, its divisor D = 256 |dy| (|dy| in sub-pixels), two".into(),
        format!("divisions on {} ({bound_w} quotient bits, {} a clock, run by the owner's div_cnt):", names.fe_div, hw.div_bits),
        "the first bound g = floor(n / D) - B and the step qs = floor(sn / |dy|) - B (B = 2^(GW-1)), remainders kept.".into(),
        format!("Walker ({}): on an active row g += qs + carry, the remainder", walker_moves(&e)),
        "rem += rs256 modulo D (its carry rem >= D - rs256 and both steps side by side); lg/ha is g on the edge's side of the row, else lo/hi.".into(),
        format!("Widths: bound GW = {bound_w} signed, divisor {ediv_w}, rows {row_w}, bounds out {end_w} signed."),
    ];
    let mut ports = vec![
        Port::input("clk", 1, "", "rising edge"),
        Port::input("calc_go", 1, "", "CALC's last clock: take this edge's values, start its divisions"),
        Port::input("div_run", 1, "", "the set-up's divider clock"),
        Port::input("div_cnt", cnt_w, "unsigned integer", "the set-up's divider counter"),
        Port::input("n", pw_init, "unsigned integer", "the first bound's dividend, offset by B D"),
        Port::input("sn", pw_step, "unsigned integer", "the step's dividend, offset by B D / 256"),
        Port::input("ady", vy_w, &format!("UQ{}.8", vy_w - 8), "|dy|, pixels"),
        Port::input("act", 1, "", "the edge bounds some row"),
        Port::input("right", 1, "", "the interior is on its left: it bounds the span's right end"),
        Port::input("rs", row_w, "unsigned integer", "first row"),
        Port::input("re", row_w, "unsigned integer", "last row"),
    ];
    ports.extend(walker_ports(&e));
    ports.extend(state_ports(hw));
    let mut body = vec![comment("Set-up: the edge's rows, side and divisor, held until the walker takes them.")];
    // Behind the row stages the DDA takes D's high bits alone (`held_w`): |dy| itself.
    let s_d = if e.tracked { "ady".to_string() } else { format!("{{ady, {SCALE_BITS}'d0}}") };
    body.extend([reg("s_act", 1), reg("s_right", 1), reg("s_rs", row_w), reg("s_re", row_w), reg("s_d", e.held_w())]);
    body.push(Item::Always(vec![Stmt::If(
        "calc_go".into(),
        vec![set("s_act", "act"), set("s_right", "right"), set("s_rs", "rs"), set("s_re", "re"), set("s_d", s_d)],
        vec![],
    )]));
    body.push(comment("Its divisions: the first bound (ei) and the step (es), q - B = g."));
    let [ei, es] = dividers(hw);
    for (d, dividend, shift) in [(&ei, "n", bound_w + 7), (&es, "sn", bound_w - 1)] {
        let divisor = format!("{} << {shift}", zext("ady", vy_w, d.pw));
        let conns = DivConns { cnt: "div_cnt", load: "calc_go", run: "div_run", dividend, divisor: &divisor };
        // The remainder is read in part (its low bits): declared with the unused.
        body.extend(d.instance(&names.fe_div, hw.div_bits, cnt_w, &conns, &["q"]));
    }
    let flip = |q: &str| offset_to_signed(q, bound_w);
    // Behind the row stages the DDA holds the bits above SCALE_BITS (`held_w`): rs256's are the
    // step's remainder itself, D's |dy|.
    let (rs256, rem, d) = if e.tracked {
        (format!("es_p[{}:0]", vy_w - 1), format!("ei_p[{}:{SCALE_BITS}]", ediv_w - 1), "s_d".to_string())
    } else {
        (format!("{{es_p[{}:0], {SCALE_BITS}'d0}}", vy_w - 1), format!("ei_p[{}:0]", ediv_w - 1), "s_d".to_string())
    };
    body.extend(dda(&e));
    let load = vec![
        set("w_act", "s_act"),
        set("w_right", "s_right"),
        set("w_rs", "s_rs"),
        set("w_re", "s_re"),
        set("w_thr", format!("{d} - {rs256}")),
        set("w_g", flip("ei_q")),
        rem_load(&e, &mut body, (&rem, &rs256, &d)),
        set("w_qs", flip("es_q")),
        set("w_qs1", format!("{} + {}", flip("es_q"), zext("1'b1", 1, bound_w))),
        set("w_rs256", rs256),
    ];
    // The first bound g = q - B extended: q's top bit inverted, repeated.
    let g0 = format!("{{{{{}{{~ei_q[{}]}}}}, ei_q[{}:0]}}", end_w + 1 - bound_w, bound_w - 1, bound_w - 2);
    body.push(walk(&e, load, ("s_rs", "s_re"), (&g0, "s_right")));
    body.extend(state_outputs(hw).into_iter().map(|(port, _, _, signal, _)| Item::Assign(port.into(), signal)));
    Module { name: names.fe_edge.clone(), header, params: vec![], ports, body }
}

/// The walker's DDA of an edge: its state, its bound on the row, its step.
///
/// Behind the row stages (`tracked`) the row's place among the edge's rows is two registers
/// moved with the row (`w_ge`: row >= rs, `w_le`: row <= re), so the bound on the row is a
/// constant compare and a select from registers: the rows' compares, then the bound's compare
/// and select into the row stage, were the walker's longest path once the row stages took the
/// span's decision (docs/fpga.md).
///
/// Lean (behind the sequential span path, where the walker waits 36 clocks a covered row and the
/// clock is the iCE40's): D itself is held, not thr, and the carry is the borrow of s minus D
/// (s = rem + rs256), whose difference is also the next remainder; the bound's step adds the
/// carry as its adder's carry in. Two chained carry chains where the side-by-side form has four
/// beside a compare, a held qs + 1 and two selects; and D and rs256 have eight zero bits (both
/// are 256 times an integer), so rem's low byte never moves nor carries and the DDA holds the
/// high bits alone (the queue's low bytes then have no reader either): an edge 201 SB_LUT4 and
/// 107 flip-flops where the side-by-side form has 452 and 146 (docs/fpga.md, *The HX8K fit*).
fn dda(e: &EdgeWidths) -> Vec<Item> {
    let EdgeWidths { row_w, bound_w, ediv_w, end_w, tracked, .. } = *e;
    let mut body = vec![Item::Blank, comment("Walker: the edge's DDA state, loaded from the set-up result.")];
    let hw_ = e.high_w();
    if e.lean {
        body.push(comment("The DDA on the high bits (D and rs256 have eight zero bits: rem's low byte never carries nor moves):"));
        body.push(comment("s = rem + rs256, its carry s >= D (the borrow of s - D): the next remainder s - D or s, g + qs + carry."));
        body.extend([reg("w_act", 1), reg("w_right", 1), reg("w_rs", row_w), reg("w_re", row_w), reg("w_d", hw_)]);
        body.extend([reg("w_rem", hw_), reg("w_rs256", hw_), sreg("w_g", bound_w), sreg("w_qs", bound_w)]);
        body.push(comment("verilator lint_off UNUSEDSIGNAL"));
        let low = SCALE_BITS - 1;
        body.push(wire("unused_low", 3 * SCALE_BITS, format!("{{d[{low}:0], rem[{low}:0], rs256[{low}:0]}}")));
        body.push(comment("verilator lint_on UNUSEDSIGNAL"));
    } else {
        // The step's carry, rem + rs256 >= D, is decided as rem >= thr (thr = D - rs256, from the
        // load), and both next remainders and both next bounds (qs, qs + 1) are formed beside it:
        // the add, compare, add it chained was the staged front-end's clock once the row stage
        // took the span's decision off the walker (docs/fpga.md).
        body.push(comment("thr = D - rs256 (> 0: rs256 < D), qs1 = qs + 1: the carry and both steps side by side."));
        if tracked {
            body.push(comment("D, rs256 and thr end in eight zero bits: rem's low byte never carries nor moves, so rem, thr and rs256 are their high bits."));
        }
        // Behind the row stages only the bits above SCALE_BITS are held (`held_w`): thr is a
        // multiple of 256, so rem >= thr is decided by rem's high bits, and the low byte of
        // rem + rs256 never changes.
        let dw = e.held_w();
        body.extend([reg("w_act", 1), reg("w_right", 1), reg("w_rs", row_w), reg("w_re", row_w), reg("w_thr", dw)]);
        // Behind the row stages the remainder is held offset by the threshold, so the carry is
        // that register's sign: the compare on the carry chain, then the walker's running sums'
        // enables, was the ECP5 target's critical path (docs/fpga.md).
        body.push(if tracked { sreg("w_t", dw + 1) } else { reg("w_rem", dw) });
        body.extend([reg("w_rs256", dw), sreg("w_g", bound_w), sreg("w_qs", bound_w), sreg("w_qs1", bound_w)]);
        if tracked {
            // g's distance to the screen's bound on its side, stepped beside g: its sign is
            // `g < bound`, where the compare on the carry chain behind g, then the running sums'
            // slot select, was the 25F's critical path (docs/fpga.md). It fits the bounds' width
            // (g in GW bits, the bound 0 or at most 2^(GW-1)), and a step that wraps g flips its
            // top bit, so it is g's distance in every state a load leads to: the proof's
            // invariant ([`formal_probes`]).
            body.push(comment("w_gd = g - (right ? hi : lo), stepped with g: its sign is g < the screen's bound on the edge's side."));
            body.push(sreg("w_gd", end_w));
        }
    }
    if tracked {
        body.push(comment("The walked row among the edge's rows, moved with it: w_ge = row >= rs, w_le = row <= re."));
        body.extend([reg("w_ge", 1), reg("w_le", 1)]);
        body.push(wire("in_rows", 1, "w_act && w_ge && w_le"));
    } else {
        body.push(wire("in_rows", 1, "w_act && row >= w_rs && row <= w_re"));
    }
    body.push(swire("gg", end_w, sext("w_g", bound_w, end_w)));
    if e.lean {
        // The bound and whether it bounds the row, not the bound or the screen's: the walker
        // compares the three bounds side by side with these tests (`walker::side_by_side_ends`),
        // where the bound chosen first, then compared, chained two carry chains (docs/fpga.md).
        body.push(Item::Assign("gb".into(), "gg".into()));
        body.push(Item::Assign("bl".into(), "in_rows && !w_right && gg < lo".into()));
        body.push(Item::Assign("bh".into(), "in_rows && w_right && gg < hi".into()));
    } else {
        // This edge's bound on its side of the row, or the screen's where it bounds none here;
        // a left edge's bound is -g, kept as g (its smallest is the span's left end).
        let (below_lo, below_hi) =
            if tracked { (format!("w_gd[{}]", end_w - 1), format!("w_gd[{}]", end_w - 1)) } else { ("gg < lo".into(), "gg < hi".into()) };
        body.push(Item::Assign("lg".into(), format!("(in_rows && !w_right && {below_lo}) ? gg : lo")));
        body.push(Item::Assign("ha".into(), format!("(in_rows && w_right && {below_hi}) ? gg : hi")));
    }
    if e.lean {
        // rem < D and rs256 < D: s < 2D fits HW + 1 bits, and s - D lies in (-D, D), so in
        // HW + 1 bits too, its sign the top bit.
        let sw = hw_ + 1;
        body.push(wire("s", sw, format!("{} + {}", zext("w_rem", hw_, sw), zext("w_rs256", hw_, sw))));
        body.push(wire("dif", sw, format!("s - {}", zext("w_d", hw_, sw))));
        body.push(wire("cy", 1, format!("!dif[{hw_}]")));
        body.push(wire("rnext", hw_, format!("cy ? dif[{}:0] : s[{}:0]", hw_ - 1, hw_ - 1)));
        body.push(swire("gnext", bound_w, format!("w_g + w_qs + {}", zext("cy", 1, bound_w))));
        return body;
    }
    if tracked {
        // The carry rem >= thr is t >= 0 for t = rem - thr: a register's sign. Both next t side by
        // side, rem - thr - thr and rem + rs256 - thr; t's range is -thr..rs256 - 1 (0 <= rem < D).
        let dw = e.held_w();
        let t = |e: &str| zext(e, dw, dw + 1);
        body.push(comment("w_t = rem - thr: the carry is its sign."));
        body.push(wire("cy", 1, format!("!w_t[{dw}]")));
        body.push(swire("tnext", dw + 1, format!("cy ? w_t - {} : w_t + {}", t("w_thr"), t("w_rs256"))));
        // One step for g and its distance: the select of qs or qs + 1 is shared.
        body.push(swire("gstep", bound_w, "cy ? w_qs1 : w_qs"));
        body.push(swire("gnext", bound_w, "w_g + gstep"));
        body.push(swire("gdsum", end_w, format!("w_gd + {}", sext("gstep", bound_w, end_w))));
        let top = bound_w - 1;
        body.push(wire("gwrap", 1, format!("w_g[{top}] == gstep[{top}] && gnext[{top}] != w_g[{top}]")));
        body.push(swire("gdnext", end_w, format!("{{gdsum[{top_d}] ^ gwrap, gdsum[{top}:0]}}", top_d = end_w - 1)));
        return body;
    }
    body.push(wire("cy", 1, "w_rem >= w_thr"));
    body.push(wire("rnext", ediv_w, "cy ? w_rem - w_thr : w_rem + w_rs256"));
    body.push(swire("gnext", bound_w, "cy ? w_g + w_qs1 : w_g + w_qs"));
    body
}

/// The load of the DDA's remainder `rem`: as itself, or behind the row stages as `t = rem - thr`
/// = `rem + rs256 - D` ([`dda`]), its wires into `body`. The three operands are added carry-save,
/// `rem + rs256 + ~D + 1` as the bits' sum plus their majority a place up with the 1 below it:
/// one LUT then one carry chain from the queue head, as the load's `D - rs256`, not two chains.
fn rem_load(e: &EdgeWidths, body: &mut Vec<Item>, (rem, rs256, d): (&str, &str, &str)) -> Stmt {
    let w = e.held_w();
    if !e.tracked {
        return set("w_rem", rem);
    }
    body.push(comment("The load's t = rem + rs256 - D carry-save: the bits' sum, their majority a place up, + 1."));
    body.push(wire("t_x", w + 1, format!("{{1'b1, {rem} ^ {rs256} ^ ~{d}}}")));
    body.push(wire("t_m", w, format!("({rem} & {rs256}) | ({rem} & ~{d}) | ({rs256} & ~{d})")));
    set("w_t", "t_x + {t_m, 1'b1}")
}

/// The DDA's always block: `load` on take, else a step on an active row. Tracked (`dda`): the
/// load and the step chosen from the walker's registers alone (`next`, `more`) under its stall
/// (`go`), which then gates the registers' enable only, not the choice of their value (`take`,
/// the stall and the choice together, fanned out to every register of the edges was the
/// walker's other long path); the row's place moved on each row, `rs`/`re` the loaded rows'
/// sources.
fn walk(e: &EdgeWidths, load: Vec<Stmt>, (rs, re): (&str, &str), (g, right): (&str, &str)) -> Item {
    // `g` comes extended to the distance's width, `w_gd`'s (end_w).
    if !e.tracked {
        let step = vec![set("w_rem", "rnext"), set("w_g", "gnext")];
        return Item::Always(vec![Stmt::If("take".into(), load, vec![Stmt::If("step && w_act && row >= w_rs".into(), step, vec![])])]);
    }
    let step = vec![set("w_t", "tnext"), set("w_g", "gnext"), set("w_gd", "gdnext")];
    let mut load = load;
    load.extend([set("w_ge", format!("first >= {rs}")), set("w_le", format!("first <= {re}"))]);
    load.push(set("w_gd", format!("{g} - ({right} ? hi : lo)")));
    let one = format!("{}'d1", e.row_w);
    let moved = vec![
        set("w_ge", format!("w_ge || row + {one} == w_rs")),
        set("w_le", "w_le && row != w_re"),
        Stmt::If("w_act && w_ge".into(), step, vec![]),
    ];
    Item::Always(vec![Stmt::If("go".into(), vec![Stmt::If("next".into(), load, vec![Stmt::If("more".into(), moved, vec![])])], vec![])])
}

/// `tri_fe_edge` behind the shared set-up engine: the set-up result arrives complete (the
/// engine made the divisions), so the edge is its DDA only.
fn module_engine(hw: &Hw, names: &Names) -> Module {
    let e = EdgeWidths::new(hw);
    let EdgeWidths { row_w, bound_w, ediv_w, end_w, .. } = e;
    let header = vec![
        format!("{} — one edge of {}'s triangle (edge k from vertex k+1 to vertex k+2; three instances).", names.fe_edge, names.frontend),
        "Generated by segshade hdl-gen; do not edit.".into(),
        String::new(),
        format!("Its set-up result comes from the shared set-up engine ({}) through the queue: rows rs..re, side,", names.fe_engine),
        "divisor D = 256 |dy|, first bound g with its remainder, step qs with rs256 = 256 (its remainder).".into(),
        format!("Walker ({}): on an active row g += qs + carry, the remainder", walker_moves(&e)),
        if e.lean {
            "rem += rs256 modulo D (its carry s = rem + rs256 >= D, the borrow of s - D); lg/ha is g on the edge's side of the row, else lo/hi."
        } else {
            "rem += rs256 modulo D (its carry rem >= D - rs256 and both steps side by side); lg/ha is g on the edge's side of the row, else lo/hi."
        }
        .into(),
        format!("Widths: bound GW = {bound_w} signed, divisor {ediv_w}, rows {row_w}, bounds out {end_w} signed."),
    ];
    let mut ports = vec![Port::input("clk", 1, "", "rising edge")];
    for (port, _, w) in input_buses(hw).inputs {
        let p = Port::input(port, w, "", &format!("the set-up result's {port}"));
        ports.push(if port == "g" || port == "qs" { p.signed() } else { p });
    }
    ports.extend(walker_ports(&e));
    ports.extend(state_ports(hw));
    let mut body = dda(&e);
    // The lean DDA holds the high bits of rem, rs256 and D (see dda).
    let held = |p: &str| if ["rem", "rs256", "d"].contains(&p) { format!("{p}[{}:{SCALE_BITS}]", ediv_w - 1) } else { p.to_string() };
    let mut load = if e.lean {
        ["act", "right", "rs", "re", "g", "rem", "qs", "rs256", "d"].map(|p| set(format!("w_{p}"), held(p))).to_vec()
    } else {
        ["act", "right", "rs", "re", "g", "qs", "rs256"].map(|p| set(format!("w_{p}"), p)).to_vec()
    };
    if e.engine_t {
        load.extend([set("w_t", "t"), set("w_thr", "thr")]);
    } else if !e.lean {
        load.push(rem_load(&e, &mut body, ("rem", "rs256", "d")));
        load.push(set("w_thr", "d - rs256"));
    }
    if !e.lean {
        load.push(set("w_qs1", format!("qs + {}", zext("1'b1", 1, bound_w))));
    }
    if hw.edges_in_walk_ram() {
        body.push(walk_by_field(&mut ports, load));
    } else {
        body.push(walk(&e, load, ("rs", "re"), (&sext("g", bound_w, end_w), "right")));
    }
    body.extend(state_outputs(hw).into_iter().map(|(port, _, _, signal, _)| Item::Assign(port.into(), signal)));
    Module { name: names.fe_edge.clone(), header, params: vec![], ports, body }
}

/// The lean DDA loaded a field a clock (the set-up result's fields in the walk memory,
/// `span_seq::walk_ram::edges_in_ram`): `take` is `ld`, a bit a field in the edge's input
/// order, and `g`, `rem` step where their bit is clear.
fn walk_by_field(ports: &mut [Port], load: Vec<Stmt>) -> Item {
    const ORDER: [&str; 9] = ["act", "right", "rs", "re", "d", "g", "rem", "qs", "rs256"];
    let take = ports.iter_mut().find(|p| p.name == "take").expect("the take port");
    *take = Port::input("ld", ORDER.len() as u32, "", "per field, in the input order: load it (the walker is idle)");
    let st = load
        .into_iter()
        .map(|st| {
            let Stmt::Set(l, _) = &st else { unreachable!("a load is a set") };
            let j = ORDER.iter().position(|f| l[2..] == **f).expect("an edge field");
            let step = match &l[2..] {
                "g" => vec![Stmt::If("step && w_act && row >= w_rs".into(), vec![set("w_g", "gnext")], vec![])],
                "rem" => vec![Stmt::If("step && w_act && row >= w_rs".into(), vec![set("w_rem", "rnext")], vec![])],
                _ => vec![],
            };
            Stmt::If(format!("ld[{j}]"), vec![st], step)
        })
        .collect();
    Item::Always(st)
}

/// How the walker's ports load and step the edge, for its header.
fn walker_moves(e: &EdgeWidths) -> &'static str {
    if e.tracked {
        "go and next: load; go and more: the next row, whose place among rs..re is moved with it"
    } else {
        "take: load; step: the next row"
    }
}

/// The walker's side of an edge, the same in every set-up form.
fn walker_ports(e: &EdgeWidths) -> Vec<Port> {
    let EdgeWidths { row_w, end_w, .. } = *e;
    let moves = if e.tracked {
        vec![
            Port::input("go", 1, "", "the walker is not stalled: next or more then holds (in a reset, the edge waits for a load)"),
            Port::input("next", 1, "", "the walker's next row is the set-up result's first: it loads it"),
            Port::input("more", 1, "", "the walker has a row after this one: it steps"),
            Port::input("first", row_w, "unsigned integer", "the set-up result's first row, walked once it is loaded"),
        ]
    } else {
        vec![
            Port::input("take", 1, "", "the walker loads the set-up result"),
            Port::input("step", 1, "", "the walker moves to the next row"),
        ]
    };
    moves
        .into_iter()
        .chain([
            Port::input("row", row_w, "unsigned integer", "the walked row"),
            Port::input("lo", end_w, "signed integer", "the screen's left bound (as -x)").signed(),
            Port::input("hi", end_w, "signed integer", "the screen's right bound").signed(),
        ])
        .chain(if e.lean {
            vec![
                Port::output("gb", end_w, "signed integer", "the edge's bound on the row (a left edge's as -x)").signed(),
                Port::output("bl", 1, "", "gb bounds the row's left end: a left edge on its rows, gb < lo"),
                Port::output("bh", 1, "", "gb bounds the row's right end: a right edge on its rows, gb < hi"),
            ]
        } else {
            vec![
                Port::output("lg", end_w, "signed integer", "a left edge's bound on the row (as -x), else lo").signed(),
                Port::output("ha", end_w, "signed integer", "a right edge's bound on the row, else hi").signed(),
            ]
        })
        .collect()
}

/// The edge's outputs for the row's span, `(port, width)`: its bound on each side or the
/// screen's (`lg`, `ha`), or behind the lean DDA its bound and whether it bounds each side (`gb`,
/// `bl`, `bh`).
pub(super) fn end_ports(hw: &Hw) -> Vec<(&'static str, u32)> {
    let e = EdgeWidths::new(hw);
    if e.lean {
        vec![("gb", e.end_w), ("bl", 1), ("bh", 1)]
    } else {
        vec![("lg", e.end_w), ("ha", e.end_w)]
    }
}

/// Whether the edges give the walker their bounds with side tests ([`end_ports`]): the lean DDA's
/// form.
pub(super) fn ends_side_by_side(hw: &Hw) -> bool {
    EdgeWidths::new(hw).lean
}

/// The proof's view of each edge behind the row stages (`scripts/prove` drives each formal-only
/// wire from the flattened design's register, `(wire, register, width)`), and what holds of them
/// while the walker walks a triangle: `w_gd` is `g`'s distance to the screen's bound on its side
/// ([`dda`]), so the flag it gives is the compare `g < bound` and the row stages' bounds lie within
/// the screen's. Empty without the row stages.
pub(super) fn formal_probes(hw: &Hw) -> (Vec<(String, String, u32)>, Vec<String>) {
    let e = EdgeWidths::new(hw);
    if !e.tracked || e.lean {
        return (Vec::new(), Vec::new());
    }
    let (mut probes, mut holds) = (Vec::new(), Vec::new());
    for k in 0..3 {
        let reg = |r: &str| format!("g_edge[{k}].u_edge.{r}");
        probes.extend([
            (format!("f_eg{k}"), reg("w_g"), e.bound_w),
            (format!("f_egd{k}"), reg("w_gd"), e.end_w),
            (format!("f_eright{k}"), reg("w_right"), 1),
        ]);
        holds.push(format!("f_egd{k} == {} - (f_eright{k} ? hi0 : lo0)", sext(&format!("f_eg{k}"), e.bound_w, e.end_w)));
    }
    (probes, holds)
}
