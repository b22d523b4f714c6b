//! `bench`: the harness's side of `scripts/bench-cosim`.
//!
//! * `bench gen`: writes a stimulus file and an expected-output file (both little-endian
//!   binary, laid out in `verilator_harness::benchfile`) for the segment shader (spans from
//!   golden set-up of random triangles) or the specular unit (random spans from golden specular
//!   set-up) of any configuration `generate` accepts, which the stimulus file's header names.
//!   The native C++ testbench (`bench/native_tb.cpp`) and the cocotb test
//!   (`bench/cocotb/test_bench.py`) read the same two files.
//! * `bench harness`: reads a stimulus file and streams it through the harness exactly as users
//!   run it (`SegmentCosim::stream` / `SpecularCosim::stream`, golden comparison on), timing
//!   only the streaming loop. Prints one `RESULT` line.
//! * `bench info`: where a configuration's models come from: for its segment shader and
//!   specular unit, the Verilog the harness verilated (so the native and cocotb benches simulate
//!   the very same files) and how long it took to verilate and compile each.

use clap::{Parser, Subcommand, ValueEnum};
use golden::rng::SeedRng;
use golden::segment::segments;
use golden::setup::{triangle_spans, Screen};
use golden::specular::SpecularSpan;
use golden::Span;
use hdl_gen::cli::ModelArgs;
use hdl_gen::output::{commit, stage, Staged};
use rand::SeedableRng;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;
use verilator_harness::benchfile::{expect_header, read_stim, seg_record_bytes, stim_record, Header, StimModel, HEADER};
use verilator_harness::ffi::to_port;
use verilator_harness::models::Kind;
use verilator_harness::ondemand;
use verilator_harness::registry::unit_of;
use verilator_harness::segment::{Report, SegmentCosim, Stim};
use verilator_harness::specular::{random_span, SpecularCosim};
use verilator_harness::stimulus::random_triangle;
use verilator_harness::traffic::{state_of, Traffic};

/// Widest and tallest screen of the random triangles (golden::setup::COORD_LIMIT), as cosim's.
const MAX_SIDE: i64 = golden::setup::COORD_LIMIT as i64;

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum, Debug)]
enum Design {
    Segment,
    Specular,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum, Debug)]
enum TrafficArg {
    Random,
    Full,
}

#[derive(Parser)]
#[command(about = "Stimulus files and harness timing for scripts/bench-cosim")]
struct Args {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Write PREFIX.stim and PREFIX.expect.
    // A negative number is a value its flag's range then refuses by name, not an unknown flag.
    #[command(allow_negative_numbers = true)]
    Gen {
        #[arg(long, value_enum)]
        design: Design,
        // The model: any configuration `generate` accepts, by the same flags (the compiled
        // catalogue's model when it has it, else built the first time, then cached). The file's
        // header names it, so `harness` runs the same one.
        #[command(flatten)]
        model: ModelArgs,
        /// Screen width of the random triangles (segment design; 1..=32768, at most what the
        /// x ports carry). Default: the configuration's, 640 narrowed to 2^XW and 2^F.
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_SIDE))]
        width: Option<u32>,
        /// Screen height of the random triangles (segment design; 1..=32768). Default: 480.
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_SIDE))]
        height: Option<u32>,
        /// Spans to write (1..=4294967295: the header holds the count as a u32). Written as they
        /// are made, so memory does not grow with the count; refused at once when the folder
        /// has not the room the two files take at the least.
        #[arg(long, value_parser = clap::value_parser!(u64).range(1..=u32::MAX as u64))]
        spans: u64,
        #[arg(long, default_value_t = 1)]
        seed: u64,
        #[arg(long, value_enum, default_value = "random")]
        traffic: TrafficArg,
        /// Output path prefix: PREFIX.stim and PREFIX.expect are written (all or none).
        #[arg(long, value_name = "PREFIX")]
        out: PathBuf,
    },
    /// The RTL folder and build time of the models the benchmark uses.
    // A negative number is a value its flag's range then refuses by name, not an unknown flag.
    #[command(allow_negative_numbers = true)]
    Info {
        // The models: any configuration `generate` accepts, by the same flags.
        #[command(flatten)]
        model: ModelArgs,
    },
    /// Stream a stimulus file through the harness with the golden comparison on; time the loop.
    #[command(allow_negative_numbers = true)]
    Harness {
        stim: PathBuf,
        /// Only the first N spans (0: all).
        #[arg(long, default_value_t = 0)]
        limit: usize,
    },
}

