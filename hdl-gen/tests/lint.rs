//! Generated Verilog is clean under `verilator --lint-only -Wall` and compiles in Icarus
//! (`iverilog -g2005`), for a spread of configurations. A missing tool fails the test with
//! the command that installs it: a lint that did not run must not pass.

use golden::{Align, Config};
use hdl_gen::{generate, output, Options};
use std::process::Command;

fn run(tool: &str, args: &[String]) -> String {
    let out = Command::new(tool).args(args).output().unwrap_or_else(|e| {
        panic!("{tool} could not be run ({e}); install it with: apt-get install -y {}", if tool == "iverilog" { "iverilog" } else { tool })
    });
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "{tool} {}:\n{text}", args.join(" "));
    text
}

fn configs() -> Vec<(Config, &'static str)> {
    let mut v = Vec::new();
    for p in [1, 2, 4, 8, 16, 64, 256] {
        for align in Align::ALL {
            v.push((Config { p, align, ..Config::default() }, ""));
        }
    }
    v.push((Config::new(16, 4, 4, Align::Screen).unwrap(), "edge_"));
    v.push((Config::new(2, 20, 16, Align::Screen).unwrap(), ""));
    v.push((Config::new(128, 7, 9, Align::Span).unwrap(), "x_"));
    v
}

#[test]
fn verilator_lint_and_icarus_are_clean() {
    for (cfg, prefix) in configs() {
        let dir = std::env::temp_dir().join(format!("hdl-gen-lint-{}-{}-{}", std::process::id(), cfg.p, cfg.align));
        let _ = std::fs::remove_dir_all(&dir);
        let files = generate(&Options { cfg, prefix: prefix.into(), ..Default::default() });
        output::write_all(&dir, &files).unwrap();
        let sources: Vec<String> =
            files.iter().filter(|f| f.name.ends_with(".v")).map(|f| dir.join(&f.name).display().to_string()).collect();
        for top in [hdl_gen::Names::new(prefix, &cfg).segment, hdl_gen::specular::SpecNames::new(prefix).unit] {
            let mut lint = vec!["--lint-only".to_string(), "-Wall".into(), "--top-module".into(), top];
            lint.extend(sources.iter().cloned());
            let text = run("verilator", &lint);
            assert!(!text.contains("%Warning"), "{cfg:?}: {text}");
        }
        let mut ivl = vec!["-g2005".to_string(), "-Wall".into(), "-o".into(), dir.join("a.out").display().to_string()];
        ivl.extend(sources);
        let text = run("iverilog", &ivl);
        assert!(text.trim().is_empty(), "{cfg:?}: iverilog says:\n{text}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
