//! Reliability of the co-simulation and of the hardware under stress (issue 6):
//!
//! - `rst` at random clocks in the middle of spans, long `out_ready`-low stretches, long
//!   `in_valid` gaps and zero-length spans, for every segment-shader model and the specular
//!   unit: every span accepted and not cut by a reset comes out exactly once, in order,
//!   bit-exact; after a reset nothing stale comes out (the protocol monitor also checks that
//!   `out_valid` is low right after a reset and that an offered output holds until taken);
//! - `out_valid` rises without waiting for `out_ready`, at the stated latency;
//! - every word of both specular ROMs is reached (so a changed word cannot hide);
//! - the harness API rejects spans the ports cannot carry before they reach a model.
//!
//! Bad triangle input (rejected with its line number, never a panic or garbage pixels) is
//! golden's alone: `golden::setup`'s tests.

use golden::pipeline::Pipeline;
use golden::rng::SeedRng;
use golden::setup::{triangle_spans, Screen, Triangle, Vertex, COORD_LIMIT};
use golden::specular::{SpecularSpan, N_BITS};
use golden::{Config, Span, SpanError};
use rand::{Rng, SeedableRng};
use verilator_harness::ffi::{to_port, ModelInfo, Rtl, SegIn, SegOut, SpecIn, SpecOut};
use verilator_harness::registry::{require_models, require_specular_model, specular_unit, SEGMENT_MODELS};
use verilator_harness::segment::{assert_clean, Report, SegmentCosim, SpanRejected, Stim, Stress, Traffic};
use verilator_harness::specular::{random_span, SpecSpanRejected, SpecularCosim};
use verilator_harness::stimulus::{directed, random_triangle};

/// Backpressure bursts, input gaps and a reset about every 700 clocks.
const STRESS: Stress = Stress { reset: 0.0015, stall: 0.004, stall_max: 300, gap: 0.05, gap_max: 200 };
/// The same with a reset about every 1500 clocks: specular spans are long (up to 400 pixels).
const SPEC_STRESS: Stress = Stress { reset: 0.0007, ..STRESS };

fn spec_model(what: &str) -> Option<&'static ModelInfo<SpecIn, SpecOut>> {
    require_specular_model(&format!("reliability: {what}"))
}

/// Rounds of stress stimulus at most, a runaway guard: see [`enough_stress`].
const MAX_ROUNDS: u32 = 1_000;

/// Spans of random triangles with raw short spans and zero-length spans mixed in: after each
/// triangle one to three raw spans, the first never empty, so a round of `triangles` holds at
/// least that many spans with an output owed, whatever the seed.
fn stress_stims(rng: &mut SeedRng, cfg: &Config, screen: &Screen, triangles: usize) -> Vec<Stim> {
    let mut stims = Vec::new();
    for k in 0..triangles {
        let t = random_triangle(rng, screen);
        triangle_spans(cfg, screen, &t, |y, span| stims.push(Stim { triangle: k, y, span })).expect("set-up");
        for r in 0..rng.gen_range(1..=3) {
            let len = if r > 0 && rng.gen_bool(0.5) { 0 } else { rng.gen_range(1..=(3 * cfg.p).min(cfg.max_len())) };
            let x0 = rng.gen_range(0..=cfg.max_len() - len.max(1));
            let half = 1i32 << (cfg.dw() - 1);
            let span = Span { x0, len, i0: rng.gen_range(0..1 << cfg.iw()), di: rng.gen_range(-half..half) };
            stims.push(Stim { triangle: k, y: 0, span });
        }
    }
    stims
}

