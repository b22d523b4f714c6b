//! `hdl-gen testbench`: the self-checking benches pass in Icarus Verilog on the generated RTL,
//! and fail (non-zero exit, `M failed` with M > 0) when the RTL is broken. A missing Icarus
//! fails the test with the command that installs it: a bench that did not run must not pass.

mod common;
use common::scratch;
use std::path::Path;
use std::process::Command;

fn testbench(dir: &Path, args: &[&str]) {
    let mut full = vec!["testbench", "--out", dir.to_str().unwrap()];
    full.extend_from_slice(args);
    let out = Command::new(env!("CARGO_BIN_EXE_hdl-gen")).args(&full).output().expect("running hdl-gen");
    assert!(out.status.success(), "hdl-gen {full:?}: {}", String::from_utf8_lossy(&out.stderr));
}

/// Compiles and runs bench `top` in `dir`: (exit success, standard output).
fn icarus(dir: &Path, top: &str) -> (bool, String) {
    let sources: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".v"))
        .collect();
    let vvp = format!("{top}.vvp");
    let compiled = Command::new("iverilog")
        .current_dir(dir)
        .args(["-g2005", "-Wall", "-s", top, "-o", &vvp])
        .args(&sources)
        .output()
        .unwrap_or_else(|e| panic!("iverilog could not be run ({e}); install it with: apt-get install -y iverilog"));
    let text = String::from_utf8_lossy(&compiled.stderr).into_owned();
    assert!(compiled.status.success() && text.trim().is_empty(), "iverilog on {top}:\n{text}");
    let run = Command::new("vvp").current_dir(dir).args(["-n", &vvp]).output().expect("running vvp");
    (run.status.success(), String::from_utf8_lossy(&run.stdout).into_owned())
}

/// The `N passed, M failed` line.
fn result(stdout: &str) -> (u32, u32) {
    let line = stdout.lines().find(|l| l.contains(" passed, ")).unwrap_or_else(|| panic!("no result line in:\n{stdout}"));
    let nums: Vec<u32> = line.split(|c: char| !c.is_ascii_digit()).filter(|s| !s.is_empty()).map(|s| s.parse().unwrap()).collect();
    (nums[0], nums[1])
}

fn break_file(dir: &Path, file: &str, from: &str, to: &str) {
    let path = dir.join(file);
    let text = std::fs::read_to_string(&path).unwrap();
    assert_eq!(text.matches(from).count(), 1, "{file}: '{from}'");
    std::fs::write(&path, text.replace(from, to)).unwrap();
}

#[test]
fn benches_pass_on_the_generated_rtl_and_fail_on_broken_rtl() {
    let dir = scratch("p8");
    testbench(&dir, &["--p", "8", "--vectors", "150", "--seed", "3"]);
    for top in ["tb_segment_shader_p8", "tb_specular_unit"] {
        let (ok, out) = icarus(&dir, top);
        assert!(ok, "{top}:\n{out}");
        assert_eq!(result(&out), (150, 0), "{top}:\n{out}");
    }
    // The segment's last flag one pixel early and the specular accumulator running backwards.
    break_file(&dir, "segment_shader_p8.v", "cur_rem <= 13'd8", "cur_rem < 13'd8");
    break_file(&dir, "specular_unit.v", "theta <= theta + dtheta;", "theta <= theta - dtheta;");
    for top in ["tb_segment_shader_p8", "tb_specular_unit"] {
        let (ok, out) = icarus(&dir, top);
        assert!(!ok, "{top} passed broken RTL:\n{out}");
        let (passed, failed) = result(&out);
        assert!(failed > 0 && passed + failed == 150, "{top}:\n{out}");
        assert!(out.contains("FAIL"), "{top} names the mismatch:\n{out}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_hung_block_fails_the_bench() {
    let dir = scratch("hang");
    testbench(&dir, &["--p", "4", "--align", "screen", "--vectors", "20"]);
    break_file(&dir, "segment_shader_p4.v", "assign in_ready = !cur_valid || (fire && cur_last);", "assign in_ready = 1'b0;");
    let (ok, out) = icarus(&dir, "tb_segment_shader_p4");
    assert!(!ok);
    assert_eq!(result(&out), (0, 20), "{out}");
    assert!(out.contains("no transfer for"), "{out}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn prefixed_narrow_configuration_passes() {
    let dir = scratch("narrow");
    testbench(&dir, &["--p", "16", "--xbits", "5", "--frac", "6", "--align", "screen", "--prefix", "acme_", "--vectors", "80"]);
    for top in ["tb_acme_segment_shader_p16", "tb_acme_specular_unit"] {
        let (ok, out) = icarus(&dir, top);
        assert!(ok, "{top}:\n{out}");
        assert_eq!(result(&out), (80, 0), "{top}:\n{out}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
