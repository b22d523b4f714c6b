//! `tri_frontend` (SPEC §6): triangles in, one span per covered scanline out, and
//! `tri_shader_p<P>`, which chains it with `segment_shader_p<P>`: triangles in, segments with
//! their `y` out. The arithmetic is `golden::frontend`'s, with its widths; see that module for
//! why it is exact and how accurate the intensities are.
//!
//! Structure of `tri_frontend`:
//! - **set-up**: a triangle waits in the vertex registers until the dividers are free; in that
//!   clock CALC checks the guard band, computes the area, orients the edges, finds the rows,
//!   culls, and loads eight restoring dividers (`--fe-div-bits` quotient bits a clock; one module,
//!   [`divider`], two in each edge's module, [`edge`], the edges a `generate` loop); `DIV`
//!   runs them together; `HOLD` offers the result to the walker. The hand-off clock is also the
//!   next triangle's CALC, and the next triangle is latched while the dividers run. At
//!   `--pipeline 1` and above CALC is five register stages ([`golden::pipeline::SETUP_STAGES`],
//!   written once through [`stager`]), a queue in front of the dividers: the triangles behind
//!   move through it while the dividers run, so only the latency grows.
//! - **edge walker**: one row per clock. Per active edge one DDA step (add, compare, subtract);
//!   `lo` and `hi` are the max and min of the active bounds, clipped to the screen. It loads the
//!   next triangle in the clock its current one finishes, so set-up overlaps the walk.
//! - **I0 pipeline** (two stages after the walker): `S2n = 2 (Tn + Gxn lo) + An` modulo
//!   2^(K-1) in the walker's clock, then `q~ = ((S2n >> t) Rn) >> (K - t)` from its top bits,
//!   then the correction `q~ + (S2n - 2 An q~ >= 2 An)` modulo 2^(AW+2) (golden's
//!   `Widths::reciprocal_quotient`). Products modulo a power of two keep only the tile-sized
//!   partial products with a bit below it (`span::mul_mod`). At `--pipeline 1` and above six
//!   stages, one multiply or two adders each ([`golden::pipeline::I0_STAGES`]), the product by
//!   `Rn` in two registered halves, behind two row stages (the reciprocal `I0`): each edge's
//!   bound on the walked row is registered, the row's span ends (the minima) a clock later, and
//!   the pixel test and the span's start and length decided from those, so the walker's clock is
//!   its DDA alone ([`golden::pipeline::Pipeline::row_stages`]).
//!   One stall signal holds the walker and every stage while the output waits.

mod calc;
mod chain;
mod divider;
mod edge;
mod engine;
mod hw;
mod incremental;
mod mul18;
mod properties;
mod setup;
mod span;
mod span_seq;
mod stager;
mod sums;
mod walker;

pub use chain::top_module;
pub use hw::{ports, span_ports, Hw, DEFAULT_DIV_BITS, DIV_BITS, QUEUE_DEPTH};
use stager::Stager;

use crate::verilog::Module;
use crate::Names;
use golden::frontend::{DiMode, Widths};

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

/// The span path's stages for the manifest: the row stages (`row`, then `row_ends`, numbered
/// 0: they are the walker's row, before the span path's first), then `span<j>`.
fn span_stage_list(hw: &Hw, sp: &Stager) -> Vec<golden::pipeline::PipeStage> {
    let format = |signed: bool| if signed { "signed" } else { "unsigned" };
    let rows =
        walker::row_registers(hw).into_iter().zip(["row", "row_ends"]).zip(golden::pipeline::ROW_STAGES).map(|((regs, name), logic)| {
            golden::pipeline::PipeStage {
                stage: 0,
                name: name.into(),
                logic: logic.into(),
                regs: regs.into_iter().map(|(n, bits, signed)| golden::pipeline::PipeReg::new(&n, bits, format(signed))).collect(),
            }
        });
    rows.chain(stage_list(sp, "span", &golden::pipeline::I0_STAGES)).collect()
}

