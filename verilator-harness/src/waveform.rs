//! Waveforms: FST files of the verilated models, to look at a failure in GTKWave or Surfer.
//!
//! **On failure (`COSIM_TRACE=DIR`).** Every streaming model has a traced twin (`verilator
//! --trace-fst`: [`crate::ffi::TracedModel`]), built at run time the first time it is needed and
//! cached like any model built on demand ([`crate::ffi::ModelInfo::twin`]). Run with COSIM_TRACE
//! set, every driver keeps a tape (`tape.rs`) of what it put on its
//! model's ports, and when a check fails, it replays the tape into the twin and writes the failing
//! window to `DIR/<tag>-seed<seed>-clock<N>.fst`; the mismatch's message names the file and the
//! clock N of the first mismatch. One file per model instance: its first failure's.
//!
//! *The design*, the simplest that works with the one-struct-per-clock FFI: the driver already
//! hands the model every clock's inputs as one struct, so the tape keeps those structs, except
//! that it stores only one byte for a clock that leaves the data ports alone (`keep` = 1: the
//! control bits `rst`, `in_valid`, `out_ready`, `keep`) and the whole struct only when the data
//! ports are written (`keep` = 0: a new span), which is exactly what the shim reads. A model is
//! deterministic, so the twin (the same Verilog, seeded alike) fed the same structs from the same
//! reset goes through the same clocks. The tape starts at the driver's reset and, after each
//! stream, is cut at the last reset that stream saw ([`crate::driver::Stress`]'s), so a replay
//! runs from the last reset before the failure (registers that no reset clears may power up
//! differently in the twin: a design that depends on them may fail differently there, which is
//! itself worth seeing). The window is [`BEFORE`] clocks before the first mismatch (or from
//! that reset) to [`AFTER`] clocks after it (or the stream's end). Failures the driver sees (the
//! protocol) carry their clock; for the scoreboard's, on the other thread, the tape notes the
//! clock of every output transfer and the checker the index of its first failing output. The
//! file is checked whole ([`check_fst`]) before it is named. With waveforms off nothing is taped
//! and the clock loop is the code it was: the recorder is a type parameter (`NoTape`).
//!
//! **Everything (`--trace DIR`).** [`trace_everything`] makes every model instance of the process
//! its traced twin, writing `DIR/<tag>-seed<seed>.fst` from its first clock (the `cosim` and
//! `render` binaries' `--trace`, for small runs: measured 45 bytes per clock for `seg_p8_span`
//! and 27 for the specular unit, at a quarter to an eighth of the untraced speed;
//! `docs/regressions.md`).
//!
//! **Time.** Clock N of a model instance (counted from its construction, reset clocks included,
//! the numbers every mismatch message uses) has its inputs applied with `clk` low at t = 10 N,
//! where the outputs are sampled too (the values its rising edge sees, as the harness reads
//! them), and its rising edge at t = 10 N + 5, in ns (a 100 MHz clock on screen).

use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, OnceLock};

/// Why a waveform was not written (or a traced model not made).
#[derive(Debug, thiserror::Error)]
pub enum TraceError {
    #[error("no traced model of {tag}: {why}")]
    NoTwin { tag: &'static str, why: String },
    #[error("the traced model {0} failed to construct")]
    Construct(&'static str),
    #[error("{0} is not a traced model")]
    NotTraced(&'static str),
    #[error("{}: {error}", path.display())]
    Io { path: PathBuf, error: std::io::Error },
    #[error("{}: a NUL in the path", .0.display())]
    Nul(PathBuf),
    #[error("{}: the FST writer cannot create it", .0.display())]
    Create(PathBuf),
    #[error("{}: the FST writer failed", .0.display())]
    Writer(PathBuf),
    #[error("{}: the FST writer failed to close it", .0.display())]
    Close(PathBuf),
    #[error("waveforms: trace_everything called twice")]
    Twice,
    #[error("waveforms are off")]
    Off,
    /// Written, but [`check_fst`] does not read it whole.
    #[error("written but unreadable: {0}")]
    Unreadable(FstError),
    #[error("{} holds clocks {} to {}, not {} to {}", path.display(), held.0, held.1, wanted.0, wanted.1)]
    Window { path: PathBuf, held: (u64, u64), wanted: (u64, u64) },
}

/// Nanoseconds per clock in a waveform file: clock N at t = 10 N (`clk` low), its edge at 10 N + 5.
pub const TIME_PER_CLOCK: u64 = 10;
/// Clocks before the first mismatch that a failure's waveform starts at (or the tape's reset).
pub const BEFORE: u64 = 1000;
/// Clocks after the first mismatch that a failure's waveform ends at (or the stream's end).
pub const AFTER: u64 = 100;

/// The folder failure waveforms go to: `COSIM_TRACE` at run time (read once), if set.
pub fn failure_dir() -> Option<&'static Path> {
    static DIR: OnceLock<Option<PathBuf>> = OnceLock::new();
    DIR.get_or_init(|| std::env::var_os("COSIM_TRACE").filter(|d| !d.is_empty()).map(PathBuf::from)).as_deref()
}

static EVERYTHING: OnceLock<PathBuf> = OnceLock::new();
/// The files [`trace_everything`] opened.
static WRITTEN: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// From now on every model instance this process builds ([`Rtl::new`]) is its traced twin,
/// writing every clock to a file of its own in `dir` (created if missing). Build the models'
/// twins first ([`crate::ffi::ModelInfo::require_traced`]): an instance whose twin cannot be
/// built panics.
pub fn trace_everything(dir: &Path) -> Result<(), TraceError> {
    std::fs::create_dir_all(dir).map_err(|error| TraceError::Io { path: dir.to_path_buf(), error })?;
    EVERYTHING.set(dir.to_path_buf()).map_err(|_| TraceError::Twice)
}

pub(crate) fn everything() -> Option<&'static Path> {
    EVERYTHING.get().map(PathBuf::as_path)
}

/// `dir/<tag>-seed<seed>.fst`, or `-2`, `-3`, ... after it when this process has used the name.
pub(crate) fn full_trace_path(dir: &Path, tag: &str, seed: u64) -> PathBuf {
    let mut written = WRITTEN.lock().unwrap_or_else(|e| e.into_inner());
    let mut path = dir.join(format!("{tag}-seed{seed}.fst"));
    for k in 2.. {
        if !written.contains(&path) {
            break;
        }
        path = dir.join(format!("{tag}-seed{seed}-{k}.fst"));
    }
    written.push(path.clone());
    path
}

/// The files [`trace_everything`] has opened so far, in order (complete once their models are
/// dropped).
pub fn written() -> Vec<PathBuf> {
    WRITTEN.lock().unwrap_or_else(|e| e.into_inner()).clone()
}

/// A waveform written for a failure: where, and the clock of the first mismatch.
#[derive(Clone, Debug, PartialEq)]
pub struct Waveform {
    pub path: PathBuf,
    pub clock: u64,
    /// The first and last clock in the file; `None`: the model's every clock (`--trace`).
    pub window: Option<(u64, u64)>,
}

impl fmt::Display for Waveform {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "waveform {}: clock {} at t = {} ns", self.path.display(), self.clock, self.clock * TIME_PER_CLOCK)?;
        match self.window {
            Some((a, b)) => write!(f, " (clocks {a} to {b})"),
            None => write!(f, " (every clock of the run)"),
        }
    }
}

