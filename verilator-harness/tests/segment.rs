//! Co-simulation of every `segment_shader_p<P>` model built (both alignments): random
//! triangles under random gaps and backpressure (sliced for soaking: `verilator_harness::soak`),
//! directed corner cases, zero-length spans and full-rate throughput. Every segment is checked
//! bit-exactly against golden, every frame against golden and the f64 reference.

use golden::rng::SeedRng;
use golden::setup::Screen;
use golden::Span;
use rand::{Rng, SeedableRng};
use verilator_harness::registry::{require, SEGMENT_MODELS};
use verilator_harness::segment::{assert_clean, Report, SegmentCosim, Stim, Traffic, DRAIN_CLOCKS};
use verilator_harness::soak;
use verilator_harness::stimulus::{directed, random_triangle};

const BATCH: u64 = 50;

/// Slice `k` of one model's random triangles under random gaps and backpressure: its
/// [`soak::share`] of [`soak::triangles`] (2,000 per model by default; `SEGSHADE_SOAK_TRIANGLES`
/// soaks), numbered from the slice's first so that a mismatch names a triangle as one whole run
/// would. Every segment is checked bit-exactly and every batch's frame against golden and the
/// f64 reference.
fn random_slice(tag: &str, k: u32) {
    let what = format!("segment: random triangles of {tag}, slice {k}");
    let Some(info) = require(SEGMENT_MODELS.iter().find(|m| m.tag == tag), tag, &what) else { return };
    let base = verilator_harness::seed(&format!("random_triangles::{tag}::slice_{k}"));
    let seed = soak::slice_seed(base, tag, k);
    let (first, count) = soak::share(soak::triangles(), k);
    let screen = Screen::default();
    let mut rng = SeedRng::seed_from_u64(seed);
    let mut sim = SegmentCosim::new(info, seed, Traffic::RANDOM);
    let mut report = Report::default();
    for start in (0..count).step_by(BATCH as usize) {
        let batch: Vec<_> = (start..count.min(start + BATCH)).map(|_| random_triangle(&mut rng, &screen)).collect();
        sim.run_triangles(&screen, &batch, (first + start) as usize, &mut report);
    }
    assert_clean(&format!("{tag} slice {k}"), base, &report);
    assert_eq!(report.triangles as u64, count);
    eprintln!(
        "{tag} slice {k}/{}: triangles {first}..{}: {} spans, {} segments, {} pixels, {} clocks, worst error {:.3}",
        soak::SLICES,
        first + count,
        report.spans,
        report.segments,
        report.pixels,
        report.cycles,
        report.max_error
    );
}

/// `segment::random_triangles::<model>::slice_<k>`: one module per segment-shader model of the
/// compiled catalogue (build.rs lists them), one test per soak slice; and `SLICED`, their tags.
macro_rules! random_triangle_slices {
    ($($tag:ident),* $(,)?) => {
        const SLICED: &[&str] = &[$(stringify!($tag)),*];
        mod random_triangles {
            $(
                mod $tag {
                    soak_slices!(|k| super::super::random_slice(stringify!($tag), k));
                }
            )*
        }
    };
}
include!(concat!(env!("OUT_DIR"), "/segment_slices.rs"));

/// The shaders of a COSIM_RTL_DIR run whose tags the catalogue has no slice tests for (a folder
/// of another P, or another F: `seg_p8_span` of `--frac 12` is the catalogue's tag with another
/// circuit, and runs in its slices above), every slice in turn. None in a default run.
#[test]
fn random_triangles_of_other_models() {
    for info in SEGMENT_MODELS.iter().filter(|m| !SLICED.contains(&m.tag)) {
        assert!(verilator_harness::registry::rtl_dir().is_some(), "{}: a catalogue model without slice tests", info.tag);
        for k in 0..soak::SLICES {
            random_slice(info.tag, k);
        }
    }
}

