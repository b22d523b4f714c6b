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

mod calc;
mod chain;
mod divider;
mod properties;
mod setup;
mod span;
mod stager;
mod walker;

pub use chain::top_module;
use stager::Stager;

use crate::verilog::{Module, Port};
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

pub fn module(hw: &Hw, names: &Names) -> Module {
    build(hw, names).0
}

/// The module, and its register stages when it is pipelined ([`stages`]): the set-up, the
/// walker, the span path and the output register, then the properties.
fn build(hw: &Hw, names: &Names) -> (Module, Vec<golden::pipeline::PipeStage>) {
    let fe = &hw.fe;
    let wd = fe.widths();
    let mut body = Vec::new();
    let set_up = setup::emit(hw, &mut body);
    walker::emit(hw, &mut body);
    let sp = span::path(hw, &mut body);
    let sp = span::output(hw, sp, &mut body);
    // Every boundary is registered above level 0, so stage j's logic is logical step j - 1's.
    let stages = if hw.calc_clocks() > 1 {
        let mut v = stage_list(&set_up.st, "calc", &golden::pipeline::SETUP_STAGES);
        v.extend(stage_list(&sp, "span", &golden::pipeline::I0_STAGES));
        v
    } else {
        Vec::new()
    };
    if fe.di == DiMode::Triangle {
        body.push(properties::emit(hw, set_up, &sp));
    }
    let module = Module {
        name: names.frontend.clone(),
        header: header(hw, names),
        params: vec![],
        ports: ports(fe, &wd).into_iter().chain(span_ports(fe, &wd)).collect(),
        body,
    };
    (module, stages)
}

/// The module's header: configuration, formats, set-up, latency and widths.
fn header(hw: &Hw, names: &Names) -> Vec<String> {
    let fe = &hw.fe;
    let bits = hw.div_bits;
    let cfg = &fe.cfg;
    let Widths { yw: row_w, cx: vx_w, cy: vy_w, aw: area_w, gw: bound_w, dw_edge: ediv_w, k: sum_w, rw: recip_w, .. } = fe.widths();
    let (xw, iw) = (cfg.xbits, cfg.iw());
    let (w, h) = (fe.screen.width as i64, fe.screen.height as i64);
    vec![
        format!("{} — triangle front-end (SPEC §6): set-up and edge walker, one span per clock.", names.frontend),
        "Generated by segshade hdl-gen; do not edit.".into(),
        String::new(),
        format!("Configuration: screen {}x{}, F = {}, XW = {xw}, pipeline level {}; rows {row_w} bits.", w, h, cfg.frac, hw.pipeline),
        format!("Vertices: x signed Q{}.8 ({vx_w} bits), y signed Q{}.8 ({vy_w} bits), I UQ8.{} ({iw} bits).", xw + 2, row_w + 2, cfg.frac),
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
        format!("Widths: |A| {area_w}, edge bound {bound_w} signed, edge divisor {ediv_w}, intensity sums modulo 2^{sum_w}, reciprocal {recip_w}."),
    ]
}
