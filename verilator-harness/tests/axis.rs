//! The AXI4-Stream wrappers (`generate --bus axis`) against golden, through the same drivers and
//! scoreboards as their cores: build.rs drives each wrapper with its core's per-clock structs,
//! packed and unpacked by code it prints from the typed layout (`hdl_gen::axis`). A default build
//! has `segment_shader_p8_axis` and `specular_unit_axis`; COSIM_RTL_DIR every wrapper its folder
//! lists. The runs are shorter than the cores' own suites: the cores are the same RTL, checked
//! there; what is new here is the packing, which any one wrong bit of shows within a few spans.

use golden::rng::SeedRng;
use golden::setup::Screen;
use golden::specular::SpecularSpan;
use rand::SeedableRng;
use verilator_harness::ffi::{ModelInfo, SegIn, SegOut};
use verilator_harness::frontend::{random_triangles, run_chain, run_frontend};
use verilator_harness::registry::{
    require_models, specular_unit, AXIS_FRONTEND_MODELS, AXIS_SEGMENT_MISPACKED, AXIS_SEGMENT_MODELS, AXIS_SPECULAR_MODELS,
    AXIS_TRISHADER_MODELS,
};
use verilator_harness::segment::{assert_clean, Report, SegmentCosim, Stim, Stress, Traffic, DRAIN_CLOCKS};
use verilator_harness::specular::{random_span, SpecularCosim};
use verilator_harness::stimulus::random_triangle;

fn shaders(what: &str) -> &'static [ModelInfo<SegIn, SegOut>] {
    require_models(&AXIS_SEGMENT_MODELS, "AXI4-Stream segment shader", &format!("axis: {what}")).unwrap_or_default()
}

/// Random triangles under random gaps and backpressure, every segment bit-exact, and a
/// full-rate stream at one segment per clock (the wrapper adds no register and no bubble).
#[test]
fn shader_wrappers_equal_golden() {
    let seed = verilator_harness::seed("axis shader");
    let screen = Screen::default();
    for info in shaders("shader") {
        let mut rng = SeedRng::seed_from_u64(seed);
        let tris: Vec<_> = (0..300).map(|_| random_triangle(&mut rng, &screen)).collect();
        let mut sim = SegmentCosim::new(info, seed, Traffic::RANDOM);
        let mut report = Report::default();
        sim.run_triangles(&screen, &tris, 0, &mut report);
        assert_clean(info.tag, seed, &report);
        assert!(report.segments > 1000, "{}: {} segments", info.tag, report.segments);
        eprintln!(
            "{}: {} triangles, {} spans, {} segments, {} clocks",
            info.tag, report.triangles, report.spans, report.segments, report.cycles
        );

        let cfg = info.cfg;
        let stims: Vec<Stim> = (0..200)
            .map(|k| {
                let len = 1 + (k * 7) % (4 * cfg.p);
                let span = golden::Span { x0: (k * 13) % (cfg.max_len() - len), len, i0: 1 << cfg.frac, di: 3 - k as i32 };
                Stim { triangle: k as usize, y: 0, span }
            })
            .collect();
        let mut sim = SegmentCosim::new(info, seed, Traffic::FULL);
        let mut report = Report::default();
        sim.stream(&stims, &mut report, |_, _| {});
        assert_clean(info.tag, seed, &report);
        assert_eq!(report.cycles, report.segments + info.latency as u64 + DRAIN_CLOCKS, "{}: bubbles at full rate", info.tag);
    }
}

