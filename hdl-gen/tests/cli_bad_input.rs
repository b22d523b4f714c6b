//! Every `hdl-gen` subcommand with a bad value for each of its flags (missing, out of range,
//! wrong type, unwritable path, unreadable or malformed input): one message naming the flag or
//! the file, exit status 2, nothing written.

mod common;
use common::{hdl_gen, listing, scratch};
use std::path::{Path, PathBuf};

/// Every entry under `dir`, recursively, with what it is and its bytes (none if `dir` does not
/// exist): two snapshots are equal when nothing was written, removed, replaced or changed.
fn files_under(dir: &Path) -> Vec<(PathBuf, String, Vec<u8>)> {
    let mut out = Vec::new();
    if let Ok(entries) = std::fs::read_dir(dir) {
        for e in entries.flatten() {
            let p = e.path();
            let kind = e.file_type().unwrap();
            if kind.is_dir() {
                out.push((p.clone(), "dir".into(), Vec::new()));
                out.extend(files_under(&p));
            } else if kind.is_symlink() {
                out.push((p.clone(), format!("link to {}", std::fs::read_link(&p).unwrap().display()), Vec::new()));
            } else if kind.is_file() {
                out.push((p.clone(), "file".into(), std::fs::read(&p).unwrap()));
            } else {
                out.push((p.clone(), format!("{kind:?}"), Vec::new()));
            }
        }
    }
    out.sort();
    out
}

