//! `cosim`: streams random triangles through one verilated segment shader and checks every
//! segment and frame against the golden model. Ends with `N passed, M failed` (triangles).
//! With `--specular`, the same for the specular unit, pixel by pixel (spans).

use clap::{Parser, ValueEnum};
use golden::rng::SeedRng;
use golden::setup::Screen;
use hdl_gen::cli::ModelArgs;
use rand::SeedableRng;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;
use verilator_harness::ffi::ModelInfo;
use verilator_harness::frontend::{random_triangles, run_chain_at};
use verilator_harness::ondemand;
use verilator_harness::registry::unit_of;
use verilator_harness::segment::{Report, SegmentCosim, Traffic};
use verilator_harness::specular::{random_span, SpecularCosim};
use verilator_harness::stimulus::random_triangle;
use verilator_harness::waveform;

/// Widest and tallest screen: `golden::stimulus::random_triangle` puts vertices anywhere on it,
/// and the set-up refuses a coordinate beyond `COORD_LIMIT` (a larger screen made bad triangles,
/// reported as mismatches).
const MAX_SIDE: i64 = golden::setup::COORD_LIMIT as i64;

/// `--traffic`: the valid/ready pattern at both ends.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum TrafficArg {
    Random,
    Full,
}

impl TrafficArg {
    fn traffic(self) -> Traffic {
        match self {
            TrafficArg::Random => Traffic::RANDOM,
            TrafficArg::Full => Traffic::FULL,
        }
    }
    fn name(self) -> &'static str {
        match self {
            TrafficArg::Random => "random",
            TrafficArg::Full => "full",
        }
    }
}

#[derive(Parser)]
#[command(about = "Co-simulate the generated segment shader against the golden model", allow_negative_numbers = true)]
struct Args {
    // The model to run: any configuration `generate` accepts, by the same flags (the compiled
    // catalogue's model when it has it, else built the first time, then cached).
    #[command(flatten)]
    model: ModelArgs,
    /// Random triangles to stream.
    #[arg(long, default_value_t = 10_000)]
    triangles: usize,
    /// Seed of the triangles and of the traffic (default: fresh, printed).
    #[arg(long)]
    seed: Option<u64>,
    /// Screen width (1..=32768; see --height).
    #[arg(long, default_value_t = 640, value_parser = clap::value_parser!(u32).range(1..=MAX_SIDE))]
    width: u32,
    /// Screen height (1..=32768: the random triangles' vertices lie anywhere on the screen, and
    /// the set-up takes coordinates up to golden::setup::COORD_LIMIT).
    #[arg(long, default_value_t = 480, value_parser = clap::value_parser!(u32).range(1..=MAX_SIDE))]
    height: u32,
    /// `random`: random input gaps and output backpressure; `full`: both ends always ready
    /// (the shader's own throughput).
    #[arg(long, value_enum, default_value_t = TrafficArg::Random)]
    traffic: TrafficArg,
    /// Triangles painted into one frame between frame checks.
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u64).range(1..))]
    batch: u64,
    /// Who sets up the triangles: `host` (golden::setup feeds spans to segment_shader_p<P>) or
    /// `rtl` (triangles into tri_shader_p<P>: the generated front-end, then the shader).
    #[arg(long, value_enum, default_value_t = Frontend::Host)]
    frontend: Frontend,
    /// Run the specular unit instead: random spans set up from random normals and
    /// half-vectors, every pixel checked; `N passed, M failed` then counts spans.
    #[arg(long)]
    specular: bool,
    /// With --specular: pixels to stream.
    #[arg(long, default_value_t = 1_000_000, requires = "specular")]
    pixels: u64,
    /// Write every clock of the run into FST files in DIR (`<model>-seed<seed>.fst`, one per model
    /// instance), for GTKWave or Surfer. For small runs: about 45 bytes per clock for
    /// seg_p8_span, 27 for the specular unit, and a run 4 to 8 times slower (docs/regressions.md). The
    /// models' traced twins are built first, the first time (seconds each), then cached.
    #[arg(long, value_name = "DIR")]
    trace: Option<PathBuf>,
}

