//! Soak mode: how much random stimulus the suites' random tests draw, and how it is cut into
//! slices so that a regression split across machines (`cargo nextest run --partition`) still
//! draws exactly that much.
//!
//! nextest partitions by test, so one configuration's random triangles cannot be one test: each
//! segment-shader model's random test is [`SLICES`] tests (`segment::random_triangles::<model>::
//! slice_<k>`), and the specular units' random test is [`SLICES`] tests too. Slice `k` of a
//! total `N` draws [`share`]`(N, k)` triangles (pixels), numbered from [`share`]'s first, from a
//! seed derived from the test's base seed, the model and `k` ([`slice_seed`]). The slices of a
//! model add up to exactly `N` whatever the number of shards and however nextest deals them out,
//! since every test runs in exactly one shard.
//!
//! - [`TRIANGLES_VAR`] (`SEGSHADE_SOAK_TRIANGLES`): random triangles per segment-shader model
//!   (per p, alignment and pipeline level), [`DEFAULT_TRIANGLES`] when unset;
//! - [`PIXELS_VAR`] (`SEGSHADE_SOAK_PIXELS`): random specular pixels per run and specular model,
//!   [`PIXELS_PER_TRIANGLE`] × the triangles when only `SEGSHADE_SOAK_TRIANGLES` is set,
//!   [`DEFAULT_PIXELS`] when neither is.
//!
//! A bad value (not a whole number, or 0) stops the test that reads it with a message naming the
//! variable. Measurements and the CI matrix: `docs/regressions.md`.

/// Random tests per soaked configuration. Fixed, not the shard count: a test's seed and its
/// share of the stimulus must not depend on how many machines run the regression.
pub const SLICES: u32 = 8;
/// Random triangles per segment-shader model.
pub const TRIANGLES_VAR: &str = "SEGSHADE_SOAK_TRIANGLES";
/// Random specular pixels per run.
pub const PIXELS_VAR: &str = "SEGSHADE_SOAK_PIXELS";
/// Triangles per model with the variable unset: the fast suite's.
pub const DEFAULT_TRIANGLES: u64 = 2_000;
/// Specular pixels with neither variable set: the fast suite's.
pub const DEFAULT_PIXELS: u64 = 200_000;
/// Specular pixels per soaked triangle when only [`TRIANGLES_VAR`] is set (the fast suite's
/// ratio), so one variable scales both.
pub const PIXELS_PER_TRIANGLE: u64 = DEFAULT_PIXELS / DEFAULT_TRIANGLES;

/// A soak variable's value: `None` when unset or empty, else a whole number of at least 1
/// (`_` may group digits: `1_000_000`).
pub fn parse(var: &str, value: Option<&str>) -> Result<Option<u64>, String> {
    let Some(v) = value.map(str::trim).filter(|v| !v.is_empty()) else { return Ok(None) };
    match v.replace('_', "").parse::<u64>() {
        Ok(0) => Err(format!("{var}=0: at least 1 is needed (unset it for the fast suite)")),
        Ok(n) => Ok(Some(n)),
        Err(_) => Err(format!("{var}='{v}' is not a whole number (e.g. {var}=1000000)")),
    }
}

fn read(var: &str) -> Option<u64> {
    parse(var, std::env::var(var).ok().as_deref()).unwrap_or_else(|e| panic!("{e}"))
}

/// Random triangles per segment-shader model: [`TRIANGLES_VAR`] or [`DEFAULT_TRIANGLES`].
pub fn triangles() -> u64 {
    read(TRIANGLES_VAR).unwrap_or(DEFAULT_TRIANGLES)
}

/// Random specular pixels per run: [`PIXELS_VAR`], else [`PIXELS_PER_TRIANGLE`] ×
/// [`TRIANGLES_VAR`], else [`DEFAULT_PIXELS`].
pub fn pixels() -> u64 {
    read(PIXELS_VAR).or_else(|| read(TRIANGLES_VAR).map(|t| t.saturating_mul(PIXELS_PER_TRIANGLE))).unwrap_or(DEFAULT_PIXELS)
}

/// Slice `k` of `total` (k < [`SLICES`]): (its first item, how many). The first `total %
/// SLICES` slices take one more, so the slices tile `0..total` exactly.
pub fn share(total: u64, k: u32) -> (u64, u64) {
    assert!(k < SLICES, "slice {k} of {SLICES}");
    let (base, extra, k) = (total / SLICES as u64, total % SLICES as u64, k as u64);
    (k * base + k.min(extra), base + (k < extra) as u64)
}

/// The seed of slice `k` of `model`'s random test, from the test's base seed: distinct per
/// model and slice, and the same on every machine (SplitMix64 over FNV-1a of the name).
pub fn slice_seed(base: u64, model: &str, k: u32) -> u64 {
    let name = model.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| (h ^ b as u64).wrapping_mul(0x0100_0000_01b3));
    let mut z = base ^ name.rotate_left(17) ^ (k as u64 + 1).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The soak variables as set, for a replay command (empty with both unset).
pub fn replay_env() -> String {
    [TRIANGLES_VAR, PIXELS_VAR]
        .iter()
        .filter_map(|v| std::env::var(v).ok().filter(|s| !s.trim().is_empty()).map(|s| format!(" {v}={}", s.trim())))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slices_tile_the_total_exactly() {
        for total in [1, 2, 7, 8, 9, 15, 16, 17, 2_000, 1_000_000, 1_000_003] {
            let mut next = 0;
            for k in 0..SLICES {
                let (first, n) = share(total, k);
                assert_eq!(first, next, "total {total}, slice {k}");
                next += n;
            }
            assert_eq!(next, total, "total {total}");
        }
        assert_eq!(share(2_000, 3), (750, 250));
    }

    #[test]
    fn slice_seeds_differ_by_model_and_slice() {
        let mut seen = std::collections::HashSet::new();
        for model in ["seg_p1_span", "seg_p1_screen", "seg_p8_span", "seg_p8_span_pl1", "spec"] {
            for k in 0..SLICES {
                assert!(seen.insert(slice_seed(42, model, k)), "{model} slice {k}");
            }
        }
        assert_eq!(slice_seed(42, "seg_p8_span", 3), slice_seed(42, "seg_p8_span", 3));
        assert_ne!(slice_seed(42, "seg_p8_span", 3), slice_seed(43, "seg_p8_span", 3));
    }

    #[test]
    fn bad_values_are_refused_with_the_variable_named() {
        assert_eq!(parse(TRIANGLES_VAR, None), Ok(None));
        assert_eq!(parse(TRIANGLES_VAR, Some(" ")), Ok(None));
        assert_eq!(parse(TRIANGLES_VAR, Some("1_000_000")), Ok(Some(1_000_000)));
        assert_eq!(parse(TRIANGLES_VAR, Some(" 250 ")), Ok(Some(250)));
        for bad in ["0", "-5", "1e6", "many", "1.5"] {
            let e = parse(TRIANGLES_VAR, Some(bad)).expect_err(bad);
            assert!(e.starts_with("SEGSHADE_SOAK_TRIANGLES="), "{e}");
        }
    }
}
