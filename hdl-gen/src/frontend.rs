//! `tri_frontend` (SPEC §6): triangles in, one span per covered scanline out, and
//! `tri_shader_p<P>`, which chains it with `segment_shader_p<P>`: triangles in, segments with
//! their `y` out. The arithmetic is `golden::frontend`'s, with its widths; see that module for
//! why it is exact and how accurate the intensities are.
//!
//! Structure of `tri_frontend`:
//! - **set-up**: a triangle waits in the vertex registers until the dividers are free; in that
//!   clock CALC checks the guard band, computes the area, orients the edges, finds the rows,
//!   culls, and loads eight restoring dividers (`--fe-div-bits` quotient bits a clock); `DIV`
//!   runs them together; `HOLD` offers the result to the walker. The hand-off clock is also the
//!   next triangle's CALC, and the next triangle is latched while the dividers run.
//! - **edge walker**: one row per clock. Per active edge one DDA step (add, compare, subtract);
//!   `lo` and `hi` are the max and min of the active bounds, clipped to the screen. It loads the
//!   next triangle in the clock its current one finishes, so set-up overlaps the walk.
//! - **I0 pipeline** (two stages after the walker): `S2n = 2 (Tn + Gxn lo) + An` in the
//!   walker's clock, then `q~ = (S2n Rn) >> K`, then the correction `q~ + (S2n - 2 An q~ >= 2 An)`.
//!   One stall signal holds the walker and every stage while the output waits.

use crate::verilog::{assign, comment, lit, net, reg, set, sext, sreg, swire, wire, zext, Item, Module, Port, Stmt};
use crate::Names;
use golden::frontend::{DiMode, FrontEnd, Widths};

/// Quotient bits the set-up's dividers take per clock (`--fe-div-bits`): area against rate.
pub const DIV_BITS: [u32; 3] = [1, 2, 4];
pub const DEFAULT_DIV_BITS: u32 = 4;

/// A front-end as generated: golden's configuration and the hardware's own choices.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Hw {
    pub fe: FrontEnd,
    /// Quotient bits per clock of every set-up divider (one of [`DIV_BITS`]).
    pub div_bits: u32,
    /// The chain's register stages (`--pipeline`): the shader's; the front-end has none yet.
    pub pipeline: golden::pipeline::Pipeline,
}

impl Hw {
    /// Clocks the dividers run: the reciprocal's RW quotient bits, `div_bits` a clock.
    pub fn div_clocks(&self) -> u32 {
        self.fe.widths().rw.div_ceil(self.div_bits)
    }

    /// Clocks the per-scanline divider runs for a span of two pixels or more (`DiMode::Scanline`,
    /// the comparison option; 0 with the per-triangle `dI`): IW quotient bits, `div_bits` a clock.
    pub fn span_div_clocks(&self) -> u32 {
        match self.fe.di {
            DiMode::Triangle => 0,
            DiMode::Scanline => self.fe.cfg.iw().div_ceil(self.div_bits),
        }
    }

    /// Clocks from a triangle's transfer to the first span's `out_valid` when the walker is
    /// idle: CALC, the dividers, the hand-off, the walker's clock, two pipeline stages (and, per
    /// scanline, the span's division when it has two pixels or more).
    pub fn latency(&self) -> u32 {
        self.div_clocks() + 5 + self.span_div_clocks()
    }

    /// Clocks from a triangle's transfer to the first segment out of `tri_shader_p<P>` when idle:
    /// the front-end's latency, then the shader's at the chain's pipeline level.
    pub fn shader_latency(&self) -> u32 {
        self.latency() + golden::segment::latency(&self.fe.cfg, self.pipeline)
    }

    /// Set-up clocks per triangle that is walked (the rate limit for tiny triangles: the
    /// dividers, then the hand-off clock, which is also the next triangle's CALC), and per
    /// triangle dropped in set-up (its CALC).
    pub fn setup_clocks(&self) -> (u32, u32) {
        (self.div_clocks() + 1, 1)
    }
}

fn slit(w: u32, v: i64) -> String {
    if v < 0 {
        format!("-{w}'sd{}", -v)
    } else {
        format!("{w}'sd{v}")
    }
}

/// `out = a * b` at the product's natural width. Both operands are signed names of their own
/// widths: the language extends them to the result, and synthesis builds a `wa` x `wb`
/// multiplier (extending them by hand would make it as wide as the result on both sides).
fn smul(out: &str, a: &str, wa: u32, b: &str, wb: u32) -> Vec<Item> {
    vec![comment("verilator lint_off WIDTH"), swire(out, wa + wb, format!("{a} * {b}")), comment("verilator lint_on WIDTH")]
}

pub fn ports(fe: &FrontEnd, wd: &Widths) -> Vec<Port> {
    let cfg = &fe.cfg;
    let mut v = vec![
        Port::input("clk", 1, "", "rising edge"),
        Port::input("rst", 1, "", "synchronous, active high; drops the triangles in progress"),
        Port::input("in_valid", 1, "", "triangle valid"),
        Port::output("in_ready", 1, "", "triangle accepted when in_valid && in_ready"),
    ];
    for k in 0..3 {
        v.push(Port::input(&format!("in_x{k}"), wd.cx, &format!("signed Q{}.8", cfg.xbits + 2), &format!("vertex {k} x, pixels")).signed());
        v.push(Port::input(&format!("in_y{k}"), wd.cy, &format!("signed Q{}.8", wd.yw + 2), &format!("vertex {k} y, pixels")).signed());
        v.push(Port::input(&format!("in_i{k}"), cfg.iw(), &format!("UQ8.{}", cfg.frac), &format!("vertex {k} intensity")));
    }
    v.push(Port::output("err", 1, "", "one-clock pulse: a triangle with a vertex outside the guard band was dropped").reg());
    v
}

pub fn span_ports(fe: &FrontEnd, wd: &Widths) -> Vec<Port> {
    let cfg = &fe.cfg;
    vec![
        Port::output("out_valid", 1, "", "span valid").reg(),
        Port::input("out_ready", 1, "", "span taken when out_valid && out_ready"),
        Port::output("out_y", wd.yw, "unsigned integer", "scanline").reg(),
        Port::output("out_x", cfg.xbits, "unsigned integer", "x0, first covered pixel").reg(),
        Port::output("out_len", cfg.xbits + 1, "unsigned integer", "m >= 1, covered pixels").reg(),
        Port::output("out_i0", cfg.iw(), &format!("UQ8.{}", cfg.frac), "intensity at the first pixel's centre").reg(),
        Port::output("out_di", cfg.dw(), &format!("signed Q8.{}", cfg.frac), "dI/dx, once per triangle").signed().reg(),
    ]
}

/// One restoring divider: registers `<n>_p` (partial remainder), `<n>_d` (shifted divisor),
/// `<n>_q`; it takes quotient bits while the shared counter is below `qb`.
struct Div {
    name: &'static str,
    pw: u32,
    qb: u32,
}

