//! `sweep`: pixels per clock of the segment shader for every p built, in both alignments,
//! measured in RTL clocks by co-simulation at full rate, next to the cycle models of the seeds'
//! other parallel schemes (`golden::schemes`), on one workload of random triangles in three size
//! classes. Prints a Markdown table (or writes it with --out).
//!
//! Every segment is checked against golden as usual; the RTL clock count of every run must also
//! equal the analytical one (`Σ segments + latency`). Either failing gives exit status 1.

use clap::Parser;
use golden::rng::SeedRng;
use golden::schemes::{fill, workload_count, Scheme};
use golden::setup::{Screen, Triangle, Vertex};
use golden::Align;
use hdl_gen::cli::VariantArgs;
use rand::{Rng, SeedableRng};
use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;
use verilator_harness::ffi::{ModelInfo, SegIn, SegOut, TriIn, TriSegOut, WrIn, WrOut};
use verilator_harness::frontend::{drain_clocks, run_chain};
use verilator_harness::models::{catalogue, ModelError};
use verilator_harness::ondemand;
use verilator_harness::registry::{self, SEGMENT_MODELS, TRISHADER_MODELS, WRITER_MODELS};
use verilator_harness::render::{busy_cycles, scene_job, SceneKind};
use verilator_harness::segment::Stress;
use verilator_harness::segment::{Report, SegmentCosim, Stim, Traffic};
use verilator_harness::writer::run_writer;

#[derive(Parser)]
#[command(about = "Pixels per clock of the segment shader (RTL) and the seeds' other parallel schemes (models)")]
struct Args {
    /// Random triangles per size class.
    #[arg(long, default_value_t = 10_000, value_parser = clap::value_parser!(u64).range(1..=1_000_000))]
    triangles: u64,
    /// Seed of the workload.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    #[arg(long, default_value_t = 640, value_parser = clap::value_parser!(u32).range(64..=4096))]
    width: u32,
    /// Screen height (64..=32768: the workload's vertices lie anywhere on the screen, and the
    /// set-up takes coordinates up to golden::setup::COORD_LIMIT).
    #[arg(long, default_value_t = 480, value_parser = clap::value_parser!(u32).range(64..=golden::setup::COORD_LIMIT as i64))]
    height: u32,
    /// Write the table here (atomically) instead of to standard output.
    #[arg(long, value_name = "FILE.md")]
    out: Option<PathBuf>,
    // The models swept, at every P and alignment: any options `generate` accepts but those,
    // by the same flags (the catalogue's models at the defaults; others built the first time,
    // then cached).
    #[command(flatten)]
    variant: VariantArgs,
    /// Instead: each `--target`'s chain next to the defaults' at p = 4, 8, 16 (triangles per 1000
    /// clocks, the spans-fed share, triangles a second at the front-end's measured clock).
    #[arg(long, conflicts_with = "target")]
    targets: bool,
}

/// The chains and writers (p > 1) to sweep on `screen`: with the default options the compiled
/// catalogue's on its own screen; else, or on another screen, the catalogue's configurations
/// built with `variant` for it (once, then cached: `verilator_harness::ondemand`). A
/// COSIM_RTL_DIR folder's own. None on a screen the front-end cannot draw on.
#[allow(clippy::type_complexity)]
fn on_screen(
    screen: Screen,
    variant: &VariantArgs,
) -> Result<(Vec<&'static ModelInfo<TriIn, TriSegOut>>, Vec<&'static ModelInfo<WrIn, WrOut>>), ModelError> {
    let key = |o: &hdl_gen::Options| catalogue::options_key(o);
    let plain = variant.options(8, Align::Span, None).is_ok_and(|o| key(&o) == key(&Default::default()));
    let chains: Vec<_> = TRISHADER_MODELS.iter().filter(|m| m.screen == screen).collect();
    let writers: Vec<_> = WRITER_MODELS.iter().filter(|m| m.screen == screen && m.cfg.p > 1).collect();
    if (plain && !chains.is_empty()) || registry::rtl_dir().is_some() {
        return Ok((chains, writers));
    }
    let opts = |p, a| variant.options(p, a, Some(screen)).map_err(|e| ModelError::Config(e.to_string()));
    let built = || -> Result<_, ModelError> {
        let chains = catalogue::BUILT_TRI.iter().map(|&(p, a)| registry::tri_shader(&opts(p, a)?));
        let writers = catalogue::BUILT_WR.iter().filter(|(p, _)| *p > 1).map(|&(p, a)| registry::writer(&opts(p, a)?));
        Ok((chains.collect::<Result<Vec<_>, _>>()?, writers.collect::<Result<Vec<_>, _>>()?))
    };
    match built() {
        Err(ModelError::Config(_)) => Ok((Vec::new(), Vec::new())),
        other => other,
    }
}

