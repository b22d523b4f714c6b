//! The README's commands, run as a new user runs them: every command line of every `sh` code
//! block of README.md, found by a parser (so a command added to the README is covered without
//! touching this file), run from a scratch folder, and required to exit 0. The other documents
//! whose commands take seconds ([`RUN`]: docs/render.md, docs/specular.md, CONTRIBUTING.md,
//! meshes/README.md) run the same way, and what they write that the repository has (the images
//! of docs/render.md, the plot of docs/specular.md) must be the committed files, byte for byte.
//!
//! How a command runs:
//! - `cargo run [--release] -p verilator-harness --bin B -- ARGS` runs the binary B this test
//!   binary was built with; `cargo run [--release] -p hdl-gen -- ARGS` runs the hdl-gen binary
//!   (`scripts/hdl-gen-bin`). Nothing is compiled per command.
//! - Leading `NAME=value` words are the command's environment; `$PWD` is the scratch folder.
//! - It runs in a scratch folder, so `--out rtl` and `--out sphere.png` write nothing into the
//!   checkout. A relative path that names a file of the repository (an input: `meshes/teapot.obj`,
//!   `docs/triangles.txt`) is copied there first; a relative folder of the repository that a
//!   path runs through (an output's `docs/`) is created there.
//! - **Scale-down:** a number of random triangles above [`TRIANGLES`] (`--triangles 100000`) is
//!   run as [`TRIANGLES`], which keeps the whole README to seconds; every other word is as written.
//! - **Not run**, each with its reason: `./scripts/test`, `cargo test` and `cargo nextest` run
//!   the test suite this test is part of.
//!
//! Anything else (another program, a pipe, quotes, a redirection) fails the test: teach this file
//! how to run it rather than skipping it.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

/// The largest `--triangles N` run as written; larger counts are run at this one.
pub const TRIANGLES: u64 = 200;

fn repo() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."))
}

/// A command line of a code block: the document's line it starts on and its text, with `\`
/// continuations joined and comments removed.
#[derive(Debug, Clone, PartialEq)]
pub struct Line {
    pub line: usize,
    pub text: String,
}

/// Every command line of the `sh`, `bash` and `shell` fenced blocks of a Markdown text (other
/// blocks, `text` ones included, hold output and usage summaries, not commands).
pub fn command_lines(markdown: &str) -> Vec<Line> {
    let mut out = Vec::new();
    let mut in_shell = None::<bool>;
    let mut pending: Option<Line> = None;
    for (k, raw) in markdown.lines().enumerate() {
        let trimmed = raw.trim_start();
        if let Some(lang) = trimmed.strip_prefix("```") {
            in_shell = match in_shell {
                None => Some(matches!(lang.trim(), "sh" | "bash" | "shell")),
                Some(_) => None,
            };
            pending = None;
            continue;
        }
        if in_shell != Some(true) {
            continue;
        }
        // A comment starts at a `#` that begins a word.
        let code = match trimmed.find('#').filter(|&i| i == 0 || trimmed[..i].ends_with(char::is_whitespace)) {
            Some(i) => &trimmed[..i],
            None => trimmed,
        };
        let (code, continued) = match code.trim_end().strip_suffix('\\') {
            Some(c) => (c, true),
            None => (code, false),
        };
        let mut cur = pending.take().unwrap_or(Line { line: k + 1, text: String::new() });
        if !code.trim().is_empty() {
            if !cur.text.is_empty() {
                cur.text.push(' ');
            }
            cur.text.push_str(code.trim());
        }
        if continued {
            pending = Some(cur);
        } else if !cur.text.is_empty() {
            out.push(cur);
        }
    }
    out
}

/// What running a command line came to.
#[derive(Debug)]
pub enum Outcome {
    /// It ran and exited 0; `note` says what was scaled down, if anything.
    Passed { note: String },
    /// Not run, and why.
    NotRun(&'static str),
}

fn hdl_gen() -> &'static Path {
    static BIN: OnceLock<PathBuf> = OnceLock::new();
    BIN.get_or_init(|| {
        let out = Command::new(repo().join("scripts/hdl-gen-bin")).output().expect("scripts/hdl-gen-bin runs");
        assert!(out.status.success(), "scripts/hdl-gen-bin: {}", String::from_utf8_lossy(&out.stderr));
        PathBuf::from(String::from_utf8(out.stdout).unwrap().trim())
    })
}

