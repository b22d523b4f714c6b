//! SPEC §7's block video memory in RTL against golden: `fb_writer_p<P>` fed golden's segments,
//! and `tri_fb_p<P>` fed triangles, each with a memory model behind the write port that stalls
//! at random. Every write is checked (address, enables, pixels under them), no write may lack an
//! enable or write a pixel twice within a span, and the memory is compared as a frame.

use golden::frontend::{FixedTriangle, FrontEnd};
use golden::rng::SeedRng;
use golden::setup::Screen;
use golden::writer::Writer;
use golden::Span;
use rand::{Rng, SeedableRng};
use verilator_harness::ffi::{Rtl, WrIn, WrOut};
use verilator_harness::frontend::{mesh, random_triangles};
use verilator_harness::registry::{require_models, TRIWRITER_MODELS, WRITER_MODELS};
use verilator_harness::segment::{assert_clean, Stress, Traffic};
use verilator_harness::writer::{run_fb, run_writer, run_writer_against};

/// Spans of every shape the glue has a corner for: one pixel, shorter than a block, starting or
/// ending on a block edge, the whole row, the row's last pixels, and anything at random.
fn random_spans(rng: &mut SeedRng, w: &Writer, n: usize) -> Vec<(u32, Span)> {
    let (width, height, p) = (w.screen.width, w.screen.height, w.cfg.p);
    let imax = (255u32 << w.cfg.frac) as i64;
    (0..n)
        .map(|_| {
            let y = rng.gen_range(0..height);
            let (x0, len) = match rng.gen_range(0..7) {
                0 => (rng.gen_range(0..width), 1),
                1 => {
                    let x0 = rng.gen_range(0..width);
                    (x0, rng.gen_range(1..=p.min(width - x0)))
                }
                2 => {
                    let x0 = rng.gen_range(0..width) / p * p;
                    (x0, rng.gen_range(1..=width - x0))
                }
                3 => {
                    let end = (rng.gen_range(1..=width.div_ceil(p)) * p).min(width);
                    let x0 = rng.gen_range(0..end);
                    (x0, end - x0)
                }
                4 => (0, width),
                5 => {
                    let len = rng.gen_range(1..=width.min(3 * p));
                    (width - len, len)
                }
                _ => {
                    let x0 = rng.gen_range(0..width);
                    (x0, rng.gen_range(1..=width - x0))
                }
            };
            let i0 = rng.gen_range(0..=imax);
            // dI keeps every pixel in 0..255 or runs off it (clamped): both are the pixel rule.
            let di = rng.gen_range(-(1i64 << (w.cfg.frac + 2))..(1i64 << (w.cfg.frac + 2))) as i32;
            (y, Span { x0, len, i0: i0 as u32, di })
        })
        .collect()
}

fn writer_of(m: &verilator_harness::ffi::ModelInfo<WrIn, WrOut>) -> Writer {
    Writer::new(m.cfg, m.screen).unwrap()
}

#[test]
fn writes_equal_golden_under_memory_stalls() {
    let seed = verilator_harness::seed("writer writes");
    let Some(models) = require_models(&WRITER_MODELS, "fb_writer", "writer writes") else { return };
    for m in models {
        let w = writer_of(m);
        let spans = random_spans(&mut SeedRng::seed_from_u64(seed ^ m.cfg.p as u64), &w, 4000);
        for (traffic, stress) in [(Traffic::RANDOM, Stress::BURSTS), (Traffic::FULL, Stress::NONE)] {
            let mut run = run_writer(m, seed, traffic, stress, &spans);
            run.check_frame(&spans);
            let writes: u64 = spans.iter().map(|(_, s)| w.write_count(s) as u64).sum();
            let pixels: u64 = spans.iter().map(|(_, s)| s.len as u64).sum();
            eprintln!("{}: {} spans, {} writes, {} clocks", m.tag, spans.len(), run.report.segments, run.report.cycles);
            assert_clean(m.tag, seed, &run.report);
            assert_eq!((run.report.segments, run.report.pixels), (writes, pixels), "{}: every write and pixel, once", m.tag);
        }
    }
}

