//! Generated Verilog is clean under `verilator --lint-only -Wall` and compiles in Icarus
//! (`iverilog -g2005`), for a spread of configurations and every increment form. Every `.v`
//! file that `generate` writes is linted as the top module, whatever modules it holds, and so
//! is the synthesis harness around every module the manifest lists. A missing tool fails the
//! test with the command that installs it: a lint that did not run must not pass.
//!
//! The full sweep (every P, both alignments, every form, plus Yosys) is `scripts/lint-all`.

use golden::frontend::{DiMode, I0Form};
use golden::pipeline::Pipeline;
use golden::{Align, Config};
use hdl_gen::tools::wrapper;
use hdl_gen::{generate, output, BfpiArch, Bus, Options};
use std::path::Path;
use std::process::Command;

/// Runs `tool`: whether it exited 0, and what it printed (stdout, then stderr).
fn tool_output(tool: &str, args: &[String]) -> (bool, String) {
    let out = Command::new(tool).args(args).output().unwrap_or_else(|e| {
        panic!("{tool} could not be run ({e}); install it with: apt-get install -y {}", if tool == "iverilog" { "iverilog" } else { tool })
    });
    (out.status.success(), format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr)))
}

fn run(tool: &str, args: &[String]) -> String {
    let (ok, text) = tool_output(tool, args);
    assert!(ok, "{tool} {}:\n{text}", args.join(" "));
    text
}

fn configs() -> Vec<(Config, &'static str, BfpiArch, Pipeline)> {
    let seed = Pipeline::NONE;
    let mut v = Vec::new();
    for p in [1, 2, 4, 8, 16, 64, 256] {
        for align in Align::ALL {
            v.push((Config { p, align, ..Config::default() }, "", BfpiArch::ShiftAdd, seed));
        }
    }
    v.push((Config::new(16, 4, 4, Align::Screen).unwrap(), "edge_", BfpiArch::ShiftAdd, seed));
    v.push((Config::new(2, 20, 16, Align::Screen).unwrap(), "", BfpiArch::ShiftAdd, seed));
    v.push((Config::new(128, 7, 9, Align::Span).unwrap(), "x_", BfpiArch::ShiftAdd, seed));
    for arch in [BfpiArch::Naive, BfpiArch::Tree] {
        // Comparison forms (scripts/synth's, not the default): the smallest P with increments,
        // a middle one and the widest; scripts/lint-all lints every P.
        for (p, align) in [(2, Align::Screen), (8, Align::Span), (256, Align::Span)] {
            v.push((Config { p, align, ..Config::default() }, "", arch, seed));
        }
        v.push((Config::new(16, 4, 4, Align::Screen).unwrap(), "edge_", arch, seed));
    }
    // `--pipeline`: every level at P = 8, the deepest at the corners (P = 1 has no BFPI; P = 2^XW
    // and the narrowest formats) and with the naive increments.
    let deepest = Pipeline::new(Pipeline::MAX).unwrap();
    for pipe in Pipeline::all().skip(1) {
        v.push((Config { p: 8, align: Align::Screen, ..Config::default() }, "", BfpiArch::ShiftAdd, pipe));
    }
    for (p, align) in [(1, Align::Span), (64, Align::Span), (256, Align::Screen)] {
        v.push((Config { p, align, ..Config::default() }, "", BfpiArch::ShiftAdd, deepest));
    }
    v.push((Config::new(16, 4, 4, Align::Screen).unwrap(), "edge_", BfpiArch::ShiftAdd, deepest));
    v.push((Config { p: 8, align: Align::Span, ..Config::default() }, "", BfpiArch::Naive, deepest));
    v
}

/// `verilator --version` and `iverilog -V`'s first line: part of every cache key.
fn tools() -> &'static str {
    static TOOLS: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    TOOLS.get_or_init(|| {
        let version = |tool: &str, arg: &str| {
            Command::new(tool).arg(arg).output().map(|o| String::from_utf8_lossy(&o.stdout).into_owned()).unwrap_or_default()
        };
        format!("{}{}", version("verilator", "--version"), version("iverilog", "-V").lines().next().unwrap_or(""))
    })
}