/// With `--trace DIR`: every model instance from now on writes its waveform into DIR. Exit
/// status 2 when `info` has no traced twin in this build or DIR cannot be made.
fn start_trace<I, O>(args: &Args, info: &ModelInfo<I, O>) -> Result<(), ExitCode> {
    let Some(dir) = &args.trace else { return Ok(()) };
    ondemand::require_traced(info).and_then(|()| waveform::trace_everything(dir)).map_err(|e| {
        eprintln!("error: --trace: {e}");
        ExitCode::from(2)
    })
}

/// The `waveform:` lines of a run: the files `--trace` wrote.
fn print_waveforms() {
    for path in waveform::written() {
        println!("waveform:   {}", path.display());
    }
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Frontend {
    Host,
    Rtl,
}

fn main() -> ExitCode {
    // A COSIM_RTL_DIR folder that describes no models, or that a model flag contradicts, is
    // refused before anything runs.
    let args = match verilator_harness::given::start::<Args>(|a| Some(a.model.options(None))) {
        Ok(args) => args,
        Err(code) => return code,
    };
    if args.specular {
        return specular(&args);
    }
    if args.frontend == Frontend::Rtl {
        return rtl_frontend(&args);
    }
    // The compiled catalogue's model, or one built (once, then cached) for this configuration.
    let info = match options(&args, None).map(|o| verilator_harness::registry::segment(&o)) {
        Err(code) => return code,
        Ok(Ok(info)) => info,
        Ok(Err(e)) => return ondemand::exit(&model_flags(&args), &e),
    };
    let screen = Screen { width: args.width, height: args.height };
    if let Err(e) = screen.check_for(&info.cfg) {
        eprintln!("error: --width/--height: {e}");
        return ExitCode::from(2);
    }
    if let Err(code) = start_trace(&args, info) {
        return code;
    }
    let seed = args.seed.unwrap_or_else(|| verilator_harness::seed("cosim"));
    let traffic = args.traffic.traffic();
    println!("model {} ({}), screen {}x{}, seed {seed}, traffic {}", info.tag, info.top, screen.width, screen.height, args.traffic.name());

    let mut rng = SeedRng::seed_from_u64(seed);
    let mut sim = SegmentCosim::new(info, seed, traffic);
    let mut report = Report::default();
    let start = Instant::now();
    let mut done = 0;
    while done < args.triangles {
        let n = (args.batch as usize).min(args.triangles - done);
        let batch: Vec<_> = (0..n).map(|_| random_triangle(&mut rng, &screen)).collect();
        sim.run_triangles(&screen, &batch, done, &mut report);
        done += n;
    }
    let secs = start.elapsed().as_secs_f64();

    let triangles = report.triangles.to_string();
    let speed = format!("{:.0} segments/s, {:.0} pixels/s", report.segments as f64 / secs, report.pixels as f64 / secs);
    finish(seed, &report, &triangles, Some(report.spans), &speed, secs)
}

/// The closing lines every triangle run prints (ending `N passed, M failed`), and its exit code.
fn finish(seed: u64, report: &Report, triangles: &str, spans: Option<u64>, speed: &str, secs: f64) -> ExitCode {
    for m in &report.mismatches {
        println!("MISMATCH (seed {seed}) {m}");
    }
    println!("triangles:  {triangles}");
    if let Some(spans) = spans {
        println!("spans:      {spans}");
    }
    println!("segments:   {} compared", report.segments);
    println!("pixels:     {} compared", report.pixels);
    println!("mismatches: {}", report.mismatch_count);
    println!("cycles:     {}", report.cycles);
    println!("pixels per clock: {:.3}", report.pixels_per_clock());
    println!("worst |pixel - exact|: {:.3}", report.max_error);
    println!("wall: {secs:.2} s, {speed}, {:.0} clocks/s", report.cycles as f64 / secs);
    print_waveforms();
    println!("{} passed, {} failed", report.passed_count(), report.failed_count());
    exit_code(report)
}

/// Random triangles of every kind into `tri_shader_p<P>`; every segment, `y` and frame checked.
fn rtl_frontend(args: &Args) -> ExitCode {
    // The chain on the screen asked for: the catalogue's, or built for it.
    let screen = Screen { width: args.width, height: args.height };
    let info = match options(args, Some(screen)).map(|o| verilator_harness::registry::tri_shader(&o)) {
        Err(code) => return code,
        Ok(Ok(info)) => info,
        Ok(Err(e)) => return ondemand::exit(&format!("--frontend rtl {}", model_flags(args)), &e),
    };
    if (args.width, args.height) != (info.screen.width, info.screen.height) {
        eprintln!("error: --width/--height: the front-end model draws on {}x{}", info.screen.width, info.screen.height);
        return ExitCode::from(2);
    }
    if let Err(code) = start_trace(args, info) {
        return code;
    }
    let seed = args.seed.unwrap_or_else(|| verilator_harness::seed("cosim --frontend rtl"));
    let traffic = args.traffic.traffic();
    println!(
        "model {} ({}), screen {}x{}, seed {seed}, traffic {}",
        info.tag,
        info.top,
        info.screen.width,
        info.screen.height,
        args.traffic.name()
    );
    let fe = info.frontend();
    let mut rng = SeedRng::seed_from_u64(seed);
    let mut report = Report::default();
    let start = Instant::now();
    let mut done = 0;
    while done < args.triangles {
        let n = (args.batch as usize).min(args.triangles - done);
        let tris = random_triangles(&mut rng, &fe, n);
        report.absorb(run_chain_at(info, seed.wrapping_add(done as u64), traffic, &tris, done).report);
        done += n;
    }
    let secs = start.elapsed().as_secs_f64();
    let triangles = format!("{} ({} dropped for the guard band)", report.triangles, report.pulses);
    let speed = format!("{:.0} triangles/s", report.triangles as f64 / secs);
    finish(seed, &report, &triangles, None, &speed, secs)
}

fn exit_code(report: &Report) -> ExitCode {
    if report.ok() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    }
}