/// A bad argument or input file: one `error:` line, exit status 2.
type Bad = String;

fn main() -> ExitCode {
    // A COSIM_RTL_DIR folder that describes no models, or that a model flag contradicts, is
    // refused before anything runs.
    let args = match verilator_harness::given::start::<Args>(|a| match &a.cmd {
        Cmd::Gen { model, .. } | Cmd::Info { model } => Some(model.options(None)),
        Cmd::Harness { .. } => None,
    }) {
        Ok(args) => args,
        Err(code) => return code,
    };
    let run = match args.cmd {
        Cmd::Gen { design, model, width, height, spans, seed, traffic, out } => {
            let traffic = match traffic {
                TrafficArg::Random => Traffic::RANDOM,
                TrafficArg::Full => Traffic::FULL,
            };
            // clap bounds the count to the header's u32.
            let count = spans as u32;
            let run = Run { count, seed, traffic, out: &out };
            match design {
                Design::Segment => gen_segment(&model, width, height, &run),
                Design::Specular if width.or(height).is_some() => {
                    Err("--width/--height: the specular design draws no triangles (they set the segment design's screen)".into())
                }
                Design::Specular => gen_specular(&model, &run),
            }
        }
        Cmd::Harness { stim, limit } => harness(&stim, limit),
        Cmd::Info { model } => info(&model),
    };
    run.unwrap_or_else(|e| {
        eprintln!("error: {e}");
        ExitCode::from(2)
    })
}

/// `MODEL tag=... top=... rtl=DIR verilate=S compile=S total=S` for the segment shader and the
/// specular unit of the configuration, then the runtime's `RUNTIME compile=S`: the Verilog each
/// model was verilated from (build.rs's for the catalogue's models, the cache entry's for one
/// built at run time, which this builds first, or the `COSIM_RTL_DIR` folder), so the native and
/// cocotb benches simulate the very same files, and how long its build took.
fn info(model: &ModelArgs) -> Result<ExitCode, Bad> {
    let opts = model.options(None).map_err(|e| e.to_string())?;
    let out = PathBuf::from(env!("OUT_DIR"));
    let times = |record: &std::path::Path| -> String {
        let text = std::fs::read_to_string(record.join("build.time")).unwrap_or_default();
        text.lines().filter_map(|l| l.split_once(' ')).map(|(k, v)| format!(" {k}={v}")).collect()
    };
    let seg = verilator_harness::registry::segment(&opts).map_err(|e| format!("{}: {e}", model_flags(model)))?;
    let spec = verilator_harness::registry::specular(&opts).map_err(|e| format!("--specular: {e}"))?;
    for (tag, top, kind) in [(seg.tag, seg.top, Kind::Segment), (spec.tag, spec.top, Kind::Specular)] {
        let compiled = out.join("rtl").join(tag);
        let (rtl, record) = match verilator_harness::registry::rtl_dir() {
            Some(dir) => (dir.to_path_buf(), PathBuf::new()),
            None if compiled.is_dir() => (compiled, out.join("obj").join(tag)),
            None => {
                let entry = ondemand::describe(&opts, kind).and_then(|m| ondemand::cache_entry(&m)).map_err(|e| format!("{tag}: {e}"))?;
                (entry.join("rtl"), entry)
            }
        };
        println!("MODEL tag={tag} top={top} rtl={}{}", rtl.display(), times(&record));
    }
    println!("RUNTIME{}", times(&out.join("obj").join("runtime")));
    Ok(ExitCode::SUCCESS)
}

fn with_ext(prefix: &std::path::Path, ext: &str) -> PathBuf {
    let mut s = prefix.as_os_str().to_owned();
    s.push(ext);
    PathBuf::from(s)
}

