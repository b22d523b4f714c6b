//! Every `hdl-gen` subcommand with a bad value for each of its flags (missing, out of range,
//! wrong type, unwritable path, unreadable or malformed input): one message naming the flag or
//! the file, exit status 2, nothing written.

mod common;
use common::{hdl_gen, scratch};
use std::path::{Path, PathBuf};

/// Every file under `dir`, recursively (none if it does not exist).
fn files_under(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    if let Ok(entries) = std::fs::read_dir(dir) {
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                out.extend(files_under(&p));
            } else {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

fn assert_rejected(args: &[&str], needle: &str, out_dir: &Path) {
    let before = files_under(out_dir);
    let out = hdl_gen(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: exit status; stderr: {err}");
    assert!(err.contains(needle), "{args:?}: the message should name '{needle}': {err}");
    assert_eq!(err.lines().filter(|l| l.starts_with("error")).count(), 1, "{args:?}: one message: {err}");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    assert!(out.stdout.is_empty(), "{args:?}: wrote to stdout");
    assert_eq!(files_under(out_dir), before, "{args:?}: files written or removed");
}

#[test]
fn generate_bad_flags() {
    let dir = scratch("generate");
    let d = dir.join("out");
    let d = d.to_str().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["generate", "--out", d, "--p"], "--p"),
        (&["generate", "--out", d, "--p", "-8"], "--p"),
        (&["generate", "--out", d, "--p", "8.0"], "--p"),
        (&["generate", "--out", d, "--frac", "-1"], "--frac"),
        (&["generate", "--out", d, "--frac", "twelve"], "--frac"),
        (&["generate", "--out", d, "--xbits", "99999999999"], "--xbits"),
        (&["generate", "--out", d, "--width", "5000"], "outside 1..=4096"),
        (&["generate", "--out", d, "--frac", "8", "--width", "640"], "exceeds 2^F = 256"),
        (&["generate", "--out", d, "--height", "0"], "--height"),
        (&["generate", "--out", d, "--width", "abc"], "--width"),
        (&["generate", "--out", d, "--align"], "--align"),
        (&["generate", "--out", d, "--prefix", "a-b"], "--prefix"),
        (&["generate", "--out", d, "--prefix", "a b"], "--prefix"),
        (&["generate", "--out", d, "--bfpi-arch", "wallace"], "--bfpi-arch"),
        (&["generate", "--out", d, "--bus", "axi"], "--bus"),
        (&["generate", "--out", d, "--bus"], "--bus"),
        (&["generate", "--out", d, "--brdf-k", "16,4"], "--brdf-k"),
        (&["generate", "--out", d, "--brdf-k", "0"], "--brdf-k"),
        (&["generate", "--out", d, "--brdf-k", "auto", "--max-rel-error", "150%"], "--max-rel-error"),
        (&["generate", "--out", d, "--brdf-k", "auto", "--max-rel-error", "tiny"], "--max-rel-error"),
        (&["generate", "--out", d, "--max-rel-error", "1%"], "--brdf-k"),
        (&["generate", "--out"], "--out"),
        (&["generate", "--out", d, "--bogus"], "--bogus"),
    ];
    for (args, needle) in cases {
        assert_rejected(args, needle, &dir);
    }
    assert!(!dir.exists(), "a rejected generate created its folder");
}

#[test]
fn rom_bad_flags() {
    let dir = scratch("rom");
    std::fs::create_dir_all(&dir).unwrap();
    let missing = dir.join("no/such/folder/brdf.hex");
    let folder = dir.to_str().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["rom"], "--table"),
        (&["rom", "--table"], "--table"),
        (&["rom", "--table", "cos"], "--table"),
        (&["rom", "--table", "brdf", "--format", "bin"], "--format"),
        (&["rom", "--table", "brdf", "--format"], "--format"),
        (&["rom", "--table", "brdf", "--brdf-k", "1,2,2"], "--brdf-k"),
        (&["rom", "--table", "brdf", "--brdf-k", "65"], "--brdf-k"),
        (&["rom", "--table", "brdf", "--out"], "--out"),
        (&["rom", "--table", "brdf", "--out", missing.to_str().unwrap()], missing.to_str().unwrap()),
        (&["rom", "--table", "brdf", "--out", folder], folder),
    ];
    for (args, needle) in cases {
        assert_rejected(args, needle, &dir);
    }
    assert!(files_under(&dir).is_empty());
}

