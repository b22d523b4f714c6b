//! Co-simulation of `specular_unit`: at least 200,000 pixels of random spans set up from random
//! normals and half-vectors, every k range and its boundaries, invalid n, zero-length spans,
//! random gaps and backpressure. Every pixel bit-exact, within SPEC §4, monotone along a span.

use golden::rng::SeedRng;
use golden::specular::reference::epicentre;
use golden::specular::{n_valid, theta_at, SpecularSpan, THETA_FRAC};
use rand::{Rng, SeedableRng};
use verilator_harness::cosim::{assert_clean, Report, Traffic, DRAIN_CLOCKS};
use verilator_harness::ffi::{require_models, require_specular_model, specular_unit, ModelInfo, SpecIn, SpecOut, SPECULAR_MODELS};
use verilator_harness::specular::{random_span, SpecularCosim};

const PIXELS: u64 = 200_000;

fn model(what: &str) -> Option<&'static ModelInfo<SpecIn, SpecOut>> {
    require_specular_model(&format!("specular: {what}"))
}

/// Every specular model built: SPEC's seed structure and each `--pipeline` form.
fn models(what: &str) -> &'static [ModelInfo<SpecIn, SpecOut>] {
    require_models(SPECULAR_MODELS, "specular unit", &format!("specular: {what}")).unwrap_or_default()
}

#[test]
fn random_spans_bit_exact_accurate_and_monotone() {
    let seed = verilator_harness::seed("random_spans_bit_exact_accurate_and_monotone");
    for info in models("random spans") {
        let mut rng = SeedRng::seed_from_u64(seed);
        let mut sim = SpecularCosim::new(info, specular_unit(), seed, Traffic::RANDOM);
        let mut report = Report::default();
        let mut seen_n = [false; 1024];
        // The SPEC §4 checks only bite where there is light: count pixels inside the epicentre.
        let (mut owed, mut inside) = (0u64, 0u64);
        while report.pixels < PIXELS {
            let mut spans: Vec<SpecularSpan> = (0..200).map(|_| random_span(&mut rng, info.cfg.max_len())).collect();
            // Empty spans anywhere in the stream take one transfer and yield nothing.
            for _ in 0..10 {
                let k = rng.gen_range(0..spans.len());
                spans[k].len = 0;
            }
            for s in &spans {
                seen_n[s.n as usize] = true;
                owed += s.len as u64;
                if n_valid(s.n as u32) {
                    let edge = epicentre(s.n as u32);
                    inside += (0..s.len)
                        .filter(|&j| (theta_at(s.theta0, s.dtheta, j).unsigned_abs() as f64) / (1u64 << THETA_FRAC) as f64 <= edge)
                        .count() as u64;
                }
            }
            sim.stream(&spans, &mut report);
            assert_clean(info.tag, seed, &report);
        }
        for n in [0, 1, 2, 3, 6, 7, 1000, 1001, 1023] {
            assert!(seen_n[n], "n = {n} never drawn (seed {seed})");
        }
        assert_eq!(report.pixels, owed, "every owed pixel came out");
        assert!(inside * 3 > owed, "only {inside} of {owed} pixels inside an epicentre (seed {seed})");
        eprintln!(
            "{}: {} spans, {} pixels ({inside} inside an epicentre), {} clocks",
            info.tag, report.spans, report.pixels, report.cycles
        );
    }
}

/// One pixel per clock sustained: a full-rate stream takes one clock per pixel plus the fill.
#[test]
fn one_pixel_per_clock_at_full_rate() {
    let seed = verilator_harness::seed("one_pixel_per_clock_at_full_rate");
    for info in models("full rate") {
        let mut rng = SeedRng::seed_from_u64(seed);
        let spans: Vec<SpecularSpan> = (0..300)
            .map(|_| {
                let mut s = random_span(&mut rng, info.cfg.max_len());
                s.len = s.len.max(1);
                s
            })
            .collect();
        let mut sim = SpecularCosim::new(info, specular_unit(), seed, Traffic::FULL);
        let mut report = Report::default();
        sim.stream(&spans, &mut report);
        assert_clean(info.tag, seed, &report);
        assert_eq!(report.cycles, report.pixels + info.latency as u64 + DRAIN_CLOCKS, "bubbles at full rate");
    }
}

/// The negative control of the table set build.rs takes from the manifest: the same model
/// checked against golden's unit for another `--brdf-k` set must fail, so a checker left on
/// the default plan would not pass RTL generated with other tables.
#[test]
fn a_golden_unit_of_another_table_set_is_caught() {
    use golden::specular::{SpecularPlan, SpecularUnit};
    let seed = verilator_harness::seed("a_golden_unit_of_another_table_set_is_caught");
    let Some(info) = model("another table set") else { return };
    let built = specular_unit();
    let other_ks: &[u32] = if built.plan().decoder.ks() == [1, 2, 3, 9] { &[1, 2, 4, 16] } else { &[1, 2, 3, 9] };
    let wrong = SpecularUnit::new(SpecularPlan::from_k_set(other_ks).expect("a valid set"));
    let mut rng = SeedRng::seed_from_u64(seed);
    let spans: Vec<SpecularSpan> = (0..400).map(|_| random_span(&mut rng, info.cfg.max_len())).collect();
    let mut sim = SpecularCosim::new(info, wrong, seed, Traffic::FULL);
    let mut report = Report::default();
    let _ = sim.try_stream(&spans, &mut report);
    assert!(report.mismatch_count > 0, "the model passed against golden's k = {other_ks:?} unit (seed {seed})");
}
