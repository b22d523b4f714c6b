//! The triangle front-end (SPEC §6) in RTL against golden: `tri_frontend` span by span, and
//! `tri_shader_p<P>` segment by segment and frame by frame, with random gaps and backpressure.

use golden::frontend::{FixedTriangle, FrontEnd, Outcome};
use golden::rng::SeedRng;
use rand::SeedableRng;
use verilator_harness::frontend::{mesh, random_triangles, run_chain, run_frontend, Expected};
use verilator_harness::registry::{require, require_models, FRONTEND_MODELS, TRISHADER_MODELS};
use verilator_harness::segment::{assert_clean, Stress, Traffic};

fn frontend(m: &verilator_harness::ffi::ModelInfo<impl Sized, impl Sized>) -> FrontEnd {
    m.frontend()
}

#[test]
fn spans_equal_golden_for_every_kind_of_triangle() {
    let seed = verilator_harness::seed("frontend spans");
    let Some(models) = require_models(&FRONTEND_MODELS, "tri_frontend", "frontend spans") else { return };
    for m in models {
        let fe = frontend(m);
        let tris = random_triangles(&mut SeedRng::seed_from_u64(seed), &fe, 3000);
        let exp = Expected::new(fe, &tris);
        // The stimulus reaches every outcome. Not certain by construction: each of the 3,000
        // triangles is drawn independently and reaches each outcome with probability at least
        // 1/20 (golden::stimulus's own test measures it), so P(an outcome missing)
        // <= 3 (1 - 1/20)^3000 < 1e-65 per model.
        for o in [Outcome::Guard, Outcome::Culled, Outcome::Walked] {
            assert!(exp.stims.iter().any(|s| s.outcome == o), "no {o:?} triangle");
        }
        let report = run_frontend(m, seed, Traffic::RANDOM, Stress::NONE, &tris);
        eprintln!(
            "{}: {} triangles, {} spans out, {} guard drops, {} clocks",
            m.tag, report.triangles, report.segments, report.pulses, report.cycles
        );
        assert_clean(m.tag, seed, &report);
        assert_eq!(report.segments, exp.spans.len() as u64);
        assert_eq!(report.pulses, exp.guard_drops());
    }
}

#[test]
fn resets_in_the_middle_of_triangles_drop_them_cleanly() {
    let seed = verilator_harness::seed("frontend resets");
    let Some(models) = require_models(&FRONTEND_MODELS, "tri_frontend", "frontend resets") else { return };
    for m in models {
        let fe = frontend(m);
        // Rounds of 1,500 triangles until a reset came, so the test always has one. Each triangle
        // is a transfer, so a round is at least 1,500 clocks, each drawing a reset with
        // probability 0.002: a round has none with probability <= 0.998^1500 = e^-3, and all
        // 40 rounds <= e^-120 (the only way this fails on correct RTL).
        let mut resets = 0;
        for round in 0u64.. {
            assert!(round < 40, "{}: no reset in {round} rounds of 1,500 triangles (seed {seed})", m.tag);
            let tris = random_triangles(&mut SeedRng::seed_from_u64((seed ^ 1).wrapping_add(round << 32)), &fe, 1500);
            let report = run_frontend(m, seed.wrapping_add(round), Traffic::RANDOM, Stress::HARSH, &tris);
            assert_clean(m.tag, seed, &report);
            resets += report.resets;
            if resets > 0 {
                break;
            }
        }
    }
}

#[test]
fn segments_and_frames_through_the_chain() {
    let seed = verilator_harness::seed("tri_shader");
    let Some(models) = require_models(&TRISHADER_MODELS, "tri_shader", "tri_shader segments") else { return };
    for m in models {
        let fe = frontend(m);
        let mut rng = SeedRng::seed_from_u64(seed ^ m.cfg.p as u64);
        // Few enough per frame that the frame comparison stays meaningful where they overlap:
        // the last writer wins in both the RTL frame and golden's.
        for round in 0..4 {
            let tris = random_triangles(&mut rng, &fe, 150);
            let run = run_chain(m, seed + round, Traffic::RANDOM, &tris);
            assert_clean(m.tag, seed, &run.report);
            assert!(run.report.max_error <= 1.0);
        }
    }
}

#[test]
fn a_shared_edge_mesh_writes_every_covered_pixel_exactly_once() {
    let seed = verilator_harness::seed("tri_shader mesh");
    let Some(models) = require_models(&TRISHADER_MODELS, "tri_shader", "tri_shader mesh") else { return };
    for m in models {
        let fe = frontend(m);
        let tris: Vec<FixedTriangle> = mesh(&mut SeedRng::seed_from_u64(seed), &fe, 17, 11);
        let run = run_chain(m, seed, Traffic::RANDOM, &tris);
        assert_clean(m.tag, seed, &run.report);
        // The mesh covers the screen [0, W) x [0, H) exactly: every pixel, once.
        let (once, more, none) = run.writes.iter().fold((0, 0, 0), |(a, b, c), &n| match n {
            1 => (a + 1, b, c),
            0 => (a, b, c + 1),
            _ => (a, b + 1, c),
        });
        assert_eq!((more, none), (0, 0), "{}: {once} pixels written once, {more} more than once, {none} never", m.tag);
    }
}