/// A file [`check_fst`] does not read as a whole FST file.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{}: {problem}", path.display())]
pub struct FstError {
    pub path: PathBuf,
    pub problem: FstProblem,
}

/// What is wrong with the file.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FstProblem {
    #[error("{0}")]
    Read(String),
    #[error("not an FST file (no header block)")]
    NoHeader,
    #[error("header cut short")]
    ShortHeader,
    #[error("block at byte {at} cut short")]
    ShortBlock { at: usize },
    #[error("block {kind} at byte {at} runs past the end")]
    PastEnd { kind: usize, at: usize },
    #[error("{blocks} blocks: {vc} of value changes, {geometry} geometry, {hier} hierarchy (unfinished?)")]
    Unfinished { blocks: u64, vc: u64, geometry: u64, hier: u64 },
}

/// What [`check_fst`] found in a waveform file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FstSummary {
    /// The first and last clock the file holds.
    pub first: u64,
    pub last: u64,
    /// Variables in its hierarchy.
    pub vars: u64,
    /// Value-change blocks.
    pub blocks: u64,
}

/// Checks that `path` is a whole FST file: its header block, then blocks (a type byte and a
/// big-endian length) that end exactly at the end of the file, with a hierarchy, a geometry and
/// value changes among them, as GTKWave's `fstapi.c` writes them. No decompression: `fst2vcd`
/// (Debian's gtkwave) reads the values (`verilator-harness/tests/waveforms.rs`, `scripts/check-rtl-dir --trace`).
pub fn check_fst(path: &Path) -> Result<FstSummary, FstError> {
    let fail = |problem: FstProblem| FstError { path: path.to_path_buf(), problem };
    let bytes = std::fs::read(path).map_err(|e| fail(FstProblem::Read(e.to_string())))?;
    let u64_at = |at: usize| bytes.get(at..at + 8).map(|b| u64::from_be_bytes(b.try_into().expect("8 bytes")));
    // fstapi.h: FST_BL_HDR 0, VCDATA 1, GEOM 3, HIER 4, VCDATA_DYN_ALIAS 5, HIER_LZ4 6,
    // HIER_LZ4DUO 7, VCDATA_DYN_ALIAS2 8, BLACKOUT 2, SKIP 255.
    if bytes.first() != Some(&0) {
        return Err(fail(FstProblem::NoHeader));
    }
    // The header's fields after its type and length: start and end time, an endianness test,
    // memory used, scopes, variables.
    let (Some(start), Some(end), Some(vars)) = (u64_at(9), u64_at(17), u64_at(49)) else { return Err(fail(FstProblem::ShortHeader)) };
    let (mut at, mut kinds, mut blocks) = (0usize, [0u64; 256], 0);
    while at < bytes.len() {
        let kind = bytes[at] as usize;
        let len = u64_at(at + 1).ok_or_else(|| fail(FstProblem::ShortBlock { at }))? as usize;
        if len < 8 || at + 1 + len > bytes.len() {
            return Err(fail(FstProblem::PastEnd { kind, at }));
        }
        kinds[kind] += 1;
        blocks += 1;
        at += 1 + len;
    }
    let hier = kinds[4] + kinds[6] + kinds[7];
    let vc = kinds[1] + kinds[5] + kinds[8];
    if kinds[3] != 1 || hier != 1 || vc == 0 {
        return Err(fail(FstProblem::Unfinished { blocks, vc, geometry: kinds[3], hier }));
    }
    Ok(FstSummary { first: start / TIME_PER_CLOCK, last: end / TIME_PER_CLOCK, vars, blocks: vc })
}