/// Whether a stressed run has shown what the stress tests are about: `min_rounds` rounds, at
/// least `min_resets` resets and a reset inside a span. The tests stream rounds until it has, so
/// those hold after the loop for every seed, by construction. The loop's only way to fail is
/// [`MAX_ROUNDS`], and its probability is negligible: every span with an output owed is the
/// oldest outstanding one for at least one clock (its first output comes at least a clock after
/// its transfer), and in each such clock the driver draws a reset with probability `reset`
/// (0.0015 for the shaders, 0.0007 for the specular unit) independently of the past; a round
/// holds at least 60 (shaders) or 135 (specular) such spans, so 1,000 rounds draw at least
/// 60,000 (135,000) times: P(no span cut) <= (1 - 0.0015)^60000 = e^-90 (e^-94 for specular),
/// and P(fewer than 5 (10) resets) <= P(Binomial(60000, 0.0015) < 5) < 1e-30, per model.
fn enough_stress(report: &Report, rounds: u32, min_rounds: u32, min_resets: u64) -> bool {
    rounds >= min_rounds && report.resets >= min_resets && report.cut_spans > 0
}

#[test]
fn segment_shaders_survive_resets_stalls_and_gaps() {
    let Some(models) = require_models(&SEGMENT_MODELS, "segment shader", "reliability: segment shaders under stress") else { return };
    let seed = verilator_harness::seed("segment_shaders_survive_resets_stalls_and_gaps");
    let screen = Screen::default();
    for (m, info) in models.iter().enumerate() {
        let model_seed = seed.wrapping_add(m as u64);
        let mut rng = SeedRng::seed_from_u64(model_seed);
        let mut sim = SegmentCosim::new(info, model_seed, Traffic::RANDOM);
        sim.set_stress(STRESS);
        let mut report = Report::default();
        // Fewer, so cheaper, triangles for narrow shaders: their spans take more clocks.
        let triangles = if info.cfg.p < 8 { 60 } else { 150 };
        let mut rounds = 0;
        while !enough_stress(&report, rounds, 4, 5) {
            assert!(
                rounds < MAX_ROUNDS,
                "{}: {} resets cutting {} spans in {rounds} rounds (seed {seed})",
                info.tag,
                report.resets,
                report.cut_spans
            );
            let stims = stress_stims(&mut rng, &info.cfg, &screen, triangles);
            let before = report.spans;
            sim.stream(&stims, &mut report, |_, _| {});
            assert_eq!(report.spans - before, stims.len() as u64, "{}: every span is taken once, cut or not (seed {seed})", info.tag);
            rounds += 1;
        }
        assert_clean(&format!("{} under reset stress", info.tag), seed, &report);
        // After the resets, a round without them: every span completes, bit-exact (this replaces
        // a "most spans complete" ratio, which no bound on the stimulus made certain).
        sim.set_stress(Stress::BURSTS);
        let stims = stress_stims(&mut rng, &info.cfg, &screen, triangles);
        let mut after = Report::default();
        sim.stream(&stims, &mut after, |_, _| {});
        assert_clean(&format!("{} after the reset stress", info.tag), seed, &after);
        assert_eq!((after.spans, after.cut_spans), (stims.len() as u64, 0), "{}: every span after the stress", info.tag);
        eprintln!(
            "{}: {} spans ({} cut by {} resets) in {rounds} rounds, {} segments, {} clocks; then {} spans without resets",
            info.tag, report.spans, report.cut_spans, report.resets, report.segments, report.cycles, after.spans
        );
    }
}

/// No reset, so whole frames can be checked: long backpressure bursts and input gaps lose
/// nothing and change nothing, against golden's frame and the f64 reference.
#[test]
fn segment_frames_exact_under_bursts() {
    let seed = verilator_harness::seed("segment_frames_exact_under_bursts");
    let screen = Screen::default();
    for (m, info) in SEGMENT_MODELS.iter().enumerate() {
        let model_seed = seed.wrapping_add(m as u64);
        let mut rng = SeedRng::seed_from_u64(model_seed);
        let mut sim = SegmentCosim::new(info, model_seed, Traffic::RANDOM);
        sim.set_stress(Stress::BURSTS);
        let mut report = Report::default();
        let batch: Vec<Triangle> = (0..60).map(|_| random_triangle(&mut rng, &screen)).collect();
        sim.run_triangles(&screen, &batch, 0, &mut report);
        assert_clean(&format!("{} under bursts", info.tag), seed, &report);
        assert_eq!(report.resets, 0);
    }
}

