//! The driver's and the sink's per-clock decisions: one tiny deterministic generator, shared
//! bit for bit by the harness, the native C++ bench (`bench/native_tb.cpp`) and the cocotb
//! bench (`bench/cocotb/test_bench.py`), so all three see the same valid gaps and the same
//! backpressure from the same seed.
//!
//! The generator is xorshift32 (13, 17, 5). Every clock draws exactly two words, in this order:
//!
//! 1. `offer`: a pending span starts being offered iff `(word >> 24) < valid_thr`;
//! 2. `ready`: `out_ready` is high iff `(word >> 24) < ready_thr`.
//!
//! Thresholds are in 256ths (0 = never, 256 = always), so probabilities are quantized to 1/256:
//! [`Traffic::RANDOM`]'s 0.7 is 179/256. The offer draw is made even in clocks that do not use
//! it (a span already offered, none left), so the two streams never depend on the model.
//! The 32-bit start state comes from the run's 64-bit seed through splitmix64 ([`state_of`]);
//! the benches' stimulus files carry that state, so the other implementations need only the
//! three lines of xorshift.

use rand::RngCore;

/// How often the driver offers a span and the sink takes an output.
#[derive(Clone, Copy, Debug)]
pub struct Traffic {
    /// Probability per clock that a pending span starts being offered (quantized to 1/256).
    pub valid: f64,
    /// Probability per clock that `out_ready` is high (quantized to 1/256).
    pub ready: f64,
}

impl Traffic {
    /// Both ends always willing: measures the design's own throughput.
    pub const FULL: Traffic = Traffic { valid: 1.0, ready: 1.0 };
    /// Random gaps and backpressure.
    pub const RANDOM: Traffic = Traffic { valid: 0.7, ready: 0.7 };

    /// `valid` as a threshold in 256ths.
    pub fn valid_thr(&self) -> u32 {
        threshold(self.valid)
    }

    /// `ready` as a threshold in 256ths.
    pub fn ready_thr(&self) -> u32 {
        threshold(self.ready)
    }
}

/// A probability as a threshold in 256ths: 0..=256, 256 meaning always.
pub fn threshold(p: f64) -> u32 {
    (p * 256.0).round().clamp(0.0, 256.0) as u32
}

/// The xorshift32 start state of a run's seed: the high half of splitmix64(seed), never zero.
pub fn state_of(seed: u64) -> u32 {
    let mut z = seed.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^= z >> 31;
    match (z >> 32) as u32 {
        0 => 0x9e37_79b9,
        s => s,
    }
}

/// The traffic of one model under test: the generator and its two thresholds.
#[derive(Clone, Debug)]
pub struct TrafficGen {
    state: u32,
    valid_thr: u32,
    ready_thr: u32,
    offer: bool,
    ready: bool,
}

impl TrafficGen {
    pub fn new(traffic: Traffic, seed: u64) -> TrafficGen {
        TrafficGen::from_state(state_of(seed), traffic.valid_thr(), traffic.ready_thr())
    }

    /// A generator from its raw start state (non-zero) and thresholds, as a stimulus file gives them.
    pub fn from_state(state: u32, valid_thr: u32, ready_thr: u32) -> TrafficGen {
        assert!(state != 0, "xorshift32 state must not be zero");
        assert!(valid_thr <= 256 && ready_thr <= 256, "thresholds are in 256ths");
        TrafficGen { state, valid_thr, ready_thr, offer: false, ready: false }
    }

    pub fn state(&self) -> u32 {
        self.state
    }

    #[inline(always)]
    fn word(&mut self) -> u32 {
        let mut x = self.state;
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        self.state = x;
        x
    }

    /// Draws this clock's two decisions; [`TrafficGen::offer`] and [`TrafficGen::ready`] then
    /// read them.
    #[inline(always)]
    pub fn clock(&mut self) {
        self.offer = (self.word() >> 24) < self.valid_thr;
        self.ready = (self.word() >> 24) < self.ready_thr;
    }

    /// Whether a pending span starts being offered this clock.
    #[inline(always)]
    pub fn offer(&self) -> bool {
        self.offer
    }

    /// `out_ready` this clock.
    #[inline(always)]
    pub fn ready(&self) -> bool {
        self.ready
    }
}

/// Further draws from the same stream, for stress patterns on top of the two per clock (they
/// come after the clock's two draws, so a run without stress is the plain sequence).
impl RngCore for TrafficGen {
    fn next_u32(&mut self) -> u32 {
        self.word()
    }
    fn next_u64(&mut self) -> u64 {
        (self.word() as u64) << 32 | self.word() as u64
    }
    fn fill_bytes(&mut self, dest: &mut [u8]) {
        for chunk in dest.chunks_mut(4) {
            let w = self.word().to_le_bytes();
            chunk.copy_from_slice(&w[..chunk.len()]);
        }
    }
    fn try_fill_bytes(&mut self, dest: &mut [u8]) -> Result<(), rand::Error> {
        self.fill_bytes(dest);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reference sequence the C++ and Python benches are checked against.
    #[test]
    fn xorshift32_reference_words() {
        let mut g = TrafficGen::from_state(1, 256, 256);
        let words: Vec<u32> = (0..4).map(|_| g.word()).collect();
        assert_eq!(words, [270369, 67634689, 2647435461, 307599695]);
    }

    #[test]
    fn thresholds() {
        assert_eq!(Traffic::FULL.valid_thr(), 256);
        assert_eq!(Traffic::RANDOM.ready_thr(), 179);
        assert_eq!(threshold(0.0), 0);
        let mut g = TrafficGen::from_state(state_of(7), 256, 0);
        for _ in 0..1000 {
            g.clock();
            assert!(g.offer() && !g.ready());
        }
    }

    #[test]
    fn random_traffic_is_about_seventy_percent() {
        let mut g = TrafficGen::new(Traffic::RANDOM, 42);
        let (mut o, mut r) = (0, 0);
        for _ in 0..100_000 {
            g.clock();
            o += g.offer() as u32;
            r += g.ready() as u32;
        }
        for n in [o, r] {
            assert!((69_000..70_800).contains(&n), "{n} of 100000");
        }
    }

    #[test]
    fn seeds_differ_and_state_is_never_zero() {
        assert_ne!(state_of(1), state_of(2));
        assert!((0..10_000u64).all(|s| state_of(s) != 0));
    }
}
