//! The scripts that take arguments (scripts/prove, scripts/synth, scripts/check-rtl-dir) with
//! bad ones: one line on stderr naming the argument (and, where the generator decides, its
//! message), exit status 2, within seconds (before anything is installed, generated into the
//! output folder, built or proven), and the folder given unchanged. Each script runs with this
//! test's hdl-gen (`SEGSHADE_HDL_GEN`), so nothing is compiled.

mod common;
use common::{hdl_gen, scratch_dir};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

fn script(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scripts").join(name)
}

fn run(name: &str, args: &[&str]) -> (Output, Duration) {
    let t = Instant::now();
    let out = Command::new(script(name))
        .args(args)
        .env("SEGSHADE_HDL_GEN", env!("CARGO_BIN_EXE_hdl-gen"))
        .output()
        .unwrap_or_else(|e| panic!("running scripts/{name}: {e}"));
    (out, t.elapsed())
}

/// Every file under `dir` with its bytes.
fn snapshot(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut v = Vec::new();
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            v.push((p.clone(), Vec::new()));
            v.extend(snapshot(&p));
        } else {
            v.push((p.clone(), std::fs::read(&p).unwrap()));
        }
    }
    v.sort();
    v
}

/// Exit status 2, one stderr line that contains every needle, quick, `dir` unchanged.
fn assert_refused(name: &str, args: &[&str], needles: &[&str], dir: &Path) {
    let before = snapshot(dir);
    let (out, took) = run(name, args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "scripts/{name} {args:?}: exit status; stderr: {err}");
    assert_eq!(err.lines().count(), 1, "scripts/{name} {args:?}: one line: {err}");
    for n in needles {
        assert!(err.contains(n), "scripts/{name} {args:?}: the message should name '{n}': {err}");
    }
    assert!(!err.contains("unbound variable") && !err.contains(": line "), "scripts/{name} {args:?}: a raw bash error: {err}");
    assert!(took < Duration::from_secs(60), "scripts/{name} {args:?}: refused only after {took:?}");
    assert!(snapshot(dir) == before, "scripts/{name} {args:?}: changed {}", dir.display());
}

#[test]
fn prove_refuses_bad_arguments() {
    let dir = scratch_dir("prove");
    let empty = dir.join("empty");
    std::fs::create_dir(&empty).unwrap();
    let spaced = dir.join("my rtl");
    let out = hdl_gen(&["generate", "--p", "1", "--out", spaced.to_str().unwrap()]);
    assert!(out.status.success());
    let (e, s) = (empty.to_str().unwrap(), spaced.to_str().unwrap());
    // The shared set-up engine's front-end: its folder is taken (it has properties of its own).
    let engine = dir.join("engine");
    let out =
        hdl_gen(&["generate", "--p", "1", "--width", "37", "--height", "23", "--fe-setup", "ecp5-25f", "--out", engine.to_str().unwrap()]);
    assert!(out.status.success());
    let missing = dir.join("missing");
    let cases: &[(&[&str], &[&str])] = &[
        (&["--depth", "abc"], &["--depth 'abc'"]),
        (&["--depth", "-1"], &["--depth '-1'"]),
        (&["--depth", "0"], &["--depth '0'"]),
        (&["--depth"], &["--depth needs a value"]),
        (&["--deep", "x"], &["--deep 'x'"]),
        (&["--rtl"], &["--rtl needs a value"]),
        (&["--rtl", ""], &["--rtl needs a value"]),
        (&["--rtl", missing.to_str().unwrap()], &["is not a folder"]),
        (&["--rtl", e], &["holds no Verilog module with properties"]),
        (&["--rtl", s, "--only", "("], &["--only '('", "not a valid regular expression"]),
        (&["--rtl", s, "--skip", "[a"], &["--skip '[a'"]),
        (&["--only"], &["--only needs a value"]),
        (&["--bogus"], &["unknown argument '--bogus'"]),
    ];
    for (args, needles) in cases {
        assert_refused("prove", args, needles, &dir);
    }
    // A folder whose path has a space: read whole, and an --only that matches none of its
    // proofs is a failure, not an empty success. This one gets as far as the solver: only
    // where scripts/test installed it (no PyPI from a test).
    let venv = Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/formal-venv/bin/yices-smt2");
    let yosys = Command::new("yosys-smtbmc").arg("-h").output().is_ok();
    if venv.exists() && yosys {
        assert_refused("prove", &["--rtl", s, "--only", "NOMATCH"], &["--only 'NOMATCH' matches no proof"], &dir);
        assert_refused("prove", &["--rtl", engine.to_str().unwrap(), "--only", "NOMATCH"], &["--only 'NOMATCH' matches no proof"], &dir);
        assert_refused("prove", &["--self-test", "--only", "NOMATCH"], &["--only 'NOMATCH' matches no planted fault"], &dir);
    } else {
        eprintln!("cli_scripts: skipped: prove --only NOMATCH needs yosys and target/formal-venv (scripts/test installs them)");
    }
}