/// Refuses an --out prefix whose files cannot be written, or whose folder has less room than
/// `least` bytes, the least the two files take: checked before a span is made (with a lower
/// bound) and again with the exact size.
fn check_out(out: &std::path::Path, spans: u32, least: u64) -> Result<(), Bad> {
    if out.file_name().is_none() || out.as_os_str().to_string_lossy().ends_with('/') {
        return Err(format!("--out {}: a path prefix, not a folder", out.display()));
    }
    for path in [with_ext(out, ".stim"), with_ext(out, ".expect")] {
        hdl_gen::output::check_writable(&path).map_err(|e| format!("--out: {e}"))?;
    }
    let dir = out.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(std::path::Path::new("."));
    match free_bytes(dir) {
        Some(free) if free < least => Err(format!(
            "--spans {spans}: the two files take at least {:.1} GB, {} has {:.1} GB free",
            least as f64 / 1e9,
            dir.display(),
            free as f64 / 1e9
        )),
        _ => Ok(()),
    }
}

/// PREFIX.stim and PREFIX.expect, staged (nothing visible until [`commit`]), each begun with its
/// header.
fn create_pair(out: &std::path::Path, header: &Header, least: u64) -> Result<(Staged, Staged), Bad> {
    check_out(out, header.spans, least)?;
    let mut sf = stage(&with_ext(out, ".stim")).map_err(|e| format!("--out: {e}"))?;
    let mut ef = stage(&with_ext(out, ".expect")).map_err(|e| format!("--out: {e}"))?;
    sf.put(&header.bytes()).map_err(|e| e.to_string())?;
    ef.put(&expect_header(header.design, header.rec, header.outputs)).map_err(|e| e.to_string())?;
    Ok((sf, ef))
}

/// Bytes free to an unprivileged user in `dir`'s file system, if the system says.
fn free_bytes(dir: &std::path::Path) -> Option<u64> {
    use std::os::unix::ffi::OsStrExt;
    let c = std::ffi::CString::new(dir.as_os_str().as_bytes()).ok()?;
    let mut st: libc::statvfs = unsafe { std::mem::zeroed() };
    // SAFETY: a NUL-terminated path and a statvfs we own, filled by the call.
    let rc = unsafe { libc::statvfs(c.as_ptr(), &mut st) };
    (rc == 0).then(|| st.f_bavail as u64 * st.f_frsize as u64)
}

/// The first `count` spans of golden set-up of random triangles from `seed`, each to `f`: made
/// as they are used, so a pass over them holds no list (gen makes them twice: counting, writing).
fn segment_spans(
    cfg: &golden::Config,
    screen: Screen,
    count: u32,
    seed: u64,
    mut f: impl FnMut(Stim) -> Result<(), Bad>,
) -> Result<(), Bad> {
    let mut rng = SeedRng::seed_from_u64(seed);
    let (mut made, mut triangle) = (0u32, 0usize);
    while made < count {
        let t = random_triangle(&mut rng, &screen);
        let mut spans = Vec::new();
        let _ = triangle_spans(cfg, &screen, &t, |y, span| spans.push(Stim { triangle, y, span }));
        for s in spans.into_iter().take((count - made) as usize) {
            f(s)?;
            made += 1;
        }
        triangle += 1;
    }
    Ok(())
}

/// What every `gen` is asked for besides its model.
struct Run<'a> {
    count: u32,
    seed: u64,
    traffic: Traffic,
    out: &'a std::path::Path,
}

/// How a model's error names the configuration (as cosim's do).
fn model_flags(m: &ModelArgs) -> String {
    format!("--p {} --align {}", m.seg.p, m.seg.align)
}

/// The header's model, from the command line's flags; an error is a usage error.
fn header_model(model: &ModelArgs, screen: Option<Screen>) -> Result<StimModel, Bad> {
    StimModel::of(model, screen).map_err(|e| e.to_string())
}

