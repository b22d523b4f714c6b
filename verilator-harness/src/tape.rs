//! The tape of a driver's inputs, replayed into a model's traced twin to write a failure's
//! waveform: the design is [`crate::waveform`]'s module comment. With waveforms off the clock
//! loop records into [`NoTape`], which compiles to nothing.

use crate::ffi::{Control, Rtl};
use crate::waveform::TraceError;
use std::path::Path;

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
    pub fn replay<O: Default>(&self, rtl: &mut Rtl<I, O>, from: u64, to: u64, path: &Path) -> Result<(), TraceError> {
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
