//! The harness's command-line tools with bad input: every flag with a missing, out-of-range or
//! wrongly typed value gets one clear message naming the flag, exit status 2, and no output.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use verilator_harness::registry::{default_model_args, require, require_segment_model, SEGMENT_MODELS};

fn run(bin: &str, args: &[&str]) -> Output {
    Command::new(bin).args(args).output().unwrap_or_else(|e| panic!("running {bin}: {e}"))
}

/// Exit status 2, one `error` message that contains `needle`, nothing on standard output.
fn assert_rejected(bin: &str, args: &[&str], needle: &str) {
    let out = run(bin, args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: exit status; stderr: {err}");
    assert!(err.contains(needle), "{args:?}: the message should name '{needle}': {err}");
    assert_eq!(err.lines().filter(|l| l.starts_with("error")).count(), 1, "{args:?}: one message: {err}");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    assert!(out.stdout.is_empty(), "{args:?}: wrote to stdout: {}", String::from_utf8_lossy(&out.stdout));
}

/// `args` after `model` (from [`default_model_args`]) unless the case sets --p or --align itself.
fn with_model<'a>(model: &'a [String], args: &[&'a str]) -> Vec<&'a str> {
    let own = args.iter().any(|a| *a == "--p" || *a == "--align");
    model.iter().map(String::as_str).filter(|_| !own).chain(args.iter().copied()).collect()
}

const COSIM: &str = env!("CARGO_BIN_EXE_cosim");
const RENDER: &str = env!("CARGO_BIN_EXE_render");
const SWEEP: &str = env!("CARGO_BIN_EXE_sweep");
const BENCH: &str = env!("CARGO_BIN_EXE_bench");

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cli-harness-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Every entry of `dir` with its kind, size and (for files under 1 MiB) bytes: equal snapshots
/// mean nothing was written, removed, replaced or changed.
fn snapshot(dir: &Path) -> Vec<(String, String, u64, Vec<u8>)> {
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            let meta = std::fs::symlink_metadata(e.path()).unwrap();
            let bytes = if meta.is_file() && meta.len() < 1 << 20 { std::fs::read(e.path()).unwrap() } else { Vec::new() };
            (e.file_name().to_string_lossy().into_owned(), format!("{:?}", meta.file_type()), meta.len(), bytes)
        })
        .collect();
    v.sort();
    v
}

fn listing(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    v.sort();
    v
}

#[test]
fn cosim_rejects_every_bad_flag() {
    let cases: &[(&[&str], &str)] = &[
        (&["--p"], "--p"),
        (&["--p", "eight"], "--p"),
        (&["--p", "-8"], "--p"),
        (&["--p", "3"], "--p"),
        (&["--p", "512"], "--p"),
        (&["--align"], "--align"),
        (&["--align", "diagonal"], "--align"),
        (&["--triangles"], "--triangles"),
        (&["--triangles", "-1"], "--triangles"),
        (&["--triangles", "many"], "--triangles"),
        (&["--triangles", "1e6"], "--triangles"),
        (&["--seed", "x"], "--seed"),
        (&["--seed", "-1"], "--seed"),
        (&["--seed", "18446744073709551616"], "--seed"),
        (&["--width", "0"], "--width"),
        (&["--width", "65537"], "--width"),
        (&["--width", "wide"], "--width"),
        (&["--height", "0"], "--height"),
        (&["--height", "-480"], "--height"),
        // Random vertices lie anywhere on the screen, and the set-up stops at COORD_LIMIT: a
        // taller screen was reported as an RTL MISMATCH.
        (&["--height", "65536"], "--height"),
        (&["--height", "32769"], "--height"),
        (&["--width", "40000"], "--width"),
        (&["--width", "5000"], "--width"),
        (&["--traffic", "bursty"], "--traffic"),
        (&["--traffic"], "--traffic"),
        (&["--batch", "0"], "--batch"),
        (&["--batch", "many"], "--batch"),
        (&["--pixels", "100"], "--specular"),
        (&["--specular", "--pixels", "lots"], "--pixels"),
        (&["--specular", "--pixels", "-5"], "--pixels"),
        (&["--specular", "--specular"], "--specular"),
        (&["--frobnicate"], "--frobnicate"),
        (&["extra"], "extra"),
        // generate's options (hdl_gen::cli), each refused as generate refuses it.
        (&["--frac", "3"], "--frac"),
        (&["--frac", "21"], "--frac"),
        (&["--xbits", "17"], "--xbits"),
        (&["--pipeline", "4"], "--pipeline"),
        (&["--pipeline", "-1"], "--pipeline"),
        (&["--bus", "pci"], "--bus"),
        (&["--fe-div-bits", "3"], "--fe-div-bits"),
        (&["--fe-di", "vertex"], "--fe-di"),
        (&["--bfpi-arch", "abacus"], "--bfpi-arch"),
        (&["--bfpi-arch", "tree", "--pipeline", "1"], "--pipeline above 0"),
        (&["--brdf-k", "0"], "--brdf-k"),
        (&["--max-rel-error", "1%"], "--brdf-k"),
        (&["--brdf-k", "1,2", "--max-rel-error", "1%"], "--max-rel-error goes with --brdf-k auto"),
        (&["--prefix", "9lives"], "--prefix"),
        // The front-end's screen is cosim's: 640 pixels is wider than 4 fraction bits shade. A
        // COSIM_RTL_DIR folder refuses the flag first: it was not generated with F = 4.
        (
            &["--frontend", "rtl", "--frac", "4"],
            if verilator_harness::registry::rtl_dir().is_some() { "--frac" } else { "--width/--height" },
        ),
    ];
    let Some(model) = default_model_args("cli_harness: cosim's bad flags") else { return };
    for (args, needle) in cases {
        assert_rejected(COSIM, &with_model(&model, args), needle);
    }
}

