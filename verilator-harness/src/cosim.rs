//! Streams spans through a segment-shader model and checks everything that comes out.
//!
//! Driver: offers spans in order, raising `in_valid` after random gaps and holding it (and the
//! data) until the span is taken, as SPEC §3 requires of a source. Backpressure: `out_ready`
//! random every clock. Monitor and scoreboard: every accepted span queues its golden segments;
//! every segment that leaves the model must be the next one queued, with the same x, mask,
//! last flag and in-span pixels. The segments are also painted into a frame that must equal
//! golden's frame exactly and the f64 reference within SPEC §5's bounds.

use crate::ffi::{to_port, ModelInfo, Rtl, SegIn, SegOut};
use golden::raster::{compare, reference_triangle, Frame, RefFrame};
use golden::segment::{segments, Segment};
use golden::setup::{triangle_spans, Screen, Triangle};
use golden::{Config, Span};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use std::collections::{BTreeSet, VecDeque};
use std::fmt;

/// How often the driver offers a span and the sink takes a segment.
#[derive(Clone, Copy, Debug)]
pub struct Traffic {
    /// Probability per clock that a pending span starts being offered.
    pub valid: f64,
    /// Probability per clock that `out_ready` is high.
    pub ready: f64,
}

impl Traffic {
    /// Both ends always willing: measures the shader's own throughput.
    pub const FULL: Traffic = Traffic { valid: 1.0, ready: 1.0 };
    /// Random gaps and backpressure.
    pub const RANDOM: Traffic = Traffic { valid: 0.7, ready: 0.7 };
}

/// A span with where it came from, for failure messages.
#[derive(Clone, Copy, Debug)]
pub struct Stim {
    pub triangle: usize,
    pub y: u32,
    pub span: Span,
}

/// One disagreement between the RTL and golden.
#[derive(Clone, Debug)]
pub struct Mismatch {
    pub triangle: Option<usize>,
    pub context: String,
    pub what: String,
}

impl fmt::Display for Mismatch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.triangle {
            Some(t) => write!(f, "triangle {t}: {}: {}", self.context, self.what),
            None => write!(f, "{}: {}", self.context, self.what),
        }
    }
}

/// Counts of one run; `merge` adds runs up.
#[derive(Clone, Debug, Default)]
pub struct Report {
    pub triangles: usize,
    pub spans: u64,
    pub segments: u64,
    pub pixels: u64,
    pub cycles: u64,
    pub failed: BTreeSet<usize>,
    pub mismatch_count: u64,
    /// The first mismatches, in full.
    pub mismatches: Vec<Mismatch>,
    /// Worst |pixel - exact plane| over all frames compared with the f64 reference.
    pub max_error: f64,
}

const KEEP_MISMATCHES: usize = 20;

impl Report {
    pub fn mismatch(&mut self, m: Mismatch) {
        self.mismatch_count += 1;
        if let Some(t) = m.triangle {
            self.failed.insert(t);
        }
        if self.mismatches.len() < KEEP_MISMATCHES {
            self.mismatches.push(m);
        }
    }

    pub fn ok(&self) -> bool {
        self.mismatch_count == 0
    }

    /// Triangles that failed; a mismatch no triangle can be blamed for counts as one.
    pub fn failed_count(&self) -> usize {
        if !self.ok() && self.failed.is_empty() {
            1
        } else {
            self.failed.len()
        }
    }

    pub fn passed_count(&self) -> usize {
        self.triangles - self.failed.len().min(self.triangles)
    }

    pub fn pixels_per_clock(&self) -> f64 {
        self.pixels as f64 / self.cycles.max(1) as f64
    }
}

/// Stops a test with every mismatch it kept, the seed and the replay hint.
pub fn assert_clean(what: &str, seed: u64, report: &Report) {
    if report.ok() {
        return;
    }
    let mut msg = format!("{what}: {} mismatches (seed {seed}, replay with COSIM_SEED={seed})\n", report.mismatch_count);
    for m in &report.mismatches {
        msg.push_str(&format!("  {m}\n"));
    }
    panic!("{msg}");
}