/// The negative control of the packing: the same wrapper driven with its first two input fields
/// at each other's bits (a driver and a wrapper that disagree on the layout) must fail.
#[test]
fn a_mispacked_field_is_caught() {
    let seed = verilator_harness::seed("axis mispacked");
    let screen = Screen::default();
    for info in shaders("mispacked") {
        let (_, step) = AXIS_SEGMENT_MISPACKED.iter().find(|(t, _)| *t == info.tag).expect("every shader wrapper has its control");
        // SAFETY: the same model's shim, with the same structs; only the packing differs.
        let mutant: &'static ModelInfo<SegIn, SegOut> = Box::leak(Box::new(unsafe { info.with_step(*step) }));
        let mut rng = SeedRng::seed_from_u64(seed);
        let tris: Vec<_> = (0..20).map(|_| random_triangle(&mut rng, &screen)).collect();
        let mut sim = SegmentCosim::new(mutant, seed, Traffic::RANDOM);
        let mut report = Report::default();
        // A swapped x and length shows as wrong segments or as a span the shader never ends.
        let caught = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| sim.run_triangles(&screen, &tris, 0, &mut report)));
        assert!(caught.is_err() || !report.ok(), "{}: a mis-packed s_axis_tdata passed (seed {seed})", info.tag);
        let first = report.mismatches.first().map_or("a panic".to_string(), |m| m.to_string());
        eprintln!("{}: the mis-packed control is caught: {} mismatches, first: {first}", info.tag, report.mismatch_count);
    }
}

/// Random spans (every k range, invalid n, empty spans) under gaps and backpressure, every
/// pixel, `out_err` (TUSER) and `out_last` (TLAST) bit-exact; one pixel per clock at full rate.
#[test]
fn specular_wrappers_equal_golden() {
    let seed = verilator_harness::seed("axis specular");
    let Some(models) = require_models(&AXIS_SPECULAR_MODELS, "AXI4-Stream specular unit", "axis: specular") else { return };
    for info in models {
        let mut rng = SeedRng::seed_from_u64(seed);
        let mut spans: Vec<SpecularSpan> = (0..150).map(|_| random_span(&mut rng, info.cfg.max_len())).collect();
        for (s, n) in spans.iter_mut().zip([0u16, 1, 2, 3, 6, 7, 1000, 1001, 1023]) {
            (s.n, s.len) = (n, s.len.max(1));
        }
        spans[20].len = 0;
        let mut sim = SpecularCosim::new(info, specular_unit(), seed, Traffic::RANDOM);
        let mut report = Report::default();
        sim.stream(&spans, &mut report);
        assert_clean(info.tag, seed, &report);
        let want: u64 = spans.iter().map(|s| s.len as u64).sum();
        assert_eq!(report.pixels, want, "{}", info.tag);
        eprintln!("{}: {} spans, {} pixels, {} clocks", info.tag, report.spans, report.pixels, report.cycles);

        let mut sim = SpecularCosim::new(info, specular_unit(), seed, Traffic::FULL);
        let mut report = Report::default();
        let full: Vec<SpecularSpan> = spans.iter().filter(|s| s.len > 0).copied().collect();
        sim.stream(&full, &mut report);
        assert_clean(info.tag, seed, &report);
        assert_eq!(report.cycles, report.pixels + info.latency as u64 + DRAIN_CLOCKS, "{}: bubbles at full rate", info.tag);
    }
}

/// The front-end's and the chain's wrappers, when the build has them (COSIM_RTL_DIR of a folder
/// generated with `--bus axis`): spans and segments bit-exact, as the cores' suites check them.
#[test]
fn triangle_wrappers_equal_golden() {
    let seed = verilator_harness::seed("axis triangles");
    for m in AXIS_FRONTEND_MODELS.iter() {
        let tris = random_triangles(&mut SeedRng::seed_from_u64(seed), &m.frontend(), 500);
        assert_clean(m.tag, seed, &run_frontend(m, seed, Traffic::RANDOM, Stress::NONE, &tris));
    }
    for m in AXIS_TRISHADER_MODELS.iter() {
        let tris = random_triangles(&mut SeedRng::seed_from_u64(seed), &m.frontend(), 150);
        let run = run_chain(m, seed, Traffic::RANDOM, &tris);
        assert_clean(m.tag, seed, &run.report);
    }
}
