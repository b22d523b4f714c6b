//! The board tests' Verilator models, kept under the target directory in a folder named by the
//! hash of everything the build reads (the RTL, the bench's files, Verilator's version), so a
//! warm run reuses them.

use segshade_board::sim;
use std::path::{Path, PathBuf};

/// Builds (or finds) the model of the RTL `files`; returns its folder (the RTL in `rtl/`) and
/// the simulation's executable.
pub fn model(files: &[hdl_gen::GeneratedFile]) -> (PathBuf, PathBuf) {
    use std::hash::{Hash, Hasher};
    let verilator = std::process::Command::new("verilator").arg("--version").output().expect("verilator").stdout;
    let mut h = std::collections::hash_map::DefaultHasher::new();
    (files.iter().map(|f| (&f.name, &f.contents)).collect::<Vec<_>>(), segshade_board::SIM_FILES, verilator).hash(&mut h);
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("board-sim-{:016x}", h.finish()));
    let exe = dir.join("sim/obj/board_sim");
    if !exe.exists() {
        // Built aside and renamed into place: a run stopped half-way leaves nothing to reuse.
        let staging = tempfile::tempdir_in(env!("CARGO_TARGET_TMPDIR")).unwrap();
        hdl_gen::output::write_all(&staging.path().join("rtl"), files).unwrap();
        sim::build(&staging.path().join("rtl"), &staging.path().join("sim")).unwrap();
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::rename(staging.keep(), &dir).unwrap();
    }
    (dir, exe)
}