#[test]
fn specular_unit_survives_resets_stalls_and_gaps() {
    let seed = verilator_harness::seed("specular_unit_survives_resets_stalls_and_gaps");
    let Some(info) = spec_model("the specular unit under stress") else { return };
    let mut rng = SeedRng::seed_from_u64(seed);
    let mut sim = SpecularCosim::new(info, specular_unit(), seed, Traffic::RANDOM);
    sim.set_stress(SPEC_STRESS);
    let mut report = Report::default();
    // Rounds of 150 spans, 15 of them emptied, the rest at least a pixel long: see enough_stress.
    let round = |rng: &mut SeedRng| {
        let mut spans: Vec<SpecularSpan> = (0..150)
            .map(|_| {
                let mut s = random_span(rng, info.cfg.max_len());
                s.len = s.len.max(1);
                s
            })
            .collect();
        for _ in 0..15 {
            let k = rng.gen_range(0..spans.len());
            spans[k].len = 0;
        }
        spans
    };
    let mut rounds = 0;
    while !enough_stress(&report, rounds, 8, 10) {
        assert!(rounds < MAX_ROUNDS, "{} resets cutting {} spans in {rounds} rounds (seed {seed})", report.resets, report.cut_spans);
        let spans = round(&mut rng);
        let before = report.spans;
        sim.stream(&spans, &mut report);
        assert_eq!(report.spans - before, spans.len() as u64, "every span is taken once (seed {seed})");
        rounds += 1;
    }
    assert_clean("specular unit under reset stress", seed, &report);
    // Then a round without resets: every span completes, bit-exact.
    sim.set_stress(Stress::BURSTS);
    let spans = round(&mut rng);
    let mut after = Report::default();
    sim.stream(&spans, &mut after);
    assert_clean("specular unit after the reset stress", seed, &after);
    assert_eq!((after.spans, after.cut_spans), (spans.len() as u64, 0), "every span after the stress");
    assert_eq!(after.pixels, spans.iter().map(|s| s.len as u64).sum::<u64>());
    eprintln!(
        "{}: {} spans ({} cut by {} resets) in {rounds} rounds, {} pixels, {} clocks; then {} spans without resets",
        info.tag, report.spans, report.cut_spans, report.resets, report.pixels, report.cycles, after.spans
    );
}

/// SPEC §3: a source never waits for `ready` before raising `valid`. With `out_ready` held low
/// from the start, the first output is valid exactly `latency` clocks after the transfer and
/// stays there, unchanged, until taken.
#[test]
fn out_valid_does_not_wait_for_out_ready() {
    for info in SEGMENT_MODELS.iter() {
        let cfg = info.cfg;
        let mut rtl = Rtl::new(info, 11);
        let mut out = SegOut::default();
        let mut input = SegIn { rst: 1, ..SegIn::default() };
        rtl.step_into(&input, &mut out);
        rtl.step_into(&input, &mut out);
        input = SegIn {
            in_valid: 1,
            in_x: 3,
            in_len: 2 * cfg.p + 1,
            in_i0: 40 << cfg.frac,
            in_di: to_port(1 << cfg.frac, cfg.dw()),
            ..SegIn::default()
        };
        rtl.step_into(&input, &mut out);
        assert_eq!(out.in_ready, 1, "{}: an idle shader takes a span", info.tag);
        input.in_valid = 0;
        for k in 1..info.latency {
            rtl.step_into(&input, &mut out);
            assert_eq!(out.out_valid, 0, "{}: valid {k} clocks after the transfer, latency {}", info.tag, info.latency);
        }
        let mut first = None;
        for k in 0..20 {
            rtl.step_into(&input, &mut out);
            assert_eq!(
                out.out_valid, 1,
                "{}: out_valid must rise {} clocks after the transfer with out_ready low (clock +{k})",
                info.tag, info.latency
            );
            let now = (out.out_x, out.pix[0], out.mask[0], out.out_last);
            assert_eq!(*first.get_or_insert(now), now, "{}: the offered segment changed while out_ready was low", info.tag);
        }
        let want = if cfg.align == golden::Align::Screen { 3 / cfg.p * cfg.p } else { 3 };
        assert_eq!(out.out_x, want, "{}", info.tag);
    }
    let Some(info) = spec_model("the specular unit's out_valid with out_ready low") else { return };
    let mut rtl = Rtl::new(info, 12);
    let mut out = SpecOut::default();
    let mut input = SpecIn { rst: 1, ..SpecIn::default() };
    rtl.step_into(&input, &mut out);
    rtl.step_into(&input, &mut out);
    input = SpecIn { in_valid: 1, in_c: 200 << 8, in_n: 20, in_theta0: 0, in_dtheta: to_port(1 << 18, 32), in_len: 5, ..SpecIn::default() };
    rtl.step_into(&input, &mut out);
    assert_eq!(out.in_ready, 1);
    input.in_valid = 0;
    for k in 1..info.latency {
        rtl.step_into(&input, &mut out);
        assert_eq!(out.out_valid, 0, "specular: valid {k} clocks after the transfer");
    }
    let want = specular_unit().pixel(200 << 8, 20, 0, 1 << 18, 0).0;
    for k in 0..20 {
        rtl.step_into(&input, &mut out);
        assert_eq!((out.out_valid, out.out_spec, out.out_last), (1, want, 0), "specular: first pixel held with out_ready low (clock +{k})");
    }
}

