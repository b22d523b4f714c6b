//! Models built when first asked for (`verilator_harness::ondemand`): a configuration outside the
//! compiled catalogue is generated, verilated, compiled into a shared object, loaded, and runs
//! bit-exact against golden (and a planted fault in it is caught); asking again loads it from the
//! cache without building; a configuration the catalogue has is taken from it, built nothing.

use golden::setup::Screen;
use golden::{Align, Config};
use std::sync::OnceLock;
use verilator_harness::ffi::{ModelInfo, SegIn, SegOut, StepFn};
use verilator_harness::models::Kind;
use verilator_harness::ondemand::{self, Outcome};
use verilator_harness::registry::SEGMENT_MODELS;
use verilator_harness::segment::{assert_clean, Report, SegmentCosim, Traffic};
use verilator_harness::stimulus::random_triangle;

/// p = 2 with 10 fraction bits: small (a few seconds to build, once; cached after) and in no
/// catalogue.
fn options() -> hdl_gen::Options {
    hdl_gen::Options { cfg: Config::new(2, 10, 12, Align::Span).expect("a valid configuration"), ..Default::default() }
}

/// Whether this run asks models of `ondemand` (under COSIM_RTL_DIR it hands out the folder's
/// models only); says so on stderr when it does not.
fn on_demand(what: &str) -> bool {
    if let Some(dir) = verilator_harness::registry::rtl_dir() {
        use std::io::Write;
        let _ = writeln!(std::io::stderr().lock(), "{what}: skipped: COSIM_RTL_DIR={} provides the models", dir.display());
        return false;
    }
    true
}

/// `report` after `triangles` random triangles through `info`, under random gaps and backpressure.
fn run(info: &'static ModelInfo<SegIn, SegOut>, seed: u64, triangles: usize) -> Report {
    let screen = Screen::default();
    let mut rng = <golden::rng::SeedRng as rand::SeedableRng>::seed_from_u64(seed);
    let mut sim = SegmentCosim::new(info, seed, Traffic::RANDOM);
    let mut report = Report::default();
    let batch: Vec<_> = (0..triangles).map(|_| random_triangle(&mut rng, &screen)).collect();
    sim.run_triangles(&screen, &batch, 0, &mut report);
    report
}

static REAL_STEP: OnceLock<StepFn<SegIn, SegOut>> = OnceLock::new();

/// The built model's step, then lane 0's pixel with its lowest bit flipped.
unsafe extern "C" fn flipped_step(h: *mut std::ffi::c_void, i: *const SegIn, o: *mut SegOut) {
    (REAL_STEP.get().expect("set before use"))(h, i, o);
    (*o).pix[0] ^= 1;
}

/// One test for the build and the cache, so that a cold run compiles the model once: two test
/// processes asking at once would each compile it (safely, but twice the CPU).
#[test]
fn a_configuration_outside_the_catalogue_is_built_runs_bit_exact_and_is_cached() {
    if !on_demand("ondemand: a configuration outside the catalogue") {
        return;
    }
    built_and_bit_exact();
    second_ask_loads_from_the_cache();
}