/// The good path still works, so the rejections above are not a broken binary.
#[test]
fn cosim_runs_a_few_triangles() {
    let Some(model) = default_model_args("cli_harness: cosim on a few triangles") else { return };
    let out = run(COSIM, &with_model(&model, &["--triangles", "5", "--seed", "1"]));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}{}", String::from_utf8_lossy(&out.stderr));
    assert!(text.trim_end().ends_with("5 passed, 0 failed"), "{text}");
}

/// The negative control of the rows above: generate's options, valid, reach the model. Each
/// configuration here is in the compiled catalogue (nothing is built), and its model's tag is
/// printed: a flag parsed and then dropped would run the default model instead.
#[test]
fn cosim_and_render_run_the_model_generate_options_name() {
    if verilator_harness::registry::rtl_dir().is_some() {
        eprintln!("cli_harness: generate's options: skipped under COSIM_RTL_DIR (the folder's models are the run's)");
        return;
    }
    let cases: &[(&[&str], &str)] = &[
        (&["--pipeline", "1", "--triangles", "5"], "model seg_p8_span_pl1 (segment_shader_p8)"),
        (&["--align", "screen", "--pipeline", "2", "--triangles", "5"], "model seg_p8_screen_pl2 (segment_shader_p8)"),
        (&["--bus", "axis", "--triangles", "5"], "model seg_p8_span_axis (segment_shader_p8_axis)"),
        (&["--specular", "--pipeline", "1", "--pixels", "2000"], "model spec_pl1 (specular_unit)"),
        (&["--specular", "--bus", "axis", "--pixels", "2000"], "model spec_axis (specular_unit_axis)"),
    ];
    for (args, model) in cases {
        let out = run(COSIM, &[&["--seed", "1"], *args].concat());
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success(), "{args:?}: {text}{}", String::from_utf8_lossy(&out.stderr));
        assert!(text.starts_with(&format!("{model},")) && text.trim_end().ends_with(" 0 failed"), "{args:?}: {text}");
    }
    let dir = scratch("render-options");
    let (tri, png) = (dir.join("t.txt"), dir.join("t.png"));
    std::fs::write(
        &tri,
        "0 0 0 60 0 128 0 40 255
",
    )
    .unwrap();
    let args = ["--triangles", tri.to_str().unwrap(), "--out", png.to_str().unwrap(), "--width", "64", "--height", "48", "--quiet"];
    let out = run(RENDER, &[&args[..], &["--pipeline", "2", "--align", "screen"]].concat());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success() && text.contains("seg_p8_screen_pl2"), "{text}{}", String::from_utf8_lossy(&out.stderr));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `render`: every flag, and triangle files that are missing, not files, not text, malformed
