//! Co-simulation of every `specular_unit` model: 200,000 pixels each (or `SEGSHADE_SOAK_PIXELS`,
//! in slices: `verilator_harness::soak`) of random spans set up from random normals and
//! half-vectors, every k range and its boundaries, invalid n, zero-length spans, random gaps and
//! backpressure. Every pixel bit-exact, within SPEC §4, monotone along a span.

use golden::rng::SeedRng;
use golden::specular::reference::epicentre;
use golden::specular::{n_valid, theta_at, SpecularSpan, THETA_FRAC};
use rand::{Rng, SeedableRng};
use verilator_harness::ffi::{ModelInfo, SpecIn, SpecOut};
use verilator_harness::registry::{require_models, require_specular_model, specular_unit, SPECULAR_MODELS};
use verilator_harness::segment::{assert_clean, Report, Traffic, DRAIN_CLOCKS};
use verilator_harness::soak;
use verilator_harness::specular::{random_span, SpecularCosim};

/// The values of n every slice streams first (one span each, at least one pixel long): the ends of
/// every k range, and invalid n at both ends of the port.
const COVER_N: [u16; 9] = [0, 1, 2, 3, 6, 7, 1000, 1001, 1023];
/// The longest span `random_span` draws.
const MAX_SPAN: u64 = 400;

fn model(what: &str) -> Option<&'static ModelInfo<SpecIn, SpecOut>> {
    require_specular_model(&format!("specular: {what}"))
}

/// Every specular model built: SPEC's seed structure and each `--pipeline` form.
fn models(what: &str) -> &'static [ModelInfo<SpecIn, SpecOut>] {
    require_models(&SPECULAR_MODELS, "specular unit", &format!("specular: {what}")).unwrap_or_default()
}

/// Slice `k` of the random spans, for every specular model: exactly its [`soak::share`] of
/// [`soak::pixels`] (200,000 per model by default; `SEGSHADE_SOAK_PIXELS` or
/// `SEGSHADE_SOAK_TRIANGLES` soak), from spans set up from random normals and half-vectors, with
/// zero-length spans mixed in; the last span is cut to what the slice still owes. Every pixel
/// bit-exact, within SPEC §4, monotone along its span.
fn random_span_slice(k: u32) {
    let base = verilator_harness::seed(&format!("random_spans::slice_{k}"));
    for info in models("random spans") {
        random_spans_of(info, base, k);
    }
}

fn random_spans_of(info: &'static ModelInfo<SpecIn, SpecOut>, base: u64, k: u32) {
    let seed = soak::slice_seed(base, info.tag, k);
    let (_, share) = soak::share(soak::pixels(), k);
    let mut rng = SeedRng::seed_from_u64(seed);
    let mut sim = SpecularCosim::new(info, specular_unit(), seed, Traffic::RANDOM);
    let mut report = Report::default();
    let mut seen_n = [false; 1024];
    // Pixels inside the epicentre, where the SPEC §4 checks bite (printed; how many the mix
    // lights is random_span's own test, on a fixed seed).
    let (mut owed, mut inside) = (0u64, 0u64);
    let mut batch = 0;
    while owed < share {
        let mut spans: Vec<SpecularSpan> = (0..200).map(|_| random_span(&mut rng, info.cfg.max_len())).collect();
        // Empty spans anywhere in the stream take one transfer and yield nothing.
        for _ in 0..10 {
            let j = rng.gen_range(0..spans.len());
            spans[j].len = 0;
        }
        if batch == 0 {
            for (s, n) in spans.iter_mut().zip(COVER_N) {
                s.n = n;
                s.len = s.len.max(1);
            }
        }
        batch += 1;
        for s in spans.iter_mut() {
            s.len = s.len.min((share - owed) as u32);
            owed += s.len as u64;
            if s.len > 0 {
                seen_n[s.n as usize] = true;
            }
            if n_valid(s.n as u32) {
                let edge = epicentre(s.n as u32);
                inside += (0..s.len)
                    .filter(|&j| (theta_at(s.theta0, s.dtheta, j).unsigned_abs() as f64) / (1u64 << THETA_FRAC) as f64 <= edge)
                    .count() as u64;
            }
        }
        sim.stream(&spans, &mut report);
        assert_clean(&format!("{} slice {k}", info.tag), base, &report);
    }
    // By construction: the first spans carry COVER_N, each at least a pixel, and the slice owes
    // room for all of them unless it is tiny.
    if share >= COVER_N.len() as u64 * MAX_SPAN {
        for n in COVER_N {
            assert!(seen_n[n as usize], "n = {n} never streamed (seed {base})");
        }
    }
    assert_eq!((report.pixels, owed), (share, share), "every owed pixel came out, and the slice owed its share");
    eprintln!(
        "{} slice {k}/{}: {} spans, {} pixels ({inside} inside an epicentre), {} clocks",
        info.tag,
        soak::SLICES,
        report.spans,
        report.pixels,
        report.cycles
    );
}