/// The segment shaders to sweep: every P and alignment of the catalogue with `variant`'s
/// options (SPEC's seed structure unless `--pipeline` says otherwise: it only adds fill clocks),
/// or a COSIM_RTL_DIR folder's level-0 shaders; those whose screen `screen` fits.
fn shaders(screen: &Screen, variant: &VariantArgs) -> Result<Vec<&'static ModelInfo<SegIn, SegOut>>, ModelError> {
    let mut models: Vec<_> = match registry::rtl_dir() {
        Some(_) => SEGMENT_MODELS.iter().filter(|m| m.pipeline == golden::pipeline::Pipeline::NONE).collect(),
        None => {
            let mut all = Vec::new();
            for p in catalogue::BUILT_P {
                for align in Align::ALL {
                    let opts = variant.options(p, align, None).map_err(|e| ModelError::Config(e.to_string()))?;
                    // A configuration that cannot shade this screen is not swept (nor built).
                    if screen.check_for(&opts.cfg).is_err() {
                        continue;
                    }
                    all.push(registry::segment(&opts)?);
                }
            }
            all
        }
    };
    models.retain(|m| screen.check_for(&m.cfg).is_ok());
    models.sort_by_key(|m| (m.cfg.p, m.cfg.align == Align::Screen));
    Ok(models)
}

/// The size classes: target area in pixels.
const CLASSES: [f64; 3] = [10.0, 100.0, 1000.0];

/// A random triangle of about `area` pixels (log-uniform within ±20%), entirely on the screen,
/// vertices on the 1/128-pixel grid (so the midline split tiles it exactly), random intensities.
/// The shape: three points uniform in a disk, scaled to the area; very thin ones (under 5% of
/// the disk's largest triangle) are drawn again, so the class is not dominated by slivers.
fn sized_triangle(rng: &mut SeedRng, screen: &Screen, area: f64) -> Triangle {
    let target = area * rng.gen_range(0.8f64.ln()..1.25f64.ln()).exp();
    loop {
        let mut p = [[0.0f64; 2]; 3];
        for q in &mut p {
            loop {
                let (x, y) = (rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0));
                if x * x + y * y <= 1.0 {
                    *q = [x, y];
                    break;
                }
            }
        }
        let a = ((p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[1][1] - p[0][1]) * (p[2][0] - p[0][0])).abs() / 2.0;
        if a < 0.05 * 1.299 {
            continue;
        }
        let s = (target / a).sqrt();
        let xs = p.map(|q| q[0] * s);
        let ys = p.map(|q| q[1] * s);
        let (x0, x1) = (xs.iter().cloned().fold(f64::INFINITY, f64::min), xs.iter().cloned().fold(f64::NEG_INFINITY, f64::max));
        let (y0, y1) = (ys.iter().cloned().fold(f64::INFINITY, f64::min), ys.iter().cloned().fold(f64::NEG_INFINITY, f64::max));
        let (w, h) = (screen.width as f64, screen.height as f64);
        if x1 - x0 > w - 2.0 || y1 - y0 > h - 2.0 {
            continue;
        }
        let dx = rng.gen_range(1.0 - x0..w - 1.0 - x1);
        let dy = rng.gen_range(1.0 - y0..h - 1.0 - y1);
        let grid = |c: f64| (c * 128.0).round() / 128.0;
        let v = [0, 1, 2].map(|k| Vertex { x: grid(xs[k] + dx), y: grid(ys[k] + dy), i: rng.gen_range(0.0..=255.0) });
        return Triangle { v };
    }
}