/// Every n-table word (n = 0..1023) and every BRDF word is reached: for each n, one span sweeps
/// |theta| from 0 to past the end of n's table in steps of less than one table entry, at the
/// largest C, so any changed word changes some output.
#[test]
fn specular_sweep_reaches_every_rom_word() {
    let seed = verilator_harness::seed("specular_sweep_reaches_every_rom_word");
    let Some(info) = spec_model("the specular ROM sweep") else { return };
    let unit = specular_unit();
    let plan = unit.plan().clone();
    let len = 1024u32.min(info.cfg.max_len());
    let spans: Vec<SpecularSpan> = (0..1u32 << N_BITS)
        .map(|n| {
            let m = plan.m_of(n);
            let end = match plan.decoder.table_of(n) {
                Some(t) if m > 0 => {
                    let tb = &plan.tables[t];
                    // The |theta| code where idx reaches len, with 5% to spare.
                    ((((tb.len as u64) << tb.shift) / m) << plan.theta_drop) as f64 * 1.05
                }
                _ => (1u64 << 28) as f64,
            };
            let dtheta = (end / len as f64).ceil() as i32;
            let sign = if n % 2 == 0 { 1 } else { -1 };
            SpecularSpan { c: u16::MAX, n: n as u16, theta0: 0, dtheta: sign * dtheta, len }
        })
        .collect();
    // The sweep really steps by less than one entry: every index of every table appears.
    let mut hit: Vec<Vec<bool>> = plan.tables.iter().map(|t| vec![false; t.len as usize]).collect();
    for s in &spans {
        if let (Some(t), m) = (plan.decoder.table_of(s.n as u32), plan.m_of(s.n as u32)) {
            for j in 0..s.len {
                let mag = (golden::specular::theta_at(s.theta0, s.dtheta, j).unsigned_abs() >> plan.theta_drop) as u64;
                let idx = (mag * m) >> plan.tables[t].shift;
                if let Some(h) = hit[t].get_mut(idx as usize) {
                    *h = true;
                }
            }
        }
    }
    for (t, h) in hit.iter().enumerate() {
        assert!(h.iter().all(|&x| x), "table {t}: entries {:?} never reached", h.iter().positions_false());
    }
    let mut sim = SpecularCosim::new(info, unit, seed, Traffic::FULL);
    let mut report = Report::default();
    sim.stream(&spans, &mut report);
    assert_clean("specular ROM sweep", seed, &report);
    assert_eq!(report.pixels, spans.len() as u64 * len as u64);
}