/// At full rate the writer keeps up with the shader: a span costs its writes, plus at most one
/// clock where its segment count and write count differ (the glued tail).
#[test]
fn one_write_per_clock_at_full_rate() {
    let seed = verilator_harness::seed("writer rate");
    let Some(models) = require_models(&WRITER_MODELS, "fb_writer", "writer rate") else { return };
    for m in models {
        let w = writer_of(m);
        let spans = random_spans(&mut SeedRng::seed_from_u64(seed), &w, 2000);
        let run = run_writer(m, seed, Traffic::FULL, Stress::NONE, &spans);
        assert_clean(m.tag, seed, &run.report);
        let writes: u64 = spans.iter().map(|(_, s)| w.write_count(s) as u64).sum();
        let segments: u64 = spans.iter().map(|(_, s)| w.cfg.segment_count(s.x0, s.len) as u64).sum();
        let bound = writes.max(segments) + 20;
        assert!(run.report.cycles <= bound, "{}: {} clocks for {writes} writes ({segments} segments)", m.tag, run.report.cycles);
    }
}

/// The negative control: the same RTL judged by golden's writer for a narrower screen (another
/// row stride) must fail, and so must a writer judged against shifted spans.
#[test]
fn the_scoreboard_catches_a_wrong_writer() {
    let seed = verilator_harness::seed("writer negative control");
    let Some(models) = require_models(&WRITER_MODELS, "fb_writer", "writer negative control") else { return };
    for m in models {
        let w = writer_of(m);
        let spans = random_spans(&mut SeedRng::seed_from_u64(seed), &w, 300);
        let narrow = Writer::new(m.cfg, Screen { width: w.screen.width - m.cfg.p, ..w.screen }).unwrap();
        let mut spans_narrow: Vec<(u32, Span)> = spans.iter().filter(|(_, s)| s.x0 + s.len <= narrow.screen.width).cloned().collect();
        // A pixel of row 1, whose address the two row strides put a block apart: the control
        // catches the wrong writer for every seed, not only when the random spans leave row 0.
        spans_narrow.push((1, Span { x0: 0, len: 1, ..spans[0].1 }));
        let run = run_writer_against(m, seed, Traffic::RANDOM, Stress::NONE, &spans_narrow, narrow);
        assert!(!run.report.ok(), "{}: a writer with another row stride passed", m.tag);
    }
}

/// `rst` between two segments of a span drops the pending tail: nothing of the cut span is
/// written after the reset, and the next span is written as golden says.
#[test]
fn a_reset_drops_a_pending_tail() {
    let Some(models) = require_models(&WRITER_MODELS, "fb_writer", "writer reset") else { return };
    for m in models.iter().filter(|m| m.cfg.p > 1 && m.cfg.align == golden::Align::Span) {
        let w = writer_of(m);
        let p = m.cfg.p;
        let mut rtl = Rtl::new(m, 7);
        let mut input = WrIn { rst: 1, ..Default::default() };
        let mut out = WrOut::default();
        rtl.step_into(&input, &mut out);
        let cut = Span { x0: 3, len: 3 * p, i0: 50 << m.cfg.frac, di: 1 << m.cfg.frac };
        let next = Span { x0: 5 * p + 1, len: p + 2, i0: 90 << m.cfg.frac, di: 0 };
        let load = |input: &mut WrIn, span: &Span, s: u32| {
            let seg = golden::segment::segment(&m.cfg, span, s);
            (input.in_x, input.in_y, input.in_last) = (seg.x, 2, seg.last as u8);
            input.mask = [0; 32];
            for i in 0..p {
                if let Some(j) = seg.lane_pixel(i) {
                    input.mask[(i / 8) as usize] |= 1 << (i % 8);
                    input.pix[i as usize] = span.pixel(j, m.cfg.frac);
                }
            }
        };
        // Segment 0 of `cut` goes in (its tail now waits), then a reset.
        input = WrIn { out_ready: 1, in_valid: 1, ..Default::default() };
        load(&mut input, &cut, 0);
        rtl.step_into(&input, &mut out);
        assert_eq!(out.in_ready, 1);
        input.rst = 1;
        input.in_valid = 0;
        rtl.step_into(&input, &mut out);
        input.rst = 0;
        let mut writes = Vec::new();
        let mut s = 0;
        for _ in 0..20 {
            input.in_valid = (s < w.cfg.segment_count(next.x0, next.len)) as u8;
            if input.in_valid == 1 {
                load(&mut input, &next, s);
            }
            rtl.step_into(&input, &mut out);
            if out.out_valid == 1 {
                writes.push((out.mem_addr, out.we[..(p as usize).div_ceil(8)].to_vec()));
            }
            if input.in_valid == 1 && out.in_ready == 1 {
                s += 1;
            }
        }
        let want: Vec<(u32, Vec<u8>)> = w
            .writes(2, &next)
            .map(|g| {
                let mut we = vec![0u8; (p as usize).div_ceil(8)];
                for i in (0..p).filter(|&i| g.enabled(i)) {
                    we[(i / 8) as usize] |= 1 << (i % 8);
                }
                (g.addr, we)
            })
            .collect();
        assert_eq!(writes, want, "{}: after the reset only the next span's writes", m.tag);
    }
}