#[test]
fn the_scoreboard_catches_a_wrong_span() {
    // Negative control: the same run against golden spans with one I0 off by one must fail.
    let seed = verilator_harness::seed("frontend negative control");
    let Some(m) = require(FRONTEND_MODELS.first(), "tri_frontend", "frontend negative control") else { return };
    let fe = frontend(m);
    let tris = random_triangles(&mut SeedRng::seed_from_u64(seed), &fe, 200);
    let mut bad = tris.clone();
    // A vertex intensity changed by one LSB changes golden's spans but not the RTL's input.
    let k = Expected::new(fe, &tris).stims.iter().position(|s| s.count > 0).unwrap();
    bad[k].i[0] ^= 1 << 10;
    let exp_bad = Expected::new(fe, &bad);
    let exp_good = Expected::new(fe, &tris);
    assert_ne!(exp_bad.spans, exp_good.spans, "the planted fault must change golden's answer");
    let report = verilator_harness::frontend::run_frontend_against(m, seed, &tris, &exp_bad);
    assert!(!report.ok(), "a wrong expectation went unnoticed");
}

#[test]
fn set_up_costs_what_the_manifest_says() {
    // Triangles of one row each are set-up bound; zero-area ones cost their CALC clock only.
    // The same with CALC in stages (they overlap the division of the triangle ahead), at every
    // divider rate and in both dI modes.
    let Some(models) = require_models(&FRONTEND_MODELS, "tri_frontend", "frontend set-up clocks") else { return };
    for m in models {
        set_up_costs(m);
    }
}

fn set_up_costs(m: &'static verilator_harness::ffi::ModelInfo<verilator_harness::ffi::TriIn, verilator_harness::ffi::FeOut>) {
    // The model's divider rate, from the latency the build recorded for it.
    let hw = hdl_gen::frontend::DIV_BITS
        .map(|div_bits| hdl_gen::frontend::Hw { fe: frontend(m), div_bits, pipeline: m.pipeline })
        .into_iter()
        .find(|hw| hw.latency() == m.latency)
        .expect("a divider rate with the model's latency");
    let (walked, dropped) = hw.setup_clocks();
    // Per scanline (`--fe-di scanline`, under COSIM_RTL_DIR) each span of two pixels or more
    // also waits for its divider: a walked one-row triangle may take that much longer.
    let span_div = match hw.fe.di {
        golden::frontend::DiMode::Triangle => 0,
        golden::frontend::DiMode::Scanline => hw.span_div_clocks() + 1,
    };
    let n = 400u64;
    let row = FixedTriangle { x: [2560, 7680, 2560], y: [2600, 2600, 2800], i: [100 << 12; 3] };
    let flat = FixedTriangle { x: [2560, 5120, 7680], y: [2560, 5120, 7680], i: [0; 3] };
    for (tri, per, extra, what) in [(row, walked, span_div, "one-row"), (flat, dropped, 0, "zero-area")] {
        let tris = vec![tri; n as usize];
        let report = run_frontend(m, 1, Traffic::FULL, Stress::NONE, &tris);
        assert_clean(m.tag, 1, &report);
        // The stream ends with the drain: the screen's rows, the latency and a few clocks.
        let slack = 2 * hw.latency() as u64 + m.screen.height as u64 + 8;
        let most = n * (per + extra) as u64 + slack;
        assert!(
            report.cycles >= n * per as u64 && report.cycles <= most,
            "{n} {what} triangles took {} clocks; the manifest says {per} each (at most {most} in all)",
            report.cycles
        );
    }
}

#[test]
fn scenes_render_through_the_rtl_chain_as_golden() {
    use verilator_harness::render::{run_with, scene_job, Chain, SceneKind};
    let what = "render through the chain";
    let Some(chain) = require(TRISHADER_MODELS.iter().find(|m| m.cfg.p == 8 && m.cfg.align == golden::Align::Span), "tris_p8_span", what)
    else {
        return;
    };
    let Some(seg) = verilator_harness::registry::require_segment_model(8, golden::Align::Span, what) else { return };
    for kind in [SceneKind::Sphere, SceneKind::Torus] {
        // On the chain's own screen (a COSIM_RTL_DIR folder's may be another than 640x480).
        let job = scene_job(kind, 40, &seg.cfg, &chain.screen).unwrap();
        let o = run_with(&job, seg, Chain::Rtl(chain), None, |_| {});
        assert!(o.cosim_ok(), "{:?}", o.segment.iter().flat_map(|r| &r.mismatches).next());
        assert_eq!(o.differing_pixels(3), 0, "RTL image differs from golden's front-end image");
        // Against the host set-up only the rounding of vertex intensities onto the ports shows.
        let host = o.host.as_ref().expect("the host image");
        let differ = (0..host.len() / 3).filter(|&k| host[3 * k..3 * k + 3] != o.rtl[3 * k..3 * k + 3]).count();
        assert!(differ * 1000 < job.visible_pixels() as usize, "{differ} pixels differ from the host image");
    }
}