/// The binary a `cargo run` command line stands for, and the arguments after its `--`.
fn cargo_run(words: &[&str]) -> Result<(PathBuf, usize), String> {
    let sep = words.iter().position(|w| *w == "--").ok_or("`cargo run` without `--` before the program's arguments")?;
    let flags = &words[2..sep];
    let value = |flag: &str| flags.iter().position(|w| *w == flag).and_then(|i| flags.get(i + 1)).copied();
    let known = |w: &&str| matches!(*w, "--release" | "-p" | "--bin") || Some(*w) == value("-p") || Some(*w) == value("--bin");
    if let Some(other) = flags.iter().find(|w| !known(w)) {
        return Err(format!("`cargo run` flag {other} is not one this test knows"));
    }
    let bin = match (value("-p"), value("--bin")) {
        (Some("hdl-gen"), None | Some("hdl-gen")) => hdl_gen().to_path_buf(),
        (Some("verilator-harness"), Some(b)) => PathBuf::from(match b {
            "cosim" => env!("CARGO_BIN_EXE_cosim"),
            "render" => env!("CARGO_BIN_EXE_render"),
            "sweep" => env!("CARGO_BIN_EXE_sweep"),
            "bench" => env!("CARGO_BIN_EXE_bench"),
            other => return Err(format!("no binary {other} in verilator-harness")),
        }),
        (p, b) => return Err(format!("`cargo run` of package {p:?}, binary {b:?}: not one this test knows")),
    };
    Ok((bin, sep + 1))
}

/// Copies a relative path's file from the repository into `dir`, or creates the repository
/// folders it runs through, so that inputs are found and outputs land inside `dir`.
fn stage_path(word: &str, dir: &Path) {
    let rel = Path::new(word);
    if word.starts_with('-') || rel.is_absolute() || rel.components().any(|c| matches!(c, std::path::Component::ParentDir)) {
        return;
    }
    let src = repo().join(rel);
    if src.is_file() {
        std::fs::create_dir_all(dir.join(rel).parent().unwrap()).unwrap();
        std::fs::copy(&src, dir.join(rel)).unwrap();
    } else if let Some(parent) = rel.parent().filter(|p| !p.as_os_str().is_empty() && repo().join(p).is_dir()) {
        std::fs::create_dir_all(dir.join(parent)).unwrap();
    }
}