fn div_regs(d: &Div) -> Vec<Item> {
    vec![reg(&format!("{}_p", d.name), d.pw), reg(&format!("{}_d", d.name), d.pw), reg(&format!("{}_q", d.name), d.qb)]
}

/// Statements that load a divider: dividend and divisor, both `pw` bits wide already.
fn div_load(d: &Div, dividend: &str, divisor_shifted: &str) -> Vec<Stmt> {
    vec![set(format!("{}_p", d.name), dividend), set(format!("{}_d", d.name), divisor_shifted), set(format!("{}_q", d.name), lit(d.qb, 0))]
}

/// `bits` restoring steps in one clock, chained: step j takes quotient bit `cnt - j`, if
/// that bit exists and is one of this divider's `qb`.
fn div_chain(d: &Div, cnt: &str, cnt_w: u32, bits: u32) -> Vec<Item> {
    let n = d.name;
    let mut items = Vec::new();
    for j in 0..bits {
        let (p, dd, q) = if j == 0 {
            (format!("{n}_p"), format!("{n}_d"), format!("{n}_q"))
        } else {
            (format!("{n}_p{j}"), format!("{n}_d{j}"), format!("{n}_q{j}"))
        };
        let on = if j == 0 {
            format!("{cnt} < {}", lit(cnt_w, d.qb as u64))
        } else {
            format!("{cnt} >= {} && {cnt} - {} < {}", lit(cnt_w, j as u64), lit(cnt_w, j as u64), lit(cnt_w, d.qb as u64))
        };
        items.push(wire(&format!("{n}_on{j}"), 1, on));
        items.push(wire(&format!("{n}_ge{j}"), 1, format!("{p} >= {dd}")));
        let k = j + 1;
        let shifted = if d.qb == 1 { format!("{n}_ge{j}") } else { format!("{{{q}[{}:0], {n}_ge{j}}}", d.qb - 2) };
        items.push(wire(&format!("{n}_p{k}"), d.pw, format!("({n}_on{j} && {n}_ge{j}) ? {p} - {dd} : {p}")));
        items.push(wire(&format!("{n}_d{k}"), d.pw, format!("{n}_on{j} ? {dd} >> 1 : {dd}")));
        items.push(wire(&format!("{n}_q{k}"), d.qb, format!("{n}_on{j} ? {shifted} : {q}")));
    }
    items
}

fn div_iter(d: &Div, bits: u32) -> Vec<Stmt> {
    let n = d.name;
    vec![
        set(format!("{n}_p"), format!("{n}_p{bits}")),
        set(format!("{n}_d"), format!("{n}_d{bits}")),
        set(format!("{n}_q"), format!("{n}_q{bits}")),
    ]
}