fn gen_segment(model: &ModelArgs, width: Option<u32>, height: Option<u32>, run: &Run) -> Result<ExitCode, Bad> {
    let Run { count, seed, traffic, out } = *run;
    let opts = model.options(None).map_err(|e| e.to_string())?;
    let default = hdl_gen::Options::default_screen(&opts.cfg);
    let screen = Screen { width: width.unwrap_or(default.width), height: height.unwrap_or(default.height) };
    screen.check_for(&opts.cfg).map_err(|e| format!("--width/--height: {e}"))?;
    let stim_model = header_model(model, Some(screen))?;
    let p = opts.cfg.p;
    let rec = seg_record_bytes(p);
    // Every span yields at least one record. A bad --out is refused before the model is asked
    // for (which may take a build, or not exist in a COSIM_RTL_DIR run).
    check_out(out, count, (HEADER + 24) as u64 + (32 + rec as u64) * count as u64)?;
    let info = verilator_harness::registry::segment(&opts).map_err(|e| format!("{}: {e}", model_flags(model)))?;
    let cfg = info.cfg;
    let mut outputs = 0u64;
    segment_spans(&cfg, screen, count, seed, |s| {
        outputs += cfg.segment_count(s.span.x0, s.span.len) as u64;
        Ok(())
    })?;
    let header = Header {
        design: 0,
        p,
        state: state_of(seed),
        valid_thr: traffic.valid_thr(),
        ready_thr: traffic.ready_thr(),
        spans: count,
        outputs,
        seed,
        rec,
        dw: cfg.dw(),
        model: stim_model,
    };
    let least = (HEADER + 24) as u64 + 32 * count as u64 + rec as u64 * outputs;
    let (mut sf, mut ef) = create_pair(out, &header, least)?;
    let mut r = vec![0u8; rec as usize];
    let mut pixels = 0u64;
    segment_spans(&cfg, screen, count, seed, |s| {
        let Span { x0, len, i0, di } = s.span;
        let n = cfg.segment_count(x0, len);
        sf.put(&stim_record([x0, len, i0, to_port(di as i64, cfg.dw()), 0], n, s.triangle as u32, s.y)).map_err(|e| e.to_string())?;
        for seg in segments(&cfg, &s.span) {
            r.fill(0);
            r[..4].copy_from_slice(&(seg.x | (seg.last as u32) << 31).to_le_bytes());
            let mask_at = 4;
            let pix_at = 4 + p.div_ceil(8) as usize;
            for i in 0..p {
                if let Some(j) = seg.lane_pixel(i) {
                    r[mask_at + (i / 8) as usize] |= 1 << (i % 8);
                    r[pix_at + i as usize] = s.span.pixel(j, cfg.frac);
                    pixels += 1;
                }
            }
            ef.put(&r).map_err(|e| e.to_string())?;
        }
        Ok(())
    })?;
    commit(vec![sf, ef]).map_err(|e| e.to_string())?;
    println!("wrote {} spans, {outputs} segments, {pixels} pixels ({})", count, info.tag);
    Ok(ExitCode::SUCCESS)
}

fn gen_specular(model: &ModelArgs, run: &Run) -> Result<ExitCode, Bad> {
    let Run { count, seed, traffic, out } = *run;
    let opts = model.options(None).map_err(|e| e.to_string())?;
    let stim_model = header_model(model, None)?;
    check_out(out, count, (HEADER + 24) as u64 + (32 + 4) * count as u64)?;
    let info = verilator_harness::registry::specular(&opts).map_err(|e| format!("--specular: {e}"))?;
    let unit = unit_of(info);
    let spans = || {
        let mut rng = SeedRng::seed_from_u64(seed);
        (0..count).map(move |_| random_span(&mut rng, info.cfg.max_len()))
    };
    let outputs: u64 = spans().map(|s| s.len as u64).sum();
    let header = Header {
        design: 1,
        p: 1,
        state: state_of(seed),
        valid_thr: traffic.valid_thr(),
        ready_thr: traffic.ready_thr(),
        spans: count,
        outputs,
        seed,
        rec: 4,
        dw: 32,
        model: stim_model,
    };
    let least = (HEADER + 24) as u64 + 32 * count as u64 + 4 * outputs;
    let (mut sf, mut ef) = create_pair(out, &header, least)?;
    for (k, s) in spans().enumerate() {
        let ports = [s.c as u32, s.n as u32, to_port(s.theta0 as i64, 32), to_port(s.dtheta as i64, 32), s.len];
        sf.put(&stim_record(ports, s.len, k as u32, 0)).map_err(|e| e.to_string())?;
        for px in unit.span(&s) {
            let mut r = [0u8; 4];
            r[..2].copy_from_slice(&px.spec.to_le_bytes());
            r[2] = px.err as u8;
            r[3] = px.last as u8;
            ef.put(&r).map_err(|e| e.to_string())?;
        }
    }
    commit(vec![sf, ef]).map_err(|e| e.to_string())?;
    println!("wrote {count} spans, {outputs} pixels ({})", info.tag);
    Ok(ExitCode::SUCCESS)
}

