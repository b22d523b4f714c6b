//! What the driver asks of each unit it streams (segment shader, specular unit, writer,
//! front-end), and of the checker that judges the unit's outputs.

use crate::ffi::{Control, Handshake};
use crate::report::Report;

/// What the driving thread knows of a unit: how a span goes onto its ports, how many outputs
/// it owes, and the compact record of an output that the checker reads.
pub(crate) trait Unit: Sync {
    type In: Control;
    type Out: Handshake;
    type Span: Sync;
    /// Bytes of one output's record.
    fn record_bytes(&self) -> usize;
    fn load(&self, input: &mut Self::In, span: &Self::Span);
    /// Outputs (segments, pixels) the span yields.
    fn owed(&self, span: &Self::Span) -> u32;
    /// Writes the record of `out` into `rec` (`record_bytes` long).
    fn record(&self, out: &Self::Out, rec: &mut [u8]);
    /// Whether `out` is the output recorded in `held`, offered in the clock before and not
    /// taken (don't-care bits ignored).
    fn same(&self, held: &[u8], out: &Self::Out) -> bool;
    /// What differs when `out` is not [`Unit::same`] as `held`.
    fn describe_change(&self, held: &[u8], out: &Self::Out) -> String;
    /// Quiet clocks after the last expected output before the stream ends. A unit whose inputs
    /// may owe no output but a late side pulse (a front-end dropping a triangle) waits longer.
    fn drain_clocks(&self) -> u64 {
        DRAIN_CLOCKS
    }
    /// A one-clock side pulse of the unit (the front-end's `err`), counted in `Report::pulses`.
    #[inline(always)]
    fn pulse(&self, _out: &Self::Out) -> bool {
        false
    }
    /// The triangle (or span) to blame and a description, for a mismatch about span `k`.
    fn blame(&self, k: usize, span: &Self::Span) -> (Option<usize>, String);
}

/// The checking thread's side: output `j` of span `k`, as [`Unit::record`] wrote it. Outputs
/// come in transfer order; a span cut by a reset stops early, and the next record is of a
/// later span.
pub(crate) trait Check: Send {
    fn check(&mut self, k: usize, j: u32, rec: &[u8], report: &mut Report);
}

/// Clocks run after the last expected output, in which the model must stay quiet.
pub const DRAIN_CLOCKS: u64 = 3;
