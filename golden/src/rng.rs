//! The one random generator behind every seeded stream (tests, co-simulation, benches), named
//! so a printed seed replays the same stimulus after a dependency upgrade.
//!
//! `rand::rngs::StdRng` is documented as *not* reproducible across `rand` versions: it may switch
//! algorithm in any release. `ChaCha12Rng` from `rand_chacha` is a fixed algorithm, and the one
//! `StdRng` wraps in rand 0.8, so the seeds printed before the switch still replay.

pub type SeedRng = rand_chacha::ChaCha12Rng;

#[cfg(test)]
mod tests {
    use super::SeedRng;
    use rand::{RngCore, SeedableRng};

    /// Pins the stream: if an upgrade changed what a seed draws, old seeds would stop
    /// replaying, and this fails first.
    #[test]
    fn a_seed_draws_what_it_always_drew() {
        let mut rng = SeedRng::seed_from_u64(20_250_601);
        let got: Vec<u64> = (0..3).map(|_| rng.next_u64()).collect();
        assert_eq!(got, PINNED, "the seeded generator's stream changed");
    }

    // Also what rand 0.8's StdRng drew for this seed, so seeds printed before the switch replay.
    const PINNED: [u64; 3] = [5210945893867167669, 16732692142646868246, 16755272352782700768];
}
