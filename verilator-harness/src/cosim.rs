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
use crate::traffic::TrafficGen;
use rand::Rng;
use std::collections::{BTreeSet, VecDeque};
use std::fmt;

pub use crate::traffic::Traffic;

/// Stress on top of [`Traffic`], off by default: `rst` at random clocks, long stretches of
/// `out_ready` low, long `in_valid` gaps between spans. With a reset, the spans accepted and not
/// yet fully out are *cut* (their remaining output is dropped from the scoreboard) and a span
/// being offered is offered again afterwards; in a clock with `rst` high nothing transfers.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stress {
    /// Probability per clock of asserting `rst` (for 1..=3 clocks).
    pub reset: f64,
    /// Probability per clock that `out_ready` drops for 1..=`stall_max` clocks.
    pub stall: f64,
    pub stall_max: u32,
    /// Probability after each input transfer of an `in_valid` gap of 1..=`gap_max` clocks.
    pub gap: f64,
    pub gap_max: u32,
}

impl Stress {
    pub const NONE: Stress = Stress { reset: 0.0, stall: 0.0, stall_max: 0, gap: 0.0, gap_max: 0 };
    /// Long backpressure bursts and input gaps, no reset.
    pub const BURSTS: Stress = Stress { reset: 0.0, stall: 0.01, stall_max: 300, gap: 0.05, gap_max: 200 };
    /// Everything at once: resets about every 500 clocks, bursts and gaps.
    pub const HARSH: Stress = Stress { reset: 0.002, ..Stress::BURSTS };
}

/// The per-clock decisions of the driver and the sink under [`Traffic`] and [`Stress`]: the
/// generator's two draws of the clock ([`TrafficGen::clock`]), then the stress draws. Without
/// stress it is exactly the plain traffic of the native and cocotb benches.
#[derive(Clone, Debug)]
pub(crate) struct Pacer {
    stress: Stress,
    rst_left: u32,
    stall_left: u32,
    gap_left: u32,
}

impl Pacer {
    pub(crate) fn new(stress: Stress) -> Pacer {
        Pacer { stress, rst_left: 0, stall_left: 0, gap_left: 0 }
    }

    /// Whether `rst` is high this clock.
    #[inline]
    pub(crate) fn reset(&mut self, rng: &mut TrafficGen) -> bool {
        if self.rst_left == 0 && self.stress.reset > 0.0 && rng.gen_bool(self.stress.reset) {
            self.rst_left = rng.gen_range(1..=3);
        }
        if self.rst_left > 0 {
            self.rst_left -= 1;
            return true;
        }
        false
    }

    /// Whether a pending span starts being offered this clock.
    #[inline]
    pub(crate) fn offer(&mut self, rng: &mut TrafficGen) -> bool {
        if self.gap_left > 0 {
            self.gap_left -= 1;
            return false;
        }
        rng.offer()
    }

    /// `out_ready` this clock.
    #[inline]
    pub(crate) fn ready(&mut self, rng: &mut TrafficGen) -> bool {
        if self.stall_left == 0 && self.stress.stall > 0.0 && rng.gen_bool(self.stress.stall) {
            self.stall_left = rng.gen_range(1..=self.stress.stall_max.max(1));
        }
        if self.stall_left > 0 {
            self.stall_left -= 1;
            return false;
        }
        rng.ready()
    }