/// The options of the model to run (`screen`: a front-end's), or exit status 2 with the reason.
fn options(args: &Args, screen: Option<Screen>) -> Result<hdl_gen::Options, ExitCode> {
    args.model.options(screen).map_err(|e| {
        eprintln!("error: {e}");
        ExitCode::from(2)
    })
}

/// `--p P --align A`: how a model's error names the configuration.
fn model_flags(args: &Args) -> String {
    format!("--p {} --align {}", args.model.seg.p, args.model.seg.align)
}

fn specular(args: &Args) -> ExitCode {
    let info = match options(args, None).map(|o| verilator_harness::registry::specular(&o)) {
        Err(code) => return code,
        Ok(Ok(info)) => info,
        Ok(Err(e)) => return ondemand::exit("--specular", &e),
    };
    if let Err(code) = start_trace(args, info) {
        return code;
    }
    let seed = args.seed.unwrap_or_else(|| verilator_harness::seed("cosim --specular"));
    let traffic = args.traffic.traffic();
    println!("model {} ({}), seed {seed}, traffic {}", info.tag, info.top, args.traffic.name());
    let mut rng = SeedRng::seed_from_u64(seed);
    let mut sim = SpecularCosim::new(info, unit_of(info), seed, traffic);
    let mut report = Report::default();
    let start = Instant::now();
    while report.pixels < args.pixels {
        let spans: Vec<_> = (0..256).map(|_| random_span(&mut rng, info.cfg.max_len())).collect();
        sim.stream(&spans, &mut report);
    }
    let secs = start.elapsed().as_secs_f64();
    for m in &report.mismatches {
        println!("MISMATCH (seed {seed}) {m}");
    }
    println!("spans:      {}", report.spans);
    println!("pixels:     {} compared", report.pixels);
    println!("mismatches: {}", report.mismatch_count);
    println!("cycles:     {}", report.cycles);
    println!("cycles per pixel: {:.3} (latency {} clocks)", report.cycles as f64 / report.pixels.max(1) as f64, info.latency);
    println!("wall: {secs:.2} s, {:.0} pixels/s, {:.0} clocks/s", report.pixels as f64 / secs, report.cycles as f64 / secs);
    let failed = report.failed_count();
    print_waveforms();
    println!("{} passed, {failed} failed", report.spans as usize - report.failed.len().min(report.spans as usize));
    exit_code(&report)
}