/// Exit status 2, exactly one `error` line naming `needle`, no panic, nothing on stdout, and
/// nothing under `out_dir` written, removed or changed.
fn assert_rejected(args: &[&str], needle: &str, out_dir: &Path) {
    let before = files_under(out_dir);
    let out = hdl_gen(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: exit status; stderr: {err}");
    assert!(err.contains(needle), "{args:?}: the message should name '{needle}': {err}");
    assert_eq!(err.lines().filter(|l| l.starts_with("error")).count(), 1, "{args:?}: one message: {err}");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    assert!(out.stdout.is_empty(), "{args:?}: wrote to stdout");
    assert!(files_under(out_dir) == before, "{args:?}: files written, removed or changed");
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
        (&["generate", "--out", d, "--fe-i0", "lazy"], "--fe-i0"),
        (&["generate", "--out", d, "--fe-i0", "incremental", "--fe-di", "scanline"], "--fe-i0 incremental takes --fe-di triangle"),
        (&["generate", "--out", d, "--fe-setup", "ecp5-85f"], "--fe-setup"),
        (&["generate", "--out", d, "--fe-setup", "ecp5-25f", "--fe-i0", "incremental"], "--fe-setup ecp5-25f takes --fe-di triangle"),
        (&["generate", "--out", d, "--fe-setup", "ice40-hx8k", "--fe-di", "scanline"], "--fe-setup ice40-hx8k takes --fe-di triangle"),
        (&["generate", "--out", d, "--fe-span", "sequential"], "--fe-span sequential takes --fe-setup ice40-hx8k or ice40-up5k"),
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
        // `manifest`, the scripts' reader of the same file.
        (vec!["manifest", "--role", "writer"], "--rtl".into()),
        (vec!["manifest", "--rtl", r], "--role".into()),
        (vec!["manifest", "--rtl", r, "--role", "no-such-role"], "no-such-role".into()),
        (vec!["manifest", "--rtl", empty.to_str().unwrap(), "--role", "writer"], empty.join("manifest.json").display().to_string()),
        (vec!["manifest", "--rtl", bad.to_str().unwrap(), "--role", "writer"], "manifest.json".into()),
        (vec!["manifest", "--rtl", r, "--role", "axis"], "no module in the role axis".into()),
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

/// A port of a hand-written manifest: name, direction, width.
type PortSpec<'a> = (&'a str, &'a str, u64);

/// A manifest.json of one module `m` with these ports.
fn manifest_with(ports: &[PortSpec]) -> String {
    let ports: Vec<String> = ports
        .iter()
        .map(|(n, d, w)| {
            format!(r#"{{"name": "{n}", "direction": "{d}", "width": {w}, "signed": false, "format": "", "description": ""}}"#)
        })
        .collect();
    let good = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../rtl/manifest.json")).unwrap();
    let mut m: serde_json::Value = serde_json::from_str(&good).unwrap();
    let entry = &mut m["modules"][0];
    entry["name"] = "m".into();
    entry["ports"] = serde_json::from_str(&format!("[{}]", ports.join(", "))).unwrap();
    serde_json::to_string(&m).unwrap()
}

/// Manifest values no `generate` writes are refused when read, before a byte is written: the
/// issue's port of 99,999,999 bits wrote a 1.5 GB harness. And the harness may not overwrite
/// the manifest it reads, by its name or through a link.
#[test]
fn synth_wrapper_refuses_insane_manifests_and_its_own_input() {
    let dir = scratch("wrapper-limits");
    std::fs::create_dir_all(&dir).unwrap();
    let w = dir.join("w.v");
    let w = w.to_str().unwrap();
    let cases: &[(&[PortSpec], &str)] = &[
        (&[("clk", "input", 1), ("a", "input", 4), ("y", "output", 99_999_999)], "port 'y' is 99999999 bits"),
        (&[("clk", "input", 1), ("a", "input", 4), ("y", "output", 0)], "port 'y' is 0 bits"),
        (&[("clk", "input", 1), ("a", "input", 40_000), ("b", "input", 40_000), ("y", "output", 1)], "the inputs together"),
        (&[("clk", "input", 1), ("a", "input", 4), ("y", "output", 4), ("y", "output", 4)], "twice"),
        (&[("clk", "input", 1), ("a];", "input", 4), ("y", "output", 4)], "not a Verilog identifier"),
        (&[("clk", "input", 1), ("a", "input", 4_294_967_296), ("y", "output", 4)], "manifest.json"),
    ];
    for (k, (ports, needle)) in cases.iter().enumerate() {
        let rtl = dir.join(format!("m{k}"));
        std::fs::create_dir_all(&rtl).unwrap();
        std::fs::write(rtl.join("manifest.json"), manifest_with(ports)).unwrap();
        assert_rejected(&["synth-wrapper", "--rtl", rtl.to_str().unwrap(), "--module", "m", "--out", w], needle, &dir);
    }
    // A manifest.json that never ends is not read whole.
    let endless = dir.join("endless");
    std::fs::create_dir_all(&endless).unwrap();
    std::os::unix::fs::symlink("/dev/zero", endless.join("manifest.json")).unwrap();
    assert_rejected(&["synth-wrapper", "--rtl", endless.to_str().unwrap(), "--module", "m", "--out", w], "larger than 16 MiB", &dir);
    // The limit itself is accepted (a negative control of the refusals above).
    let rtl = dir.join("ok");
    std::fs::create_dir_all(&rtl).unwrap();
    std::fs::write(rtl.join("manifest.json"), manifest_with(&[("clk", "input", 1), ("a", "input", 65536), ("y", "output", 3)])).unwrap();
    let ok_out = dir.join("ok.v");
    let out = hdl_gen(&["synth-wrapper", "--rtl", rtl.to_str().unwrap(), "--module", "m", "--out", ok_out.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    std::fs::remove_file(&ok_out).unwrap();

    let real = dir.join("real");
    assert!(hdl_gen(&["generate", "--out", real.to_str().unwrap()]).status.success());
    let manifest = real.join("manifest.json");
    let link = dir.join("link.v");
    std::os::unix::fs::symlink(&manifest, &link).unwrap();
    let r = real.to_str().unwrap();
    for out in [manifest.to_str().unwrap(), link.to_str().unwrap()] {
        assert_rejected(&["synth-wrapper", "--rtl", r, "--module", "segment_shader_p8", "--out", out], "is the input file", &dir);
    }
}

/// `generate` owns its folder: a second configuration replaces the first entirely (no module of
/// the old one left beside the new), and a folder holding anything it did not write is refused
/// untouched.
#[test]
fn generate_owns_its_folder() {
    let dir = scratch("owns");
    std::fs::create_dir_all(&dir).unwrap();
    let (d, fresh) = (dir.join("rtl"), dir.join("fresh"));
    let (ds, fs) = (d.to_str().unwrap(), fresh.to_str().unwrap());
    let gen = |args: &[&str], out: &str| {
        let mut full = vec!["generate", "--out", out];
        full.extend_from_slice(args);
        let o = hdl_gen(&full);
        assert!(o.status.success(), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
    };
    // Every file the widest configuration writes is one its manifest lists: it regenerates over
    // itself, then a smaller configuration leaves exactly its own files.
    let wide: &[&str] = &["--p", "16", "--bus", "axis", "--pipeline", "1", "--prefix", "x_", "--brdf-k", "1,2,8"];
    gen(wide, ds);
    gen(wide, ds);
    gen(&["--p", "4"], ds);
    gen(&["--p", "4"], fs);
    assert!(listing(&d) == listing(&fresh), "the folder holds files of the earlier configuration");

    // Someone else's files: refused, nothing written or removed, each kind named.
    std::fs::write(d.join("notes.txt"), "mine").unwrap();
    assert_rejected(&["generate", "--p", "8", "--out", ds], "notes.txt", &dir);
    std::fs::remove_file(d.join("notes.txt")).unwrap();
    std::fs::create_dir(d.join("sub")).unwrap();
    assert_rejected(&["generate", "--p", "8", "--out", ds], "sub/", &dir);
    std::fs::remove_dir(d.join("sub")).unwrap();
    // Without its manifest, the folder's files are no longer known to be generate's.
    std::fs::remove_file(d.join("manifest.json")).unwrap();
    assert_rejected(&["generate", "--p", "4", "--out", ds], "segment_shader_p4.v", &dir);
    let other = dir.join("other");
    std::fs::create_dir(&other).unwrap();
    std::fs::write(other.join("a.v"), "module a; endmodule").unwrap();
    assert_rejected(&["generate", "--out", other.to_str().unwrap()], "a.v", &dir);
    assert_rejected(&["generate", "--out", other.to_str().unwrap()], "generate did not write", &dir);
}

/// Outputs that are not regular files: a FIFO (as `/dev/null` or a pipe) is written through and
/// stays a FIFO; a link is followed and stays a link; a folder is refused. The issue's case, `rom
/// --out /dev/null` as root, replaced the device with a file: the FIFO takes the same path
/// through the writer without putting the machine's /dev/null at risk.
#[test]
fn outputs_that_are_not_regular_files() {
    use std::os::unix::fs::FileTypeExt;
    let dir = scratch("special");
    std::fs::create_dir_all(&dir).unwrap();
    let want = hdl_gen(&["rom", "--table", "nk"]).stdout;
    assert!(!want.is_empty());

    let fifo = dir.join("pipe");
    let status = std::process::Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(status.success());
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read(&fifo).unwrap())
    };
    let out = hdl_gen(&["rom", "--table", "nk", "--out", fifo.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(std::fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo(), "the FIFO was replaced");
    // A reader still waiting (nothing was written) gets its end of file from this empty writer,
    // so a failure fails instead of hanging. O_NONBLOCK (Linux: 0o4000): no wait for a reader.
    use std::os::unix::fs::OpenOptionsExt;
    drop(std::fs::OpenOptions::new().write(true).custom_flags(0o4000).open(&fifo));
    assert_eq!(reader.join().unwrap(), want, "the FIFO's reader gets the image");

    let target = dir.join("target.hex");
    std::fs::write(&target, "old").unwrap();
    let link = dir.join("link.hex");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    let out = hdl_gen(&["rom", "--table", "nk", "--out", link.to_str().unwrap()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink(), "the link was replaced");
    assert_eq!(std::fs::read(&target).unwrap(), want);

    let broken = dir.join("broken.hex");
    std::os::unix::fs::symlink(dir.join("nowhere/x"), &broken).unwrap();
    assert_rejected(&["rom", "--table", "nk", "--out", broken.to_str().unwrap()], "broken symbolic link", &dir);
    assert_rejected(&["report", "accuracy", "--svg", dir.to_str().unwrap()], "is a folder", &dir);
    let leftovers: Vec<_> = files_under(&dir).into_iter().filter(|(p, _, _)| p.to_string_lossy().contains(".tmp")).collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}