pub fn module(hw: &Hw, names: &Names) -> Module {
    let fe = &hw.fe;
    let bits = hw.div_bits;
    let cfg = &fe.cfg;
    let wd = fe.widths();
    let Widths { yw, cx, cy, aw, gw, dw_edge: de, k: kk, rw, sw } = wd;
    let (xw, iw, dw) = (cfg.xbits, cfg.iw(), cfg.dw());
    let (w, h) = (fe.screen.width as i64, fe.screen.height as i64);
    let nxw = iw + cy + 3; // Nx, signed
    let nyw = iw + cx + 3; // Ny, signed
    let rxw = xw + 3; // column numbers, signed
    let ryw = cy - 7; // row numbers, signed (= YW + 3)
    let cnt_w = 32 - rw.leading_zeros();

    let header = vec![
        format!("{} — triangle front-end (SPEC §6): set-up and edge walker, one span per clock.", names.frontend),
        "Generated by segshade hdl-gen; do not edit.".into(),
        String::new(),
        format!("Configuration: screen {}x{}, F = {}, XW = {xw}; rows {yw} bits.", w, h, cfg.frac),
        format!("Vertices: x signed Q{}.8 ({cx} bits), y signed Q{}.8 ({cy} bits), I UQ8.{} ({iw} bits).", xw + 2, yw + 2, cfg.frac),
        format!("Guard band: -{w} <= x < {}, -{h} <= y < {} pixels; a triangle outside it is dropped and pulses err.", 2 * w, 2 * h),
        "Coverage: exactly golden::setup's (top-left rule, pixel centres, clipped), by an integer DDA per edge.".into(),
        format!("Spans: (y, x0, m, I0, dI) in SPEC §2's formats; I0 correctly rounded, dI rounded once per triangle;"),
        format!("every pixel within 1/2 + W 2^-(F+1) <= 1 of the plane through the vertex intensities."),
        format!(
            "Set-up: CALC 1 clock, {} divider clocks (8 restoring dividers in parallel, {bits} quotient bit(s) a clock), hand-off;",
            hw.div_clocks()
        ),
        format!("{} clocks per walked triangle, 1 per dropped one; the next triangle is latched meanwhile.", hw.setup_clocks().0),
        format!("Latency: first span valid {} clocks after the triangle's transfer when the walker is idle.", hw.latency()),
        "Walker: one row per clock (rows with no covered pixel make a bubble); the next triangle's set-up overlaps it.".into(),
        format!("Widths: |A| {aw}, edge bound {gw} signed, edge divisor {de}, intensity sums modulo 2^{kk}, reciprocal {rw}."),
    ];

    let mut body = vec![
        comment("Set-up: a triangle waits in the vertex registers (v_full) until the dividers are free: idle, or"),
        comment("handing their last result to the walker (take). In that clock CALC computes everything and loads"),
        comment("the dividers; DIV runs them; HOLD offers the result. The next triangle is latched meanwhile."),
    ];
    body.push(Item::Localparam { name: "IDLE".into(), width: 2, value: "2'd0".into() });
    body.push(Item::Localparam { name: "DIV".into(), width: 2, value: "2'd2".into() });
    body.push(Item::Localparam { name: "HOLD".into(), width: 2, value: "2'd3".into() });
    body.push(reg("st", 2));
    body.push(reg("div_cnt", cnt_w));
    for k in 0..3 {
        body.push(sreg(&format!("vx{k}"), cx));
        body.push(sreg(&format!("vy{k}"), cy));
        body.push(reg(&format!("vi{k}"), iw));
    }
    body.push(reg("v_full", 1));
    body.push(net("take", 1));
    body.push(wire("calc", 1, "v_full && (st == IDLE || take)"));
    body.push(assign("in_ready", "!v_full || calc"));
    body.push(Item::Blank);

    // ---- CALC: everything from the vertex registers, combinational.
    body.push(comment("Guard band, on the registered vertices."));
    let gx = |v: &str| {
        let hi = 2 * w * 256;
        let below = if hi > (1i64 << (cx - 1)) - 1 { String::new() } else { format!(" && {v} < {}", slit(cx, hi)) };
        format!("({v} >= {}{below})", slit(cx, -w * 256))
    };
    let gy = |v: &str| {
        let hi = 2 * h * 256;
        let below = if hi > (1i64 << (cy - 1)) - 1 { String::new() } else { format!(" && {v} < {}", slit(cy, hi)) };
        format!("({v} >= {}{below})", slit(cy, -h * 256))
    };
    let guard: Vec<String> = (0..3).flat_map(|k| [gx(&format!("vx{k}")), gy(&format!("vy{k}"))]).collect();
    body.push(wire("guard_ok", 1, guard.join(" && ")));
    body.push(Item::Blank);
    body.push(comment("Twice the signed area, its orientation and magnitude."));
    for (n, a, b, ww) in [("u1", "vx1", "vx0", cx), ("u2", "vx2", "vx0", cx), ("v1", "vy1", "vy0", cy), ("v2", "vy2", "vy0", cy)] {
        body.push(swire(n, ww + 1, format!("{} - {}", sext(a, ww, ww + 1), sext(b, ww, ww + 1))));
    }
    body.extend(smul("m_a1", "u1", cx + 1, "v2", cy + 1));
    body.extend(smul("m_a2", "v1", cy + 1, "u2", cx + 1));
    body.push(swire("area", aw + 1, "m_a1 - m_a2"));
    body.push(wire("neg", 1, format!("area[{aw}]")));
    body.push(comment("verilator lint_off UNUSEDSIGNAL"));
    body.push(wire("area_n", aw + 1, "neg ? -area : area"));
    body.push(wire("aabs", aw, format!("area_n[{}:0]", aw - 1)));
    body.push(comment("verilator lint_on UNUSEDSIGNAL"));
    body.push(Item::Blank);

    body.push(comment("Edge k runs from vertex k+1 to vertex k+2, oriented so the interior is positive."));
    for k in 0..3 {
        let (a, b) = ((k + 1) % 3, (k + 2) % 3);
        body.push(swire(
            &format!("rdx{k}"),
            cx + 1,
            format!("{} - {}", sext(&format!("vx{b}"), cx, cx + 1), sext(&format!("vx{a}"), cx, cx + 1)),
        ));
        body.push(swire(
            &format!("rdy{k}"),
            cy + 1,
            format!("{} - {}", sext(&format!("vy{b}"), cy, cy + 1), sext(&format!("vy{a}"), cy, cy + 1)),
        ));
        body.push(swire(&format!("dx{k}"), cx + 1, format!("neg ? -rdx{k} : rdx{k}")));
        body.push(swire(&format!("dy{k}"), cy + 1, format!("neg ? -rdy{k} : rdy{k}")));
        body.push(wire(&format!("tl{k}"), 1, format!("dy{k}[{cy}] || (dy{k} == {} && dx{k} > {})", slit(cy + 1, 0), slit(cx + 1, 0))));
    }
    body.push(comment("A horizontal edge that is not top-left is a bottom edge: centres on it are not covered."));
    body.push(wire("kill", 1, (0..3).map(|k| format!("(dy{k} == {} && !tl{k})", slit(cy + 1, 0))).collect::<Vec<_>>().join(" || ")));
    body.push(Item::Blank);

    body.push(comment("Bounding box in rows and columns (centres at +128 sub-pixels), clipped."));
    let min3 = |a: &str, b: &str, c: &str, less: bool| {
        let op = if less { "<" } else { ">" };
        format!("(({a} {op} {b}) ? (({a} {op} {c}) ? {a} : {c}) : (({b} {op} {c}) ? {b} : {c}))")
    };
    body.push(swire("ymin", cy, min3("vy0", "vy1", "vy2", true)));
    body.push(swire("ymax", cy, min3("vy0", "vy1", "vy2", false)));
    body.push(swire("xmin", cx, min3("vx0", "vx1", "vx2", true)));
    body.push(swire("xmax", cx, min3("vx0", "vx1", "vx2", false)));
    body.push(comment("verilator lint_off UNUSEDSIGNAL"));
    body.push(swire("ymin_c", cy + 1, format!("{} + {}", sext("ymin", cy, cy + 1), slit(cy + 1, 127))));
    body.push(swire("ymax_c", cy + 1, format!("{} - {} - {}", sext("ymax", cy, cy + 1), slit(cy + 1, 128), zext("kill", 1, cy + 1))));
    body.push(swire("xmin_c", cx + 1, format!("{} + {}", sext("xmin", cx, cx + 1), slit(cx + 1, 127))));
    body.push(swire("xmax_c", cx + 1, format!("{} - {}", sext("xmax", cx, cx + 1), slit(cx + 1, 128))));
    body.push(comment("verilator lint_on UNUSEDSIGNAL"));
    body.push(swire("first_raw", ryw, format!("ymin_c[{cy}:8]")));
    body.push(swire("last_raw", ryw, format!("ymax_c[{cy}:8]")));
    body.push(swire("cfirst", rxw, format!("xmin_c[{cx}:8]")));
    body.push(swire("clast", rxw, format!("xmax_c[{cx}:8]")));
    body.push(swire("first_s", ryw, format!("first_raw[{}] ? {} : first_raw", ryw - 1, slit(ryw, 0))));
    body.push(swire("last_s", ryw, format!("last_raw > {} ? {} : last_raw", slit(ryw, h - 1), slit(ryw, h - 1))));
    body.push(wire(
        "cull",
        1,
        format!("area == {} || first_s > last_s || cfirst > clast || cfirst > {} || clast[{}]", slit(aw + 1, 0), slit(rxw, w - 1), rxw - 1),
    ));
    body.push(Item::Blank);

    // ---- Edge dividers' inputs. Arithmetic is done at the full target width on sign- or
    // zero-extended operands (right modulo 2^width); only named signed wires are compared.
    let pw_init = gw + de;
    let pw_step = gw + cy;
    let nw = cx + cy + 5;
    let snw = (cx + 2).max(gw + cy + 1);
    body.push(comment("Per edge: its active rows, and the dividends of its first bound and of its step, offset by"));
    body.push(comment("B = 2^(GW-1) divisors so both quotients are non-negative (q = g + B)."));
    body.push(comment("verilator lint_off UNUSEDSIGNAL"));
    for k in 0..3 {
        let (a, bb) = ((k + 1) % 3, (k + 2) % 3);
        let (ya, yb2, xa) = (format!("vy{a}"), format!("vy{bb}"), format!("vx{a}"));
        body.push(swire(&format!("yt{k}"), cy, format!("{ya} < {yb2} ? {ya} : {yb2}")));
        body.push(swire(&format!("yb{k}"), cy, format!("{ya} < {yb2} ? {yb2} : {ya}")));
        body.push(swire(&format!("ytc{k}"), cy + 1, format!("{} + {}", sext(&format!("yt{k}"), cy, cy + 1), slit(cy + 1, 127))));
        body.push(swire(&format!("ybc{k}"), cy + 1, format!("{} - {}", sext(&format!("yb{k}"), cy, cy + 1), slit(cy + 1, 128))));
        body.push(swire(&format!("rs_raw{k}"), ryw, format!("ytc{k}[{cy}:8]")));
        body.push(swire(&format!("re_raw{k}"), ryw, format!("ybc{k}[{cy}:8]")));
        body.push(swire(&format!("rs{k}"), ryw, format!("rs_raw{k} > first_s ? rs_raw{k} : first_s")));
        body.push(swire(&format!("re{k}"), ryw, format!("re_raw{k} < last_s ? re_raw{k} : last_s")));
        body.push(wire(&format!("act{k}"), 1, format!("dy{k} != {} && rs{k} <= re{k}", slit(cy + 1, 0))));
        body.push(wire(&format!("ady{k}"), cy, format!("dy{k}[{cy}] ? -dy{k}[{}:0] : dy{k}[{}:0]", cy - 1, cy - 1)));
        body.push(wire(&format!("rsu{k}"), yw, format!("rs{k}[{}:0]", yw - 1)));
        // e(128, 256 rs + 128) - t + B D, from vertex a on the edge's line.
        body.push(swire(
            &format!("ry{k}"),
            cy + 2,
            format!("{} - {}", zext(&format!("{{rsu{k}, 8'd128}}"), yw + 8, cy + 2), sext(&ya, cy, cy + 2)),
        ));
        body.push(swire(&format!("rx{k}"), cx + 2, format!("{} - {}", lit(cx + 2, 128), sext(&xa, cx, cx + 2))));
        body.extend(smul(&format!("m_e{k}"), &format!("dx{k}"), cx + 1, &format!("ry{k}"), cy + 2));
        body.extend(smul(&format!("m_f{k}"), &format!("dy{k}"), cy + 1, &format!("rx{k}"), cx + 2));
        body.push(wire(
            &format!("n{k}"),
            nw,
            format!(
                "{} - {} - {} + ({} << {})",
                sext(&format!("m_e{k}"), nw - 2, nw),
                sext(&format!("m_f{k}"), nw - 2, nw),
                zext(&format!("!tl{k}"), 1, nw),
                zext(&format!("ady{k}"), cy, nw),
                gw + 7
            ),
        ));
        body.push(wire(
            &format!("sn{k}"),
            snw,
            format!("{} + ({} << {})", sext(&format!("dx{k}"), cx + 1, snw), zext(&format!("ady{k}"), cy, snw), gw - 1),
        ));
    }
    body.push(comment("verilator lint_on UNUSEDSIGNAL"));
    body.push(Item::Blank);

    // ---- The plane.
    body.push(comment("The plane: Nx, Ny (oriented), dI's dividend 2*256|Nx| + |A| and its saturation."));
    body.push(comment("verilator lint_off UNUSEDSIGNAL"));
    let iz = |v: &str, to: u32| zext(v, iw, to);
    body.push(swire("d1", iw + 1, format!("{} - {}", iz("vi1", iw + 1), iz("vi0", iw + 1))));
    body.push(swire("d2", iw + 1, format!("{} - {}", iz("vi2", iw + 1), iz("vi0", iw + 1))));
    body.extend(smul("m_x1", "d1", iw + 1, "v2", cy + 1));
    body.extend(smul("m_x2", "d2", iw + 1, "v1", cy + 1));
    body.extend(smul("m_y1", "d2", iw + 1, "u1", cx + 1));
    body.extend(smul("m_y2", "d1", iw + 1, "u2", cx + 1));
    body.push(wire("nx", nxw, format!("{} - {}", sext("m_x1", nxw - 1, nxw), sext("m_x2", nxw - 1, nxw))));
    body.push(wire("ny", nyw, format!("{} - {}", sext("m_y1", nyw - 1, nyw), sext("m_y2", nyw - 1, nyw))));
    body.push(swire("onx", nxw, "neg ? -nx : nx"));
    body.push(swire("ony", nyw, "neg ? -ny : ny"));
    body.push(wire("nx_neg", 1, format!("onx[{}]", nxw - 1)));
    body.push(wire("mag", nxw, "nx_neg ? -onx : onx"));
    let x2w = (nxw + 9).max(aw + 1);
    let cmpw = x2w.max(aw + iw + 1);
    body.push(wire("x2", x2w, format!("({} << 9) + {}", zext("mag", nxw, x2w), zext("aabs", aw, x2w))));
    body.push(wire("di_sat", 1, format!("{} >= ({} << {})", zext("x2", x2w, cmpw), zext("aabs", aw, cmpw), iw + 1)));
    body.push(comment("verilator lint_on UNUSEDSIGNAL"));
    body.push(Item::Blank);

    body.push(comment("Normalisation: s leading zeros of |A|, An = |A| << s, and the sums S(0, first), 256 Nx, 256 Ny,"));
    body.push(comment("each shifted by s and kept modulo 2^K."));
    let mut chain = lit(sw, (aw - 1) as u64);
    for bit in 1..aw {
        chain = format!("aabs[{bit}] ? {} : {chain}", lit(sw, (aw - 1 - bit) as u64));
    }
    body.push(wire("lz", sw, chain));
    body.push(wire("an", aw, "aabs << lz"));
    body.push(comment("verilator lint_off UNUSEDSIGNAL"));
    body.push(wire("first_u", yw, format!("first_s[{}:0]", yw - 1)));
    body.push(wire("last_u", yw, format!("last_s[{}:0]", yw - 1)));
    body.push(comment("verilator lint_on UNUSEDSIGNAL"));
    body.push(swire("xo", cx + 2, format!("{} - {}", lit(cx + 2, 128), sext("vx0", cx, cx + 2))));
    body.push(swire("yo", cy + 2, format!("{} - {}", zext("{first_u, 8'd128}", yw + 8, cy + 2), sext("vy0", cy, cy + 2))));
    body.push(comment("verilator lint_off WIDTH"));
    body.push(wire("m_s1", iw + aw, "vi0 * aabs"));
    body.push(comment("verilator lint_on WIDTH"));
    body.push(comment("verilator lint_off UNUSEDSIGNAL"));
    body.extend(smul("m_s2", "onx", nxw, "xo", cx + 2));
    body.extend(smul("m_s3", "ony", nyw, "yo", cy + 2));
    body.push(comment("verilator lint_on UNUSEDSIGNAL"));
    let low = |m: &str, w: u32| if w > kk { format!("{m}[{}:0]", kk - 1) } else { sext(m, w, kk) };
    body.push(wire("s0", kk, format!("{} + {} + {}", zext("m_s1", iw + aw, kk), low("m_s2", nxw + cx + 2), low("m_s3", nyw + cy + 2))));
    body.push(wire("tn0", kk, "s0 << lz"));
    body.push(wire("gxn0", kk, format!("({} << 8) << lz", sext("onx", nxw, kk))));
    body.push(wire("dyn0", kk, format!("({} << 8) << lz", sext("ony", nyw, kk))));
    body.push(Item::Blank);

    // ---- Dividers and the set-up result registers.
    let divs: Vec<Div> = (0..3)
        .flat_map(|k| {
            [Div { name: ["ei0", "ei1", "ei2"][k], pw: pw_init, qb: gw }, Div { name: ["es0", "es1", "es2"][k], pw: pw_step, qb: gw }]
        })
        .chain([Div { name: "ddi", pw: iw + aw + 1, qb: iw }, Div { name: "drn", pw: aw + rw + 1, qb: rw }])
        .collect();
    body.push(comment("Eight restoring dividers, one quotient bit per clock, sharing one counter: per edge its first"));
    body.push(comment("bound (ei) and its step (es), then dI (ddi) and the reciprocal Rn = 2^K / (2 An) (drn)."));
    for d in &divs {
        body.extend(div_regs(d));
    }
    for d in &divs {
        body.extend(div_chain(d, "div_cnt", cnt_w, bits));
    }
    body.push(comment("The set-up result, complete when the dividers are (HOLD)."));
    for k in 0..3 {
        body.push(reg(&format!("s_act{k}"), 1));
        body.push(reg(&format!("s_right{k}"), 1));
        body.push(reg(&format!("s_rs{k}"), yw));
        body.push(reg(&format!("s_re{k}"), yw));
        body.push(reg(&format!("s_d{k}"), de));
    }
    for (n, ww) in [("s_first", yw), ("s_last", yw), ("s_an", aw), ("s_tn", kk), ("s_gxn", kk), ("s_dyn", kk)] {
        body.push(reg(n, ww));
    }
    body.push(reg("s_sat", 1));
    body.push(reg("s_dineg", 1));
    body.push(Item::Blank);

    let mut calc_load = vec![set("div_cnt", lit(cnt_w, (rw - 1) as u64)), set("st", "DIV")];
    for k in 0..3 {
        let ei = &divs[2 * k];
        let es = &divs[2 * k + 1];
        calc_load.extend(div_load(
            ei,
            &format!("n{k}[{}:0]", pw_init - 1),
            &format!("{} << {}", zext(&format!("ady{k}"), cy, pw_init), gw + 7),
        ));
        calc_load.extend(div_load(
            es,
            &format!("sn{k}[{}:0]", pw_step - 1),
            &format!("{} << {}", zext(&format!("ady{k}"), cy, pw_step), gw - 1),
        ));
        calc_load.push(set(format!("s_act{k}"), format!("act{k}")));
        calc_load.push(set(format!("s_right{k}"), format!("!dy{k}[{cy}]")));
        calc_load.push(set(format!("s_rs{k}"), format!("rsu{k}")));
        calc_load.push(set(format!("s_re{k}"), format!("re{k}[{}:0]", yw - 1)));
        calc_load.push(set(format!("s_d{k}"), format!("{{ady{k}, 8'd0}}")));
    }
    let ddi_pw = iw + aw + 1;
    let x2_fit = if x2w >= ddi_pw { format!("x2[{}:0]", ddi_pw - 1) } else { zext("x2", x2w, ddi_pw) };
    calc_load.extend(div_load(&divs[6], &x2_fit, &format!("{} << {}", zext("aabs", aw, ddi_pw), iw)));
    calc_load.extend(div_load(
        &divs[7],
        &format!("{} << {}", lit(aw + rw + 1, 1), kk),
        &format!("{} << {}", zext("an", aw, aw + rw + 1), rw),
    ));
    calc_load.extend([
        set("s_first", "first_u"),
        set("s_last", "last_u"),
        set("s_an", "an"),
        set("s_tn", "tn0"),
        set("s_gxn", "gxn0"),
        set("s_dyn", "dyn0"),
        set("s_sat", "di_sat"),
        set("s_dineg", "nx_neg"),
    ]);
    let mut div_run: Vec<Stmt> = divs.iter().flat_map(|d| div_iter(d, bits)).collect();
    div_run.push(Stmt::If(
        format!("div_cnt < {}", lit(cnt_w, bits as u64)),
        vec![set("st", "HOLD")],
        vec![set("div_cnt", format!("div_cnt - {}", lit(cnt_w, bits as u64)))],
    ));
    let mut take_in = vec![set("v_full", "1'b1")];
    for k in 0..3 {
        take_in.push(set(format!("vx{k}"), format!("in_x{k}")));
        take_in.push(set(format!("vy{k}"), format!("in_y{k}")));
        take_in.push(set(format!("vi{k}"), format!("in_i{k}")));
    }
    body.push(Item::Always(vec![Stmt::If(
        "rst".into(),
        vec![set("st", "IDLE"), set("v_full", "1'b0"), set("err", "1'b0")],
        vec![
            set("err", "1'b0"),
            Stmt::If("in_valid && in_ready".into(), take_in, vec![Stmt::If("calc".into(), vec![set("v_full", "1'b0")], vec![])]),
            Stmt::If(
                "calc".into(),
                vec![Stmt::If(
                    "!guard_ok".into(),
                    vec![set("err", "1'b1"), set("st", "IDLE")],
                    vec![Stmt::If("cull".into(), vec![set("st", "IDLE")], calc_load)],
                )],
                vec![Stmt::If("st == DIV".into(), div_run, vec![]), Stmt::If("take".into(), vec![set("st", "IDLE")], vec![])],
            ),
        ],
    )]));
    body.push(Item::Blank);

    // Results of the dividers.
    body.push(comment("Divider results: bounds and steps (q - B), the remainders, dI with its sign and saturation."));
    body.push(comment("verilator lint_off UNUSEDSIGNAL"));
    for k in 0..3 {
        let flip = |q: &str| if gw == 1 { format!("~{q}") } else { format!("{{~{q}[{}], {q}[{}:0]}}", gw - 1, gw - 2) };
        body.push(wire(&format!("r_g{k}"), gw, flip(&format!("ei{k}_q"))));
        body.push(wire(&format!("r_rem{k}"), de, format!("ei{k}_p[{}:0]", de - 1)));
        body.push(wire(&format!("r_qs{k}"), gw, flip(&format!("es{k}_q"))));
        body.push(wire(&format!("r_rs256_{k}"), de, format!("{{es{k}_p[{}:0], 8'd0}}", cy - 1)));
    }
    body.push(comment("verilator lint_on UNUSEDSIGNAL"));
    let max_pos = format!("{{1'b0, {{{iw}{{1'b1}}}}}}");
    let max_neg = format!("{{1'b1, {}}}", lit(iw, 0));
    body.push(wire(
        "r_di",
        dw,
        format!("s_sat ? (s_dineg ? {max_neg} : {max_pos}) : (s_dineg ? -{} : {})", zext("ddi_q", iw, dw), zext("ddi_q", iw, dw)),
    ));
    body.push(Item::Blank);

    // ---- The walker.
    body.push(comment("Walker: the triangle being walked, one row per clock."));
    body.push(reg("w_valid", 1));
    body.push(reg("w_row", yw));
    body.push(reg("w_last", yw));
    for k in 0..3 {
        for (n, ww) in [("act", 1), ("right", 1), ("rs", yw), ("re", yw), ("d", de), ("rem", de), ("rs256_", de)] {
            body.push(reg(&format!("w_{n}{k}"), ww));
        }
        body.push(sreg(&format!("w_g{k}"), gw));
        body.push(sreg(&format!("w_qs{k}"), gw));
    }
    for (n, ww) in [("w_di", dw), ("w_an", aw), ("w_rn", rw), ("w_tn", kk), ("w_gxn", kk), ("w_dyn", kk)] {
        body.push(reg(n, ww));
    }
    let scan = fe.di == DiMode::Scanline;
    let (sq, sd_cw) = (iw, 32 - (iw - 1).leading_zeros());
    let sdv = Div { name: "sdv", pw: xw + iw + 2, qb: sq };
    if scan {
        body.push(comment("Per-scanline dI (the comparison option): a restoring divider, busy for each span of m >= 2."));
        body.extend([reg("sd_busy", 1), reg("sd_cnt", sd_cw), reg("sd_neg", 1)]);
        body.extend(div_regs(&sdv));
        body.push(wire("adv", 1, "(!out_valid || out_ready) && !sd_busy"));
    } else {
        body.push(wire("adv", 1, "!out_valid || out_ready"));
    }
    body.push(wire("w_end", 1, "w_row == w_last"));
    body.push(assign("take", "st == HOLD && adv && (!w_valid || w_end)"));
    let bw = gw + 1;
    body.push(swire("lo0", bw, slit(bw, 0)));
    body.push(swire("hi0", bw, slit(bw, w - 1)));
    for k in 0..3 {
        body.push(wire(&format!("in{k}"), 1, format!("w_act{k} && w_row >= w_rs{k} && w_row <= w_re{k}")));
        body.push(swire(&format!("ng{k}"), bw, format!("-{}", sext(&format!("w_g{k}"), gw, bw))));
        body.push(swire(&format!("gg{k}"), bw, sext(&format!("w_g{k}"), gw, bw)));
        let (l, h2) = (k + 1, k + 1);
        body.push(swire(&format!("lo{l}"), bw, format!("(in{k} && !w_right{k} && ng{k} > lo{k}) ? ng{k} : lo{k}")));
        body.push(swire(&format!("hi{h2}"), bw, format!("(in{k} && w_right{k} && gg{k} < hi{k}) ? gg{k} : hi{k}")));
    }
    body.push(wire("emit", 1, "w_valid && lo3 <= hi3"));
    body.push(comment("verilator lint_off UNUSEDSIGNAL"));
    body.push(wire("len_w", bw, "hi3 - lo3 + 1"));
    body.push(comment("verilator lint_on UNUSEDSIGNAL"));
    body.push(wire("lo_u", xw, format!("lo3[{}:0]", xw - 1)));
    body.push(wire("s2n", kk, format!("((w_tn + w_gxn * {}) << 1) + {}", zext("lo_u", xw, kk), zext("w_an", aw, kk))));
    for k in 0..3 {
        body.push(wire(
            &format!("rsum{k}"),
            de + 1,
            format!("{} + {}", zext(&format!("w_rem{k}"), de, de + 1), zext(&format!("w_rs256_{k}"), de, de + 1)),
        ));
        body.push(wire(&format!("cy{k}"), 1, format!("rsum{k} >= {}", zext(&format!("w_d{k}"), de, de + 1))));
        body.push(comment("verilator lint_off UNUSEDSIGNAL"));
        body.push(wire(&format!("rnext{k}"), de + 1, format!("cy{k} ? rsum{k} - {} : rsum{k}", zext(&format!("w_d{k}"), de, de + 1))));
        body.push(comment("verilator lint_on UNUSEDSIGNAL"));
    }
    let mut load = vec![set("w_valid", "1'b1"), set("w_row", "s_first"), set("w_last", "s_last")];
    for k in 0..3 {
        for (n, v) in [
            ("act", format!("s_act{k}")),
            ("right", format!("s_right{k}")),
            ("rs", format!("s_rs{k}")),
            ("re", format!("s_re{k}")),
            ("d", format!("s_d{k}")),
        ] {
            load.push(set(format!("w_{n}{k}"), v));
        }
        load.push(set(format!("w_g{k}"), format!("r_g{k}")));
        load.push(set(format!("w_rem{k}"), format!("r_rem{k}")));
        load.push(set(format!("w_qs{k}"), format!("r_qs{k}")));
        load.push(set(format!("w_rs256_{k}"), format!("r_rs256_{k}")));
    }
    load.extend([
        set("w_di", "r_di"),
        set("w_an", "s_an"),
        set("w_rn", "drn_q"),
        set("w_tn", "s_tn"),
        set("w_gxn", "s_gxn"),
        set("w_dyn", "s_dyn"),
    ]);
    let mut step = vec![set("w_row", format!("w_row + {}", lit(yw, 1))), set("w_tn", "w_tn + w_dyn")];
    for k in 0..3 {
        step.push(Stmt::If(
            format!("w_act{k} && w_row >= w_rs{k}"),
            vec![
                set(format!("w_rem{k}"), format!("rnext{k}[{}:0]", de - 1)),
                set(format!("w_g{k}"), format!("w_g{k} + w_qs{k} + {}", zext(&format!("cy{k}"), 1, gw))),
            ],
            vec![],
        ));
    }
    body.push(Item::Always(vec![Stmt::If(
        "rst".into(),
        vec![set("w_valid", "1'b0")],
        vec![Stmt::If(
            "take".into(),
            load,
            vec![Stmt::If("adv && w_valid".into(), vec![Stmt::If("w_end".into(), vec![set("w_valid", "1'b0")], step)], vec![])],
        )],
    )]));
    body.push(Item::Blank);

    // ---- I0 pipeline.
    body.push(comment("I0: q~ = (S2n Rn) >> K is the quotient or one below it; one compare corrects it."));
    for (n, ww) in
        [("p1_v", 1), ("p1_y", yw), ("p1_x", xw), ("p1_len", xw + 1), ("p1_di", dw), ("p1_s2n", kk), ("p1_rn", rw), ("p1_an", aw)]
    {
        body.push(reg(n, ww));
    }
    for (n, ww) in
        [("p2_v", 1), ("p2_y", yw), ("p2_x", xw), ("p2_len", xw + 1), ("p2_di", dw), ("p2_lo", aw + 2), ("p2_qt", iw), ("p2_an", aw)]
    {
        body.push(reg(n, ww));
    }
    if scan {
        body.push(comment("The same for the span's last pixel: its intensity, as the edge gives it."));
        body.push(wire("hi_u", xw, format!("hi3[{}:0]", xw - 1)));
        body.push(wire("s2h", kk, format!("((w_tn + w_gxn * {}) << 1) + {}", zext("hi_u", xw, kk), zext("w_an", aw, kk))));
        body.extend([reg("p1_s2h", kk), reg("p2_hi", aw + 2), reg("p2_qh", iw)]);
    }
    let pr = kk + rw;
    body.push(comment("verilator lint_off UNUSEDSIGNAL"));
    body.push(wire("prod", pr, format!("{} * {}", zext("p1_s2n", kk, pr), zext("p1_rn", rw, pr))));
    body.push(comment("verilator lint_on UNUSEDSIGNAL"));
    let cw = aw + 2;
    body.push(wire("an2", cw, format!("{} << 1", zext("p2_an", aw, cw))));
    body.push(wire("corr", cw, format!("p2_lo - {} * an2", zext("p2_qt", iw, cw))));
    body.push(wire("i0", iw, format!("p2_qt + {}", zext("corr >= an2", 1, iw))));
    let mut p_scan = Vec::new();
    if scan {
        body.push(comment("verilator lint_off UNUSEDSIGNAL"));
        body.push(wire("prodh", pr, format!("{} * {}", zext("p1_s2h", kk, pr), zext("p1_rn", rw, pr))));
        body.push(comment("verilator lint_on UNUSEDSIGNAL"));
        body.push(wire("corrh", cw, format!("p2_hi - {} * an2", zext("p2_qh", iw, cw))));
        body.push(wire("ilast", iw, format!("p2_qh + {}", zext("corrh >= an2", 1, iw))));
        body.push(comment("dI = round(|I_last - I0| / (m - 1)), its sign apart: (2 |N| + D) / 2D, D = m - 1."));
        body.push(wire("p2_div", 1, format!("p2_len > {}", lit(xw + 1, 1))));
        body.push(wire("nabs", iw, "ilast >= i0 ? ilast - i0 : i0 - ilast"));
        body.push(wire("dm1", xw + 1, format!("p2_len - {}", lit(xw + 1, 1))));
        body.extend(div_chain(&sdv, "sd_cnt", sd_cw, hw.div_bits));
        body.push(wire("sd_fin", 1, format!("sd_cnt < {}", lit(sd_cw, hw.div_bits as u64))));
        let q = format!("sdv_q{}", hw.div_bits);
        body.push(wire("sd_di", dw, format!("sd_neg ? -{} : {}", zext(&q, iw, dw), zext(&q, iw, dw))));
        let mut start = vec![set("sd_busy", "1'b1"), set("sd_cnt", lit(sd_cw, (sq - 1) as u64)), set("sd_neg", "ilast < i0")];
        start.extend(div_load(
            &sdv,
            &format!("({} << 1) + {}", zext("nabs", iw, sdv.pw), zext("dm1", xw + 1, sdv.pw)),
            &format!("{} << {sq}", zext("dm1", xw + 1, sdv.pw)),
        ));
        let mut run = div_iter(&sdv, hw.div_bits);
        run.push(Stmt::If(
            "sd_fin".into(),
            vec![set("sd_busy", "1'b0")],
            vec![set("sd_cnt", format!("sd_cnt - {}", lit(sd_cw, hw.div_bits as u64)))],
        ));
        body.push(Item::Always(vec![Stmt::If(
            "rst".into(),
            vec![set("sd_busy", "1'b0")],
            vec![Stmt::If("adv && p2_v && p2_div".into(), start, vec![Stmt::If("sd_busy".into(), run, vec![])])],
        )]));
        body.push(comment("verilator lint_off UNUSEDSIGNAL"));
        body.push(wire("unused_di", dw, "p2_di"));
        body.push(comment("verilator lint_on UNUSEDSIGNAL"));
        p_scan =
            vec![set("p1_s2h", "s2h"), set("p2_hi", format!("p1_s2h[{}:0]", cw - 1)), set("p2_qh", format!("prodh[{}:{kk}]", kk + iw - 1))];
    }
    body.push(Item::Always(vec![Stmt::If(
        "rst".into(),
        vec![set("p1_v", "1'b0"), set("p2_v", "1'b0"), set("out_valid", "1'b0")],
        vec![Stmt::If(
            "adv".into(),
            vec![
                set("p1_v", "emit"),
                set("p1_y", "w_row"),
                set("p1_x", "lo_u"),
                set("p1_len", format!("len_w[{xw}:0]")),
                set("p1_di", "w_di"),
                set("p1_s2n", "s2n"),
                set("p1_rn", "w_rn"),
                set("p1_an", "w_an"),
                set("p2_v", "p1_v"),
                set("p2_y", "p1_y"),
                set("p2_x", "p1_x"),
                set("p2_len", "p1_len"),
                set("p2_di", "p1_di"),
                set("p2_lo", format!("p1_s2n[{}:0]", cw - 1)),
                set("p2_qt", format!("prod[{}:{kk}]", kk + iw - 1)),
                set("p2_an", "p1_an"),
                set("out_valid", if scan { "p2_v && !p2_div" } else { "p2_v" }),
                set("out_y", "p2_y"),
                set("out_x", "p2_x"),
                set("out_len", "p2_len"),
                set("out_i0", "i0"),
                set("out_di", if scan { lit(dw, 0) } else { "p2_di".into() }),
            ]
            .into_iter()
            .chain(p_scan)
            .collect(),
            match scan {
                true => vec![Stmt::If("sd_busy && sd_fin".into(), vec![set("out_valid", "1'b1"), set("out_di", "sd_di")], vec![])],
                false => vec![],
            },
        )],
    )]));

    // The formal properties (scripts/prove): the per-triangle dI's control. The scanline
    // comparison option's divider adds a stall of its own and is left to co-simulation.
    if !scan {
        body.push(crate::formal::frontend_properties(&crate::formal::FrontendShape {
            yw,
            cx,
            cy,
            xw,
            dw,
            width: w as u64,
            height: h as u64,
            cnt_w,
            bits,
            rw,
            div_clocks: hw.div_clocks(),
            div_regs: divs.iter().flat_map(|d| ["p", "d", "q"].map(|r| format!("{}_{r}", d.name))).collect(),
        }));
    }

    Module {
        name: names.frontend.clone(),
        header,
        params: vec![],
        ports: ports(fe, &wd).into_iter().chain(span_ports(fe, &wd)).collect(),
        body,
    }
}

