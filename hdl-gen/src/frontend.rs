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
//!   next triangle's CALC, and the next triangle is latched while the dividers run. At
//!   `--pipeline 1` and above CALC is five register stages ([`golden::pipeline::SETUP_STAGES`],
//!   written once through [`stager`]), a queue in front of the dividers: the triangles behind
//!   move through it while the dividers run, so only the latency grows.
//! - **edge walker**: one row per clock. Per active edge one DDA step (add, compare, subtract);
//!   `lo` and `hi` are the max and min of the active bounds, clipped to the screen. It loads the
//!   next triangle in the clock its current one finishes, so set-up overlaps the walk.
//! - **I0 pipeline** (two stages after the walker): `S2n = 2 (Tn + Gxn lo) + An` in the
//!   walker's clock, then `q~ = (S2n Rn) >> K`, then the correction `q~ + (S2n - 2 An q~ >= 2 An)`.
//!   At `--pipeline 1` and above six stages, one multiply or two adders each
//!   ([`golden::pipeline::I0_STAGES`]), the product by `Rn` in two registered halves.
//!   One stall signal holds the walker and every stage while the output waits.

mod stager;

use stager::Stager;

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
    /// The chain's register stages (`--pipeline`): the shader's, and the set-up's CALC stages.
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

    /// Clocks CALC takes: 1, or its stages at `--pipeline 1` and above.
    pub fn calc_clocks(&self) -> u32 {
        self.pipeline.calc_clocks()
    }

    /// Register stages between the walker and the output register: 2, or 6 at `--pipeline 1`
    /// and above ([`golden::pipeline::i0_registers`]).
    pub fn i0_stages(&self) -> u32 {
        golden::pipeline::i0_registers(self.pipeline).iter().filter(|&&r| r).count() as u32
    }

    /// Clocks from a triangle's transfer to the first span's `out_valid` when the walker is
    /// idle: CALC, the dividers, the hand-off, the walker's clock, the span path's stages (and,
    /// per scanline, the span's division when it has two pixels or more).
    pub fn latency(&self) -> u32 {
        self.calc_clocks() + self.div_clocks() + 2 + self.i0_stages() + self.span_div_clocks()
    }

    /// Clocks from a triangle's transfer to the first segment out of `tri_shader_p<P>` when idle:
    /// the front-end's latency, then the shader's at the chain's pipeline level.
    pub fn shader_latency(&self) -> u32 {
        self.latency() + golden::segment::latency(&self.fe.cfg, self.pipeline)
    }

    /// Set-up clocks per triangle that is walked (the rate limit for tiny triangles: the
    /// dividers, then the hand-off clock, which is also the next triangle's last CALC clock),
    /// and per triangle dropped in set-up (its last CALC clock). CALC's earlier stages overlap
    /// the triangle ahead's division, so neither depends on the pipeline level.
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

/// The register stages of a pipelined front-end, for the manifest (none at level 0, whose
/// structure SPEC's seed fixes): CALC's (`calc<j>`), then the span path's (`span<j>`); stage j
/// holds what the logical step before it computed, for the clocks after it.
pub fn stages(hw: &Hw) -> Vec<golden::pipeline::PipeStage> {
    build(hw, &Names::new("", &hw.fe.cfg)).1
}

fn stage_list(st: &Stager, name: &str, logic: &[&str]) -> Vec<golden::pipeline::PipeStage> {
    (1..=st.stage())
        .map(|j| golden::pipeline::PipeStage {
            stage: j as u32,
            name: format!("{name}{j}"),
            logic: logic[j - 1].into(),
            regs: st
                .regs(j - 1)
                .into_iter()
                .map(|(n, bits, signed)| golden::pipeline::PipeReg::new(&n, bits, if signed { "signed" } else { "unsigned" }))
                .collect(),
        })
        .collect()
}