fn built_and_bit_exact() {
    let m = ondemand::describe(&options(), Kind::Segment).expect("the model of p = 2, frac 10");
    assert!(SEGMENT_MODELS.iter().all(|c| c.identity() != m.identity()), "{}: the catalogue has it, pick another", m.tag);
    let info = verilator_harness::registry::segment(&options()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((info.tag, info.top, info.cfg), ("seg_p2_span_f10", "segment_shader_p2", options().cfg));
    let seed = verilator_harness::seed("ondemand::a_configuration_outside_the_catalogue");
    let report = run(info, seed, 200);
    assert_clean(info.tag, seed, &report);
    assert!(report.pixels > 1000, "{} pixels compared", report.pixels);
    // Negative control: the same model with one bit of one lane flipped fails.
    REAL_STEP.set(info.step_fn()).expect("one mutant");
    // SAFETY: flipped_step calls the model's own step with the same arguments, then edits its output.
    let mutant: &'static ModelInfo<SegIn, SegOut> = Box::leak(Box::new(unsafe { info.with_step(flipped_step) }));
    assert!(run(mutant, seed, 20).mismatch_count > 0, "a flipped pixel bit went unnoticed");
}

fn second_ask_loads_from_the_cache() {
    let m = ondemand::describe(&options(), Kind::Segment).expect("the model of p = 2, frac 10");
    // The first ask (above) built it.
    let (so, _) = ondemand::shared_object(&m).unwrap_or_else(|e| panic!("{e}"));
    let built = std::fs::metadata(&so).and_then(|f| f.modified()).expect("the shared object");
    let (again, outcome) = ondemand::shared_object(&m).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((&again, outcome), (&so, Outcome::Cached), "the second ask rebuilt it");
    assert_eq!(std::fs::metadata(&so).and_then(|f| f.modified()).expect("the shared object"), built, "rewritten");
    // Loaded once per process: the same ModelInfo.
    let a = verilator_harness::registry::segment(&options()).unwrap_or_else(|e| panic!("{e}"));
    let b = verilator_harness::registry::segment(&options()).unwrap_or_else(|e| panic!("{e}"));
    assert!(std::ptr::eq(a, b));
    // Another configuration is another cache entry (and would be built on its own).
    let other = hdl_gen::Options { cfg: Config::new(2, 11, 12, Align::Span).expect("valid"), ..Default::default() };
    let other = ondemand::describe(&other, Kind::Segment).expect("the model of p = 2, frac 11");
    assert_ne!(ondemand::cache_entry(&other).expect("verilator"), ondemand::cache_entry(&m).expect("verilator"));
}

#[test]
fn the_catalogue_answers_what_it_has() {
    if !on_demand("ondemand: the catalogue first") {
        return;
    }
    for (p, align) in [(8, Align::Span), (1, Align::Screen), (64, Align::Span)] {
        let opts = ondemand::options(p, align, None).expect("a valid configuration");
        let found = verilator_harness::registry::segment(&opts).unwrap_or_else(|e| panic!("{e}"));
        let compiled = SEGMENT_MODELS.iter().find(|m| m.tag == format!("seg_p{p}_{align}")).expect("in the catalogue");
        assert!(std::ptr::eq(found, compiled), "seg_p{p}_{align}: {} was loaded, not the catalogue's", found.tag);
    }
    // The pipelined ones too, and the front-end's chain on its default screen.
    let opts = hdl_gen::Options { pipeline: golden::pipeline::Pipeline::at(1), ..Default::default() };
    assert_eq!(verilator_harness::registry::segment(&opts).map(|m| m.tag).unwrap_or_else(|e| panic!("{e}")), "seg_p8_span_pl1");
    let opts = ondemand::options(8, Align::Span, Some(Screen::default())).expect("valid");
    assert_eq!(verilator_harness::registry::tri_shader(&opts).map(|m| m.tag).unwrap_or_else(|e| panic!("{e}")), "tris_p8_span");
}

#[test]
fn a_configuration_generate_refuses_is_a_usage_error() {
    for (p, screen, needle) in [(3, None, "power of two"), (8, Some(Screen { width: 9000, height: 480 }), "--width/--height")] {
        // `describe`, not `tri_shader`: a COSIM_RTL_DIR build hands out its folder's chain by P and
        // alignment, and the binaries check its screen themselves.
        let e = ondemand::options(p, Align::Span, screen).and_then(|o| ondemand::describe(&o, Kind::TriShader)).expect_err("refused");
        assert_eq!(ondemand::exit_status(&e), 2, "{e}");
        assert!(e.to_string().contains(needle), "{e}");
    }
}

/// COSIM_RTL_DIR's rule for a relative path: from the process's folder when it exists there, else
/// from the workspace's root (cargo runs build scripts and tests in the package's folder, so
/// `COSIM_RTL_DIR=rtl` typed at the root means `<root>/rtl`); an absolute path is itself.
#[test]
fn a_relative_cosim_rtl_dir_is_found_from_the_workspace_root() {
    use std::path::Path;
    use verilator_harness::models::catalogue::resolve_rtl_dir;
    let package = Path::new(env!("CARGO_MANIFEST_DIR"));
    let root = package.parent().expect("the workspace");
    let rtl = resolve_rtl_dir(Path::new("rtl"), package, package);
    assert_eq!(rtl, root.join("rtl"));
    assert!(rtl.join(hdl_gen::manifest::MANIFEST_FILE).is_file(), "{}: the repository's rtl/", rtl.display());
    // A folder that exists from the process's own folder is that one; an absolute path is kept.
    assert_eq!(resolve_rtl_dir(Path::new("csrc"), package, package), package.join("csrc"));
    assert_eq!(resolve_rtl_dir(&root.join("rtl"), package, package), root.join("rtl"));
    // From the root, the same relative path is the same folder.
    assert_eq!(resolve_rtl_dir(Path::new("rtl"), root, package), root.join("rtl"));
    // The folder's models, described from it, are the catalogue's circuits: checking an
    // unmodified generate folder builds nothing.
    let manifest = verilator_harness::models::catalogue::read_manifest(&rtl).unwrap_or_else(|e| panic!("{e}"));
    let models = verilator_harness::models::catalogue::models_from_dir(&rtl, &manifest).unwrap_or_else(|e| panic!("{e}"));
    let seg = models.iter().find(|m| m.kind == Kind::Segment && m.axis.is_none()).expect("rtl/ has a segment shader");
    if on_demand("ondemand: rtl/ against the catalogue") {
        assert!(SEGMENT_MODELS.iter().any(|c| c.identity() == seg.identity()), "rtl/'s {} is not the catalogue's", seg.tag);
    }
}

/// The binaries read COSIM_RTL_DIR when they run (the crate is built without it): `cosim` on a
/// folder of p = 2 runs that folder's shader, relative paths included (from the process's folder,
/// else from the workspace's root), and refuses, exit status 2 in one line, what the folder does
/// not have (the default p = 8: the negative control that the folder, not the catalogue, was
/// used) and a folder that does not exist. The folder's shader is the catalogue's circuit, so
/// nothing is built: a few tenths of a second.
#[test]
fn cosim_reads_cosim_rtl_dir_when_it_runs() {
    use std::process::Command;
    let package = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let root = package.parent().expect("the workspace");
    let dir = std::env::temp_dir().join(format!("ondemand-{}-rtl-dir", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let opts = ondemand::options(2, Align::Span, None).expect("valid");
    for f in hdl_gen::generate(&opts) {
        std::fs::create_dir_all(dir.join(&f.name).parent().expect("a folder")).unwrap();
        std::fs::write(dir.join(&f.name), &f.contents).unwrap();
    }
    let cosim = |cwd: &std::path::Path, rtl: &std::path::Path, args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_cosim")).current_dir(cwd).env("COSIM_RTL_DIR", rtl).args(args).output().unwrap()
    };
    // From the folder's parent (relative to the process's folder) and, for rtl/, from the package's
    // folder where no rtl/ is (relative to the workspace's root).
    let name = std::path::Path::new(dir.file_name().expect("a name"));
    for (cwd, rtl, p) in [(dir.parent().expect("temp"), name, "2"), (package, std::path::Path::new("rtl"), "8")] {
        let out = cosim(cwd, rtl, &["--p", p, "--triangles", "5", "--seed", "1"]);
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success(), "{}: {stdout}{}", rtl.display(), String::from_utf8_lossy(&out.stderr));
        assert!(stdout.contains(&format!("model seg_p{p}_span")) && stdout.contains("5 passed, 0 failed"), "{stdout}");
    }
    // A model flag typed beside the folder must be what the folder was generated with: given and
    // equal runs (the negative control), given and different is refused in one line.
    let out = cosim(package, &dir, &["--p", "2", "--pipeline", "0", "--fe-div-bits", "4", "--triangles", "5", "--seed", "1"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    for args in [&["--p", "2", "--pipeline", "1"][..], &["--p", "2", "--target", "ice40-up5k"], &["--p", "2", "--frac", "10"]] {
        let out = cosim(package, &dir, args);
        let err = String::from_utf8_lossy(&out.stderr);
        let flag = args[2];
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.starts_with(&format!("error: {flag}: COSIM_RTL_DIR=")) && err.lines().count() == 1, "{args:?}: {err}");
    }
    // bench's subcommands take the same flags and the same rule.
    let out = Command::new(env!("CARGO_BIN_EXE_bench"))
        .env("COSIM_RTL_DIR", &dir)
        .args(["info", "--p", "2", "--pipeline", "1"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.code() == Some(2) && err.starts_with("error: --pipeline: COSIM_RTL_DIR="), "bench info: {err}");
    assert!(root.join("rtl").is_dir());
    for (rtl, needle) in [(dir.as_path(), "has no such Segment model (it has: seg_p2_span)"), (&dir.join("missing"), "no such folder")] {
        let out = cosim(package, rtl, &["--triangles", "5"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.contains(needle) && err.lines().count() == 1 && out.stdout.is_empty(), "{err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