/// (the message names the line) or hold NaN, infinity or coordinates beyond the set-up's
/// limits. Nothing is written in any case.
#[test]
fn render_rejects_every_bad_flag_and_input_file() {
    let dir = scratch("render");
    let good = dir.join("good.txt");
    std::fs::write(&good, "# one triangle\n0 0 0 10 0 128 0 10 255\n").unwrap();
    let bad_file = |name: &str, body: &[u8]| {
        let p = dir.join(name);
        std::fs::write(&p, body).unwrap();
        p.to_str().unwrap().to_string()
    };
    let short = bad_file("short.txt", b"0 0 0 10 0 128 0 10 255\n\n0 0 0 1 2\n");
    let nan = bad_file("nan.txt", b"# c\n0 0 0 10 0 128 0 10 255\n0 0 0 nan 0 128 0 10 255\n");
    let inf = bad_file("inf.txt", b"0 0 0 10 0 128 0 10 inf\n");
    let far = bad_file("far.txt", b"0 0 0 10 0 128 0 10 255\n0 0 0 10 0 128 0 10 255\n0 0 0 1e6 0 128 0 10 255\n");
    let bright = bad_file("bright.txt", b"0 0 0 10 0 300 0 10 255\n");
    let word = bad_file("word.txt", b"0 0 zero 10 0 128 0 10 255\n");
    let binary = bad_file("binary.txt", &[0xff, 0xfe, 0x00, 0x41]);
    let no_faces = bad_file("points.obj", b"v 0 0 0\nv 1 0 0\n");
    let flat = bad_file("point.obj", b"v 1 1 1\nv 1 1 1\nv 1 1 1\nf 1 2 3\n");
    let short_face = bad_file("line.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2\n");
    let mut long = b"0 0 0 10 0 128 0 10 255\n#".to_vec();
    long.extend(std::iter::repeat_n(b'x', 5000));
    let long = bad_file("long.txt", &long);
    // 1 GB, sparse: the reader must stop at its limit, not read (or allocate) all of it.
    let huge = dir.join("huge.txt");
    std::fs::File::create(&huge).unwrap().set_len(1 << 30).unwrap();
    let huge = huge.to_str().unwrap().to_string();
    // The input by another name: a link to it.
    let alias = dir.join("alias.png");
    std::os::unix::fs::symlink(&good, &alias).unwrap();
    let golden_named = bad_file("in.golden.png", b"0 0 0 10 0 128 0 10 255\n");
    let golden_out = golden_named.replace(".golden.png", ".png");
    let missing = dir.join("missing.txt");
    let (g, d) = (good.to_str().unwrap(), dir.to_str().unwrap());
    let out = dir.join("out.png");
    let o = out.to_str().unwrap();
    let no_folder = dir.join("no/such/out.png");
    let cases: Vec<(Vec<&str>, String)> = vec![
        (vec!["--out", o], "--scene".into()),
        (vec!["--scene", "sphere"], "--out".into()),
        (vec!["--scene", "cube", "--out", o], "--scene".into()),
        (vec!["--scene", "sphere", "--triangles", g, "--out", o], "--triangles".into()),
        (vec!["--triangles", g, "--out", o, "--p", "3"], "--p".into()),
        (vec!["--triangles", g, "--out", o, "--frac", "30"], "--frac".into()),
        (vec!["--triangles", g, "--out", o, "--pipeline", "9"], "--pipeline".into()),
        (vec!["--triangles", g, "--out", o, "--bus", "wishbone"], "--bus".into()),
        (vec!["--triangles", g, "--out", o, "--fe-div-bits", "8"], "--fe-div-bits".into()),
        (vec!["--triangles", g, "--out", o, "--brdf-k", "64,1"], "--brdf-k".into()),
        (vec!["--triangles", g, "--out", o, "--bfpi-arch", "tree", "--pipeline", "2"], "--pipeline above 0".into()),
        (vec!["--triangles", g, "--out", o, "--p", "x"], "--p".into()),
        (vec!["--triangles", g, "--out", o, "--align", "middle"], "--align".into()),
        (vec!["--triangles", g, "--out", o, "--width", "0"], "--width".into()),
        (vec!["--triangles", g, "--out", o, "--width", "9000"], "--width".into()),
        (vec!["--triangles", g, "--out", o, "--height", "70000"], "--height".into()),
        (vec!["--scene", "torus", "--out", o, "--shininess", "0"], "--shininess".into()),
        (vec!["--scene", "torus", "--out", o, "--shininess", "1001"], "--shininess".into()),
        (vec!["--triangles", g, "--out", o, "--shininess", "5"], "--shininess".into()),
        (vec!["--triangles", g, "--out", no_folder.to_str().unwrap()], "--out".into()),
        (vec!["--triangles", g, "--out", d], "--out".into()),
        (vec!["--triangles", missing.to_str().unwrap(), "--out", o], missing.display().to_string()),
        (vec!["--triangles", d, "--out", o], d.to_string()),
        (vec!["--triangles", &binary, "--out", o], "UTF-8".into()),
        (vec!["--triangles", &short, "--out", o], "line 3".into()),
        (vec!["--triangles", &nan, "--out", o], "line 3".into()),
        (vec!["--triangles", &inf, "--out", o], "line 1".into()),
        (vec!["--triangles", &far, "--out", o], "line 3".into()),
        (vec!["--triangles", &bright, "--out", o], "line 1".into()),
        (vec!["--triangles", &word, "--out", o], "line 1".into()),
        (vec!["--triangles", g, "--out", o, "--bogus"], "--bogus".into()),
        (vec!["--obj", &no_faces, "--out", o], "no faces".into()),
        (vec!["--obj", &flat, "--out", o], "no extent".into()),
        (vec!["--obj", &no_faces, "--triangles", g, "--out", o], "--obj".into()),
        (vec!["--triangles", g, "--out", o, "--writer", "disk"], "--writer".into()),
        // The output is the input: by its name, through a link, or as the golden image's name.
        (vec!["--triangles", g, "--out", g], "is the input file".into()),
        (vec!["--triangles", g, "--out", alias.to_str().unwrap()], "is the input file".into()),
        (vec!["--triangles", &golden_named, "--out", &golden_out], "is the input file".into()),
        (vec!["--obj", &short_face, "--out", &short_face], "is the input file".into()),
        // Images taller than the set-up's coordinates reach: refused at once, for every input.
        (vec!["--scene", "sphere", "--out", o, "--height", "65536"], "--height".into()),
        (vec!["--obj", &no_faces, "--out", o, "--height", "65536"], "--height".into()),
        (vec!["--triangles", g, "--out", o, "--width", "32769"], "--width".into()),
        (vec!["--obj", &short_face, "--out", o], "line 5: a face needs at least 3 vertices, this one has 2".into()),
        (vec!["--triangles", &long, "--out", o], "line 2 is longer than 4096 bytes".into()),
        (vec!["--triangles", &huge, "--out", o], "larger than 64 MiB".into()),
    ];
    let Some(model) = default_model_args("cli_harness: render's bad flags and files") else { return };
    let before = snapshot(&dir);
    for (args, needle) in &cases {
        assert_rejected(RENDER, &with_model(&model, args), needle);
        assert!(snapshot(&dir) == before, "{args:?} wrote, removed or changed files");
    }
}