/// `specular::random_spans::slice_<k>`: the random test, one test per soak slice.
mod random_spans {
    soak_slices!(super::random_span_slice);
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
    // Random spans until golden's two units disagree on a pixel: then the checker must see a
    // mismatch for every seed, by construction (the two table sets differ inside most epicentres,
    // so the first 400 spans nearly always suffice).
    let differs =
        |s: &SpecularSpan| (0..s.len).any(|j| built.pixel(s.c, s.n, s.theta0, s.dtheta, j) != wrong.pixel(s.c, s.n, s.theta0, s.dtheta, j));
    let mut spans: Vec<SpecularSpan> = Vec::new();
    while spans.len() < 400 || !spans.iter().any(differs) {
        assert!(spans.len() < 100_000, "golden's units for {:?} and {other_ks:?} agree on 100,000 random spans", built.plan().decoder.ks());
        spans.extend((0..400).map(|_| random_span(&mut rng, info.cfg.max_len())));
    }
    let mut sim = SpecularCosim::new(info, wrong, seed, Traffic::FULL);
    let mut report = Report::default();
    let _ = sim.try_stream(&spans, &mut report);
    assert!(report.mismatch_count > 0, "the model passed against golden's k = {other_ks:?} unit (seed {seed})");
}

/// `--pipeline 2`'s unit, whose split multiplies' partial products are shifts and adds in logic
/// (no multiplier; `golden::pipeline::Pipeline::logic_products`), built on first use: bit-exact
/// on random spans under random gaps and backpressure, and a fault planted in each of its two
/// shift-add multiplies caught on the same spans (an argument slice's bit at the wrong weight, a
/// bit of the BRDF word read from its neighbour). Slow tier: three models to build, about a
/// minute of CPU each on a cold cache, then seconds.
#[test]
#[ignore]
fn logic_products_are_bit_exact_and_their_planted_faults_are_caught() {
    if verilator_harness::registry::rtl_dir().is_some() {
        eprintln!("specular logic products: skipped: COSIM_RTL_DIR provides the models");
        return;
    }
    let opts = hdl_gen::Options { pipeline: golden::pipeline::Pipeline::at(2), ..Default::default() };
    assert!(opts.pipeline.logic_products(), "level 2 is the shift-add form");
    let base = verilator_harness::ondemand::describe(&opts, verilator_harness::models::Kind::Specular).unwrap_or_else(|e| panic!("{e}"));
    let unit = &base.sources.iter().find(|(n, _)| n == "specular_unit.v").expect("the unit's file").1;
    let code = |l: &&str| !l.trim_start().starts_with("//") && !l.contains("// ");
    assert!(unit.lines().filter(code).all(|l| !l.contains(" * ")), "a multiply left in the level-2 unit");
    let seed = verilator_harness::seed("specular logic products");
    let mut rng = SeedRng::seed_from_u64(seed);
    let max_len = base.cfg.max_len();
    let spans: Vec<SpecularSpan> = (0..2000).map(|_| random_span(&mut rng, max_len)).collect();
    let run = |m: &verilator_harness::models::Model| {
        let info = verilator_harness::ondemand::load::<SpecIn, SpecOut>(m).unwrap_or_else(|e| panic!("{e}"));
        let mut sim = SpecularCosim::new(info, specular_unit(), seed, Traffic::RANDOM);
        let mut report = Report::default();
        sim.try_stream(&spans, &mut report).expect("spans the ports carry");
        report
    };
    let clean = run(&base);
    assert_clean(&base.tag, seed, &clean);
    assert!(clean.pixels > 100_000, "{} pixels compared", clean.pixels);
    let line = |start: &str| unit.lines().find(|l| l.contains(start)).unwrap_or_else(|| panic!("no {start}")).to_string();
    let (arg, cmul) = (line("pp1_1 = "), line("cp3_0 = "));
    let faults = [
        (arg.clone(), arg.replacen("<< 3)", "<< 2)", 1), "an argument slice's top bit at the next weight down"),
        (cmul.clone(), cmul.replacen("w3q[1]", "w3q[0]", 1), "the BRDF word's bit 1 read from bit 0"),
    ];
    for (k, (from, to, what)) in faults.into_iter().enumerate() {
        assert_ne!(from, to, "{what}: the fault does not apply");
        let mut m = base.clone();
        let text = m.sources.iter_mut().find(|(n, _)| n == "specular_unit.v").expect("the unit's file");
        text.1 = text.1.replacen(&from, &to, 1);
        m.tag = format!("{}_fault{k}", base.tag);
        let report = run(&m);
        eprintln!("{what}: {} mismatches of {} pixels", report.mismatch_count, report.pixels);
        assert!(report.mismatch_count > 0, "planted fault not caught: {what} (seed {seed})");
    }
}