/// A segment-shader model under test with its driver's random source.
pub struct SegmentCosim {
    info: &'static ModelInfo<SegIn, SegOut>,
    rtl: Rtl<SegIn, SegOut>,
    cfg: Config,
    rng: StdRng,
    traffic: Traffic,
    input: SegIn,
    output: SegOut,
}

/// Clocks run after the last expected segment, in which the model must stay quiet.
pub const DRAIN_CLOCKS: u64 = 3;

/// Clocks without any transfer after which the model is declared hung.
const STALL_LIMIT: u64 = 10_000;

impl SegmentCosim {
    pub fn new(info: &'static ModelInfo<SegIn, SegOut>, seed: u64, traffic: Traffic) -> SegmentCosim {
        let mut c = SegmentCosim {
            info,
            rtl: Rtl::new(info, seed),
            cfg: info.cfg,
            rng: StdRng::seed_from_u64(seed),
            traffic,
            input: SegIn::default(),
            output: SegOut::default(),
        };
        c.reset();
        c
    }

    pub fn info(&self) -> &'static ModelInfo<SegIn, SegOut> {
        self.info
    }

    /// Two clocks of reset with the inputs idle.
    pub fn reset(&mut self) {
        self.input = SegIn { rst: 1, ..SegIn::default() };
        for _ in 0..2 {
            self.rtl.step_into(&self.input, &mut self.output);
        }
        self.input.rst = 0;
    }

    fn drive(&mut self, span: &Span) {
        self.input.in_x = span.x0;
        self.input.in_len = span.len;
        self.input.in_i0 = span.i0;
        self.input.in_di = to_port(span.di as i64, self.cfg.dw());
    }

    /// Streams `stims` through the model, checking every segment against golden; `paint` gets
    /// each checked segment that left the model, with its span.
    pub fn stream(&mut self, stims: &[Stim], report: &mut Report, mut paint: impl FnMut(&Stim, &SegOut)) {
        let cfg = self.cfg;
        let mut expected: VecDeque<(usize, Segment)> = VecDeque::new();
        let mut next = 0;
        let mut offering = false;
        let mut idle = 0u64;
        let mut drain = 0;
        loop {
            if next == stims.len() && expected.is_empty() {
                // Everything came out; a few more clocks must bring nothing.
                if drain == DRAIN_CLOCKS {
                    break;
                }
                drain += 1;
            }
            if !offering && next < stims.len() {
                offering = self.traffic.valid >= 1.0 || self.rng.gen_bool(self.traffic.valid);
                if offering {
                    self.drive(&stims[next].span);
                }
            }
            self.input.in_valid = offering as u8;
            self.input.out_ready = (self.traffic.ready >= 1.0 || self.rng.gen_bool(self.traffic.ready)) as u8;
            self.rtl.step_into(&self.input, &mut self.output);
            report.cycles += 1;
            let mut progress = false;
            if self.output.out_valid == 1 && self.input.out_ready == 1 {
                progress = true;
                match expected.pop_front() {
                    Some((k, seg)) => {
                        self.check(&stims[k], &seg, report);
                        paint(&stims[k], &self.output);
                    }
                    None => report.mismatch(Mismatch {
                        triangle: None,
                        context: format!("clock {}", report.cycles),
                        what: format!("segment at x = {} with no span outstanding", self.output.out_x),
                    }),
                }
            }
            if offering && self.output.in_ready == 1 {
                progress = true;
                let stim = &stims[next];
                expected.extend(segments(&cfg, &stim.span).map(|s| (next, s)));
                report.spans += 1;
                next += 1;
                offering = false;
            }
            idle = if progress { 0 } else { idle + 1 };
            if idle > STALL_LIMIT {
                let context = match expected.front() {
                    Some((k, _)) => describe(&stims[*k]),
                    None => "idle".into(),
                };
                report.mismatch(Mismatch {
                    triangle: expected.front().map(|(k, _)| stims[*k].triangle),
                    context,
                    what: format!("no transfer for {STALL_LIMIT} clocks; {} segments still expected", expected.len()),
                });
                self.reset();
                return;
            }
        }
    }

    fn check(&self, stim: &Stim, seg: &Segment, report: &mut Report) {
        let out = &self.output;
        let mut problems = Vec::new();
        if out.out_x != seg.x {
            problems.push(format!("out_x expected {}, got {}", seg.x, out.out_x));
        }
        if (out.out_last == 1) != seg.last {
            problems.push(format!("out_last expected {}, got {}", seg.last as u8, out.out_last));
        }
        let mut pixels = 0;
        for i in 0..self.cfg.p {
            match seg.lane_pixel(i) {
                Some(j) => {
                    pixels += 1;
                    if !out.lane_enabled(i) {
                        problems.push(format!("lane {i} (pixel {j}) masked off"));
                    } else {
                        let want = stim.span.pixel(j, self.cfg.frac);
                        if out.pix[i as usize] != want {
                            problems.push(format!("lane {i} (pixel {j}): expected {want}, got {}", out.pix[i as usize]));
                        }
                    }
                }
                None if out.lane_enabled(i) => problems.push(format!("lane {i} enabled outside the span")),
                None => {}
            }
        }
        report.segments += 1;
        report.pixels += pixels;
        if !problems.is_empty() {
            report.mismatch(Mismatch {
                triangle: Some(stim.triangle),
                context: format!("{}, segment {}", describe(stim), seg.index),
                what: problems.join("; "),
            });
        }
    }

    /// Sets up `triangles` (numbered from `first`), streams their spans, paints the segments and
    /// compares the frame with golden's and with the f64 reference.
    pub fn run_triangles(&mut self, screen: &Screen, triangles: &[Triangle], first: usize, report: &mut Report) {
        let cfg = self.cfg;
        let mut stims = Vec::new();
        for (k, t) in triangles.iter().enumerate() {
            let triangle = first + k;
            let res = triangle_spans(&cfg, screen, t, |y, span| stims.push(Stim { triangle, y, span }));
            if let Err(e) = res {
                report.mismatch(Mismatch { triangle: Some(triangle), context: format!("{t}"), what: format!("set-up rejected it: {e}") });
            }
        }
        let mut rtl = Frame::new(screen.width, screen.height);
        let mut owner = vec![usize::MAX; (screen.width * screen.height) as usize];
        let p = cfg.p;
        self.stream(&stims, report, |stim, out| {
            for i in 0..p {
                let x = out.out_x + i;
                if out.lane_enabled(i) && x < screen.width {
                    rtl.set(x, stim.y, out.pix[i as usize]);
                    owner[(stim.y * screen.width + x) as usize] = stim.triangle;
                }
            }
        });
        report.triangles += triangles.len();

        let mut gold = Frame::new(screen.width, screen.height);
        for s in &stims {
            gold.write_span(s.y, &s.span, cfg.frac);
        }
        for y in 0..screen.height {
            for x in 0..screen.width {
                let (a, b) = (rtl.get(x, y), gold.get(x, y));
                if a != b {
                    let t = owner[(y * screen.width + x) as usize];
                    report.mismatch(Mismatch {
                        triangle: (t != usize::MAX).then_some(t),
                        context: format!("frame pixel ({x}, {y})"),
                        what: format!("golden {b:?}, RTL {a:?}"),
                    });
                }
            }
        }
        let mut reference = RefFrame::new(screen.width, screen.height);
        for t in triangles {
            // Set-up already reported a triangle it rejects.
            let _ = reference_triangle(screen, t, &mut reference);
        }
        let cmp = compare(&rtl, &reference);
        report.max_error = report.max_error.max(cmp.max_error);
        if !cmp.passed() {
            let t = cmp.first_mismatch.or(cmp.max_diff_at).map(|(x, y)| owner[(y * screen.width + x) as usize]);
            report.mismatch(Mismatch {
                triangle: t.filter(|&t| t != usize::MAX),
                context: "frame against the f64 reference".into(),
                what: cmp.to_string(),
            });
        }
    }
}

fn describe(s: &Stim) -> String {
    format!(
        "span y = {} x0 = {} len = {} i0 = {} di = {}",
        s.y, s.span.x0, s.span.len, s.span.i0, s.span.di
    )
}