trait PositionsFalse {
    fn positions_false(self) -> Vec<usize>;
}
impl<'a, I: Iterator<Item = &'a bool>> PositionsFalse for I {
    fn positions_false(self) -> Vec<usize> {
        self.enumerate().filter(|(_, &b)| !b).map(|(k, _)| k).take(10).collect()
    }
}

/// The harness never hands a model a span its ports cannot carry: `try_stream` names the span
/// and returns before the first clock; `stream` panics with the same message.
#[test]
fn harness_rejects_spans_the_rtl_cannot_take() {
    for info in SEGMENT_MODELS.iter() {
        let cfg = info.cfg;
        let max = cfg.max_len();
        let good = Span { x0: 0, len: 4, i0: 0, di: 0 };
        let half = 1i32 << (cfg.dw() - 1);
        let (iw, dw, frac) = (cfg.iw(), cfg.dw(), cfg.frac);
        let bad = [
            (Span { x0: max - 3, len: 4, ..good }, SpanError::Beyond { x0: max - 3, len: 4, max }),
            (Span { x0: 0, len: max + 1, ..good }, SpanError::Len { len: max + 1, max }),
            (Span { x0: max, len: 0, ..good }, SpanError::Beyond { x0: max, len: 0, max }),
            (Span { i0: 1 << iw, ..good }, SpanError::I0 { i0: 1 << iw, frac }),
            (Span { di: half, ..good }, SpanError::Di { di: half, bits: dw }),
            (Span { di: -half - 1, ..good }, SpanError::Di { di: -half - 1, bits: dw }),
        ];
        for (span, error) in bad {
            let stims = [Stim { triangle: 0, y: 0, span: good }, Stim { triangle: 7, y: 9, span }];
            let mut sim = SegmentCosim::new(info, 1, Traffic::FULL);
            let mut report = Report::default();
            let e = sim.try_stream(&stims, &mut report, |_, _| {}).expect_err(&format!("{}: {span:?} accepted", info.tag));
            assert_eq!(e, SpanRejected { index: 1, triangle: 7, y: 9, error }, "{}", info.tag);
            assert_eq!((report.cycles, report.spans), (0, 0), "{}: the model saw a clock", info.tag);
        }
        if info.tag == SEGMENT_MODELS[0].tag {
            // `stream` panics with the same message (once: the message goes to the test's output).
            let stims = [Stim { triangle: 0, y: 0, span: Span { x0: max, len: 1, ..good } }];
            let mut sim = SegmentCosim::new(info, 1, Traffic::FULL);
            let panicked = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| sim.stream(&stims, &mut Report::default(), |_, _| {})));
            assert!(panicked.is_err(), "{}: stream took a span beyond the screen", info.tag);
        }
        // The extremes the ports can carry are taken.
        let edge = [Span { x0: max - 1, len: 1, i0: (1 << cfg.iw()) - 1, di: half - 1 }, Span { x0: 0, len: max, i0: 0, di: -half }];
        let stims: Vec<Stim> = edge.iter().map(|&span| Stim { triangle: 0, y: 0, span }).collect();
        let mut sim = SegmentCosim::new(info, 1, Traffic::RANDOM);
        let mut report = Report::default();
        sim.try_stream(&stims, &mut report, |_, _| {}).unwrap();
        assert_clean(info.tag, 1, &report);
    }
    let Some(info) = spec_model("the specular unit's port limits") else { return };
    let port_max = (1u32 << (info.cfg.xbits + 1)) - 1;
    let good = SpecularSpan { c: 100, n: 10, theta0: 0, dtheta: 1000, len: 3 };
    let bits = info.cfg.xbits + 1;
    for (span, error) in [
        (SpecularSpan { len: port_max + 1, ..good }, SpecSpanRejected::Len { index: 1, len: port_max + 1, bits }),
        (SpecularSpan { n: 1 << N_BITS, ..good }, SpecSpanRejected::N { index: 1, n: 1 << N_BITS, bits: N_BITS }),
    ] {
        let mut sim = SpecularCosim::new(info, specular_unit(), 1, Traffic::FULL);
        let mut report = Report::default();
        assert_eq!(sim.try_stream(&[good, span], &mut report), Err(error));
        assert_eq!(report.cycles, 0);
    }
    // What the ports carry is valid input, an n outside 1..1000 included (out_err = 1), and the
    // longest length the port carries.
    let mut sim = SpecularCosim::new(info, specular_unit(), 1, Traffic::RANDOM);
    let mut report = Report::default();
    let spans = [SpecularSpan { n: 1023, ..good }, SpecularSpan { n: 0, ..good }, SpecularSpan { len: port_max, dtheta: 1, ..good }];
    sim.try_stream(&spans, &mut report).unwrap();
    assert_clean("specular port extremes", 1, &report);
    assert_eq!(report.pixels, 6 + port_max as u64);
}