/// What decides a configuration's lint result: its generated files, what is linted of them,
/// the tools' versions and this test's own source. A hash, so the cache is only a cache: a
/// change of any of these is a miss.
fn cache_key(files: &[hdl_gen::GeneratedFile], what: &str, fe_first: bool, chain: bool) -> String {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    (include_str!("lint.rs"), tools(), what, fe_first, chain).hash(&mut h);
    for f in files {
        (&f.name, &f.contents).hash(&mut h);
    }
    format!("{:016x}", h.finish())
}

/// A Verilog file of a configuration: its path and its text.
type Source = (String, String);

/// The files the lint of `top` reads: `top`'s own (one module per file, SPEC §3, so a file's stem
/// is its module) and, transitively, those of the modules it names (a name in a comment only adds
/// a file). The rest of the configuration's files are not in `top`'s hierarchy.
fn reads<'a>(sources: &'a [Source], top: &str) -> Vec<&'a Source> {
    let stem = |s: &Source| Path::new(&s.0).file_stem().and_then(|f| f.to_str()).unwrap_or_default().to_string();
    let mut out: Vec<&Source> = sources.iter().filter(|s| stem(s) == top).collect();
    assert_eq!(out.len(), 1, "one file holds {top}");
    let mut n = 0;
    while n < out.len() {
        let names: std::collections::HashSet<&str> = out[n].1.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_')).collect();
        for s in sources {
            if names.contains(stem(s).as_str()) && !out.iter().any(|o| o.0 == s.0) {
                out.push(s);
            }
        }
        n += 1;
    }
    out
}

/// Lints the hierarchy under `top` from the files it reads, unless the same top over the same
/// texts was linted clean before (with the same tools and this test). Across configurations most
/// files differ, but not all: the specular unit and its ROMs are the same at every P, the BFPI
/// in both alignments, so the sweep lints each of those once, not once per configuration.
fn lint_top(sources: &[Source], top: &str) {
    use std::hash::{Hash, Hasher};
    let read = reads(sources, top);
    let mut texts: Vec<(&str, &str)> =
        read.iter().map(|s| (Path::new(&s.0).file_name().and_then(|f| f.to_str()).unwrap_or_default(), s.1.as_str())).collect();
    texts.sort();
    let mut h = std::collections::hash_map::DefaultHasher::new();
    (include_str!("lint.rs"), tools(), top, &texts).hash(&mut h);
    let marker = Path::new(env!("CARGO_TARGET_TMPDIR")).join("lint-cache").join(format!("top-{:016x}", h.finish()));
    if marker.exists() {
        return;
    }
    lint(&read.iter().map(|s| s.0.clone()).collect::<Vec<_>>(), top);
    std::fs::create_dir_all(marker.parent().unwrap()).unwrap();
    std::fs::write(&marker, top).unwrap();
}

/// Verilator's lint of the hierarchy under `top`: whether it is clean, and what it printed.
fn lint_text(sources: &[String], top: &str) -> (bool, String) {
    let mut args = vec!["--lint-only".to_string(), "-Wall".into(), "--top-module".into(), top.into()];
    args.extend(sources.iter().cloned());
    let (ok, text) = tool_output("verilator", &args);
    (ok && !text.contains("%Warning"), text)
}

fn lint(sources: &[String], top: &str) {
    let (clean, text) = lint_text(sources, top);
    assert!(clean, "{top}: {text}");
}

