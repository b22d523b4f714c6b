//! The model watched clock by clock: the output side of SPEC §3's valid/ready contract, and
//! whether anything moves at all.

use super::unit::Unit;
use crate::ffi::Handshake;

/// Clocks without any transfer after which the model is declared hung.
pub(super) const STALL_LIMIT: u64 = 10_000;

/// The output handshake's rules: `out_valid` is low in the first clock after a reset, and an
/// output offered and not taken stays offered, unchanged (don't-care bits aside), until taken.
pub(super) struct Monitor {
    /// The record of the output offered and not taken in the clock before, when `holding`.
    held: Vec<u8>,
    holding: bool,
    /// The clock before had `rst` high.
    in_reset: bool,
}

impl Monitor {
    /// A monitor for records of `record_bytes` bytes.
    pub(super) fn new(record_bytes: usize) -> Monitor {
        Monitor { held: vec![0; record_bytes], holding: false, in_reset: false }
    }

    /// A clock with `rst` high: nothing is held across it. True on the first of a run of them.
    #[inline]
    pub(super) fn reset(&mut self) -> bool {
        self.holding = false;
        !std::mem::replace(&mut self.in_reset, true)
    }

    /// A clock out of reset whose outputs were `out`, with `out_ready` = `ready`: each breach of
    /// the rules goes to `found`, in the order the rules are listed above.
    #[inline]
    pub(super) fn watch<U: Unit>(&mut self, unit: &U, out: &U::Out, ready: bool, mut found: impl FnMut(String)) {
        if std::mem::take(&mut self.in_reset) && out.out_valid() {
            found("out_valid high in the first clock after a reset".into());
        }
        if out.out_valid() {
            if std::mem::take(&mut self.holding) && !unit.same(&self.held, out) {
                found(unit.describe_change(&self.held, out));
            }
            if !ready {
                self.holding = true;
                unit.record(out, &mut self.held);
            }
        } else if std::mem::take(&mut self.holding) {
            found("out_valid dropped before the output offered was taken".into());
        }
    }
}

/// Liveness: a model that transfers nothing, in or out, for more than [`STALL_LIMIT`] clocks out
/// of reset is hung (even if it streams outputs nobody asked for), not followed forever.
#[derive(Default)]
pub(super) struct Stall {
    /// Clocks since the last transfer or reset.
    idle: u64,
}

impl Stall {
    /// A reset clock: the count starts again.
    #[inline]
    pub(super) fn reset(&mut self) {
        self.idle = 0;
    }

    /// The end of a clock out of reset, in which something transferred (`progress`) or not:
    /// whether the model is now hung.
    #[inline]
    pub(super) fn hung(&mut self, progress: bool) -> bool {
        self.idle = if progress { 0 } else { self.idle + 1 };
        self.idle > STALL_LIMIT
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ffi::SegIn;

    /// Outputs that are one byte of data and the valid flag.
    #[derive(Clone, Copy, Default)]
    struct Out {
        valid: bool,
        data: u8,
    }

    impl Handshake for Out {
        fn in_ready(&self) -> bool {
            true
        }
        fn out_valid(&self) -> bool {
            self.valid
        }
    }

    struct Bytes;

    impl Unit for Bytes {
        type In = SegIn;
        type Out = Out;
        type Span = ();
        fn record_bytes(&self) -> usize {
            1
        }
        fn load(&self, _input: &mut SegIn, _span: &()) {}
        fn owed(&self, _span: &()) -> u32 {
            0
        }
        fn record(&self, out: &Out, rec: &mut [u8]) {
            rec[0] = out.data;
        }
        fn same(&self, held: &[u8], out: &Out) -> bool {
            held[0] == out.data
        }
        fn describe_change(&self, held: &[u8], out: &Out) -> String {
            format!("{} became {}", held[0], out.data)
        }
        fn blame(&self, _k: usize, _span: &()) -> (Option<usize>, String) {
            (None, String::new())
        }
    }

    /// The breaches `outputs` (out_valid, data, out_ready per clock; `None` a reset clock) show.
    fn breaches(outputs: &[Option<(bool, u8, bool)>]) -> Vec<(usize, String)> {
        let (mut m, mut found) = (Monitor::new(1), Vec::new());
        for (clock, o) in outputs.iter().enumerate() {
            match *o {
                None => {
                    m.reset();
                }
                Some((valid, data, ready)) => m.watch(&Bytes, &Out { valid, data }, ready, |what| found.push((clock, what))),
            }
        }
        found
    }

    #[test]
    fn a_protocol_kept_shows_no_breach() {
        let held_then_taken = [Some((true, 7, false)), Some((true, 7, false)), Some((true, 7, true)), Some((true, 8, true))];
        assert_eq!(breaches(&held_then_taken), []);
        let reset_then_quiet = [Some((true, 1, false)), None, None, Some((false, 0, true)), Some((true, 2, true))];
        assert_eq!(breaches(&reset_then_quiet), [], "a reset lets go of a held output");
    }

    /// Negative controls: each rule broken once is reported once, at its clock.
    #[test]
    fn each_rule_broken_is_caught() {
        assert_eq!(breaches(&[None, Some((true, 1, true))]), [(1, "out_valid high in the first clock after a reset".to_string())]);
        assert_eq!(breaches(&[Some((true, 1, false)), Some((true, 2, true))]), [(1, "1 became 2".to_string())]);
        assert_eq!(
            breaches(&[Some((true, 1, false)), Some((false, 1, true))]),
            [(1, "out_valid dropped before the output offered was taken".to_string())]
        );
    }

    #[test]
    fn the_model_is_hung_after_the_limit_of_idle_clocks() {
        let mut s = Stall::default();
        assert!((0..STALL_LIMIT).all(|_| !s.hung(false)));
        assert!(!s.hung(true), "a transfer starts the count again");
        assert!((0..STALL_LIMIT).all(|_| !s.hung(false)));
        s.reset();
        assert!((0..STALL_LIMIT).all(|_| !s.hung(false)));
        assert!(s.hung(false), "clock {} without a transfer", STALL_LIMIT + 1);
    }
}