struct Cell {
    ppc: f64,
    width: u32,
}

impl Cell {
    fn show(&self, bold: bool) -> String {
        let b = if bold { "**" } else { "" };
        format!("{b}{:.2}{b} ({:.0}%)", self.ppc, 100.0 * self.ppc / self.width as f64)
    }
}

/// What is refused before anything runs besides the folder (`given::start`): options `generate`
/// refuses (whichever models the run has), and a bad --out (now, not after the sweep's minutes).
fn refused(args: &Args) -> Result<(), String> {
    args.variant.options(8, Align::Span, None).map_err(|e| e.to_string())?;
    match args.out.as_deref().map(hdl_gen::output::check_writable) {
        Some(Err(e)) => Err(format!("--out: {e}")),
        _ => Ok(()),
    }
}

fn main() -> ExitCode {
    // A COSIM_RTL_DIR folder that describes no models, or that a model flag contradicts, is
    // refused before anything runs.
    let args = match verilator_harness::given::start::<Args>(|a| Some(a.variant.options(8, Align::Span, None))) {
        Ok(args) => args,
        Err(code) => return code,
    };
    if let Err(e) = refused(&args) {
        eprintln!("error: {e}");
        return ExitCode::from(2);
    }
    let start = Instant::now();
    let screen = Screen { width: args.width, height: args.height };
    let models = match shaders(&screen, &args.variant) {
        Ok(models) => models,
        Err(e) => return ondemand::exit("the segment shaders", &e),
    };
    if models.is_empty() {
        eprintln!("error: no segment shader model in this build fits a {}x{} screen", screen.width, screen.height);
        return ExitCode::from(2);
    }
    let cfg = models[0].cfg;
    let mut rng = SeedRng::seed_from_u64(args.seed);
    let workloads: Vec<Vec<Triangle>> =
        CLASSES.iter().map(|&a| (0..args.triangles).map(|_| sized_triangle(&mut rng, &screen, a)).collect()).collect();
    if args.targets {
        return targets(&args, screen, &workloads);
    }
    let (mut chain_models, wr_models) = match on_screen(screen, &args.variant) {
        Ok(models) => models,
        Err(e) => return ondemand::exit("--width/--height", &e),
    };
    // One bar over every RTL run; indicatif hides it when stderr is not a terminal.
    let (chain_runs, writer_runs) = (chain_models.len(), wr_models.len());
    let bar = indicatif::ProgressBar::new(((models.len() + chain_runs) * workloads.len() + writer_runs * (workloads.len() + 2)) as u64)
        .with_style(indicatif::ProgressStyle::with_template("sweep [{bar:30}] {pos}/{len} {msg}").expect("a valid template"));
    let mut failures = Vec::new();

    // Baselines: cycle models.
    let mut rows: Vec<(String, &str, Vec<Cell>)> = Vec::new();
    let mut stats = Vec::new();
    for scheme in Scheme::BASELINES {
        let mut cells = Vec::new();
        for tris in &workloads {
            let c = workload_count(scheme, &cfg, &screen, tris).expect("the workload fits the screen");
            cells.push(Cell { ppc: c.pixels_per_clock(), width: scheme.width() });
            if scheme == Scheme::Classical {
                stats.push(c);
            }
        }
        rows.push((scheme.to_string(), "model", cells));
    }

    // The segment shader: RTL clocks.
    let mut rtl: Vec<(u32, Align, Vec<f64>)> = Vec::new();
    for info in &models {
        let (p, align) = (info.cfg.p, info.cfg.align);
        let mut cells = Vec::new();
        let mut ppcs = Vec::new();
        for (k, tris) in workloads.iter().enumerate() {
            bar.set_message(format!("{} on class {k}", info.tag));
            bar.inc(1);
            let mut stims = Vec::new();
            for (t, tri) in tris.iter().enumerate() {
                golden::setup::triangle_spans(&info.cfg, &screen, tri, |y, span| stims.push(Stim { triangle: t, y, span }))
                    .expect("the workload fits the screen");
            }
            let mut sim = SegmentCosim::new(info, args.seed, Traffic::FULL);
            let mut report = Report { triangles: tris.len(), ..Report::default() };
            sim.stream(&stims, &mut report, |_, _| {});
            let cycles = busy_cycles(&report);
            let model = workload_count(Scheme::Segment { p, align }, &info.cfg, &screen, tris).expect("fits");
            let want = model.clocks + info.latency as u64;
            if !report.ok() {
                failures.push(format!("{}: class {k}: {} mismatches, first: {}", info.tag, report.mismatch_count, report.mismatches[0]));
            }
            if cycles != want || report.pixels != model.pixels || fill() != info.latency as u64 {
                failures.push(format!("{}: class {k}: {cycles} RTL clocks, the model says {want}", info.tag));
            }
            let ppc = report.pixels as f64 / cycles.max(1) as f64;
            cells.push(Cell { ppc, width: p });
            ppcs.push(ppc);
        }
        rows.push((format!("segment shader p = {p}, {align}"), "RTL", cells));
        rtl.push((p, align, ppcs));
    }
    // Triangles into the RTL front-end and shader (tri_shader_p<P>), the same workload.
    let mut chains: Vec<(String, Vec<String>)> = Vec::new();
    chain_models.sort_by_key(|m| (m.cfg.p, m.cfg.align == Align::Screen, m.di == golden::frontend::DiMode::Scanline));
    // Clocks of each per-triangle chain per class: the per-scanline rows are set against them.
    let mut tri_clocks: Vec<((u32, Align), Vec<u64>)> = Vec::new();
    for info in chain_models {
        let (p, align) = (info.cfg.p, info.cfg.align);
        let scan = info.di == golden::frontend::DiMode::Scanline;
        let mut clocks = Vec::new();
        let mut cells = Vec::new();
        for (k, tris) in workloads.iter().enumerate() {
            bar.set_message(format!("{} on class {k}", info.tag));
            bar.inc(1);
            let fixed: Vec<_> = tris.iter().map(|t| golden::frontend::FixedTriangle::from_triangle(t, info.cfg.frac)).collect();
            let run = run_chain(info, args.seed, Traffic::FULL, &fixed);
            if !run.report.ok() {
                failures.push(format!(
                    "{}: class {k}: {} mismatches, first: {}",
                    info.tag, run.report.mismatch_count, run.report.mismatches[0]
                ));
            }
            // Busy clocks: without the quiet clocks the stream waits after its last output for
            // a late `err` pulse (`frontend::drain_clocks`), as the spans-fed rows go without theirs.
            let busy = run.report.cycles.saturating_sub(drain_clocks(info.latency, &info.frontend()));
            let ppc = run.report.pixels as f64 / busy.max(1) as f64;
            let fed = rtl.iter().find(|r| (r.0, r.1) == (p, align)).map(|r| r.2[k]);
            let share = fed.map_or(String::new(), |f| format!(" ({:.0}%)", 100.0 * ppc / f));
            let ratio = match tri_clocks.iter().find(|t| t.0 == (p, align)).filter(|_| scan) {
                Some(t) => format!(", {:.2}x the clocks", busy as f64 / t.1[k].max(1) as f64),
                None => String::new(),
            };
            clocks.push(busy);
            cells.push(format!("{ppc:.2}{share}, {:.1}{ratio}", 1000.0 * tris.len() as f64 / busy.max(1) as f64));
        }
        if !scan {
            tri_clocks.push(((p, align), clocks));
        }
        let di = if scan { ", dI per scanline" } else { "" };
        chains.push((format!("front-end + shader p = {p}, {align}{di}"), cells));
    }
    // SPEC §7: the segment writer on the same spans (and on the two scenes' spans), at full rate.
    let writer_rows = writer_rows(&args, screen, &workloads, wr_models, &bar, &mut failures);
    bar.finish_and_clear();

    let md = markdown(&args, screen, failures.is_empty(), &Tables { stats, rows, rtl, chains, writer_rows });
    eprintln!("sweep: {} models x {} classes in {:.1} s", models.len(), workloads.len(), start.elapsed().as_secs_f64());
    finish(&args, &md, &failures)
}

