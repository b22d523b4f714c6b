//! The harness's command-line tools with bad input: every flag with a missing, out-of-range or
//! wrongly typed value gets one clear message naming the flag, exit status 2, and no output.

use std::process::{Command, Output};

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

const COSIM: &str = env!("CARGO_BIN_EXE_cosim");

#[test]
fn cosim_rejects_every_bad_flag() {
    let cases: &[(&[&str], &str)] = &[
        (&["--p"], "--p"),
        (&["--p", "eight"], "--p"),
        (&["--p", "-8"], "--p"),
        (&["--p", "3"], "--p 3"),
        (&["--p", "512"], "--p 512"),
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
    ];
    for (args, needle) in cases {
        assert_rejected(COSIM, args, needle);
    }
}

/// The good path still works, so the rejections above are not a broken binary.
#[test]
fn cosim_runs_a_few_triangles() {
    let out = run(COSIM, &["--triangles", "5", "--seed", "1"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}{}", String::from_utf8_lossy(&out.stderr));
    assert!(text.trim_end().ends_with("5 passed, 0 failed"), "{text}");
}
