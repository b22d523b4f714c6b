//! Generated output is byte-identical across runs and machines.
//!
//! - The same command run from different folders, into differently named folders, under a
//!   different environment (time zone, locale, user, SOURCE_DATE_EPOCH) writes the same bytes.
//! - A fingerprint of the whole output of a spread of configurations is committed in
//!   `tests/output-fingerprints.txt`, so output made on another machine is compared too (the
//!   default configuration is compared byte for byte with `rtl/` by `rtl.rs`).
//!
//! After an intended change to the generated files, refresh the fingerprints with
//! `SEGSHADE_BLESS=1 cargo test -p hdl-gen --test determinism` and commit the file.

mod common;
use common::{listing, scratch_dir as scratch};
use std::path::Path;
use std::process::Command;

const CONFIGS: &[&str] = &[
    "--p 1 --align screen",
    "--p 16 --frac 4 --xbits 4 --align screen --prefix edge_",
    "--p 64 --prefix my_ --frac 10 --xbits 11",
    "--p 256 --align screen --frac 20 --xbits 16",
    "--p 8 --bfpi-arch naive",
    "--p 16 --align screen --bfpi-arch tree",
    "--p 2 --align screen --prefix acme_ --pipeline 1 --bus axis",
];

/// Runs `hdl-gen generate ARGS --out out` in `cwd` with exactly `env`.
fn generate(args: &str, cwd: &Path, out: &Path, env: &[(&str, &str)]) {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_hdl-gen"));
    cmd.arg("generate").args(args.split_whitespace()).arg("--out").arg(out).current_dir(cwd).env_clear();
    cmd.envs(env.iter().copied());
    let o = cmd.output().expect("running hdl-gen");
    assert!(o.status.success(), "hdl-gen generate {args}: {}", String::from_utf8_lossy(&o.stderr));
}

/// FNV-1a (64 bit) over every file's name, length and bytes: a fingerprint, not a signature.
fn fingerprint(files: &[(String, Vec<u8>)]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |bytes: &[u8]| {
        for &b in bytes {
            h ^= b as u64;
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    };
    for (name, bytes) in files {
        eat(name.as_bytes());
        eat(&(bytes.len() as u64).to_le_bytes());
        eat(bytes);
    }
    format!("{h:016x}")
}

#[test]
fn same_bytes_whatever_the_folder_and_environment() {
    let base = scratch("env");
    let (cwd_a, cwd_b) = (base.join("a"), base.join("some other place"));
    std::fs::create_dir_all(&cwd_a).unwrap();
    std::fs::create_dir_all(&cwd_b).unwrap();
    let env_a: &[(&str, &str)] = &[("TZ", "UTC"), ("LC_ALL", "C"), ("USER", "alice"), ("HOME", "/nonexistent")];
    let env_b: &[(&str, &str)] = &[
        ("TZ", "Pacific/Kiritimati"),
        ("LC_ALL", "uk_UA.UTF-8"),
        ("LANG", "uk_UA.UTF-8"),
        ("USER", "bob"),
        ("HOME", "/tmp"),
        ("SOURCE_DATE_EPOCH", "1"),
    ];
    for args in CONFIGS.iter().chain(&["--p 8"]) {
        let (out_a, out_b) = (cwd_a.join("out"), base.join("elsewhere/deeper/rtl output"));
        let _ = std::fs::remove_dir_all(&out_a);
        let _ = std::fs::remove_dir_all(&out_b);
        generate(args, &cwd_a, Path::new("out"), env_a);
        generate(args, &cwd_b, &out_b, env_b);
        let (la, lb) = (listing(&out_a), listing(&out_b));
        assert!(la.len() >= 4, "{args}: {la:?}");
        assert!(la == lb, "{args}: output differs between folders or environments");
        for (name, bytes) in &la {
            let text = String::from_utf8_lossy(bytes);
            assert!(!text.contains(base.to_str().unwrap()), "{args}: {name} mentions the output path");
        }
    }
    let _ = std::fs::remove_dir_all(&base);
}

#[test]
fn output_matches_the_committed_fingerprints() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/output-fingerprints.txt");
    let base = scratch("fp");
    let mut lines = vec![
        "# Fingerprints (FNV-1a 64 over name, length and bytes of every file) of `hdl-gen generate ARGS`.".to_string(),
        "# Refresh after an intended change: SEGSHADE_BLESS=1 cargo test -p hdl-gen --test determinism".to_string(),
    ];
    for (k, args) in CONFIGS.iter().enumerate() {
        let out = base.join(k.to_string());
        generate(args, &base, &out, &[("LC_ALL", "C")]);
        lines.push(format!("{}  {args}", fingerprint(&listing(&out))));
    }
    let _ = std::fs::remove_dir_all(&base);
    let now = lines.join("\n") + "\n";
    if std::env::var_os("SEGSHADE_BLESS").is_some() {
        std::fs::write(&file, &now).unwrap();
        return;
    }
    let committed = std::fs::read_to_string(&file).unwrap_or_default();
    if committed != now {
        let diff: Vec<String> = now.lines().filter(|l| !committed.lines().any(|c| c == *l)).map(|l| format!("  now: {l}")).collect();
        panic!(
            "generated output differs from the committed fingerprints in {}:\n{}\n\
             If the change to the generated files is intended, refresh them with:\n  \
             SEGSHADE_BLESS=1 cargo test -p hdl-gen --test determinism",
            file.display(),
            diff.join("\n")
        );
    }
}