#[test]
fn synth_and_check_rtl_dir_show_the_generators_message() {
    let dir = scratch_dir("synth");
    let o = dir.join("out");
    let o = o.to_str().unwrap();
    // The flags checked before any PyPI install (ECP5 would install nextpnr) or the output folder.
    let cases: &[(&[&str], &[&str])] = &[
        (&["--writer", "3", "--out", o], &["--writer 3", "power of two"]),
        (&["--family", "ecp5", "--p", "3", "--out", o], &["--p 3", "power of two"]),
        (&["--family", "ecp5", "--arch", "wallace", "--out", o], &["--arch wallace", "wallace"]),
        (&["--pipeline", "7", "--out", o], &["--pipeline", "'7'"]),
        (&["--frontend", "--fe-div-bits", "3", "--out", o], &["--fe-div-bits 3"]),
        (&["--chain", "3", "--out", o], &["--chain 3", "power of two"]),
        (&["--chain", "16", "--chain-align", "diagonal", "--out", o], &["--chain 16 --chain-align diagonal", "diagonal"]),
        (&["--chain", "16", "--fe-setup", "xc7", "--out", o], &["--fe-setup xc7", "xc7"]),
        (&["--chain-specular", "0", "--out", o], &["--chain-specular is for --chain"]),
        (&["--chain", "16", "--chain-specular", "7", "--out", o], &["--chain-specular 7", "'7'"]),
        (&["--chain"], &["--chain needs a value"]),
        (&["--family", "vhdl"], &["unknown family 'vhdl'"]),
        (&["--device", "25k", "--out", o], &["--device takes hx8k or up5k with --family ice40", "'25k'"]),
        (&["--seeds"], &["--seeds needs a value"]),
        (&["--abc-depth", "7", "--out", o], &["--abc-depth is for --family ecp5 only"]),
        (&["--family", "ecp5", "--abc-depth", "x", "--out", o], &["--abc-depth takes", "'x'"]),
        (&["--abc-depth"], &["--abc-depth needs a value"]),
        (&["--family", "ecp5", "--abc9", "--out", o], &["--abc9 is for --family ice40 only"]),
    ];
    for (args, needles) in cases {
        assert_refused("synth", args, needles, &dir);
    }
    assert!(!Path::new(o).exists(), "a refused run made its output folder");

    let cases: &[(&[&str], &[&str])] = &[
        (&["--p 3"], &["configuration '--p 3'", "power of two"]),
        (&["--p 8", "--p 8 --bus axi"], &["configuration '--p 8 --bus axi'", "axi"]),
        (&["--bogus"], &["configuration '--bogus'", "--bogus"]),
        // A configuration's own --out would write elsewhere; a glob is not this folder's files.
        (&["--p 8 --out /tmp/segshade-check-rtl-dir-out"], &["configuration '--p 8 --out", "cannot be used multiple times"]),
        (&["--prefix *"], &["configuration '--prefix *'", "--prefix"]),
    ];
    for (args, needles) in cases {
        assert_refused("check-rtl-dir", args, needles, &dir);
    }
}

/// The other scripts that take arguments: values checked before anything is installed, built or
/// run, and the generator's message shown where it decides.
#[test]
fn other_scripts_refuse_bad_arguments() {
    let dir = scratch_dir("others");
    let file = dir.join("a-file");
    std::fs::write(&file, "keep").unwrap();
    let f = file.to_str().unwrap();
    let d = dir.to_str().unwrap();
    let cases: &[(&str, &[&str], &[&str])] = &[
        ("bench-cosim", &["--runs", "abc"], &["--runs takes a positive number, not 'abc'"]),
        ("bench-cosim", &["--runs"], &["--runs needs a value"]),
        ("bench-cosim", &["--seg-spans", "0"], &["--seg-spans takes a positive number"]),
        ("bench-cosim", &["--seg-spans", "5", "--cocotb-seg-spans", "10"], &["exceeds --seg-spans 5"]),
        ("bench-cosim", &["--out", f], &["is not a folder"]),
        ("bench-cosim", &["--bogus"], &["unknown argument '--bogus'"]),
        ("mutate", &["--only", "("], &["--only '('", "not a valid regular expression"]),
        ("mutate", &["--only", "NOMATCH"], &["--only 'NOMATCH' matches no mutant"]),
        ("mutate", &["--seed"], &["--seed needs a value"]),
        ("icarus-tests", &["--vectors"], &["--vectors needs a value"]),
        ("check-fusesoc", &["--p 3"], &["configuration '--p 3'", "power of two"]),
        ("board", &["ulx3s-85f", "--source", "uart", "--out"], &["--out needs a folder"]),
        // The FPGA flow works in --out's folder: without one it would clear fpga/ where it runs.
        ("board", &["ulx3s-85f", "--bitstream"], &["--bitstream needs --out DIR"]),
        ("board", &["ulx3s-85f", "--bitstream", "--out="], &["--bitstream needs --out DIR"]),
        ("board", &["send", "--bitstream", "--port", f, f], &["--bitstream goes with ulx3s-85f"]),
        // Checked before anything is installed or built (python starts in about 0.2 s each).
        ("lint-all", &["--jobs", "0"], &["--jobs", "positive number, not '0'"]),
        ("lint-all", &["--jobs", "abc"], &["--jobs", "positive number, not 'abc'"]),
        ("lint-all", &["--only", "("], &["--only '('", "not a valid regular expression"]),
        ("lint-all", &["--only", "NOMATCH"], &["--only 'NOMATCH' matches no configuration"]),
        ("lint-all", &["--keep", f], &["is not a folder"]),
        ("lint-all", &["--keep", d], &["holds other files"]),
    ];
    for (name, args, needles) in cases {
        assert_refused(name, args, needles, &dir);
    }
    if Command::new("iverilog").arg("-V").output().is_ok() {
        assert_refused("icarus-tests", &["--vectors", "0"], &["--vectors"], &dir);
    }
}