pub fn module(hw: &Hw, names: &Names) -> Module {
    build(hw, names).0
}

/// `tri_frontend`'s parts, one file each: the edge (instanced three times) and the restoring
/// divider (its parameters' defaults those of an edge's first-bound divider).
pub fn submodules(hw: &Hw, names: &Names) -> Vec<Module> {
    if engine::on(hw) {
        // The engine made the divisions: no divider module, the engine and its queue instead.
        let mut parts = vec![edge::module(hw, names), engine::module(hw, names), engine::result_queue(hw, names)];
        parts.extend(hw.dsp_regs().then(|| mul18::module(names)));
        return parts;
    }
    let [ei, _] = edge::dividers(hw);
    vec![edge::module(hw, names), divider::module(names, &ei, hw.div_bits, divider::counter_width(&hw.fe.widths()))]
}

/// The module, and its register stages when it is pipelined ([`stages`]): the set-up, the
/// walker, the span path and the output register, then the properties.
fn build(hw: &Hw, names: &Names) -> (Module, Vec<golden::pipeline::PipeStage>) {
    let fe = &hw.fe;
    let mut body = Vec::new();
    if engine::on(hw) {
        assert!(
            fe.di == DiMode::Triangle && (!incremental::on(hw) || hw.sequential().is_some()),
            "the shared set-up engine takes --fe-di triangle, and --fe-i0 incremental on the sequential engine only (hdl_gen::cli refuses the others)"
        );
        engine::setup(hw, names, &mut body);
        if span_seq::unit(hw).is_some() {
            span_seq::handshake(hw, &mut body);
        }
        walker::emit(hw, names, &mut body);
        if span_seq::unit(hw).is_some() {
            let sp = span_seq::emit(hw, &mut body);
            let stages = if hw.calc_clocks() > 1 { span_stage_list(hw, &sp) } else { Vec::new() };
            body.push(properties::emit_engine(hw, &sp));
            return (top(hw, names, body), stages);
        }
        let sp = span::path(hw, names, &mut body);
        let sp = span::output(hw, names, sp, &mut body);
        let stages = if hw.calc_clocks() > 1 { span_stage_list(hw, &sp) } else { Vec::new() };
        body.push(properties::emit_engine(hw, &sp));
        return (top(hw, names, body), stages);
    }
    let set_up = setup::emit(hw, names, &mut body);
    walker::emit(hw, names, &mut body);
    let sp = span::path(hw, names, &mut body);
    let sp = span::output(hw, names, sp, &mut body);
    // Every boundary is registered above level 0, so stage j's logic is logical step j - 1's.
    let stages = if hw.calc_clocks() > 1 {
        let mut v = stage_list(&set_up.st, "calc", &golden::pipeline::SETUP_STAGES);
        v.extend(span_stage_list(hw, &sp));
        v
    } else {
        Vec::new()
    };
    if fe.di == DiMode::Triangle {
        body.push(properties::emit(hw, set_up, &sp));
    }
    (top(hw, names, body), stages)
}

/// `tri_frontend` around its body: the same header and ports in every set-up form.
fn top(hw: &Hw, names: &Names, body: Vec<crate::verilog::Item>) -> Module {
    let wd = hw.fe.widths();
    Module {
        name: names.frontend.clone(),
        header: header(hw, names),
        params: vec![],
        ports: ports(&hw.fe, &wd).into_iter().chain(span_ports(&hw.fe, &wd)).collect(),
        body,
    }
}