/// `tri_shader_p<P>`: the front-end, then the segment shader; `y` waits in a four-entry FIFO
/// from the span's transfer into the shader to its last segment, so the shader keeps SPEC §3's
/// ports exactly.
pub fn top_module(hw: &Hw, names: &Names) -> Module {
    let fe = &hw.fe;
    let cfg = &fe.cfg;
    let wd = fe.widths();
    let (xw, iw, dw, yw, p) = (cfg.xbits, cfg.iw(), cfg.dw(), wd.yw, cfg.p);
    let header = vec![
        format!("{} — triangles in, segments of {p} pixels with their scanline out.", names.top),
        "Generated by segshade hdl-gen; do not edit.".into(),
        String::new(),
        format!("Chain: {} (set-up, edge walker) -> 4-span FIFO -> {} -> out.", names.frontend, names.segment),
        "The span FIFO lets the walker run on while the shader cuts a long span (and the shader on through".into(),
        "the walker's bubbles); out_y comes from a 4-entry FIFO pushed when a span enters the shader and".into(),
        "popped with its last segment, so the shader keeps SPEC §3's ports.".into(),
        format!(
            "Configuration: P = {p}, F = {}, XW = {xw}, align = {}, screen {}x{}.",
            cfg.frac, cfg.align, fe.screen.width, fe.screen.height
        ),
        format!("Latency: first segment {} clocks after the triangle's transfer when idle.", hw.shader_latency()),
    ];
    let mut ports: Vec<Port> = ports(fe, &wd)
        .into_iter()
        .map(|mut p| {
            p.reg = false;
            p
        })
        .collect();
    ports.extend([
        Port::output("out_valid", 1, "", "segment valid"),
        Port::input("out_ready", 1, "", "segment taken when out_valid && out_ready"),
        Port::output("out_y", yw, "unsigned integer", "scanline of the segment"),
        Port::output("out_x", xw, "unsigned integer", "screen x of lane 0"),
        Port::output("out_pix", 8 * p, &format!("{p} lanes of UQ8.0"), "lane i = pixel at out_x + i"),
        Port::output("out_mask", p, "bit per lane", "lane i lies inside the span").vector(),
        Port::output("out_last", 1, "", "final segment of the span"),
    ]);
    let sw = yw + xw + (xw + 1) + iw + dw;
    let mut body = vec![comment("The front-end's span stream, and a 4-span FIFO between it and the shader.")];
    for (n, w) in [("f_valid", 1), ("f_ready", 1), ("f_y", yw), ("f_x", xw), ("f_len", xw + 1), ("f_i0", iw), ("f_di", dw)] {
        body.push(Item::Wire { name: n.into(), width: w, signed: false, value: None });
    }
    body.extend([
        Item::Memory { name: "sfifo".into(), width: sw, depth: 4 },
        reg("sf_n", 3),
        reg("sf_rd", 2),
        reg("sf_wr", 2),
        assign("f_ready", "sf_n != 3'd4"),
        wire("f_push", 1, "f_valid && f_ready"),
        wire("s_valid", 1, "sf_n != 3'd0"),
        wire("s_word", sw, "sfifo[sf_rd]"),
        wire("s_y", yw, format!("s_word[{}:{}]", sw - 1, sw - yw)),
        wire("s_x", xw, format!("s_word[{}:{}]", sw - yw - 1, sw - yw - xw)),
        wire("s_len", xw + 1, format!("s_word[{}:{}]", iw + dw + xw, iw + dw)),
        wire("s_i0", iw, format!("s_word[{}:{}]", iw + dw - 1, dw)),
        swire("s_di", dw, format!("s_word[{}:0]", dw - 1)),
        comment("y of the spans inside the shader, oldest first."),
        Item::Wire { name: "sh_ready".into(), width: 1, signed: false, value: None },
        reg("fifo_n", 3),
        reg("fifo_rd", 2),
        reg("fifo_wr", 2),
        Item::Memory { name: "fifo".into(), width: yw, depth: 4 },
        wire("room", 1, "fifo_n != 3'd4"),
        wire("s_pop", 1, "s_valid && sh_ready && room"),
        wire("pop", 1, "out_valid && out_ready && out_last"),
        assign("out_y", "fifo[fifo_rd]"),
    ]);
    let mut fe_conns: Vec<(String, String)> =
        ["clk", "rst", "in_valid", "in_ready", "err"].iter().map(|n| (n.to_string(), n.to_string())).collect();
    for k in 0..3 {
        for n in ["x", "y", "i"] {
            fe_conns.push((format!("in_{n}{k}"), format!("in_{n}{k}")));
        }
    }
    for (port, sig) in [
        ("out_valid", "f_valid"),
        ("out_ready", "f_ready"),
        ("out_y", "f_y"),
        ("out_x", "f_x"),
        ("out_len", "f_len"),
        ("out_i0", "f_i0"),
        ("out_di", "f_di"),
    ] {
        fe_conns.push((port.into(), sig.into()));
    }
    body.push(Item::Instance { module: names.frontend.clone(), name: "u_frontend".into(), params: vec![], conns: fe_conns });
    let sh_conns: Vec<(String, String)> = [
        ("clk", "clk"),
        ("rst", "rst"),
        ("in_valid", "s_valid && room"),
        ("in_ready", "sh_ready"),
        ("in_x", "s_x"),
        ("in_len", "s_len"),
        ("in_i0", "s_i0"),
        ("in_di", "s_di"),
        ("out_valid", "out_valid"),
        ("out_ready", "out_ready"),
        ("out_x", "out_x"),
        ("out_pix", "out_pix"),
        ("out_mask", "out_mask"),
        ("out_last", "out_last"),
    ]
    .iter()
    .map(|(a, b)| (a.to_string(), b.to_string()))
    .collect();
    body.push(Item::Instance { module: names.segment.clone(), name: "u_shader".into(), params: vec![], conns: sh_conns });
    body.push(Item::Always(vec![Stmt::If(
        "rst".into(),
        vec![
            set("fifo_n", "3'd0"),
            set("fifo_rd", "2'd0"),
            set("fifo_wr", "2'd0"),
            set("sf_n", "3'd0"),
            set("sf_rd", "2'd0"),
            set("sf_wr", "2'd0"),
        ],
        vec![
            Stmt::If("f_push".into(), vec![set("sfifo[sf_wr]", "{f_y, f_x, f_len, f_i0, f_di}"), set("sf_wr", "sf_wr + 2'd1")], vec![]),
            Stmt::If("s_pop".into(), vec![set("sf_rd", "sf_rd + 2'd1")], vec![]),
            Stmt::If(
                "f_push && !s_pop".into(),
                vec![set("sf_n", "sf_n + 3'd1")],
                vec![Stmt::If("s_pop && !f_push".into(), vec![set("sf_n", "sf_n - 3'd1")], vec![])],
            ),
            Stmt::If("s_pop".into(), vec![set("fifo[fifo_wr]", "s_y"), set("fifo_wr", "fifo_wr + 2'd1")], vec![]),
            Stmt::If("pop".into(), vec![set("fifo_rd", "fifo_rd + 2'd1")], vec![]),
            Stmt::If(
                "s_pop && !pop".into(),
                vec![set("fifo_n", "fifo_n + 3'd1")],
                vec![Stmt::If("pop && !s_pop".into(), vec![set("fifo_n", "fifo_n - 3'd1")], vec![])],
            ),
        ],
    )]));
    Module { name: names.top.clone(), header, params: vec![], ports, body }
}