/// CALC (SPEC §6's set-up arithmetic), written once as its stages ([`golden::pipeline::SETUP_STAGES`]):
/// one clock at level 0, a register boundary after each stage above it. Values are computed
/// where their operands are ready, so a sign decided late (the area's) is applied to products
/// formed early: the products are taken of unoriented differences and negated with the
/// orientation. The caller reads what the last stage hands on before it declares the stage
/// registers ([`Stager::items`] refuses a register added after).
fn calc(hw: &Hw) -> Stager {
    let fe = &hw.fe;
    let cfg = &fe.cfg;
    let Widths { yw, cx, cy, aw, gw, k: kk, sw, .. } = fe.widths();
    let (xw, iw) = (cfg.xbits, cfg.iw());
    let (w, h) = (fe.screen.width as i64, fe.screen.height as i64);
    let (nxw, nyw, rxw, ryw) = (iw + cy + 3, iw + cx + 3, xw + 3, cy - 7);
    let cuts = hw.pipeline.calc_clocks() as usize - 1;
    let mut st = Stager::new("c", vec![cuts > 0; golden::pipeline::SETUP_STAGES.len() - 1]);
    for k in 0..3 {
        st.input(&format!("vx{k}"), cx, true);
        st.input(&format!("vy{k}"), cy, true);
        st.input(&format!("vi{k}"), iw, false);
    }
    let section = |st: &mut Stager| {
        let what = golden::pipeline::SETUP_STAGES[st.logical()];
        let head = if cuts == 0 { format!("CALC, step {} of the clock", st.logical()) } else { format!("CALC stage {}", st.stage()) };
        st.note(Item::Blank);
        st.note(comment(format!("{head}: {what}.")));
    };
    let min3 = |a: &str, b: &str, c: &str, less: bool| {
        let op = if less { "<" } else { ">" };
        format!("(({a} {op} {b}) ? (({a} {op} {c}) ? {a} : {c}) : (({b} {op} {c}) ? {b} : {c}))")
    };
    let edge = |k: usize| ((k + 1) % 3, (k + 2) % 3);

    // Stage 0, from the vertex registers.
    section(&mut st);
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
    st.def("guard_ok", 1, false, guard.join(" && "));
    st.note(comment("Edge k runs from vertex k+1 to vertex k+2; u, v span the area, d the intensities."));
    for (n, a, b, ww) in [("u1", "vx1", "vx0", cx), ("u2", "vx2", "vx0", cx), ("v1", "vy1", "vy0", cy), ("v2", "vy2", "vy0", cy)] {
        st.def(n, ww + 1, true, format!("{} - {}", sext(a, ww, ww + 1), sext(b, ww, ww + 1)));
    }
    for k in 0..3 {
        let (a, b) = edge(k);
        st.def(
            &format!("rdx{k}"),
            cx + 1,
            true,
            format!("{} - {}", sext(&format!("vx{b}"), cx, cx + 1), sext(&format!("vx{a}"), cx, cx + 1)),
        );
        st.def(
            &format!("rdy{k}"),
            cy + 1,
            true,
            format!("{} - {}", sext(&format!("vy{b}"), cy, cy + 1), sext(&format!("vy{a}"), cy, cy + 1)),
        );
    }
    let iz = |v: &str, to: u32| zext(v, iw, to);
    st.def("d1", iw + 1, true, format!("{} - {}", iz("vi1", iw + 1), iz("vi0", iw + 1)));
    st.def("d2", iw + 1, true, format!("{} - {}", iz("vi2", iw + 1), iz("vi0", iw + 1)));
    st.note(comment("Bounding box in rows and columns (centres at +128 sub-pixels); each edge's rows."));
    st.def("ymin", cy, true, min3("vy0", "vy1", "vy2", true));
    st.def("ymax", cy, true, min3("vy0", "vy1", "vy2", false));
    st.def("xmin", cx, true, min3("vx0", "vx1", "vx2", true));
    st.def("xmax", cx, true, min3("vx0", "vx1", "vx2", false));
    st.def("xmin_c", cx + 1, true, format!("{} + {}", sext("xmin", cx, cx + 1), slit(cx + 1, 127)));
    st.def("xmax_c", cx + 1, true, format!("{} - {}", sext("xmax", cx, cx + 1), slit(cx + 1, 128)));
    for k in 0..3 {
        let (a, b) = edge(k);
        let (ya, yb2) = (format!("vy{a}"), format!("vy{b}"));
        st.def(&format!("yt{k}"), cy, true, format!("{ya} < {yb2} ? {ya} : {yb2}"));
        st.def(&format!("yb{k}"), cy, true, format!("{ya} < {yb2} ? {yb2} : {ya}"));
        st.def(&format!("ytc{k}"), cy + 1, true, format!("{} + {}", sext(&format!("yt{k}"), cy, cy + 1), slit(cy + 1, 127)));
        st.def(&format!("ybc{k}"), cy + 1, true, format!("{} - {}", sext(&format!("yb{k}"), cy, cy + 1), slit(cy + 1, 128)));
        // x distance from vertex a to the first column's centre, for e(128, .) below.
        st.def(&format!("rx{k}"), cx + 2, true, format!("{} - {}", lit(cx + 2, 128), sext(&format!("vx{a}"), cx, cx + 2)));
    }
    st.def("xo", cx + 2, true, format!("{} - {}", lit(cx + 2, 128), sext("vx0", cx, cx + 2)));
    st.cut();

    // Stage 1.
    section(&mut st);
    st.mul("m_a1", "u1", cx + 1, "v2", cy + 1);
    st.mul("m_a2", "v1", cy + 1, "u2", cx + 1);
    st.mul("m_x1", "d1", iw + 1, "v2", cy + 1);
    st.mul("m_x2", "d2", iw + 1, "v1", cy + 1);
    st.mul("m_y1", "d2", iw + 1, "u1", cx + 1);
    st.mul("m_y2", "d1", iw + 1, "u2", cx + 1);
    st.def("ymin_c", cy + 1, true, format!("{} + {}", sext(&st.at("ymin"), cy, cy + 1), slit(cy + 1, 127)));
    st.def("first_raw", ryw, true, format!("ymin_c[{cy}:8]"));
    st.def("first_s", ryw, true, format!("first_raw[{}] ? {} : first_raw", ryw - 1, slit(ryw, 0)));
    st.def("cfirst", rxw, true, format!("{}[{cx}:8]", st.at("xmin_c")));
    st.def("clast", rxw, true, format!("{}[{cx}:8]", st.at("xmax_c")));
    let first_centre = format!("{{first_s[{}:0], 8'd128}}", yw - 1);
    st.def("yo", cy + 2, true, format!("{} - {}", zext(&first_centre, yw + 8, cy + 2), sext(&st.at("vy0"), cy, cy + 2)));
    st.note(comment("Per edge: its rows on the screen, and the y distance from vertex a to its first row's centre."));
    for k in 0..3 {
        let (a, _) = edge(k);
        st.def(&format!("rs_raw{k}"), ryw, true, format!("{}[{cy}:8]", st.at(&format!("ytc{k}"))));
        st.def(&format!("re_raw{k}"), ryw, true, format!("{}[{cy}:8]", st.at(&format!("ybc{k}"))));
        st.def(&format!("rs{k}"), ryw, true, format!("rs_raw{k} > first_s ? rs_raw{k} : first_s"));
        st.def(&format!("rsu{k}"), yw, false, format!("rs{k}[{}:0]", yw - 1));
        st.def(
            &format!("ry{k}"),
            cy + 2,
            true,
            format!("{} - {}", zext(&format!("{{rsu{k}, 8'd128}}"), yw + 8, cy + 2), sext(&st.at(&format!("vy{a}")), cy, cy + 2)),
        );
        let r = st.at(&format!("rdy{k}"));
        st.def(&format!("ady{k}"), cy, false, format!("{r}[{cy}] ? -{r}[{}:0] : {r}[{}:0]", cy - 1, cy - 1));
        // The signs the orientation needs, before it is known: it only flips them.
        st.def(&format!("rdz{k}"), 1, false, format!("{r} == {}", slit(cy + 1, 0)));
        let x = st.at(&format!("rdx{k}"));
        st.def(&format!("rdxp{k}"), 1, false, format!("{x} > {}", slit(cx + 1, 0)));
        st.def(&format!("rdxn{k}"), 1, false, format!("{x}[{cx}]"));
    }
    st.note(comment("The last row both ways: as it is, and one sub-pixel up for a bottom edge on a row's centres."));
    let ymax = st.at("ymax");
    for (n, off) in [("0", 128), ("1", 129)] {
        st.def(&format!("ymax_c{n}"), cy + 1, true, format!("{} - {}", sext(&ymax, cy, cy + 1), slit(cy + 1, off)));
        st.def(&format!("last_raw{n}"), ryw, true, format!("ymax_c{n}[{cy}:8]"));
        st.def(&format!("last_s{n}"), ryw, true, format!("last_raw{n} > {} ? {} : last_raw{n}", slit(ryw, h - 1), slit(ryw, h - 1)));
    }
    st.cut();

    // Stage 2.
    section(&mut st);
    st.note(comment("Twice the signed area: its sign orients the edges and the plane (interior positive)."));
    st.def("area", aw + 1, true, format!("{} - {}", st.at("m_a1"), st.at("m_a2")));
    st.def("neg", 1, false, format!("area[{aw}]"));
    st.def("area_n", aw + 1, false, "neg ? -area : area");
    st.def("aabs", aw, false, format!("area_n[{}:0]", aw - 1));
    st.note(comment("The plane's normal, unoriented, and |Nx| (the orientation does not change it)."));
    st.def("nx", nxw, true, format!("{} - {}", sext(&st.at("m_x1"), nxw - 1, nxw), sext(&st.at("m_x2"), nxw - 1, nxw)));
    st.def("ny", nyw, true, format!("{} - {}", sext(&st.at("m_y1"), nyw - 1, nyw), sext(&st.at("m_y2"), nyw - 1, nyw)));
    st.def("mag", nxw, false, format!("nx[{}] ? -nx : nx", nxw - 1));
    for k in 0..3 {
        st.mul(&format!("m_e{k}"), &format!("rdx{k}"), cx + 1, &format!("ry{k}"), cy + 2);
        st.mul(&format!("m_f{k}"), &format!("rdy{k}"), cy + 1, &format!("rx{k}"), cx + 2);
    }
    st.note(comment("Orientation: edge k's direction with the interior on its left (dy < 0: going up); the"));
    st.note(comment("top-left rule. From the signs alone: the orientation flips them."));
    for k in 0..3 {
        let (z, xp, xn) = (st.at(&format!("rdz{k}")), st.at(&format!("rdxp{k}")), st.at(&format!("rdxn{k}")));
        let ry = st.at(&format!("rdy{k}"));
        st.def(&format!("dyneg{k}"), 1, false, format!("!{z} && (neg ? !{ry}[{cy}] : {ry}[{cy}])"));
        st.def(&format!("tl{k}"), 1, false, format!("dyneg{k} || ({z} && (neg ? {xn} : {xp}))"));
    }
    st.note(comment("A horizontal edge that is not top-left is a bottom edge: centres on it are not covered."));
    st.def("kill", 1, false, (0..3).map(|k| format!("({} && !tl{k})", st.at(&format!("rdz{k}")))).collect::<Vec<_>>().join(" || "));
    st.def("last_s", ryw, true, format!("kill ? {} : {}", st.at("last_s1"), st.at("last_s0")));
    let nw = cx + cy + 5;
    st.note(comment("Per edge, the offset of its first bound's dividend: B D, 1 less off a top-left edge."));
    for k in 0..3 {
        let ady = st.at(&format!("ady{k}"));
        st.def(&format!("base{k}"), nw, false, format!("({} << {}) - {}", zext(&ady, cy, nw), gw + 7, zext(&format!("!tl{k}"), 1, nw)));
    }
    st.cut();

    // Stage 3.
    section(&mut st);
    let neg = st.at("neg");
    for k in 0..3 {
        st.def(&format!("dx{k}"), cx + 1, true, format!("{neg} ? -{r} : {r}", r = st.at(&format!("rdx{k}"))));
    }
    let (first_s, cfirst, clast, last_s) = (st.at("first_s"), st.at("cfirst"), st.at("clast"), st.at("last_s"));
    st.def(
        "cull",
        1,
        false,
        format!(
            "{} == {} || {first_s} > {last_s} || {cfirst} > {clast} || {cfirst} > {} || {clast}[{}]",
            st.at("area"),
            slit(aw + 1, 0),
            slit(rxw, w - 1),
            rxw - 1
        ),
    );
    // e(128, 256 rs + 128) - t + B D from vertex a on the edge's line: the oriented products'
    // difference (one subtraction, its operands swapped by the orientation), 1 less off a
    // top-left edge, offset by B = 2^(GW-1) divisors so both quotients are non-negative (q = g + B).
    st.note(comment("Per edge: its active rows; the dividends of its first bound and of its step."));
    let snw = (cx + 2).max(gw + cy + 1);
    for k in 0..3 {
        let re_raw = st.at(&format!("re_raw{k}"));
        st.def(&format!("re{k}"), ryw, true, format!("{re_raw} < {last_s} ? {re_raw} : {last_s}"));
        st.def(&format!("act{k}"), 1, false, format!("!{} && {} <= re{k}", st.at(&format!("rdz{k}")), st.at(&format!("rs{k}"))));
        let (me, mf, ady) = (st.at(&format!("m_e{k}")), st.at(&format!("m_f{k}")), st.at(&format!("ady{k}")));
        let (me, mf) = (sext(&me, nw - 2, nw), sext(&mf, nw - 2, nw));
        st.def(&format!("e{k}"), nw, false, format!("({neg} ? {mf} : {me}) - ({neg} ? {me} : {mf})"));
        st.def(&format!("n{k}"), nw, false, format!("e{k} + {}", st.at(&format!("base{k}"))));
        st.def(
            &format!("sn{k}"),
            snw,
            false,
            format!("{} + ({} << {})", sext(&format!("dx{k}"), cx + 1, snw), zext(&ady, cy, snw), gw - 1),
        );
    }
    st.note(comment("The plane: Nx, Ny oriented; dI's dividend 2*256|Nx| + |A| and its saturation."));
    let aabs = st.at("aabs");
    st.def("onx", nxw, true, format!("{neg} ? -{nx} : {nx}", nx = st.at("nx")));
    st.def("ony", nyw, true, format!("{neg} ? -{ny} : {ny}", ny = st.at("ny")));
    st.def("nx_neg", 1, false, format!("onx[{}]", nxw - 1));
    let x2w = (nxw + 9).max(aw + 1);
    let cmpw = x2w.max(aw + iw + 1);
    st.def("x2", x2w, false, format!("({} << 9) + {}", zext(&st.at("mag"), nxw, x2w), zext(&aabs, aw, x2w)));
    st.def("di_sat", 1, false, format!("{} >= ({} << {})", zext("x2", x2w, cmpw), zext(&aabs, aw, cmpw), iw + 1));
    st.note(comment("Normalisation: s leading zeros of |A|, An = |A| << s."));
    let mut chain = lit(sw, (aw - 1) as u64);
    for bit in 1..aw {
        chain = format!("{aabs}[{bit}] ? {} : {chain}", lit(sw, (aw - 1 - bit) as u64));
    }
    st.def("lz", sw, false, chain);
    st.note(comment("The first row's sum S(0, first) = I0 |A| + Nx xo + Ny yo: its products, unoriented."));
    st.note(comment("verilator lint_off WIDTH"));
    st.def("m_s1", iw + aw, false, format!("{} * {aabs}", st.at("vi0")));
    st.note(comment("verilator lint_on WIDTH"));
    st.mul("m_s2", "nx", nxw, "xo", cx + 2);
    st.mul("m_s3", "ny", nyw, "yo", cy + 2);
    st.cut();

    // Stage 4: the sum modulo 2^K, oriented, and everything normalised by the shift s.
    section(&mut st);
    let low = |m: &str, w: u32| if w > kk { format!("{m}[{}:0]", kk - 1) } else { sext(m, w, kk) };
    let neg = st.at("neg");
    let (s2, s3) = (low(&st.at("m_s2"), nxw + cx + 2), low(&st.at("m_s3"), nyw + cy + 2));
    st.def("s0", kk, false, format!("{} + ({neg} ? -{s2} : {s2}) + ({neg} ? -{s3} : {s3})", zext(&st.at("m_s1"), iw + aw, kk)));
    let lz = st.at("lz");
    st.def("an", aw, false, format!("{} << {lz}", st.at("aabs")));
    st.def("tn0", kk, false, format!("s0 << {lz}"));
    st.note(comment("The rows, once the triangle is not culled: first_s >= 0, first_s <= last_s < height."));
    st.def("first_u", yw, false, format!("{}[{}:0]", st.at("first_s"), yw - 1));
    st.def("last_u", yw, false, format!("{}[{}:0]", st.at("last_s"), yw - 1));
    st.def("gxn0", kk, false, format!("({} << 8) << {lz}", sext(&st.at("onx"), nxw, kk)));
    st.def("dyn0", kk, false, format!("({} << 8) << {lz}", sext(&st.at("ony"), nyw, kk)));
    st
}

