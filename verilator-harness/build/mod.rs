//! One description of a verilated model, shared by `build.rs` (which compiles the catalogue the
//! test suites use into the crate) and the library (which builds any other configuration when a
//! binary or test first asks for it, `crate::ondemand`): the [`Model`] type, the [`catalogue`]
//! and the models of one `generate` configuration or one `COSIM_RTL_DIR` folder, the C++
//! [`shim`] of each model, and the one [`verilator`] invocation and compiler set-up.
//!
//! `build.rs` includes this folder with `#[path]`, so it compiles twice (into the build script
//! and into the library): it may use only what both have (golden, hdl-gen, cc, serde_json,
//! thiserror), and stands no `env!` but `CARGO_MANIFEST_DIR`, which both see.

pub mod catalogue;
pub mod model;
pub mod shim;
pub mod verilator;

pub use model::{Kind, Model};

use std::path::PathBuf;

/// Why a model could not be described or built. `build.rs` stops with it; the library hands it
/// to the binary, which prints it and exits 2 (a configuration) or 1 (a tool failing).
#[derive(Clone, Debug, thiserror::Error)]
pub enum ModelError {
    #[error(
        "verilator was not found on PATH; the co-simulation harness needs it: install Debian's package \
         (apt-get install -y verilator), or run ./scripts/test, which installs it when missing"
    )]
    NoVerilator,
    #[error("verilator failed on {top} (its Verilog: {dir}):\n{log}")]
    Verilate { top: String, dir: PathBuf, log: String },
    #[error("the C++ compiler failed on model {tag} ({dir}):\n{log}")]
    Compile { tag: String, dir: PathBuf, log: String },
    /// (An `Arc`: the registry hands one error to every test that asks for a folder's models.)
    #[error("{path}: {error}")]
    Io { path: PathBuf, error: std::sync::Arc<std::io::Error> },
    /// A `COSIM_RTL_DIR` folder (or its manifest) that does not describe a model.
    #[error("COSIM_RTL_DIR={dir}: {what}")]
    RtlDir { dir: PathBuf, what: String },
    /// A configuration `generate` refuses, or one with no model of the kind asked for.
    #[error("{0}")]
    Config(String),
}

/// `f`'s error as [`ModelError::Io`] on `path`.
pub fn io<T>(path: impl Into<PathBuf>, r: std::io::Result<T>) -> Result<T, ModelError> {
    r.map_err(|error| ModelError::Io { path: path.into(), error: std::sync::Arc::new(error) })
}
