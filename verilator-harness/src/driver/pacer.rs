//! The per-clock traffic decisions of the driver and the sink, with the stress on top.

use crate::traffic::TrafficGen;
use rand::Rng;

/// Stress on top of [`crate::traffic::Traffic`], off by default: `rst` at random clocks, long
/// stretches of `out_ready` low, long `in_valid` gaps between spans. With a reset, the spans
/// accepted and not yet fully out are *cut* (their remaining output is dropped from the
/// scoreboard) and a span being offered is offered again afterwards; in a clock with `rst`
/// high nothing transfers.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stress {
    /// Probability per clock of asserting `rst` (for 1..=3 clocks).
    pub reset: f64,
    /// Probability per clock that `out_ready` drops for 1..=`stall_max` clocks.
    pub stall: f64,
    pub stall_max: u32,
    /// Probability after each input transfer of an `in_valid` gap of 1..=`gap_max` clocks.
    pub gap: f64,
    pub gap_max: u32,
}

impl Stress {
    pub const NONE: Stress = Stress { reset: 0.0, stall: 0.0, stall_max: 0, gap: 0.0, gap_max: 0 };
    /// Long backpressure bursts and input gaps, no reset.
    pub const BURSTS: Stress = Stress { reset: 0.0, stall: 0.01, stall_max: 300, gap: 0.05, gap_max: 200 };
    /// Everything at once: resets about every 500 clocks, bursts and gaps.
    pub const HARSH: Stress = Stress { reset: 0.002, ..Stress::BURSTS };
}

/// The per-clock decisions of the driver and the sink under `Traffic` and [`Stress`]: the
/// generator's two draws of the clock ([`TrafficGen::clock`]), then the stress draws. Without
/// stress it is exactly the plain traffic of the native and cocotb benches, and with `ON`
/// false (no stress) the stress draws are compiled out of the clock loop.
pub(super) struct Pacer<const ON: bool> {
    /// The unit's traffic, moved here for the clock loop: behind the driver, whose ports every
    /// call into the model may touch, it would be stored and reloaded around each call.
    pub(super) rng: TrafficGen,
    stress: Stress,
    rst_left: u32,
    stall_left: u32,
    gap_left: u32,
}

impl<const ON: bool> Pacer<ON> {
    pub(super) fn new(stress: Stress, rng: TrafficGen) -> Self {
        Pacer { rng, stress, rst_left: 0, stall_left: 0, gap_left: 0 }
    }

    /// Draws this clock's traffic.
    #[inline]
    pub(super) fn clock(&mut self) {
        self.rng.clock();
    }

    /// Whether `rst` is high this clock.
    #[inline]
    pub(super) fn reset(&mut self) -> bool {
        if !ON {
            return false;
        }
        if self.rst_left == 0 && self.stress.reset > 0.0 && self.rng.gen_bool(self.stress.reset) {
            self.rst_left = self.rng.gen_range(1..=3);
        }
        if self.rst_left > 0 {
            self.rst_left -= 1;
            return true;
        }
        false
    }

    /// Whether a pending span starts being offered this clock.
    #[inline]
    pub(super) fn offer(&mut self) -> bool {
        if ON && self.gap_left > 0 {
            self.gap_left -= 1;
            return false;
        }
        self.rng.offer()
    }

    /// `out_ready` this clock.
    #[inline]
    pub(super) fn ready(&mut self) -> bool {
        if !ON {
            return self.rng.ready();
        }
        if self.stall_left == 0 && self.stress.stall > 0.0 && self.rng.gen_bool(self.stress.stall) {
            self.stall_left = self.rng.gen_range(1..=self.stress.stall_max.max(1));
        }
        if self.stall_left > 0 {
            self.stall_left -= 1;
            return false;
        }
        self.rng.ready()
    }

    /// A span was transferred: maybe a gap before the next one is offered.
    #[inline]
    pub(super) fn accepted(&mut self) {
        if ON && self.stress.gap > 0.0 && self.rng.gen_bool(self.stress.gap) {
            self.gap_left = self.rng.gen_range(1..=self.stress.gap_max.max(1));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::traffic::Traffic;

    #[test]
    fn an_unstressed_pacer_is_the_plain_traffic() {
        let (mut plain, mut pacer) =
            (TrafficGen::new(Traffic::RANDOM, 9), Pacer::<false>::new(Stress::NONE, TrafficGen::new(Traffic::RANDOM, 9)));
        for _ in 0..10_000 {
            plain.clock();
            pacer.clock();
            assert!(!pacer.reset());
            assert_eq!((pacer.offer(), pacer.ready()), (plain.offer(), plain.ready()));
        }
    }
}