fn frontend(m: &verilator_harness::ffi::ModelInfo<verilator_harness::ffi::TriIn, WrOut>) -> FrontEnd {
    m.frontend()
}

#[test]
fn triangles_to_memory_equal_golden_and_the_f64_reference() {
    let seed = verilator_harness::seed("tri_fb");
    let Some(models) = require_models(&TRIWRITER_MODELS, "tri_fb", "tri_fb frames") else { return };
    for m in models {
        let fe = frontend(m);
        let mut rng = SeedRng::seed_from_u64(seed ^ m.cfg.p as u64);
        for round in 0..3 {
            let tris = random_triangles(&mut rng, &fe, 150);
            let run = run_fb(m, seed + round, Traffic::RANDOM, &tris);
            assert_clean(m.tag, seed, &run.report);
            assert!(run.report.max_error <= 1.0);
        }
    }
}

#[test]
fn a_shared_edge_mesh_lands_in_memory_once_per_pixel() {
    let seed = verilator_harness::seed("tri_fb mesh");
    let Some(models) = require_models(&TRIWRITER_MODELS, "tri_fb", "tri_fb mesh") else { return };
    for m in models {
        let fe = frontend(m);
        let tris: Vec<FixedTriangle> = mesh(&mut SeedRng::seed_from_u64(seed), &fe, 13, 9);
        let run = run_fb(m, seed, Traffic::RANDOM, &tris);
        assert_clean(m.tag, seed, &run.report);
        let writes = run.mem.screen_writes();
        assert!(writes.iter().all(|&n| n == 1), "{}: every pixel of the screen written exactly once", m.tag);
    }
}

/// `render --writer rtl`, with the host's or the RTL's set-up: the image read out of the memory
/// model equals golden's in every pixel, with the hidden surfaces hidden.
#[test]
fn scenes_render_into_memory_as_golden() {
    use verilator_harness::registry::require;
    use verilator_harness::render::{run_with, scene_job, Chain, SceneKind};
    let what = "render into memory";
    let Some(seg) = verilator_harness::registry::require_segment_model(8, golden::Align::Span, what) else { return };
    let Some(wr) = require(WRITER_MODELS.iter().find(|m| m.cfg.p == 8 && m.cfg.align == golden::Align::Span), "wr_p8_span", what) else {
        return;
    };
    let Some(fb) = require(TRIWRITER_MODELS.iter().find(|m| m.cfg.p == 8 && m.cfg.align == golden::Align::Span), "trw_p8_span", what)
    else {
        return;
    };
    for chain in [Chain::HostToMemory(wr), Chain::RtlToMemory(fb)] {
        // On the chain's own screen (a COSIM_RTL_DIR folder's may be another than 640x480).
        let job = scene_job(SceneKind::Torus, 40, &seg.cfg, &fb.screen).unwrap();
        let o = run_with(&job, seg, chain, None, |_| {});
        let first = o.segment.iter().chain(&o.writer).flat_map(|r| &r.mismatches).next();
        assert!(o.cosim_ok(), "{first:?}");
        assert_eq!(o.differing_pixels(3), 0, "the image out of memory differs from golden's");
        assert!(o.rtl.iter().any(|&v| v != 0), "an empty image");
    }
}