/// `--targets`: the per-target table instead of the sweep's.
fn targets(args: &Args, screen: Screen, workloads: &[Vec<Triangle>]) -> ExitCode {
    let mut failures = Vec::new();
    let names = CLASSES.map(|a| format!("~{a} px"));
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    let md = match verilator_harness::targets::sweep(&args.variant, screen, workloads, &names, args.seed, &mut failures) {
        Ok(md) => format!("{md}\nMade by `sweep --targets --triangles {} --seed {}`.\n", args.triangles, args.seed),
        Err(e) => return ondemand::exit("--targets", &e),
    };
    finish(args, &md, &failures)
}

/// Writes the report (to --out, atomically, or to standard output) and says what failed.
fn finish(args: &Args, md: &str, failures: &[String]) -> ExitCode {
    match &args.out {
        Some(path) => {
            if let Err(e) = hdl_gen::output::write_one(path, md.as_bytes()) {
                eprintln!("error: --out {}: {e}", path.display());
                return ExitCode::from(2);
            }
        }
        None => print!("{md}"),
    }
    for f in failures {
        eprintln!("FAIL {f}");
    }
    if failures.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    }
}

/// What the sweep measured, as the report's tables take it.
struct Tables<'a> {
    /// Per size class: the workload's pixels, spans and triangles.
    stats: Vec<golden::schemes::Count>,
    /// Per scheme or model: its name, where its clocks come from, a cell per class.
    rows: Vec<(String, &'a str, Vec<Cell>)>,
    /// Per segment shader model: p, alignment, pixels per clock per class.
    rtl: Vec<(u32, Align, Vec<f64>)>,
    chains: Vec<(String, Vec<String>)>,
    writer_rows: Vec<(String, &'a str, Vec<String>)>,
}

/// The sweep's Markdown report: the workload, the schemes' pixels per clock with the best p
/// in bold, the front-end chains and the writer.
fn markdown(args: &Args, screen: Screen, passed: bool, t: &Tables) -> String {
    let Tables { stats, rows, rtl, chains, writer_rows } = t;
    // Best p per class and alignment: the smallest p within 10% of the widest model's rate.
    let best = |align: Align, k: usize| -> Option<u32> {
        let of = rtl.iter().filter(|r| r.1 == align);
        let top = of.clone().map(|r| r.2[k]).fold(0.0, f64::max);
        of.filter(|r| r.2[k] >= 0.9 * top).map(|r| r.0).min()
    };
    let mut md = String::new();
    let cmd = format!(
        "cargo run --release -p verilator-harness --bin sweep -- --triangles {} --seed {}{}",
        args.triangles,
        args.seed,
        if (args.width, args.height) == (640, 480) { String::new() } else { format!(" --width {} --height {}", args.width, args.height) }
    );
    let _ = writeln!(md, "Regenerate with `{cmd}`.\n");
    let _ = writeln!(
        md,
        "Workload: {} random triangles per size class on a {}x{} screen (seed {}); random shapes, area \
         within ±20% of the class, entirely on screen. Every segment shader is co-simulated at full rate \
         (both ends always ready) with every segment checked against golden; its clocks run from the \
         first span offered to the last segment out{}. The other schemes are cycle models \
         (`golden::schemes`, same assumptions: no per-span overhead, the same {}-clock fill).\n",
        args.triangles,
        screen.width,
        screen.height,
        args.seed,
        if passed {
            format!(" and equal Σ segments + {} (pipeline fill) in every cell", fill())
        } else {
            " (THIS RUN FAILED ITS CHECKS: see the FAIL lines)".to_string()
        },
        fill()
    );
    let _ = writeln!(md, "| | ~10 px | ~100 px | ~1000 px |\n|---|---:|---:|---:|");
    let row = |f: &dyn Fn(&golden::schemes::Count) -> String| stats.iter().map(f).collect::<Vec<_>>().join(" | ");
    let _ = writeln!(md, "| pixels per triangle (mean) | {} |", row(&|c| format!("{:.1}", c.pixels as f64 / c.triangles as f64)));
    let _ = writeln!(md, "| span length (mean pixels) | {} |", row(&|c| format!("{:.2}", c.pixels as f64 / c.spans as f64)));
    let _ = writeln!(md, "| spans per triangle (mean) | {} |\n", row(&|c| format!("{:.2}", c.spans as f64 / c.triangles as f64)));
    let _ = writeln!(md, "Pixels per clock (in brackets: of the pixels the scheme could make per clock). **Bold**: the best p of each class and alignment.\n");
    let _ = writeln!(md, "| scheme | clocks | ~10 px | ~100 px | ~1000 px |\n|---|---|---:|---:|---:|");
    for (name, source, cells) in rows {
        let bold = |k: usize| rtl.iter().any(|r| *name == format!("segment shader p = {}, {}", r.0, r.1) && best(r.1, k) == Some(r.0));
        let c: Vec<String> = cells.iter().enumerate().map(|(k, c)| c.show(bold(k))).collect();
        let _ = writeln!(md, "| {name} | {source} | {} |", c.join(" | "));
    }
    let _ = writeln!(
        md,
        "\nBest p: the smallest p within 10% of the pixels per clock of the widest model (p = {}), per alignment:\n",
        rtl.iter().map(|r| r.0).max().unwrap_or(0)
    );
    for (k, class) in ["~10 px", "~100 px", "~1000 px"].iter().enumerate() {
        let show = |a| best(a, k).map_or("-".to_string(), |p| p.to_string());
        let _ = writeln!(md, "- {class}: p = {} span-aligned, p = {} screen-aligned", show(Align::Span), show(Align::Screen));
    }

    if !chains.is_empty() {
        let _ = writeln!(
            md,
            "\nTriangles into the generated front-end and shader (`tri_shader_p<P>`, SPEC §6), the same triangles, \
             both ends always ready, every segment and the frame checked. Each cell: pixels per clock (in brackets: \
             of the spans-fed shader's above), then triangles per 1000 clocks; for the classical per-scanline dI \
             (`--fe-di scanline`, built with `SEGSHADE_ALL_CHAINS=1`), its clocks over the per-triangle chain's.\n"
        );
        let _ = writeln!(md, "| chain | ~10 px | ~100 px | ~1000 px |\n|---|---:|---:|---:|");
        for (name, cells) in chains {
            let _ = writeln!(md, "| {name} | {} |", cells.join(" | "));
        }
    }

    if !writer_rows.is_empty() {
        let _ = writeln!(
            md,
            "\nThe segment writer (`fb_writer_p<P>`, SPEC §7) on the same triangles' spans and on the two scenes' \
             (640x480, every span the host's set-up makes, one channel), fed golden's segments at full rate, the \
             memory always ready, every write checked. RTL cells: block writes per span, then the writer's clocks \
             for the whole workload (in brackets: the segments the shader makes for it, its clocks). Model rows: \
             block writes per span the seed's alternatives would make.\n"
        );
        let _ = writeln!(md, "| writer | clocks | ~10 px | ~100 px | ~1000 px | sphere | torus |\n|---|---|---:|---:|---:|---:|---:|");
        for (name, source, cells) in writer_rows {
            let _ = writeln!(md, "| {name} | {source} | {} |", cells.join(" | "));
        }
    }
    md
}

/// The segment writer's rows: each model's block writes per span and clocks on the workloads'
/// spans and the two scenes', and the seed's alternatives counted on golden's segments.
fn writer_rows(
    args: &Args,
    screen: Screen,
    workloads: &[Vec<Triangle>],
    mut wr_models: Vec<&'static ModelInfo<WrIn, WrOut>>,
    bar: &indicatif::ProgressBar,
    failures: &mut Vec<String>,
) -> Vec<(String, &'static str, Vec<String>)> {
    let mut writer_rows: Vec<(String, &str, Vec<String>)> = Vec::new();
    wr_models.sort_by_key(|m| (m.cfg.p, m.cfg.align == Align::Screen));
    let mut span_sets: Vec<Vec<(u32, golden::Span)>> = Vec::new();
    if !wr_models.is_empty() {
        let cfg = wr_models[0].cfg;
        for tris in workloads {
            let mut spans = Vec::new();
            for tri in tris {
                golden::setup::triangle_spans(&cfg, &screen, tri, |y, span| spans.push((y, span))).expect("the workload fits");
            }
            span_sets.push(spans);
        }
        for kind in [SceneKind::Sphere, SceneKind::Torus] {
            let job = scene_job(kind, 40, &cfg, &screen).expect("the scene fits the screen");
            span_sets.push(job.stims[0].iter().map(|s| (s.y, s.span)).collect());
        }
    }
    let mut last_p = 0;
    for info in &wr_models {
        let (p, align) = (info.cfg.p, info.cfg.align);
        let w = golden::writer::Writer::new(info.cfg, screen).expect("the model's screen");
        if p != last_p {
            // The seed's alternatives, counted on golden's segments: no glue (a straddling
            // segment written as two partial blocks) and a memory aligned to the segment.
            let per = |f: &dyn Fn(&golden::Span) -> u32| -> Vec<String> {
                span_sets
                    .iter()
                    .map(|spans| format!("{:.2}", spans.iter().map(|(_, s)| f(s) as f64).sum::<f64>() / spans.len().max(1) as f64))
                    .collect()
            };
            writer_rows.push((format!("p = {p}, span, no glue"), "model", per(&|s| w.unglued_writes(s))));
            writer_rows.push((format!("p = {p}, span, memory aligned to the segment"), "model", per(&|s| s.len.div_ceil(p))));
            last_p = p;
        }
        let mut cells = Vec::new();
        for (k, spans) in span_sets.iter().enumerate() {
            bar.set_message(format!("{} on workload {k}", info.tag));
            bar.inc(1);
            let run = run_writer(info, args.seed, Traffic::FULL, Stress::NONE, spans);
            if !run.report.ok() {
                failures.push(format!(
                    "{}: workload {k}: {} mismatches, first: {}",
                    info.tag, run.report.mismatch_count, run.report.mismatches[0]
                ));
            }
            let segments: u64 = spans.iter().map(|(_, s)| info.cfg.segment_count(s.x0, s.len) as u64).sum();
            cells.push(format!(
                "{:.2}, {:.0}k ({:.0}k)",
                run.report.segments as f64 / spans.len().max(1) as f64,
                busy_cycles(&run.report) as f64 / 1000.0,
                segments as f64 / 1000.0
            ));
        }
        let name = match align {
            Align::Span => format!("p = {p}, span + glue"),
            Align::Screen => format!("p = {p}, screen"),
        };
        writer_rows.push((name, "RTL", cells));
    }
    writer_rows
}