pub fn module(hw: &Hw, names: &Names) -> Module {
    build(hw, names).0
}

/// The module, and its register stages when it is pipelined ([`stages`]).
fn build(hw: &Hw, names: &Names) -> (Module, Vec<golden::pipeline::PipeStage>) {
    let fe = &hw.fe;
    let bits = hw.div_bits;
    let cfg = &fe.cfg;
    let wd = fe.widths();
    let Widths { yw, cx, cy, aw, gw, dw_edge: de, k: kk, rw, .. } = wd;
    let (xw, iw, dw) = (cfg.xbits, cfg.iw(), cfg.dw());
    let (w, h) = (fe.screen.width as i64, fe.screen.height as i64);
    let cnt_w = 32 - rw.leading_zeros();

    let header = vec![
        format!("{} — triangle front-end (SPEC §6): set-up and edge walker, one span per clock.", names.frontend),
        "Generated by segshade hdl-gen; do not edit.".into(),
        String::new(),
        format!("Configuration: screen {}x{}, F = {}, XW = {xw}, pipeline level {}; rows {yw} bits.", w, h, cfg.frac, hw.pipeline),
        format!("Vertices: x signed Q{}.8 ({cx} bits), y signed Q{}.8 ({cy} bits), I UQ8.{} ({iw} bits).", xw + 2, yw + 2, cfg.frac),
        format!("Guard band: -{w} <= x < {}, -{h} <= y < {} pixels; a triangle outside it is dropped and pulses err.", 2 * w, 2 * h),
        "Coverage: exactly golden::setup's (top-left rule, pixel centres, clipped), by an integer DDA per edge.".into(),
        format!("Spans: (y, x0, m, I0, dI) in SPEC §2's formats; I0 correctly rounded, dI rounded once per triangle;"),
        format!("every pixel within 1/2 + W 2^-(F+1) <= 1 of the plane through the vertex intensities."),
        format!(
            "Set-up: CALC in {}, {} divider clocks (8 restoring dividers in parallel, {bits} quotient bit(s) a clock), hand-off;",
            if hw.calc_clocks() == 1 { "one clock".to_string() } else { format!("{} register stages", hw.calc_clocks()) },
            hw.div_clocks()
        ),
        format!(
            "{} clocks per walked triangle, 1 per dropped one; {}",
            hw.setup_clocks().0,
            if hw.calc_clocks() > 1 {
                "the next triangles move through CALC's stages meanwhile."
            } else {
                "the next triangle is latched meanwhile."
            }
        ),
        format!("Latency: first span valid {} clocks after the triangle's transfer when the walker is idle.", hw.latency()),
        format!("Spans: the walker, then {} register stages to the output register (I0's path).", hw.i0_stages()),
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

    let st = calc(hw);
    // What the last CALC stage hands on (the dividers' loads, the set-up's result, the decision)
    // is read before the stage registers are declared, so every register carrying it is among them.
    let (pw_init, pw_step) = (gw + de, gw + cy);
    let divs: Vec<Div> = (0..3)
        .flat_map(|k| {
            [Div { name: ["ei0", "ei1", "ei2"][k], pw: pw_init, qb: gw }, Div { name: ["es0", "es1", "es2"][k], pw: pw_step, qb: gw }]
        })
        .chain([Div { name: "ddi", pw: iw + aw + 1, qb: iw }, Div { name: "drn", pw: aw + rw + 1, qb: rw }])
        .collect();
    let mut calc_load = vec![set("div_cnt", lit(cnt_w, (rw - 1) as u64)), set("st", "DIV")];
    for k in 0..3 {
        let ei = &divs[2 * k];
        let es = &divs[2 * k + 1];
        let ady = st.at(&format!("ady{k}"));
        calc_load.extend(div_load(
            ei,
            &format!("{}[{}:0]", st.at(&format!("n{k}")), pw_init - 1),
            &format!("{} << {}", zext(&ady, cy, pw_init), gw + 7),
        ));
        calc_load.extend(div_load(
            es,
            &format!("{}[{}:0]", st.at(&format!("sn{k}")), pw_step - 1),
            &format!("{} << {}", zext(&ady, cy, pw_step), gw - 1),
        ));
        calc_load.push(set(format!("s_act{k}"), st.at(&format!("act{k}"))));
        calc_load.push(set(format!("s_right{k}"), format!("!{}", st.at(&format!("dyneg{k}")))));
        calc_load.push(set(format!("s_rs{k}"), st.at(&format!("rsu{k}"))));
        calc_load.push(set(format!("s_re{k}"), format!("{}[{}:0]", st.at(&format!("re{k}")), yw - 1)));
        calc_load.push(set(format!("s_d{k}"), format!("{{{ady}, 8'd0}}")));
    }
    let ddi_pw = iw + aw + 1;
    let (x2, x2w) = (st.at("x2"), st.width("x2"));
    let x2_fit = if x2w >= ddi_pw { format!("{x2}[{}:0]", ddi_pw - 1) } else { zext(&x2, x2w, ddi_pw) };
    calc_load.extend(div_load(&divs[6], &x2_fit, &format!("{} << {}", zext(&st.at("aabs"), aw, ddi_pw), iw)));
    calc_load.extend(div_load(
        &divs[7],
        &format!("{} << {}", lit(aw + rw + 1, 1), kk),
        &format!("{} << {}", zext(&st.at("an"), aw, aw + rw + 1), rw),
    ));
    for (r, v) in [
        ("s_first", "first_u"),
        ("s_last", "last_u"),
        ("s_an", "an"),
        ("s_tn", "tn0"),
        ("s_gxn", "gxn0"),
        ("s_dyn", "dyn0"),
        ("s_sat", "di_sat"),
        ("s_dineg", "nx_neg"),
    ] {
        calc_load.push(set(r, st.at(v)));
    }
    let (guard, cull) = (st.at("guard_ok"), st.at("cull"));
    let last = st.stage();
    // The stages' moves: stage j's triangle moves into stage j + 1 when that one is empty or
    // moving on; the last stage moves on into the dividers (calc).
    let valid = |j: usize| if j == 0 { "v_full".to_string() } else { format!("c{j}_v") };
    let mv = |j: usize| if j == last { "calc".to_string() } else { format!("c{j}_mv") };
    let v_go = mv(0);
    for j in 1..=last {
        body.push(reg(&valid(j), 1));
    }
    body.push(wire("calc", 1, format!("{} && (st == IDLE || take)", valid(last))));
    for j in (0..last).rev() {
        body.push(wire(&mv(j), 1, format!("{} && (!{} || {})", valid(j), valid(j + 1), mv(j + 1))));
    }
    body.push(assign("in_ready", format!("!v_full || {}", mv(0))));
    // Stages hand on whole values and read slices of some: unused bits are expected here.
    body.push(comment("verilator lint_off UNUSEDSIGNAL"));
    body.extend(st.items());
    body.push(comment("verilator lint_on UNUSEDSIGNAL"));
    if last > 0 {
        let mut moves = Vec::new();
        let mut data = Vec::new();
        for j in 1..=last {
            moves.push(Stmt::If(mv(j - 1), vec![set(valid(j), "1'b1")], vec![Stmt::If(mv(j), vec![set(valid(j), "1'b0")], vec![])]));
            data.push(Stmt::If(mv(j - 1), st.loads(j - 1), vec![]));
        }
        body.push(Item::Always(vec![Stmt::If("rst".into(), (1..=last).map(|j| set(valid(j), "1'b0")).collect(), moves)]));
        body.push(Item::Always(data));
    }
    body.push(Item::Blank);
    // ---- Dividers and the set-up result registers.
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
            Stmt::If("in_valid && in_ready".into(), take_in, vec![Stmt::If(v_go, vec![set("v_full", "1'b0")], vec![])]),
            Stmt::If(
                "calc".into(),
                vec![Stmt::If(
                    format!("!{guard}"),
                    vec![set("err", "1'b1"), set("st", "IDLE")],
                    vec![Stmt::If(cull.clone(), vec![set("st", "IDLE")], calc_load)],
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
        body.push(swire(&format!("gg{k}"), bw, sext(&format!("w_g{k}"), gw, bw)));
        // This edge's bound on its side of the row, or the screen's where it bounds none here;
        // a left edge's bound is -g, kept as g (its smallest is the span's left end).
        body.push(swire(&format!("lg{k}"), bw, format!("(in{k} && !w_right{k} && gg{k} < lo0) ? gg{k} : lo0")));
        body.push(swire(&format!("ha{k}"), bw, format!("(in{k} && w_right{k} && gg{k} < hi0) ? gg{k} : hi0")));
    }
    // Side by side rather than in a chain, and no negation before the pixel test or the length:
    // this is the walker's row clock, the staged front-end's limit at 2 and 1 quotient bits.
    body.push(comment("The span's ends, the edges compared side by side: x = lo3 = -mg (the smallest left-edge g),"));
    body.push(comment("hi3 the smallest right bound; the row has a pixel when hi3 + mg >= 0."));
    for (end, side) in [("mg", "lg"), ("hi3", "ha")] {
        let c = |i: u32, j: u32| format!("{side}{i} <= {side}{j}");
        body.push(swire(end, bw, format!("({} && {}) ? {side}0 : ({}) ? {side}1 : {side}2", c(0, 1), c(0, 2), c(1, 2))));
    }
    body.push(comment("verilator lint_off UNUSEDSIGNAL"));
    body.push(swire("lo3", bw, "-mg"));
    body.push(swire("room", bw + 1, format!("{} + {}", sext("hi3", bw, bw + 1), sext("mg", bw, bw + 1))));
    body.push(wire("len_w", bw, "hi3 + mg + 1"));
    body.push(comment("verilator lint_on UNUSEDSIGNAL"));
    body.push(wire("emit", 1, format!("w_valid && !room[{bw}]")));
    body.push(wire("lo_u", xw, format!("lo3[{}:0]", xw - 1)));
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

    // ---- I0: the span path, written once as its logical stages (`I0_STAGES`), registered where
    // the pipeline level asks; every register moves on `adv`, so one stall holds them all.
    let mut sp = Stager::new("p", golden::pipeline::i0_registers(hw.pipeline).to_vec());
    let i0_section = |sp: &mut Stager| {
        let what = golden::pipeline::I0_STAGES[sp.logical()];
        sp.note(Item::Blank);
        sp.note(comment(format!("Span path, step {} (stage p{}): {what}.", sp.logical(), sp.stage())));
    };
    let pr = kk + rw;
    let cw = aw + 2;
    let half = rw / 2;
    // The span's first pixel's intensity and, per scanline, its last pixel's, the edge's value
    // there: the same path twice, under these names.
    struct End {
        x: &'static str,
        gx: &'static str,
        s2: &'static str,
        lo: &'static str,
        pl: &'static str,
        ph: &'static str,
        prod: &'static str,
        qt: &'static str,
        m: &'static str,
        corr: &'static str,
        out: &'static str,
    }
    let head = End { x: "x", gx: "gx", s2: "s2n", lo: "lo", pl: "pl", ph: "ph", prod: "prod", qt: "qt", m: "m", corr: "corr", out: "i0" };
    let tail = End {
        x: "xh",
        gx: "gxh",
        s2: "s2h",
        lo: "hi",
        pl: "plh",
        ph: "phh",
        prod: "prodh",
        qt: "qh",
        m: "mh",
        corr: "corrh",
        out: "ilast",
    };
    let ends: Vec<&End> = if scan { vec![&head, &tail] } else { vec![&head] };
    i0_section(&mut sp);
    for (n, ww, src) in [
        ("y", yw, "w_row".to_string()),
        ("x", xw, "lo_u".into()),
        ("len", xw + 1, format!("len_w[{xw}:0]")),
        ("tn", kk, "w_tn".into()),
        ("gxn", kk, "w_gxn".into()),
        ("an", aw, "w_an".into()),
        ("rn", rw, "w_rn".into()),
    ] {
        sp.input_as(n, ww, false, &src);
    }
    if scan {
        sp.input_as("xh", xw, false, &format!("hi3[{}:0]", xw - 1));
        body.push(comment("verilator lint_off UNUSEDSIGNAL"));
        body.push(wire("unused_di", dw, "w_di"));
        body.push(comment("verilator lint_on UNUSEDSIGNAL"));
    } else {
        sp.input_as("di", dw, false, "w_di");
    }
    sp.cut();
    i0_section(&mut sp);
    for e in &ends {
        sp.def(e.gx, kk, false, format!("{} * {}", sp.at("gxn"), zext(&sp.at(e.x), xw, kk)));
    }
    sp.cut();
    i0_section(&mut sp);
    for e in &ends {
        sp.def(e.s2, kk, false, format!("(({} + {}) << 1) + {}", sp.at("tn"), sp.at(e.gx), zext(&sp.at("an"), aw, kk)));
    }
    sp.cut();
    i0_section(&mut sp);
    let split = sp.registered_next();
    for e in &ends {
        let s2 = sp.at(e.s2);
        sp.def(e.lo, cw, false, format!("{s2}[{}:0]", cw - 1));
        if split {
            let rn = sp.at("rn");
            sp.def(
                e.pl,
                kk + half,
                false,
                format!("{} * {}", zext(&s2, kk, kk + half), zext(&format!("{rn}[{}:0]", half - 1), half, kk + half)),
            );
            sp.def(
                e.ph,
                kk + rw - half,
                false,
                format!("{} * {}", zext(&s2, kk, kk + rw - half), zext(&format!("{rn}[{}:{half}]", rw - 1), rw - half, kk + rw - half)),
            );
        }
    }
    sp.cut();
    i0_section(&mut sp);
    sp.note(comment("verilator lint_off UNUSEDSIGNAL"));
    for e in &ends {
        let prod = if split {
            let (pl, ph) = (sp.at(e.pl), sp.at(e.ph));
            format!("{} + ({} << {half})", zext(&pl, kk + half, pr), zext(&ph, kk + rw - half, pr))
        } else {
            format!("{} * {}", zext(&sp.at(e.s2), kk, pr), zext(&sp.at("rn"), rw, pr))
        };
        sp.def(e.prod, pr, false, prod);
    }
    sp.note(comment("verilator lint_on UNUSEDSIGNAL"));
    for e in &ends {
        sp.def(e.qt, iw, false, format!("{}[{}:{kk}]", e.prod, kk + iw - 1));
    }
    sp.cut();
    i0_section(&mut sp);
    sp.def("an2", cw, false, format!("{} << 1", zext(&sp.at("an"), aw, cw)));
    for e in &ends {
        sp.def(e.m, cw, false, format!("{} * an2", zext(&sp.at(e.qt), iw, cw)));
    }
    sp.cut();
    i0_section(&mut sp);
    let an2 = sp.at("an2");
    for e in &ends {
        let (lo, m, qt) = (sp.at(e.lo), sp.at(e.m), sp.at(e.qt));
        sp.def(e.corr, cw, false, format!("{lo} - {m}"));
        sp.def(e.out, iw, false, format!("{qt} + {}", zext(&format!("{} >= {an2}", e.corr), 1, iw)));
    }
    let (oy, ox, olen) = (sp.at("y"), sp.at("x"), sp.at("len"));
    let odi = if scan { lit(dw, 0) } else { sp.at("di") };
    let nsp = sp.stage();
    let pv = |j: usize| format!("p{j}_v");
    for j in 1..=nsp {
        body.push(reg(&pv(j), 1));
    }
    let mut p_scan = Vec::new();
    let mut ostall = vec![];
    if scan {
        sp.note(comment("dI = round(|I_last - I0| / (m - 1)), its sign apart: (2 |N| + D) / 2D, D = m - 1."));
        sp.def("p_div", 1, false, format!("{olen} > {}", lit(xw + 1, 1)));
        sp.def("nabs", iw, false, "ilast >= i0 ? ilast - i0 : i0 - ilast");
        sp.def("dm1", xw + 1, false, format!("{olen} - {}", lit(xw + 1, 1)));
        sp.note(Item::Blank);
        for item in div_chain(&sdv, "sd_cnt", sd_cw, hw.div_bits) {
            sp.note(item);
        }
        sp.def("sd_fin", 1, false, format!("sd_cnt < {}", lit(sd_cw, hw.div_bits as u64)));
        let q = format!("sdv_q{}", hw.div_bits);
        sp.def("sd_di", dw, false, format!("sd_neg ? -{} : {}", zext(&q, iw, dw), zext(&q, iw, dw)));
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
        p_scan.push(Item::Always(vec![Stmt::If(
            "rst".into(),
            vec![set("sd_busy", "1'b0")],
            vec![Stmt::If(format!("adv && {} && p_div", pv(nsp)), start, vec![Stmt::If("sd_busy".into(), run, vec![])])],
        )]));
        ostall = vec![Stmt::If("sd_busy && sd_fin".into(), vec![set("out_valid", "1'b1"), set("out_di", "sd_di")], vec![])];
    }
    body.extend(sp.items());
    body.extend(p_scan);
    let mut moves: Vec<Stmt> = vec![set(pv(1), "emit")];
    moves.extend((2..=nsp).map(|j| set(pv(j), pv(j - 1))));
    for j in 0..nsp {
        moves.extend(sp.loads(j));
    }
    moves.extend([
        set("out_valid", if scan { format!("{} && !p_div", pv(nsp)) } else { pv(nsp) }),
        set("out_y", oy.clone()),
        set("out_x", ox.clone()),
        set("out_len", olen.clone()),
        set("out_i0", "i0"),
        set("out_di", odi.clone()),
    ]);
    let mut resets: Vec<Stmt> = (1..=nsp).map(|j| set(pv(j), "1'b0")).collect();
    resets.push(set("out_valid", "1'b0"));
    body.push(Item::Always(vec![Stmt::If("rst".into(), resets, vec![Stmt::If("adv".into(), moves, ostall)])]));

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
            calc_stages: (1..=last)
                .map(|j| crate::formal::CalcStage {
                    valid: valid(j),
                    guard: st.held("guard_ok", j).expect("the guard-band check reaches the last stage"),
                    ymin: st.held("ymin", j),
                    ymax: st.held("ymax", j),
                    first_s: st.held("first_s", j),
                    last_s: st.held("last_s", j),
                    cull: st.held("cull", j),
                    last_alt: ["last_s0", "last_s1"].iter().filter_map(|n| st.held(n, j)).collect(),
                })
                .collect(),
            guard,
            cull,
            span_stages: (1..=nsp)
                .map(|j| {
                    let held = |n: &str| sp.held(n, j).expect("a span's fields reach the output");
                    crate::formal::SpanStage { valid: pv(j), y: held("y"), x: held("x"), len: held("len"), di: held("di") }
                })
                .collect(),
        }));
    }

    // Every boundary is registered above level 0, so stage j's logic is logical step j - 1's.
    let stages = if hw.calc_clocks() > 1 {
        let mut v = stage_list(&st, "calc", &golden::pipeline::SETUP_STAGES);
        v.extend(stage_list(&sp, "span", &golden::pipeline::I0_STAGES));
        v
    } else {
        Vec::new()
    };
    let module = Module {
        name: names.frontend.clone(),
        header,
        params: vec![],
        ports: ports(fe, &wd).into_iter().chain(span_ports(fe, &wd)).collect(),
        body,
    };
    (module, stages)
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