#[test]
fn synth_wrapper_bad_flags_and_input() {
    let dir = scratch("wrapper");
    let rtl = dir.join("rtl");
    std::fs::create_dir_all(&rtl).unwrap();
    let out_ok = hdl_gen(&["generate", "--out", rtl.to_str().unwrap()]);
    assert!(out_ok.status.success());
    let bad = dir.join("bad");
    std::fs::create_dir_all(&bad).unwrap();
    std::fs::write(bad.join("manifest.json"), "{ \"modules\": [ { \"name\": \"x\", ").unwrap();
    let no_ports = dir.join("noports");
    std::fs::create_dir_all(&no_ports).unwrap();
    std::fs::write(
        no_ports.join("manifest.json"),
        r#"{"modules": [{"name": "m", "ports": [{"name": "clk", "direction": "sideways", "width": 1}]}]}"#,
    )
    .unwrap();
    let empty = dir.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let r = rtl.to_str().unwrap();
    let w = dir.join("w.v");
    let w = w.to_str().unwrap();
    let unwritable = dir.join("missing/w.v");
    let cases: Vec<(Vec<&str>, String)> = vec![
        (vec!["synth-wrapper", "--module", "segment_shader_p8", "--out", w], "--rtl".into()),
        (vec!["synth-wrapper", "--rtl", r, "--out", w], "--module".into()),
        (vec!["synth-wrapper", "--rtl", r, "--module", "segment_shader_p8"], "--out".into()),
        (
            vec!["synth-wrapper", "--rtl", empty.to_str().unwrap(), "--module", "m", "--out", w],
            empty.join("manifest.json").display().to_string(),
        ),
        (vec!["synth-wrapper", "--rtl", bad.to_str().unwrap(), "--module", "x", "--out", w], "manifest.json".into()),
        (vec!["synth-wrapper", "--rtl", no_ports.to_str().unwrap(), "--module", "m", "--out", w], "sideways".into()),
        (vec!["synth-wrapper", "--rtl", r, "--module", "no_such_module", "--out", w], "no_such_module".into()),
        (vec!["synth-wrapper", "--rtl", r, "--module", "bfpi_p8", "--out", w], "clk".into()),
        (
            vec!["synth-wrapper", "--rtl", r, "--module", "segment_shader_p8", "--out", unwritable.to_str().unwrap()],
            unwritable.display().to_string(),
        ),
    ];
    let before = files_under(&dir);
    for (args, needle) in &cases {
        assert_rejected(args, needle, &dir);
    }
    assert_eq!(files_under(&dir), before);
}

#[test]
fn testbench_bad_flags() {
    let dir = scratch("testbench");
    let d = dir.join("tb");
    let d = d.to_str().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["testbench", "--out", d, "--vectors", "0"], "--vectors"),
        (&["testbench", "--out", d, "--vectors", "1000001"], "--vectors"),
        (&["testbench", "--out", d, "--vectors", "-3"], "--vectors"),
        (&["testbench", "--out", d, "--vectors", "lots"], "--vectors"),
        (&["testbench", "--out", d, "--vectors"], "--vectors"),
        (&["testbench", "--out", d, "--seed", "-1"], "--seed"),
        (&["testbench", "--out", d, "--seed", "0x10"], "--seed"),
        (&["testbench", "--out", d, "--p", "3"], "power of two"),
        (&["testbench", "--out", d, "--p", "64", "--xbits", "5"], "exceeds the screen width"),
        (&["testbench", "--out", d, "--frac", "21"], "--frac"),
        (&["testbench", "--out", d, "--xbits", "17"], "--xbits"),
        (&["testbench", "--out", d, "--align", "left"], "--align"),
        (&["testbench", "--out", d, "--prefix", "1x"], "--prefix"),
        (&["testbench", "--out", d, "--brdf-k", "2,1"], "--brdf-k"),
        (&["testbench", "--vectors", "10"], "--out"),
    ];
    for (args, needle) in cases {
        assert_rejected(args, needle, &dir);
    }
    assert!(!dir.exists(), "a rejected testbench created its folder");
    // An output path that is a file: the error names it and the file is untouched.
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("a-file");
    std::fs::write(&file, "keep").unwrap();
    assert_rejected(&["testbench", "--vectors", "5", "--out", file.to_str().unwrap()], file.to_str().unwrap(), &dir);
    assert_eq!(std::fs::read(&file).unwrap(), b"keep");
}

#[test]
fn report_bad_flags() {
    let dir = scratch("report");
    std::fs::create_dir_all(&dir).unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["report", "precision"], "precision"),
        (&["report", "accuracy", "--svg"], "--svg"),
        (&["report", "accuracy", "--brdf-k"], "--brdf-k"),
        (&["report", "accuracy", "--brdf-k", "auto", "--max-rel-error", "0%"], "--max-rel-error"),
        (&["report", "accuracy", "--max-rel-error"], "--max-rel-error"),
    ];
    for (args, needle) in cases {
        assert_rejected(args, needle, &dir);
    }
    assert!(files_under(&dir).is_empty());
}
