//! Waveforms: FST files of the verilated models, to look at a failure in GTKWave or Surfer.
//!
//! **On failure (`COSIM_TRACE=DIR`).** Built with COSIM_TRACE set, every streaming model has a
//! traced twin (`verilator --trace-fst`: [`crate::ffi::TracedModel`]; a default build has one for
//! `seg_p2_span` only). Run with it set, every driver keeps a [`Tape`] of what it put on its
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
//! and the clock loop is the code it was: the recorder is a type parameter ([`NoTape`]).
//!
//! **Everything (`--trace DIR`).** [`trace_everything`] makes every model instance of the process
//! its traced twin, writing `DIR/<tag>-seed<seed>.fst` from its first clock (the `cosim` and
//! `render` binaries' `--trace`, for small runs: a few hundred bytes per clock).
//!
//! **Time.** Clock N of a model instance (counted from its construction, reset clocks included,
//! the numbers every mismatch message uses) has its inputs applied with `clk` low at t = 10 N,
//! where the outputs are sampled too (the values its rising edge sees, as the harness reads
//! them), and its rising edge at t = 10 N + 5, in ns (a 100 MHz clock on screen).

use crate::driver::Control;
use crate::ffi::{ModelInfo, Rtl};
use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, OnceLock};

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
/// writing every clock to a file of its own in `dir` (created if missing). Check first that the
/// models to run have twins ([`require_traced`]): an instance without one panics.
pub fn trace_everything(dir: &Path) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    EVERYTHING.set(dir.to_path_buf()).map_err(|_| "waveforms: trace_everything called twice".to_string())
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