/// Triangles at the coordinate limits are clipped to the screen: every span fits the ports, and
/// through the RTL the frame equals golden's and the f64 reference, on the default screen and on
/// the widest one each configuration allows.
#[test]
fn extreme_triangles_are_clipped_not_garbled() {
    let seed = verilator_harness::seed("extreme_triangles_are_clipped_not_garbled");
    let mut rng = SeedRng::seed_from_u64(seed);
    let l = COORD_LIMIT;
    // Three widths at level 0 with native ports bound a default build's time (the spans are the
    // point here, and every model sees them in the random slices); a COSIM_RTL_DIR run runs
    // what it has.
    let base = |m: &&ModelInfo<SegIn, SegOut>| m.pipeline == Pipeline::default() && !m.tag.ends_with("_axis");
    let folder = verilator_harness::registry::rtl_dir().is_some();
    for info in SEGMENT_MODELS.iter().filter(|m| (base(m) && matches!(m.cfg.p, 1 | 8 | 64)) || folder) {
        let wide = Screen { width: info.cfg.max_len(), height: 64 };
        for screen in [Screen::default(), wide] {
            let mut tris = vec![
                Triangle { v: [Vertex { x: -l, y: -l, i: 0.0 }, Vertex { x: l, y: -l, i: 255.0 }, Vertex { x: -l, y: l, i: 128.0 }] },
                Triangle { v: [Vertex { x: l, y: l, i: 255.0 }, Vertex { x: -l, y: 10.5, i: 0.0 }, Vertex { x: l, y: -l, i: 30.0 }] },
                Triangle {
                    v: [Vertex { x: -l, y: 3.25, i: 0.0 }, Vertex { x: l, y: 3.75, i: 255.0 }, Vertex { x: 0.0, y: 40.0, i: 77.0 }],
                },
            ];
            for _ in 0..6 {
                let mut v = || Vertex { x: rng.gen_range(-l..=l), y: rng.gen_range(-l..=l), i: rng.gen_range(0.0..=255.0) };
                tris.push(Triangle { v: [v(), v(), v()] });
            }
            for t in &tris {
                triangle_spans(&info.cfg, &screen, t, |_, s| s.check(&info.cfg).expect("a clipped span fits the ports")).unwrap();
            }
            let mut sim = SegmentCosim::new(info, seed, Traffic::RANDOM);
            for t in tris {
                let mut report = Report::default();
                sim.run_triangles(&screen, &[t], 0, &mut report);
                assert_clean(&format!("{}: {t} on {}x{}", info.tag, screen.width, screen.height), seed, &report);
            }
        }
    }
    // The directed corner cases under reset-free bursts, for good measure.
    let Some(info) = SEGMENT_MODELS.iter().find(|m| m.cfg.p == 8).or(SEGMENT_MODELS.first()) else { return };
    let screen = Screen::default();
    let mut sim = SegmentCosim::new(info, seed, Traffic::RANDOM);
    sim.set_stress(Stress::BURSTS);
    for (name, t) in directed(&info.cfg, &screen) {
        let mut report = Report::default();
        sim.run_triangles(&screen, &[t], 0, &mut report);
        assert_clean(&format!("{}: {name} under bursts", info.tag), seed, &report);
    }
}