/// The module's header: configuration, formats, set-up, latency and widths.
fn header(hw: &Hw, names: &Names) -> Vec<String> {
    let fe = &hw.fe;
    if let Some(s) = hw.engine() {
        let Widths { yw: row_w, cx: vx_w, cy: vy_w, .. } = fe.widths();
        let (xw, iw) = (fe.cfg.xbits, fe.cfg.iw());
        let (w, h) = (fe.screen.width as i64, fe.screen.height as i64);
        let mut lines = vec![
            format!("{} — triangle front-end (SPEC §6): set-up and edge walker, one span per clock.", names.frontend),
            "Generated by segshade hdl-gen; do not edit.".into(),
            String::new(),
            format!(
                "Configuration: screen {w}x{h}, F = {}, XW = {xw}, pipeline level {}; rows {row_w} bits; set-up form {}.",
                fe.cfg.frac,
                hw.pipeline,
                fe.setup.name()
            ),
            format!(
                "Vertices: x signed Q{}.8 ({vx_w} bits), y signed Q{}.8 ({vy_w} bits), I UQ8.{} ({iw} bits).",
                xw + 2,
                row_w + 2,
                fe.cfg.frac
            ),
            format!("Guard band: -{w} <= x < {}, -{h} <= y < {} pixels; a triangle outside it is dropped and pulses err.", 2 * w, 2 * h),
            "Coverage and spans: exactly golden::setup's and golden::frontend's, as the parallel form's, bit for bit.".into(),
            format!(
                "Set-up: the {} engine {} (golden's plan {}: II = {} clocks a triangle, latency {}), then a queue of {} results;",
                if hw.sequential().is_some() { "sequential" } else { "shared" },
                names.fe_engine,
                fe.setup.name(),
                hw.engine_timing().map_or(s.ii, |t| t.0),
                hw.engine_timing().map_or(s.latency, |t| t.1),
                hw.queue_depth()
            ),
            format!("{} clocks per triangle, walked or dropped; the next triangles' set-up overlaps the walk.", hw.setup_clocks().0),
            format!("Latency: first span valid at most {} clocks after the triangle's transfer when the walker is idle.", hw.latency()),
            match hw.fe.span_seq() {
                None => format!("Spans: the walker, then {} register stages to the output register (I0's path).", hw.i0_stages()),
                Some(q) => format!(
                    "Spans: the walker, {} row stages, then one shift-add unit for I0's products: {} clocks a covered row, the walker waiting.",
                    hw.row_stages(),
                    q.row_clocks()
                ),
            },
            String::new(),
            format!(
                "Structure, in this file's order: the engine (u_engine: {}) and its queue (u_queue: {}), the head's fields; the",
                names.fe_engine, names.fe_queue
            ),
            format!(
                "walker, whose three edges are a generate loop (g_edge[k].u_edge: {}, each its DDA); the span path; the output register.",
                names.fe_edge
            ),
        ];
        if hw.preload_clocks() > 0 {
            // After the set-up's rate: where the queue's entry went (the UP5K's walk memory).
            let at = lines.iter().position(|l| l.contains("clocks per triangle")).map_or(lines.len(), |i| i + 1);
            // Where the walk memory holds dI too (`span_seq::walk_ram`), it waits beside An.
            let (queue, di) = if span_seq::walk_ram::di_value(hw).is_some() {
                ("first and last", "dI waits beside An in the walk memory, the edges' fields in the second")
            } else {
                ("first, last and dI", "the edges' fields wait in the second walk memory")
            };
            let preload = format!(
                "The queue holds {queue}; {di}, loaded into the idle edges one a clock ({} clocks before a take).",
                hw.preload_clocks()
            );
            lines.insert(at, preload);
        }
        return lines;
    }
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
        String::new(),
        "Structure, in this file's order: the vertex registers; CALC (its stages' registers c<j>_*); the set-up state".into(),
        format!(
            "machine (IDLE, DIV, HOLD) with dI's and the reciprocal's dividers (u_ddi, u_drn: {}); the walker, whose",
            names.fe_div
        ),
        format!(
            "three edges are a generate loop (g_edge[k].u_edge: {}, each with its set-up result, its two {} and its",
            names.fe_edge, names.fe_div
        ),
        format!(
            "DDA); the span path (stages p<j>_*){}; the output register.",
            if fe.di == DiMode::Scanline { format!(" and the span's dI divider (u_sdv: {})", names.fe_div) } else { String::new() }
        ),
    ]
}