/// The negative control of the sweep's shortcut: a clocked module is linted only inside its
/// synthesis wrapper, so a warning planted inside it (a signal nothing drives or reads, -Wall's UNUSEDSIGNAL; not named `*unused*`, which Verilator exempts) must
/// fail the wrapper's lint.
#[test]
fn a_warning_inside_a_wrapped_module_fails_its_wrapper_lint() {
    let opts = Options::default();
    let dir = std::env::temp_dir().join(format!("hdl-gen-lint-control-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let mut files = generate(&opts);
    let module = hdl_gen::Names::new("", &opts.cfg).segment;
    let file = files.iter_mut().find(|f| f.name == format!("{module}.v")).unwrap();
    let end = file.contents.rfind("endmodule").unwrap();
    file.contents.insert_str(end, "wire lint_control_probe;\n");
    output::write_all(&dir, &files).unwrap();
    let mut sources: Vec<Source> =
        files.iter().filter(|f| f.name.ends_with(".v")).map(|f| (dir.join(&f.name).display().to_string(), f.contents.clone())).collect();
    let manifest = &files.iter().find(|f| f.name == "manifest.json").unwrap().contents;
    let w = wrapper::module(&module, &wrapper::ports_from_manifest(manifest, &module).unwrap(), wrapper::Outputs::Registered).unwrap();
    let wfile = dir.join(format!("{}.v", w.name));
    std::fs::write(&wfile, w.render()).unwrap();
    sources.push((wfile.display().to_string(), w.render()));
    // The files the sweep's lint of this wrapper reads (`reads`): the planted module among them.
    let read: Vec<String> = reads(&sources, &w.name).iter().map(|s| s.0.clone()).collect();
    assert!(read.iter().any(|f| f.ends_with(&format!("/{module}.v"))), "{read:?}");
    let (clean, text) = lint_text(&read, &w.name);
    let _ = std::fs::remove_dir_all(&dir);
    assert!(!clean && text.contains("lint_control_probe"), "the planted unused signal passed {}'s lint:\n{text}", w.name);
}

fn module_names(manifest: &str) -> Vec<String> {
    hdl_gen::manifest::Manifest::parse(manifest).unwrap().modules.into_iter().map(|e| e.name).collect()
}

/// The sweep is cut into [`PARTS`] tests, part `i` taking every `PARTS`-th run from the `i`-th:
/// as one test it was the workspace's longest (about a minute on 2 cores) and the critical path
/// of a sharded regression (docs/regressions.md). Each part runs one tool at a time; the test
/// runner runs parts side by side.
const PARTS: usize = 8;

/// One configuration linted: formats, prefix, increment form, divider rate, the front-end's dI
/// and I0 forms, pipeline level, bus.
type Run = (Config, &'static str, BfpiArch, Option<u32>, (DiMode, I0Form), Pipeline, Bus);

fn lint_part(part: usize) {
    // The front-end depends on F, XW, the screen, the prefix and the divider rate, not on P, the
    // alignment or the increment form: it is linted once per front-end configuration, and the
    // chain there and at the extreme P values (scripts/lint-all lints every configuration).
    let mut fe_seen = std::collections::HashSet::new();
    let mut runs = configs()
        .into_iter()
        .map(|(cfg, prefix, arch, pipe)| (cfg, prefix, arch, None, (DiMode::Triangle, I0Form::Reciprocal), pipe, Bus::Native))
        .collect::<Vec<_>>();
    for bits in hdl_gen::frontend::DIV_BITS {
        runs.push((
            Config::default(),
            "",
            BfpiArch::ShiftAdd,
            Some(bits),
            (DiMode::Triangle, I0Form::Reciprocal),
            Pipeline::NONE,
            Bus::Native,
        ));
    }
    // The per-scanline dI (`--fe-di scanline`) at the slowest and the fastest divider.
    for bits in [1, 4] {
        runs.push((
            Config::default(),
            "",
            BfpiArch::ShiftAdd,
            Some(bits),
            (DiMode::Scanline, I0Form::Reciprocal),
            Pipeline::NONE,
            Bus::Native,
        ));
    }
    // The incremental I0 (`--fe-i0 incremental`) at level 0 and staged, and at the slowest divider.
    for (bits, pipe) in [(None, Pipeline::NONE), (None, Pipeline::new(1).unwrap()), (Some(1), Pipeline::NONE)] {
        runs.push((Config::default(), "", BfpiArch::ShiftAdd, bits, (DiMode::Triangle, I0Form::Incremental), pipe, Bus::Native));
    }
    // `--bus axis`: only the wrappers are linted as tops (their cores are the native modules of
    // the same options, linted above), at the default P and at P = 1 with a prefix and the
    // deepest pipeline.
    runs.push((Config::default(), "", BfpiArch::ShiftAdd, None, (DiMode::Triangle, I0Form::Reciprocal), Pipeline::NONE, Bus::Axis));
    let deepest = Pipeline::new(Pipeline::MAX).unwrap();
    runs.push((
        Config { p: 1, align: Align::Screen, ..Config::default() },
        "acme_",
        BfpiArch::ShiftAdd,
        None,
        (DiMode::Triangle, I0Form::Reciprocal),
        deepest,
        Bus::Axis,
    ));
    // Which run lints each front-end is decided over the whole sweep, then each part takes its own.
    // The incremental I0's staged front-end is its own (its engine beside the stages).
    let fe_key = |r: &Run| (r.0.frac, r.0.xbits, r.1, r.3, r.4, if r.4 .1 == I0Form::Incremental { r.5 } else { Pipeline::NONE });
    let firsts: Vec<bool> = runs.iter().map(|r| r.6 == Bus::Native && fe_seen.insert(fe_key(r))).collect();
    for (k, ((cfg, prefix, arch, fe_div_bits, fe_di, pipe, bus), fe_first)) in runs.into_iter().zip(firsts).enumerate() {
        if k % PARTS == part {
            lint_one(k, cfg, prefix, arch, (fe_div_bits, fe_di), (pipe, bus), fe_first);
        }
    }
}

/// `verilator_lint_and_icarus_are_clean::part_<i>`, one test per part.
macro_rules! parts {
    ($($name:ident = $i:expr),*) => {
        mod verilator_lint_and_icarus_are_clean {
            const _: () = assert!(super::PARTS == [$($i),*].len(), "one test per part");
            $(
                #[test]
                fn $name() {
                    super::lint_part($i)
                }
            )*
        }
    };
}
parts!(part_0 = 0, part_1 = 1, part_2 = 2, part_3 = 3, part_4 = 4, part_5 = 5, part_6 = 6, part_7 = 7);

fn lint_one(
    k: usize,
    cfg: Config,
    prefix: &str,
    arch: BfpiArch,
    (fe_div_bits, (fe_di, fe_i0)): (Option<u32>, (DiMode, I0Form)),
    (pipeline, bus): (Pipeline, Bus),
    fe_first: bool,
) {
    {
        let what = format!(
            "{cfg:?}, prefix '{prefix}', --bfpi-arch {arch}, --fe-div-bits {fe_div_bits:?}, --fe-di {fe_di:?}, --fe-i0 {fe_i0:?}, --pipeline {pipeline}, --bus {bus}"
        );
        let dir = std::env::temp_dir().join(format!("hdl-gen-lint-{}-{k}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let opts = Options { cfg, prefix: prefix.into(), bfpi_arch: arch, fe_div_bits, fe_di, fe_i0, pipeline, bus, ..Default::default() };
        let names = hdl_gen::Names::new(prefix, &cfg);
        let chain = fe_first || (arch == BfpiArch::ShiftAdd && [1, 256].contains(&cfg.p));
        let axis = bus == Bus::Axis;
        let skip = |module: &str| {
            if axis {
                return !module.ends_with("_axis");
            }
            // The front-end's parts are linted with it (under its wrapper) and as tops of their own.
            // The chain with the writer (fb_top) holds the chain without it (top), which is linted
            // as a top of its own once per front-end, so the widest P pays for one chain lint.
            let fe_part = module == names.frontend || module == names.fe_div || module == names.fe_edge;
            ((fe_part || module == names.top) && !fe_first) || (module == names.fb_top && !chain)
        };
        let files = generate(&opts);
        // A configuration linted clean before, byte for byte with the same tools and this test, is
        // not linted again: warm runs of ./scripts/test skip the sweep (scripts/lint-all does not).
        let key = cache_key(&files, &what, fe_first, chain);
        let marker = Path::new(env!("CARGO_TARGET_TMPDIR")).join("lint-cache").join(&key);
        if marker.exists() {
            return;
        }
        output::write_all(&dir, &files).unwrap();
        let path = |name: &str| dir.join(name).display().to_string();
        let sources: Vec<String> = files.iter().filter(|f| f.name.ends_with(".v")).map(|f| path(&f.name)).collect();
        assert!(sources.len() >= 2, "{what}: {sources:?}");
        let texts: Vec<Source> = files.iter().filter(|f| f.name.ends_with(".v")).map(|f| (path(&f.name), f.contents.clone())).collect();
        let manifest = &files.iter().find(|f| f.name == "manifest.json").unwrap().contents;
        // The clocked modules the manifest lists are linted below inside their synthesis wrappers,
        // which lint them whole (Verilator lints the hierarchy under the top): linting them as tops
        // too only doubled the sweep's time.
        let mut wrapped = Vec::new();
        for module in module_names(manifest) {
            assert!(Path::new(&path(&format!("{module}.v"))).exists(), "{what}: manifest lists {module} but no {module}.v");
            let ports = wrapper::ports_from_manifest(manifest, &module).unwrap();
            if ports.iter().any(|p| p.name == "clk") && !skip(&module) {
                wrapped.push((module, ports));
            }
        }
        // One module per file (SPEC §3), so the file stem is the module to lint as top.
        for f in files.iter().filter(|f| f.name.ends_with(".v")) {
            let module = f.name.trim_end_matches(".v");
            if !skip(module) && !wrapped.iter().any(|(m, _)| m == module) {
                lint_top(&texts, module);
            }
        }
        let mut with_wrappers = sources.clone();
        // The harness without output registers is what scripts/synth --harness folded uses for
        // the deepest level's widest blocks; it is linted there, the registered one elsewhere.
        let outputs =
            if pipeline == Pipeline::new(Pipeline::MAX).unwrap() { wrapper::Outputs::Folded } else { wrapper::Outputs::Registered };
        for (module, ports) in wrapped {
            let w = wrapper::module(&module, &ports, outputs).unwrap();
            let file = path(&format!("{}.v", w.name));
            let text = w.render();
            std::fs::write(&file, &text).unwrap();
            let mut srcs = texts.clone();
            srcs.push((file.clone(), text));
            lint_top(&srcs, &w.name);
            with_wrappers.push(file);
        }
        let mut ivl = vec!["-g2005".to_string(), "-Wall".into(), "-o".into(), path("a.out")];
        ivl.extend(with_wrappers);
        let text = run("iverilog", &ivl);
        assert!(text.trim().is_empty(), "{what}: iverilog says:\n{text}");
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(marker.parent().unwrap()).unwrap();
        std::fs::write(&marker, &what).unwrap();
    }
}

/// Screens narrower than 2^XW (the front-end's small test screens, e.g. 16 x 8 at XW = 12): the
/// writer's block number is wider than its memory address there. Generating panicked ("zext
/// narrows blk") before the address took only the bits a block number on that screen can have.
#[test]
fn writers_on_screens_narrower_than_the_x_port_generate_and_lint_clean() {
    for (width, height) in [(16, 8), (24, 8), (1, 1)] {
        for (p, align) in [(1, Align::Span), (8, Align::Span), (8, Align::Screen), (64, Align::Span)] {
            let cfg = Config { p, align, ..Config::default() };
            let screen = golden::setup::Screen { width, height };
            let opts = Options { cfg, screen: Some(screen), ..Default::default() };
            let dir = std::env::temp_dir().join(format!("hdl-gen-lint-narrow-{}-{width}x{height}-{p}-{align}", std::process::id()));
            let _ = std::fs::remove_dir_all(&dir);
            let files = generate(&opts);
            output::write_all(&dir, &files).unwrap();
            let sources: Vec<String> =
                files.iter().filter(|f| f.name.ends_with(".v")).map(|f| dir.join(&f.name).display().to_string()).collect();
            lint(&sources, &hdl_gen::Names::new("", &cfg).writer);
            let _ = std::fs::remove_dir_all(&dir);
        }
    }
}

/// The shared set-up engine's front-end (`--fe-setup`, issue 27) at 37x23: Verilator `-Wall`
/// and Icarus `-g2005` on `tri_frontend` with its parts, and Yosys's `proc` infers no latch.
/// The ECP5 plan in the default suite (about 4 s of CPU cold, the engine's file is some 1,400
/// lines; nothing warm, as the sweep's cache), the iCE40 plans in the slow tier.
#[test]
fn the_set_up_engine_lints_clean_and_holds_no_latch() {
    lint_engine(golden::frontend::engine::SetupForm::Ecp5_25f);
}

/// With their parallel span path, and with the sequential one (`--fe-span sequential`, the
/// targets' choice) at levels 0 and 1.
#[test]
#[ignore]
fn the_ice40_set_up_engines_lint_clean_and_hold_no_latch() {
    use golden::frontend::{engine::SetupForm::*, SpanForm};
    let (par, seq) = (SpanForm::Parallel, SpanForm::Sequential);
    for (form, span, level) in [(Ice40Up5k, par, 0), (Ice40Hx8k, par, 0), (Ice40Hx8k, seq, 0), (Ice40Up5k, seq, 1)] {
        lint_engine_at(form, span, level);
    }
}

/// The ECP5 plan at `--target ecp5-25f`'s level 1: its tiles are `tri_fe_mul18` instances,
/// whose model Verilator and Icarus read (Yosys reads the primitive: `SYNTHESIS`, no latch
/// around it). Slow tier, a few seconds.
#[test]
#[ignore]
fn the_ecp5_target_form_lints_clean_and_holds_no_latch() {
    lint_engine_at(golden::frontend::engine::SetupForm::Ecp5_25f, golden::frontend::SpanForm::Parallel, 1);
}

fn lint_engine(form: golden::frontend::engine::SetupForm) {
    lint_engine_at(form, golden::frontend::SpanForm::Parallel, 0);
}

fn lint_engine_at(form: golden::frontend::engine::SetupForm, span: golden::frontend::SpanForm, level: u32) {
    {
        let screen = Some(golden::setup::Screen { width: 37, height: 23 });
        let opts = Options { fe_setup: form, fe_span: span, pipeline: golden::pipeline::Pipeline::at(level), screen, ..Default::default() };
        let tag = format!("{}-{}-{level}", form.name(), span.name());
        let dir = std::env::temp_dir().join(format!("hdl-gen-lint-engine-{}-{tag}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let files = generate(&opts);
        // Linted clean before, byte for byte with the same tools and this test: not again (as the
        // sweep's configurations; a cold run pays the few seconds).
        let what = format!("set-up engine {tag}");
        let marker = Path::new(env!("CARGO_TARGET_TMPDIR")).join("lint-cache").join(cache_key(&files, &what, true, false));
        if marker.exists() {
            return;
        }
        output::write_all(&dir, &files).unwrap();
        let names = hdl_gen::Names::new("", &opts.cfg);
        // The tiles with their own registers (`tri_fe_mul18`) on the ECP5 plan from level 1.
        let mul = files.iter().any(|f| f.name == format!("{}.v", names.fe_mul));
        let parts = [&names.frontend, &names.fe_edge, &names.fe_engine, &names.fe_queue, &names.fe_mul];
        let parts = &parts[..if mul { 5 } else { 4 }];
        let sources: Vec<String> = parts.iter().map(|m| dir.join(format!("{m}.v")).display().to_string()).collect();
        assert!(!files.iter().any(|f| f.name == format!("{}.v", names.fe_div)), "{form:?}: the engine form has no divider module");
        lint(&sources, &names.frontend);
        let mut args = vec!["-g2005".to_string(), "-o".into(), dir.join("a.out").display().to_string()];
        args.extend(sources.iter().cloned());
        run("iverilog", &args);
        let script = format!(
            "read_verilog {}; hierarchy -top {}; proc; select -assert-none t:$dlatch t:$adlatch t:$sr",
            sources.join(" "),
            names.frontend
        );
        run("yosys", &["-q".to_string(), "-p".into(), script.clone()]);
        // Negative control: a latch planted in the engine is found.
        let engine = dir.join(format!("{}.v", names.fe_engine));
        let text = std::fs::read_to_string(&engine).unwrap();
        std::fs::write(&engine, text.replacen("endmodule", "reg probe;\n  always @(*) if (en) probe = rst;\nendmodule", 1)).unwrap();
        let (ok, _) = tool_output("yosys", &["-q".to_string(), "-p".into(), script]);
        assert!(!ok, "{form:?}: a latch planted in the engine went unnoticed");
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(marker.parent().unwrap()).unwrap();
        std::fs::write(&marker, &what).unwrap();
    }
}