/// The sign-extension of a `width`-bit port value.
fn from_port(v: u32, width: u32) -> i32 {
    ((v << (32 - width)) as i32) >> (32 - width)
}

/// CPU time of the process, every thread (Linux `CLOCK_PROCESS_CPUTIME_ID`): the harness's
/// driving and checking threads together, the cost a user pays in cores.
fn process_cpu() -> f64 {
    let mut t = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: clock_gettime fills the timespec we own; this clock exists on every Linux.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut t) };
    assert_eq!(rc, 0, "clock_gettime(CLOCK_PROCESS_CPUTIME_ID)");
    t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9
}

/// A timed region: wall seconds and the process's CPU seconds.
fn timed(f: impl FnOnce()) -> (f64, f64) {
    let (start, cpu) = (Instant::now(), process_cpu());
    f();
    (start.elapsed().as_secs_f64(), process_cpu() - cpu)
}

fn harness(path: &std::path::Path, limit: usize) -> Result<ExitCode, Bad> {
    let (h, recs) = read_stim(path, limit).map_err(|e| e.to_string())?;
    let traffic = Traffic { valid: h.valid_thr as f64 / 256.0, ready: h.ready_thr as f64 / 256.0 };
    let mut report = Report::default();
    let rejected = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
    // The model the header names, checked as `gen`'s flags are.
    let opts = h.model.options().map_err(|e| rejected(&e))?;
    let (tag, (secs, cpu)) = match h.design {
        0 => {
            if h.p != opts.cfg.p {
                return Err(rejected(&format!("the header's p is {}, its model's --p {}", h.p, opts.cfg.p)));
            }
            let info = verilator_harness::registry::segment(&opts)
                .map_err(|e| rejected(&format!("the segment shader of {:?}: {e}", h.model.generate)))?;
            if h.dw != info.cfg.dw() {
                return Err(format!("{}: in_di is {} bits in the file, {} in {}", path.display(), h.dw, info.cfg.dw(), info.tag));
            }
            let stims: Vec<Stim> = recs
                .iter()
                .map(|r| Stim { triangle: r[6] as usize, y: r[7], span: Span { x0: r[0], len: r[1], i0: r[2], di: from_port(r[3], h.dw) } })
                .collect();
            // Spans the ports cannot carry are refused before the timed loop.
            if let Some((index, e)) = stims.iter().enumerate().find_map(|(k, s)| s.span.check(&info.cfg).err().map(|e| (k, e))) {
                return Err(rejected(&format!("span {index}: {e}")));
            }
            let mut sim = SegmentCosim::new(info, h.seed, traffic);
            (info.tag, timed(|| sim.stream(&stims, &mut report, |_, _| {})))
        }
        _ => {
            let info = verilator_harness::registry::specular(&opts)
                .map_err(|e| rejected(&format!("the specular unit of {:?}: {e}", h.model.generate)))?;
            let spans: Vec<SpecularSpan> = recs
                .iter()
                .map(|r| SpecularSpan { c: r[0] as u16, n: r[1] as u16, theta0: r[2] as i32, dtheta: r[3] as i32, len: r[4] })
                .collect();
            let mut sim = SpecularCosim::new(info, unit_of(info), h.seed, traffic);
            let mut result = Ok(());
            let t = timed(|| result = sim.try_stream(&spans, &mut report));
            result.map_err(|e| rejected(&e))?;
            (info.tag, t)
        }
    };
    for m in &report.mismatches {
        eprintln!("MISMATCH {m}");
    }
    println!(
        "RESULT impl=harness model={tag} spans={} clocks={} pixels={} secs={secs:.6} cpu={cpu:.6} mismatches={}",
        report.spans, report.cycles, report.pixels, report.mismatch_count
    );
    Ok(if report.ok() { ExitCode::SUCCESS } else { ExitCode::from(1) })
}