#[test]
fn sweep_rejects_every_bad_flag() {
    let dir = scratch("sweep");
    let missing = dir.join("no/such/table.md");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--triangles", "0"], "--triangles"),
        (vec!["--triangles", "1000001"], "--triangles"),
        (vec!["--triangles", "some"], "--triangles"),
        (vec!["--seed", "x"], "--seed"),
        (vec!["--width", "63"], "--width"),
        (vec!["--width", "4097"], "--width"),
        (vec!["--height", "63"], "--height"),
        (vec!["--height", "tall"], "--height"),
        (vec!["--height", "40000"], "--height"),
        (vec!["--height", "65536"], "--height"),
        (vec!["--out"], "--out"),
        (vec!["--bogus"], "--bogus"),
        // generate's options but P and the alignment (sweep runs every P in both).
        (vec!["--p", "8"], "--p"),
        (vec!["--align", "screen"], "--align"),
        (vec!["--frac", "3"], "--frac"),
        (vec!["--pipeline", "4"], "--pipeline"),
        (vec!["--fe-di", "sideways"], "--fe-di"),
        (vec!["--bfpi-arch", "tree", "--pipeline", "1"], "--pipeline above 0"),
        // A bad --out is refused before the sweep, not after its minutes.
        (vec!["--out", dir.to_str().unwrap()], "is a folder"),
        (vec!["--triangles", "1000000", "--out", missing.to_str().unwrap()], "no/such"),
    ];
    for (args, needle) in &cases {
        let t = std::time::Instant::now();
        assert_rejected(SWEEP, args, needle);
        assert!(t.elapsed().as_secs() < 10, "{args:?}: refused only after {:?}", t.elapsed());
    }
    // An unwritable --out is found after the sweep, which runs on level-0 shaders only: a
    // COSIM_RTL_DIR folder generated with --pipeline has none (sweep then says so instead).
    let level0 = SEGMENT_MODELS.iter().find(|m| m.pipeline == golden::pipeline::Pipeline::NONE);
    if require(level0, "level-0 segment shader", "cli_harness: sweep --out into a missing folder").is_some() {
        assert_rejected(SWEEP, &["--triangles", "1", "--out", missing.to_str().unwrap()], "no/such");
    }
    assert!(listing(&dir).is_empty());
}