/// For `--trace`: an error message unless `info` has a traced twin in this build.
pub fn require_traced<I, O>(info: &ModelInfo<I, O>) -> Result<(), String> {
    if info.traced.is_some() {
        return Ok(());
    }
    Err(format!(
        "--trace: this build has no traced model of {} (traced models are built when COSIM_TRACE is set at build time, e.g. \
         COSIM_TRACE=target/waves cargo run --release -p verilator-harness --bin ...)",
        info.tag
    ))
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

/// What the clock loop tells the tape ([`Tape`]; [`NoTape`] with waveforms off).
pub(crate) trait Recorder<I> {
    /// Clock `clock` was stepped with `input`.
    fn clock(&mut self, clock: u64, input: &I);
    /// An output transferred in clock `clock`: the stream's next record.
    fn transfer(&mut self, clock: u64);
    /// The driver found a mismatch in clock `clock`.
    fn found(&mut self, clock: u64);
    /// A reset starts at clock `clock`, the next to be stepped.
    fn reset(&mut self, clock: u64);
}

/// Waveforms off: nothing recorded, and nothing left in the clock loop.
pub(crate) struct NoTape;

impl<I> Recorder<I> for NoTape {
    #[inline(always)]
    fn clock(&mut self, _clock: u64, _input: &I) {}
    #[inline(always)]
    fn transfer(&mut self, _clock: u64) {}
    #[inline(always)]
    fn found(&mut self, _clock: u64) {}
    #[inline(always)]
    fn reset(&mut self, _clock: u64) {}
}

/// [`Control::control`]'s bits, and the tape's own: this clock's whole struct is stored.
const RST: u8 = 1;
const VALID: u8 = 2;
const READY: u8 = 4;
const KEEP: u8 = 8;
const STORED: u8 = 16;

/// Every clock's inputs since a reset (see the module comment), and where this stream's outputs
/// and first mismatch happened.
pub(crate) struct Tape<I> {
    /// The clock of `ctl[0]`, a reset's first.
    start: u64,
    /// Per clock: the control bits, and [`STORED`] when the clock's struct is in `data`.
    ctl: Vec<u8>,
    data: Vec<I>,
    /// Store the next clock's struct whatever its `keep` (a replay may start there).
    force: bool,
    /// The last reset seen: (clock, `ctl` and `data` lengths then), where the tape is cut when
    /// the stream ends.
    cut: Option<(u64, usize, usize)>,
    /// This stream: the clock of each output transfer, in record order.
    pub transfers: Vec<u64>,
    /// This stream: the clock of the driver's first mismatch.
    pub found: Option<u64>,
}

impl<I: Control> Tape<I> {
    /// An empty tape whose first clock, `start`, is a reset's.
    pub fn new(start: u64) -> Tape<I> {
        Tape { start, ctl: Vec::new(), data: Vec::new(), force: true, cut: None, transfers: Vec::new(), found: None }
    }

    pub fn new_stream(&mut self) {
        self.transfers.clear();
        self.found = None;
    }

    /// After a stream (and its waveform): forget what came before its last reset.
    pub fn end_stream(&mut self) {
        if let Some((clock, ctl, data)) = self.cut.take() {
            self.ctl.drain(..ctl);
            self.data.drain(..data);
            self.start = clock;
        }
    }

    /// The clocks on the tape, first and last.
    pub fn clocks(&self) -> (u64, u64) {
        (self.start, (self.start + self.ctl.len() as u64).saturating_sub(1))
    }

    /// Steps `rtl` (a traced twin, fresh) through the tape up to clock `to`, writing clocks
    /// `from..=to` to the FST file at `path`.
    pub fn replay<O: Default>(&self, rtl: &mut Rtl<I, O>, from: u64, to: u64, path: &Path) -> Result<(), String> {
        let (mut input, mut output) = (I::default(), O::default());
        let mut data = self.data.iter();
        for (k, &c) in self.ctl.iter().enumerate() {
            let clock = self.start + k as u64;
            if clock > to {
                break;
            }
            if clock == from {
                rtl.open_waves(path, clock)?;
            }
            if c & STORED != 0 {
                input = *data.next().expect("a struct for every STORED clock");
            }
            input.set_control(c & RST != 0, c & VALID != 0, c & READY != 0);
            input.keep_data(c & KEEP != 0 && c & STORED == 0);
            rtl.step_into(&input, &mut output);
        }
        rtl.close_waves()
    }
}

impl<I: Control> Recorder<I> for Tape<I> {
    #[inline]
    fn clock(&mut self, clock: u64, input: &I) {
        debug_assert_eq!(clock, self.start + self.ctl.len() as u64, "the tape missed a clock");
        let c = input.control();
        let stored = std::mem::take(&mut self.force) || c & KEEP == 0;
        if stored {
            self.data.push(*input);
        }
        self.ctl.push(c | if stored { STORED } else { 0 });
    }

    #[inline]
    fn transfer(&mut self, clock: u64) {
        self.transfers.push(clock);
    }

    fn found(&mut self, clock: u64) {
        self.found.get_or_insert(clock);
    }

    fn reset(&mut self, clock: u64) {
        debug_assert_eq!(clock, self.start + self.ctl.len() as u64, "a reset off the tape's end");
        self.cut = Some((clock, self.ctl.len(), self.data.len()));
        self.force = true;
    }
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
/// (Debian's gtkwave) reads the values (`tests/waveforms.rs`, `scripts/check-rtl-dir --trace`).
pub fn check_fst(path: &Path) -> Result<FstSummary, String> {
    let fail = |what: &str| format!("{}: {what}", path.display());
    let bytes = std::fs::read(path).map_err(|e| fail(&e.to_string()))?;
    let u64_at = |at: usize| bytes.get(at..at + 8).map(|b| u64::from_be_bytes(b.try_into().expect("8 bytes")));
    // fstapi.h: FST_BL_HDR 0, VCDATA 1, GEOM 3, HIER 4, VCDATA_DYN_ALIAS 5, HIER_LZ4 6,
    // HIER_LZ4DUO 7, VCDATA_DYN_ALIAS2 8, BLACKOUT 2, SKIP 255.
    if bytes.first() != Some(&0) {
        return Err(fail("not an FST file (no header block)"));
    }
    // The header's fields after its type and length: start and end time, an endianness test,
    // memory used, scopes, variables.
    let (Some(start), Some(end), Some(vars)) = (u64_at(9), u64_at(17), u64_at(49)) else { return Err(fail("header cut short")) };
    let (mut at, mut kinds, mut blocks) = (0usize, [0u64; 256], 0);
    while at < bytes.len() {
        let kind = bytes[at] as usize;
        let len = u64_at(at + 1).ok_or_else(|| fail(&format!("block at byte {at} cut short")))? as usize;
        if len < 8 || at + 1 + len > bytes.len() {
            return Err(fail(&format!("block {kind} at byte {at} runs past the end")));
        }
        kinds[kind] += 1;
        blocks += 1;
        at += 1 + len;
    }
    let hier = kinds[4] + kinds[6] + kinds[7];
    let vc = kinds[1] + kinds[5] + kinds[8];
    if kinds[3] != 1 || hier != 1 || vc == 0 {
        return Err(fail(&format!("{blocks} blocks: {vc} of value changes, {} geometry, {hier} hierarchy (unfinished?)", kinds[3])));
    }
    Ok(FstSummary { first: start / TIME_PER_CLOCK, last: end / TIME_PER_CLOCK, vars, blocks: vc })
}