    /// A span was transferred: maybe a gap before the next one is offered.
    #[inline]
    pub(crate) fn accepted(&mut self, rng: &mut TrafficGen) {
        if self.stress.gap > 0.0 && rng.gen_bool(self.stress.gap) {
            self.gap_left = rng.gen_range(1..=self.stress.gap_max.max(1));
        }
    }
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
    /// Resets injected by [`Stress`], and the accepted spans they cut short.
    pub resets: u64,
    pub cut_spans: u64,
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
    rng: TrafficGen,
    stress: Stress,
    input: SegIn,
    output: SegOut,
    /// Spare golden rows (see [`golden_row`]).
    rows: Vec<Frame>,
    /// The segment offered and not taken in the previous clock (its lanes below P).
    held: SegOut,
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
            rng: TrafficGen::new(traffic, seed),
            stress: Stress::NONE,
            input: SegIn::default(),
            output: SegOut::default(),
            rows: Vec::new(),
            held: SegOut::default(),
        };
        c.reset();
        c
    }

    /// Adds [`Stress`] to the traffic of every following [`SegmentCosim::stream`].
    pub fn set_stress(&mut self, stress: Stress) {
        self.stress = stress;
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
    /// each checked segment that left the model, with its span. Panics, before the model sees
    /// anything, on a span its ports cannot take (see [`SegmentCosim::try_stream`]).
    pub fn stream(&mut self, stims: &[Stim], report: &mut Report, paint: impl FnMut(&Stim, &SegOut)) {
        if let Err(e) = self.try_stream(stims, report, paint) {
            panic!("{}: {e}", self.info.tag);
        }
    }

    /// [`SegmentCosim::stream`], or an error naming the first span the RTL cannot take
    /// (`golden::Span::check`: `x0 + len` beyond 2^XW, `len` above 2^XW, `I0` or `dI` wider than
    /// their ports). Nothing is streamed then.
    ///
    /// Besides the scoreboard, a protocol monitor checks SPEC §3's valid/ready rules on the
    /// output: a segment offered and not taken stays offered, unchanged, in the next clock; in
    /// the first clock after a reset `out_valid` is low.
    pub fn try_stream(&mut self, stims: &[Stim], report: &mut Report, mut paint: impl FnMut(&Stim, &SegOut)) -> Result<(), String> {
        let cfg = self.cfg;
        for (k, s) in stims.iter().enumerate() {
            s.span.check(&cfg).map_err(|e| format!("span {k} (triangle {}, y = {}) rejected: {e}", s.triangle, s.y))?;
        }
        let mut pacer = Pacer::new(self.stress);
        // Every accepted span with segments still owed, oldest first: its index, its golden
        // segments (made by golden as they are compared), how many are left and its golden row.
        let mut expected = VecDeque::new();
        let mut next = 0;
        let mut offering = false;
        let mut idle = 0u64;
        let mut drain = 0;
        let mut in_reset = false;
        let mut held = false;
        loop {
            if next == stims.len() && expected.is_empty() {
                // Everything came out; a few more clocks must bring nothing.
                if drain == DRAIN_CLOCKS {
                    break;
                }
                drain += 1;
            }
            self.rng.clock();
            if pacer.reset(&mut self.rng) {
                // Nothing transfers in a reset clock: the spans in flight are cut, the one
                // being offered stays offered.
                if !in_reset {
                    report.resets += 1;
                    report.cut_spans += expected.len() as u64;
                    self.rows.extend(expected.drain(..).map(|(_, _, _, row)| row));
                }
                in_reset = true;
                held = false;
                self.input.rst = 1;
                self.input.in_valid = offering as u8;
                self.input.out_ready = pacer.ready(&mut self.rng) as u8;
                self.rtl.step_into(&self.input, &mut self.output);
                self.input.rst = 0;
                report.cycles += 1;
                idle = 0;
                continue;
            }
            if !offering && next < stims.len() {
                offering = pacer.offer(&mut self.rng);
                if offering {
                    self.drive(&stims[next].span);
                }
            }
            self.input.in_valid = offering as u8;
            self.input.out_ready = pacer.ready(&mut self.rng) as u8;
            self.rtl.step_into(&self.input, &mut self.output);
            report.cycles += 1;
            if std::mem::take(&mut in_reset) && self.output.out_valid != 0 {
                report.mismatch(Mismatch {
                    triangle: None,
                    context: format!("clock {}", report.cycles),
                    what: "out_valid high in the first clock after a reset".into(),
                });
            }
            if std::mem::take(&mut held) {
                if let Some(what) = changed_while_stalled(&self.held, &self.output, cfg.p) {
                    report.mismatch(Mismatch { triangle: None, context: format!("clock {}", report.cycles), what });
                }
            }
            let mut progress = false;
            if self.output.out_valid == 1 && self.input.out_ready == 1 {
                progress = true;
                match expected.front_mut() {
                    Some((k, segs, left, row)) => {
                        let k: usize = *k;
                        let seg: Segment = Iterator::next(segs).expect("segments owed");
                        *left -= 1;
                        let all_out = *left == 0;
                        self.check(&stims[k], &seg, row.pixels(), report);
                        paint(&stims[k], &self.output);
                        if all_out {
                            let (_, _, _, row) = expected.pop_front().expect("front");
                            self.rows.push(row);
                        }
                    }
                    None => {
                        // Output nobody asked for is no progress: a model that streams garbage
                        // while refusing input is declared hung, not followed forever.
                        progress = false;
                        report.mismatch(Mismatch {
                            triangle: None,
                            context: format!("clock {}", report.cycles),
                            what: format!("segment at x = {} with no span outstanding", self.output.out_x),
                        });
                    }
                }
            } else if self.output.out_valid == 1 {
                held = true;
                keep_offered(&mut self.held, &self.output, cfg.p);
            }
            if offering && self.output.in_ready == 1 {
                progress = true;
                let stim = &stims[next];
                let owed = cfg.segment_count(stim.span.x0, stim.span.len);
                if owed > 0 {
                    expected.push_back((next, segments(&cfg, &stim.span), owed, golden_row(&mut self.rows, &cfg, &stim.span)));
                }
                report.spans += 1;
                next += 1;
                offering = false;
                pacer.accepted(&mut self.rng);
            }
            idle = if progress { 0 } else { idle + 1 };
            if idle > STALL_LIMIT {
                let context = match expected.front() {
                    Some((k, _, _, _)) => describe(&stims[*k]),
                    None => "idle".into(),
                };
                report.mismatch(Mismatch {
                    triangle: expected.front().map(|(k, _, _, _)| stims[*k].triangle),
                    context,
                    what: format!(
                        "no transfer for {STALL_LIMIT} clocks; {} segments still expected",
                        expected.iter().map(|(_, _, left, _)| *left as u64).sum::<u64>()
                    ),
                });
                self.reset();
                return Ok(());
            }
        }
        Ok(())
    }

    /// Checks one segment against golden; `row` is its span's golden row (see [`golden_row`]).
    #[inline]
    fn check(&self, stim: &Stim, seg: &Segment, row: &[u8], report: &mut Report) {
        match agrees(&self.output, &stim.span, seg, row, self.cfg.p) {
            Some(pixels) => {
                report.segments += 1;
                report.pixels += pixels;
            }
            None => self.check_lanes(stim, seg, report),
        }
    }

    /// The segment lane by lane against golden, saying what disagrees.
    #[cold]
    #[inline(never)]
    fn check_lanes(&self, stim: &Stim, seg: &Segment, report: &mut Report) {
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

/// For 8 lane-enable bits, the word selecting those lanes' bytes.
static BYTE_MASK: [u64; 256] = {
    let mut t = [0u64; 256];
    let mut m = 0;
    while m < 256 {
        let mut b = 0;
        while b < 8 {
            if m >> b & 1 == 1 {
                t[m] |= 0xff << (8 * b);
            }
            b += 1;
        }
        m += 1;
    }
    t
};

/// Keeps what [`changed_while_stalled`] compares of a segment offered and not taken: its flags,
/// x and the lanes below `p` (not the whole 300-byte struct, every stalled clock).
#[inline]
fn keep_offered(held: &mut SegOut, out: &SegOut, p: u32) {
    held.out_valid = out.out_valid;
    held.out_last = out.out_last;
    held.out_x = out.out_x;
    // Whole 8-byte words (lanes past P are never compared).
    for w in 0..p.div_ceil(8) as usize {
        held.pix[8 * w..8 * w + 8].copy_from_slice(&out.pix[8 * w..8 * w + 8]);
    }
    for w in 0..p.div_ceil(64) as usize {
        held.mask[8 * w..8 * w + 8].copy_from_slice(&out.mask[8 * w..8 * w + 8]);
    }
}

/// Golden's pixels of a span as one frame row, indexed by x: written by golden
/// (`Frame::write_span`, SPEC §2's pixel rule) once, when the span is accepted, so the
/// scoreboard compares lanes with memory instead of deriving every pixel again. Rows are reused
/// (`spare`); they are P pixels wider than the screen, so a segment at the last x stays inside.
fn golden_row(spare: &mut Vec<Frame>, cfg: &Config, span: &Span) -> Frame {
    let mut row = spare.pop().unwrap_or_else(|| Frame::new(cfg.max_len() + cfg.p, 1));
    row.write_span(0, span, cfg.frac);
    row
}

/// [`SegmentCosim::check`]'s verdict on the way every segment should go: the number of
/// in-span lanes when x, last, the mask and every in-span pixel agree with golden, `None` at
/// the first disagreement, which `check` then describes lane by lane.
///
/// Golden enables lanes `[lo, hi)`, lane i carrying span pixel `j = x + i - x0` (SPEC §3: lane
/// i is the pixel at screen x `out_x + i`). Golden's `Segment::lane_pixel` is affine in the
/// lane, so the range is confirmed by asking golden at both ends and just outside them; then
/// the mask is compared a byte at a time and the pixels eight lanes at a time with the span's
/// golden `row` from `out_x` on, masked lanes ignored.
#[inline]
fn agrees(out: &SegOut, span: &Span, seg: &Segment, row: &[u8], p: u32) -> Option<u64> {
    if out.out_x != seg.x || (out.out_last == 1) != seg.last {
        return None;
    }
    let lo = span.x0.saturating_sub(seg.x).min(p);
    let hi = (span.x0 + span.len).saturating_sub(seg.x).min(p);
    if lo >= hi {
        return None;
    }
    let j_lo = seg.x + lo - span.x0;
    if seg.lane_pixel(lo) != Some(j_lo)
        || seg.lane_pixel(hi - 1) != Some(j_lo + (hi - 1 - lo))
        || (lo > 0 && seg.lane_pixel(lo - 1).is_some())
        || (hi < p && seg.lane_pixel(hi).is_some())
    {
        return None;
    }
    let row = row.get(seg.x as usize..(seg.x + p) as usize)?;
    // Lanes [lo, hi) of the 8 from `base` as a byte of enable bits.
    let lanes_on = |base: u32| ((1u16 << (hi.clamp(base, base + 8) - base)) - (1u16 << (lo.clamp(base, base + 8) - base))) as u8;
    if p < 8 {
        let (on, n) = (lanes_on(0), p as usize);
        let word = |b: &[u8]| b[..n].iter().rev().fold(0u64, |w, &x| w << 8 | x as u64);
        return (out.mask[0] & ((1u16 << p) - 1) as u8 == on && (word(&out.pix) ^ word(row)) & BYTE_MASK[on as usize] == 0)
            .then_some((hi - lo) as u64);
    }
    for c in 0..(p / 8) as usize {
        let on = lanes_on(8 * c as u32);
        let word = |b: &[u8]| u64::from_le_bytes(b[8 * c..8 * c + 8].try_into().expect("8 lanes"));
        if out.mask[c] != on || (word(&out.pix) ^ word(row)) & BYTE_MASK[on as usize] != 0 {
            return None;
        }
    }
    Some((hi - lo) as u64)
}

/// What changed in a segment that was offered and not taken in the previous clock, if anything
/// (masked lanes are don't-care).
#[inline]
fn changed_while_stalled(before: &SegOut, now: &SegOut, p: u32) -> Option<String> {
    if now.out_valid != 1 {
        return Some(format!("out_valid dropped before the segment at x = {} was taken", before.out_x));
    }
    let lanes_differ = (0..p.div_ceil(8) as usize).any(|b| {
        let lanes = if p >= 8 * (b as u32 + 1) { 0xff } else { (1u8 << (p % 8)) - 1 };
        let on = now.mask[b] & lanes;
        let word = |o: &SegOut| u64::from_le_bytes(o.pix[8 * b..8 * b + 8].try_into().expect("8 bytes"));
        on != before.mask[b] & lanes || (word(now) ^ word(before)) & BYTE_MASK[on as usize] != 0
    });
    if now.out_x != before.out_x || now.out_last != before.out_last || lanes_differ {
        return Some(format!("segment at x = {} changed while waiting for out_ready (now x = {})", before.out_x, now.out_x));
    }
    None
}

fn describe(s: &Stim) -> String {
    format!(
        "span y = {} x0 = {} len = {} i0 = {} di = {}",
        s.y, s.span.x0, s.span.len, s.span.i0, s.span.di
    )
}