/// Bytes free in `dir`'s file system (for the one case that depends on it).
fn free_bytes(dir: &Path) -> u64 {
    use std::os::unix::ffi::OsStrExt;
    let c = std::ffi::CString::new(dir.as_os_str().as_bytes()).unwrap();
    let mut st: libc::statvfs = unsafe { std::mem::zeroed() };
    // SAFETY: a NUL-terminated path and a statvfs we own.
    assert_eq!(unsafe { libc::statvfs(c.as_ptr(), &mut st) }, 0);
    st.f_bavail as u64 * st.f_frsize as u64
}

/// `bench`: stimulus files that are missing, empty, not files, garbage, truncated or with a
/// header that lies; `gen` into a folder that is not there or with a count beyond the header's
/// u32 or the disk. Each is one message and exit status 2, nothing written, no panic, and no
/// allocation sized by a garbage count (the 32 GB). A good file still runs (the control).
#[test]
fn bench_rejects_bad_files_and_flags() {
    let dir = scratch("bench");
    let file = |name: &str, body: &[u8]| {
        let p = dir.join(name);
        std::fs::write(&p, body).unwrap();
        p.to_str().unwrap().to_string()
    };
    let empty = file("empty.stim", b"");
    let garbage = file("garbage.stim", &[0x5a; 200]);
    let mut lying = b"SSBSTIM1".to_vec();
    lying.extend([0u8; 56]);
    lying[28..32].copy_from_slice(&u32::MAX.to_le_bytes());
    let lying = file("lying.stim", &lying);
    let missing = dir.join("missing.stim");
    let m = missing.to_str().unwrap();
    let no_folder = dir.join("no/such/prefix");
    let d = dir.to_str().unwrap();
    let folder_prefix = format!("{d}/");
    let prefix = dir.join("ok");
    let p = prefix.to_str().unwrap();
    let cases: Vec<(Vec<&str>, String)> = vec![
        (vec!["harness", m], m.to_string()),
        (vec!["harness", &empty], "shorter than the 64-byte header".into()),
        (vec!["harness", &garbage], "not a bench stimulus file".into()),
        (vec!["harness", &lying], "the header promises 4294967295 spans".into()),
        (vec!["harness", d], "not a file".into()),
        (vec!["harness"], "STIM".into()),
        (vec!["harness", &empty, "--limit", "-1"], "--limit".into()),
        (vec!["gen", "--design", "segment", "--spans", "0", "--out", p], "--spans".into()),
        (vec!["gen", "--design", "segment", "--spans", "4294967296", "--out", p], "--spans".into()),
        (vec!["gen", "--design", "segment", "--spans", "many", "--out", p], "--spans".into()),
        (vec!["gen", "--design", "segment", "--spans", "10"], "--out".into()),
        (vec!["gen", "--design", "cube", "--spans", "10", "--out", p], "--design".into()),
        (vec!["gen", "--design", "segment", "--spans", "10", "--out", no_folder.to_str().unwrap()], "no/such".into()),
        (vec!["gen", "--design", "specular", "--spans", "10", "--out", &folder_prefix], "a path prefix, not a folder".into()),
        (vec!["gen", "--design", "segment", "--spans", "10", "--traffic", "bursty", "--out", p], "--traffic".into()),
        (vec!["frobnicate"], "frobnicate".into()),
        // generate's options (hdl_gen::cli), each refused as generate refuses it.
        (vec!["gen", "--design", "segment", "--spans", "10", "--out", p, "--p", "3"], "--p".into()),
        (vec!["gen", "--design", "segment", "--spans", "10", "--out", p, "--align", "diagonal"], "--align".into()),
        (vec!["gen", "--design", "segment", "--spans", "10", "--out", p, "--frac", "3"], "--frac".into()),
        (vec!["gen", "--design", "segment", "--spans", "10", "--out", p, "--xbits", "17"], "--xbits".into()),
        (vec!["gen", "--design", "segment", "--spans", "10", "--out", p, "--pipeline", "4"], "--pipeline".into()),
        (vec!["gen", "--design", "segment", "--spans", "10", "--out", p, "--bus", "pci"], "--bus".into()),
        (vec!["gen", "--design", "segment", "--spans", "10", "--out", p, "--fe-div-bits", "3"], "--fe-div-bits".into()),
        (vec!["gen", "--design", "segment", "--spans", "10", "--out", p, "--fe-i0", "cubic"], "--fe-i0".into()),
        (
            vec!["gen", "--design", "segment", "--spans", "10", "--out", p, "--bfpi-arch", "tree", "--pipeline", "1"],
            "--pipeline above 0".into(),
        ),
        (vec!["gen", "--design", "specular", "--spans", "10", "--out", p, "--brdf-k", "0"], "--brdf-k".into()),
        (vec!["gen", "--design", "specular", "--spans", "10", "--out", p, "--max-rel-error", "1%"], "--brdf-k".into()),
        (vec!["gen", "--design", "specular", "--spans", "10", "--out", p, "--prefix", "9lives"], "--prefix".into()),
        // The random triangles' screen: within the coordinates and the x ports, and only for spans.
        (vec!["gen", "--design", "segment", "--spans", "10", "--out", p, "--width", "0"], "--width".into()),
        (vec!["gen", "--design", "segment", "--spans", "10", "--out", p, "--height", "32769"], "--height".into()),
        // (A COSIM_RTL_DIR folder refuses the flag first: it was not generated with XW = 6.)
        (
            vec!["gen", "--design", "segment", "--spans", "10", "--out", p, "--xbits", "6", "--width", "100"],
            if verilator_harness::registry::rtl_dir().is_some() { "--xbits" } else { "--width/--height" }.into(),
        ),
        (vec!["gen", "--design", "specular", "--spans", "10", "--out", p, "--width", "100"], "--width/--height".into()),
        (vec!["info", "--p", "3"], "--p".into()),
        (vec!["info", "--pipeline", "-1"], "--pipeline".into()),
        (vec!["info", "--bfpi-arch", "tree", "--pipeline", "1"], "--pipeline above 0".into()),
    ];
    let before = snapshot(&dir);
    for (args, needle) in &cases {
        assert_rejected(BENCH, args, needle);
        assert!(snapshot(&dir) == before, "{args:?} wrote, removed or changed files");
    }
    // The most the header holds, on a disk without the room: refused at once.
    if free_bytes(&dir) < 200_000_000_000 {
        let t = std::time::Instant::now();
        assert_rejected(BENCH, &["gen", "--design", "specular", "--spans", "4294967295", "--out", p], "GB free");
        assert!(t.elapsed().as_secs() < 10, "refused only after {:?}", t.elapsed());
    }
    assert!(snapshot(&dir) == before);

    // The control: a small file is written and streamed; then the same file cut short is refused.
    if require_segment_model(8, golden::Align::Span, "cli_harness: bench on a good file").is_none() {
        return;
    }
    let out = run(BENCH, &["gen", "--design", "segment", "--spans", "20", "--out", p]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stim = format!("{p}.stim");
    let out = run(BENCH, &["harness", &stim]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success() && text.contains("RESULT impl=harness") && text.contains("spans=20"), "{text}");
    let bytes = std::fs::read(&stim).unwrap();
    let cut = file("cut.stim", &bytes[..bytes.len() - 5]);
    assert_rejected(BENCH, &["harness", &cut], "the header promises 20 spans");
    // A span no port can carry in an otherwise good file.
    let at = u32::from_le_bytes(bytes[56..60].try_into().unwrap()) as usize;
    let mut bad = bytes.clone();
    bad[at + 4..at + 8].copy_from_slice(&u32::MAX.to_le_bytes());
    let bad = file("badspan.stim", &bad);
    assert_rejected(BENCH, &["harness", &bad], "span 0: span length 4294967295 exceeds");

    // The header's model description (format 2): a value generate refuses, a field it does not
    // know, a P the fixed fields contradict, a length that does not fit, an unknown format.
    // An edit of the same length, so the fixed fields stay true.
    let edited = |name: &str, from: &str, to: &str| {
        let text = String::from_utf8_lossy(&bytes[64..at]).into_owned();
        assert!(text.contains(from) && from.len() == to.len(), "{from} not in {text}");
        let mut b = bytes.clone();
        b[64..at].copy_from_slice(text.replacen(from, to, 1).as_bytes());
        file(name, &b)
    };
    let cases = [
        (edited("xb99.stim", "--xbits=12", "--xbits=99"), "--xbits"),
        (edited("field.stim", "\"screen\"", "\"screan\""), "unknown field `screan`"),
        (edited("p4.stim", "--p=8", "--p=4"), "the header's p is 8, its model's --p 4"),
    ];
    for (f, needle) in &cases {
        assert_rejected(BENCH, &["harness", f], needle);
    }
    let mut long = bytes.clone();
    long[60..64].copy_from_slice(&(1u32 << 20).to_le_bytes());
    assert_rejected(BENCH, &["harness", &file("long.stim", &long)], "a model description of 1048576 bytes");
    let mut v9 = bytes.clone();
    v9[7] = b'9';
    assert_rejected(BENCH, &["harness", &file("v9.stim", &v9)], "format 9, this bench reads formats 1 and 2");
    // Format 1 (no model description) still reads, as the default configuration at its P.
    let mut v1 = bytes[..56].to_vec();
    v1[7] = b'1';
    v1.extend([0u8; 8]);
    v1.extend(&bytes[at..]);
    let out = run(BENCH, &["harness", &file("v1.stim", &v1)]);
    let text = String::from_utf8_lossy(&out.stdout);
    // (Under COSIM_RTL_DIR the folder's p = 8 shader runs, whatever its other options.)
    let model = if verilator_harness::registry::rtl_dir().is_some() { "model=seg_p8_span" } else { "model=seg_p8_span " };
    assert!(out.status.success() && text.contains(model) && text.contains("spans=20"), "{text}");
}

/// The negative control of `bench`'s rows for generate's options: valid, they reach the model
/// (named by the file's header, which `harness` builds again). Each configuration is in the
/// compiled catalogue, so nothing is built; a flag parsed and then dropped would run another model.
#[test]
fn bench_runs_the_model_generate_options_name() {
    if verilator_harness::registry::rtl_dir().is_some() {
        eprintln!("cli_harness: bench with generate's options: skipped under COSIM_RTL_DIR (the folder's models are the run's)");
        return;
    }
    let dir = scratch("bench-options");
    let prefix = dir.join("s");
    let p = prefix.to_str().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["--design", "segment", "--pipeline", "1"], "seg_p8_span_pl1"),
        (&["--design", "segment", "--align", "screen", "--pipeline", "2"], "seg_p8_screen_pl2"),
        (&["--design", "segment", "--bus", "axis", "--width", "64", "--height", "48"], "seg_p8_span_axis"),
        (&["--design", "specular", "--pipeline", "1"], "spec_pl1"),
    ];
    // `info` names the Verilog of the configuration's models.
    let out = run(BENCH, &["info", "--pipeline", "1"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success() && text.contains("MODEL tag=seg_p8_span_pl1 ") && text.contains("MODEL tag=spec_pl1 "), "{text}");
    for (args, tag) in cases {
        let out = run(BENCH, &[&["gen", "--spans", "20", "--out", p], *args].concat());
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success() && text.contains(&format!("({tag})")), "{args:?}: {text}{}", String::from_utf8_lossy(&out.stderr));
        let out = run(BENCH, &["harness", &format!("{p}.stim")]);
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success() && text.contains(&format!("model={tag} ")) && text.contains("mismatches=0"), "{args:?}: {text}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