/// Runs one command line in `dir` as described in the module documentation.
pub fn run_line(cmd: &str, dir: &Path) -> Result<Outcome, String> {
    let is_env = |w: &str| w.split_once('=').is_some_and(|(k, _)| !k.is_empty() && k.chars().all(|c| c.is_ascii_uppercase() || c == '_'));
    // Runs of the test suite are recognised before anything else: their filters need quotes.
    let program: Vec<&str> = cmd.split_whitespace().skip_while(|w| is_env(w)).take(2).collect();
    match program.as_slice() {
        ["./scripts/test" | "scripts/test", ..] => return Ok(Outcome::NotRun("the whole test suite, which this test is part of")),
        ["cargo", "test" | "nextest"] => return Ok(Outcome::NotRun("a run of the test suite, which this test is part of")),
        ["scripts/board", ..] => return Ok(Outcome::NotRun("the board flow: minutes; its quick form is segshade-board's own test")),
        ["openFPGALoader", ..] => return Ok(Outcome::NotRun("it programs a board that is plugged in")),
        _ => {}
    }
    if let Some(c) = cmd.chars().find(|c| "'\"`|;&<>()*?{}".contains(*c)) {
        return Err(format!("{c:?} needs a shell: this test runs plain words only"));
    }
    let pwd = dir.to_str().expect("a UTF-8 scratch path");
    let words: Vec<String> = cmd.split_whitespace().map(|w| w.replace("$PWD", pwd)).collect();
    if let Some(w) = words.iter().find(|w| w.contains('$')) {
        return Err(format!("{w}: only $PWD is expanded"));
    }
    let n_env = words.iter().take_while(|w| is_env(w)).count();
    let env: BTreeMap<&str, &str> = words[..n_env].iter().map(|w| w.split_once('=').unwrap()).collect();
    let words: Vec<&str> = words[n_env..].iter().map(String::as_str).collect();
    let (bin, first) = match words.as_slice() {
        ["cargo", "run", ..] => cargo_run(&words)?,
        _ => return Err("not a command this test knows how to run: teach verilator-harness/tests/readme.rs".into()),
    };
    let mut args: Vec<String> = words[first..].iter().map(|w| w.to_string()).collect();
    let mut note = String::new();
    for k in 1..args.len() {
        if args[k - 1] == "--triangles" {
            if let Ok(n) = args[k].parse::<u64>() {
                if n > TRIANGLES {
                    note = format!(" (--triangles {n} run as {TRIANGLES})");
                    args[k] = TRIANGLES.to_string();
                }
            }
        }
    }
    for w in args.iter().map(String::as_str).chain(env.values().copied()) {
        stage_path(w, dir);
    }
    let out = Command::new(&bin).args(&args).envs(&env).current_dir(dir).output().map_err(|e| format!("{}: {e}", bin.display()))?;
    if out.status.success() {
        Ok(Outcome::Passed { note })
    } else {
        let tail = |b: &[u8]| {
            let s = String::from_utf8_lossy(b).into_owned();
            let lines: Vec<&str> = s.lines().collect();
            lines[lines.len().saturating_sub(8)..].join("\n")
        };
        Err(format!("exit status {}{note}\n--- stdout (end)\n{}\n--- stderr (end)\n{}", out.status, tail(&out.stdout), tail(&out.stderr)))
    }
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("segshade-readme-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Runs every command line of `doc` (a Markdown text called `name`) in `dir`, in order; the
/// failures, one message each.
fn run_document(name: &str, doc: &str, dir: &Path) -> Vec<String> {
    let mut failures = Vec::new();
    for l in command_lines(doc) {
        let start = std::time::Instant::now();
        match run_line(&l.text, dir) {
            Ok(Outcome::Passed { note }) => {
                eprintln!("{name}:{}: passed in {:.1} s{note}: {}", l.line, start.elapsed().as_secs_f64(), l.text)
            }
            Ok(Outcome::NotRun(why)) => eprintln!("{name}:{}: not run ({why}): {}", l.line, l.text),
            Err(e) => failures.push(format!("{name}:{}: {}\n{e}", l.line, l.text)),
        }
    }
    failures
}

#[test]
fn the_parser_finds_commands_joins_continuations_and_drops_comments() {
    let md = "text\n```sh\n# a comment\ncargo run -- a \\\n  b   # trailing\n\nFOO=$PWD/x cargo test\n```\n\
              ```text\ncargo run -- not-a-command\n```\n  ```bash\nscripts/test\n  ```\n`cargo run -- inline` is prose\n";
    let got = command_lines(md);
    let want = [(4, "cargo run -- a b"), (7, "FOO=$PWD/x cargo test"), (13, "scripts/test")];
    assert_eq!(got, want.map(|(line, text)| Line { line, text: text.into() }));
}

#[test]
fn every_readme_command_runs() {
    if verilator_harness::registry::rtl_dir().is_some() {
        eprintln!("readme: skipped under COSIM_RTL_DIR: the README's commands name the default models");
        return;
    }
    let readme = std::fs::read_to_string(repo().join("README.md")).unwrap();
    assert!(command_lines(&readme).len() >= 10, "the parser finds the README's commands");
    let dir = scratch("readme");
    let failures = run_document("README.md", &readme, &dir);
    assert!(failures.is_empty(), "README commands that fail as written:\n\n{}", failures.join("\n\n"));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The negative controls: a command that fails, one with a broken flag, and one this test
/// cannot run each fail the README check.
#[test]
fn a_broken_readme_command_fails_the_check() {
    let dir = scratch("broken");
    let doc = "```sh\n\
               cargo run --release -p verilator-harness --bin render -- --scene cube --out cube.png\n\
               cargo run --release -p hdl-gen -- generate --p 3 --out rtl\n\
               make render\n\
               cargo run -p verilator-harness --bin render -- --obj meshes/missing.obj --out m.png | tee log\n\
               ```\n";
    let failures = run_document("planted.md", doc, &dir);
    assert_eq!(failures.len(), 4, "{failures:#?}");
    assert!(failures[0].contains("exit status") && failures[0].contains("cube"), "{}", failures[0]);
    assert!(failures[2].contains("teach"), "{}", failures[2]);
    assert!(failures[3].contains("needs a shell"), "{}", failures[3]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The other documents whose commands take seconds: run as the README's are.
pub const RUN: [&str; 4] = ["CONTRIBUTING.md", "docs/render.md", "docs/specular.md", "meshes/README.md"];

/// The documents whose commands are not run here, and why (a document not named in either list
/// is reported, not run).
pub const NOT_RUN: [(&str, &str); 6] = [
    ("docs/cosim-speed.md", "scripts/bench-cosim: minutes of benchmarking"),
    ("docs/formal.md", "scripts/prove: the proofs (scripts/test runs the quick set)"),
    ("docs/fpga.md", "scripts/lint-all and scripts/synth: minutes to hours of synthesis"),
    ("docs/frontend.md", "sweep over every front-end chain: a minute even in release"),
    ("docs/regressions.md", "test-suite runs, shards, soaks and a cold clone"),
    ("docs/waveforms.md", "traced models: a rebuild of the harness with COSIM_TRACE"),
];

/// Every file under `dir`, relative to it.
fn files_under(dir: &Path, base: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            files_under(&p, base, out);
        } else {
            out.push(p.strip_prefix(base).unwrap().to_path_buf());
        }
    }
}

/// The documents of [`RUN`] run as written (docs/render.md's images, docs/specular.md's plot):
/// each command exits 0, and a file they write that the repository has (docs/sphere.png,
/// docs/specular-accuracy.svg, ...) has the committed bytes, so the committed file is what its
/// command makes today (`render` and `report` are deterministic).
#[test]
fn the_documents_commands_run_and_remake_the_committed_files() {
    if verilator_harness::registry::rtl_dir().is_some() {
        eprintln!("readme: the documents' commands skipped under COSIM_RTL_DIR: they name the default models");
        return;
    }
    let dir = scratch("documents");
    let mut failures = Vec::new();
    for doc in RUN {
        let text = std::fs::read_to_string(repo().join(doc)).unwrap();
        assert!(!command_lines(&text).is_empty(), "{doc} has commands");
        failures.extend(run_document(doc, &text, &dir));
    }
    assert!(failures.is_empty(), "document commands that fail as written:\n\n{}", failures.join("\n\n"));
    let mut written = Vec::new();
    files_under(&dir, &dir, &mut written);
    let mut compared = 0;
    for rel in written {
        let Ok(committed) = std::fs::read(repo().join(&rel)) else { continue };
        compared += 1;
        assert!(
            std::fs::read(dir.join(&rel)).unwrap() == committed,
            "{}: a command of the documents writes other bytes than the committed file; rerun it and commit",
            rel.display()
        );
    }
    assert!(compared >= 5, "the commands remake the committed images and plot ({compared} compared)");
    let mut md = Vec::new();
    files_under(&repo().join("docs"), repo(), &mut md);
    for doc in md.iter().filter(|p| p.extension().is_some_and(|x| x == "md")) {
        let name = doc.to_string_lossy();
        let listed = RUN.contains(&name.as_ref()) || NOT_RUN.iter().any(|(d, _)| *d == name);
        if !listed && !command_lines(&std::fs::read_to_string(repo().join(doc)).unwrap()).is_empty() {
            eprintln!("readme: {name} has commands and is in neither RUN nor NOT_RUN of verilator-harness/tests/readme.rs: not run");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The shipped teapot is what its tessellator makes of the shipped patches (meshes/README.md).
#[test]
fn the_teapot_mesh_is_made_from_its_patches() {
    let out = Command::new(repo().join("meshes/bpt2obj")).arg(repo().join("meshes/teapot.bpt")).output().expect("meshes/bpt2obj runs");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let shipped = std::fs::read(repo().join("meshes/teapot.obj")).unwrap();
    assert!(out.stdout == shipped, "meshes/teapot.obj is stale: rerun `meshes/bpt2obj teapot.bpt > teapot.obj` in meshes/");
}