/// Each directed case on its own frame, on the default screen and on the widest screen the
/// configuration allows (so spans reach x = 2^XW - 1). The wide screen is 16 rows high: its
/// point is the width, and each row of its screen-covering triangle costs 2^XW / P clocks.
#[test]
fn directed_triangles_every_model() {
    let seed = verilator_harness::seed("directed_triangles_every_model");
    for info in SEGMENT_MODELS.iter() {
        let wide = Screen { width: info.cfg.max_len(), height: 16 };
        for screen in [Screen::default(), wide] {
            let mut sim = SegmentCosim::new(info, seed, Traffic::RANDOM);
            for (name, t) in directed(&info.cfg, &screen) {
                let mut report = Report::default();
                sim.run_triangles(&screen, &[t], 0, &mut report);
                assert_clean(&format!("{}: {name} on {}x{}", info.tag, screen.width, screen.height), seed, &report);
            }
        }
    }
}

/// The last column of the widest screen is reachable, with spans of every length ending there.
#[test]
fn spans_reaching_the_last_column() {
    let seed = verilator_harness::seed("spans_reaching_the_last_column");
    for info in SEGMENT_MODELS.iter() {
        let cfg = info.cfg;
        let end = cfg.max_len();
        let stims: Vec<Stim> = (1..=3 * cfg.p + 1)
            .chain([end / 2, end])
            .map(|len| Stim { triangle: 0, y: 0, span: Span { x0: end - len, len, i0: 100 << cfg.frac, di: -(7 << (cfg.frac - 3)) } })
            .collect();
        let mut sim = SegmentCosim::new(info, seed, Traffic::RANDOM);
        let mut report = Report::default();
        let mut last_x = 0;
        sim.stream(&stims, &mut report, |_, out| {
            for i in (0..cfg.p).filter(|&i| out.lane_enabled(i)) {
                last_x = last_x.max(out.out_x + i);
            }
        });
        assert_clean(info.tag, seed, &report);
        assert_eq!(last_x, end - 1, "{}: the last lane written", info.tag);
    }
}

/// Zero-length spans are consumed and yield nothing, wherever they fall in the stream.
#[test]
fn zero_length_spans_yield_nothing() {
    let seed = verilator_harness::seed("zero_length_spans_yield_nothing");
    let mut rng = SeedRng::seed_from_u64(seed);
    for info in SEGMENT_MODELS.iter() {
        let cfg = info.cfg;
        let stims: Vec<Stim> = (0..400)
            .map(|k| {
                let len = if rng.gen_bool(0.4) { 0 } else { rng.gen_range(1..=3 * cfg.p) };
                let x0 = rng.gen_range(0..cfg.max_len() - len);
                let span = Span { x0, len, i0: rng.gen_range(0..1 << cfg.iw()), di: rng.gen_range(-5000..5000) };
                Stim { triangle: k, y: 0, span }
            })
            .collect();
        let mut sim = SegmentCosim::new(info, seed, Traffic::RANDOM);
        let mut report = Report::default();
        sim.stream(&stims, &mut report, |_, _| {});
        assert_clean(info.tag, seed, &report);
        assert_eq!(report.spans, stims.len() as u64, "{}: every span, empty or not, is taken", info.tag);
        let want: u64 = stims.iter().map(|s| cfg.segment_count(s.span.x0, s.span.len) as u64).sum();
        assert_eq!(report.segments, want);
    }
}

/// With both ends always ready the shader emits one segment every clock, across span
/// boundaries too: the only extra clocks are the pipeline's fill and the final drain check.
#[test]
fn one_segment_per_clock_at_full_rate() {
    let seed = verilator_harness::seed("one_segment_per_clock_at_full_rate");
    let mut rng = SeedRng::seed_from_u64(seed);
    for info in SEGMENT_MODELS.iter() {
        let cfg = info.cfg;
        let stims: Vec<Stim> = (0..300)
            .map(|k| {
                let len = rng.gen_range(1..=4 * cfg.p);
                let span = Span { x0: rng.gen_range(0..cfg.max_len() - len), len, i0: 1 << cfg.frac, di: 3 };
                Stim { triangle: k, y: 0, span }
            })
            .collect();
        let mut sim = SegmentCosim::new(info, seed, Traffic::FULL);
        let mut report = Report::default();
        sim.stream(&stims, &mut report, |_, _| {});
        assert_clean(info.tag, seed, &report);
        // The pipeline's fill (the first segment leaves `latency` clocks after the first span
        // enters, on clock `latency`), and the drain check.
        let overhead = info.latency as u64 + DRAIN_CLOCKS;
        assert_eq!(report.cycles, report.segments + overhead, "{}: bubbles in a full-rate stream", info.tag);
    }
}
