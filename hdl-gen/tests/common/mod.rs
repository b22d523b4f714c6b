//! What the `hdl-gen` integration tests share: running the binary, private scratch folders and
//! reading a folder back. Each test uses some of it.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// `hdl-gen ARGS`, run to completion.
pub fn hdl_gen(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hdl-gen")).args(args).output().expect("running hdl-gen")
}

/// A path of this test binary's own under the temporary folder, with nothing there yet: tests
/// that check what a command writes (or does not) start from no folder at all.
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hdl-gen-{}-{}-{name}", env!("CARGO_CRATE_NAME"), std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// [`scratch`], created empty.
pub fn scratch_dir(name: &str) -> PathBuf {
    let dir = scratch(name);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Every file of a folder with its bytes, sorted by name.
pub fn listing(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (e.file_name().to_string_lossy().into_owned(), std::fs::read(e.path()).unwrap())
        })
        .collect();
    files.sort();
    files
}
