//! Streams spans through a segment-shader model and checks everything that comes out.
//!
//! Driver ([`crate::driver`]): offers spans in order, raising `in_valid` after random gaps and
//! holding it (and the data) until the span is taken, as SPEC §3 requires of a source, with
//! `out_ready` random every clock. Scoreboard: every segment that leaves the model must be the
//! next one owed by the oldest span in flight, with the same x, mask, last flag and in-span
//! pixels as golden's. The segments are also painted into a frame that must equal golden's
//! frame exactly and the f64 reference within SPEC §5's bounds.

use crate::driver::{Check, Driver, Unit};
use crate::ffi::{to_port, ModelInfo, Rtl, SegIn, SegOut};
use crate::report::Mismatch;
use crate::traffic::TrafficGen;
use golden::raster::{compare, reference_triangle, Frame, RefFrame};
use golden::segment::{segment, Segment};
use golden::setup::{triangle_spans, Screen, Triangle};
use golden::{Config, Span};

// The vocabulary of a run, re-exported where the suites and binaries find it with the segment
// shader's co-simulation: its report, its stress and its traffic.
pub use crate::driver::{Stress, DRAIN_CLOCKS};
pub use crate::report::{assert_clean, Report};
pub use crate::traffic::Traffic;

/// A span with where it came from, for failure messages.
#[derive(Clone, Copy, Debug)]
pub struct Stim {
    pub triangle: usize,
    pub y: u32,
    pub span: Span,
}

/// A span the segment shader's ports cannot carry ([`SegmentCosim::try_stream`]); nothing
/// was streamed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("span {index} (triangle {triangle}, y = {y}) rejected: {error}")]
pub struct SpanRejected {
    /// The span's index in the stream.
    pub index: usize,
    pub triangle: usize,
    pub y: u32,
    pub error: golden::SpanError,
}

/// A segment offered by the model, as the checker sees it: `out_x`, `out_last` and the lane
/// buses below P (lane i's pixel in `pix[i]`, its enable in bit i % 8 of `mask[i / 8]`).
#[derive(Clone, Copy, Debug)]
pub struct SegView<'a> {
    pub out_x: u32,
    pub out_last: bool,
    pub pix: &'a [u8],
    pub mask: &'a [u8],
}

impl SegView<'_> {
    pub fn lane_enabled(&self, i: u32) -> bool {
        self.mask[(i / 8) as usize] >> (i % 8) & 1 == 1
    }
}

/// The driver's view of a segment shader. An output's record is `out_x | out_last << 31`
/// (4 bytes), the mask bytes below P, then the pixels, padded to whole 8-byte words so the
/// checker compares them a word at a time.
struct SegUnit {
    cfg: Config,
    /// Bytes of the mask, and of the padded pixels.
    mask_bytes: usize,
    pix_bytes: usize,
}

impl SegUnit {
    fn new(cfg: Config) -> SegUnit {
        SegUnit { cfg, mask_bytes: cfg.p.div_ceil(8) as usize, pix_bytes: cfg.p.next_multiple_of(8) as usize }
    }

    #[inline(always)]
    fn view<'a>(&self, rec: &'a [u8]) -> SegView<'a> {
        let head = u32::from_le_bytes(rec[..4].try_into().expect("4 bytes"));
        let (mask, pix) = rec[4..].split_at(self.mask_bytes);
        SegView { out_x: head & !(1 << 31), out_last: head >> 31 == 1, pix, mask }
    }
}

impl Unit for SegUnit {
    type In = SegIn;
    type Out = SegOut;
    type Span = Stim;

    fn record_bytes(&self) -> usize {
        4 + self.mask_bytes + self.pix_bytes
    }

    #[inline]
    fn load(&self, input: &mut SegIn, stim: &Stim) {
        input.in_x = stim.span.x0;
        input.in_len = stim.span.len;
        input.in_i0 = stim.span.i0;
        input.in_di = to_port(stim.span.di as i64, self.cfg.dw());
    }

    #[inline]
    fn owed(&self, stim: &Stim) -> u32 {
        self.cfg.segment_count(stim.span.x0, stim.span.len)
    }

    #[inline(always)]
    fn record(&self, out: &SegOut, rec: &mut [u8]) {
        let (head, rest) = rec.split_at_mut(4);
        head.copy_from_slice(&(out.out_x | (out.out_last as u32) << 31).to_le_bytes());
        let (mask, pix) = rest.split_at_mut(self.mask_bytes);
        // Byte and word copies: the lengths are small and vary with P, and memcpy calls would
        // cost more than the copies.
        for (d, s) in mask.iter_mut().zip(&out.mask) {
            *d = *s;
        }
        for (d, s) in pix.chunks_exact_mut(8).zip(out.pix.chunks_exact(8)) {
            d.copy_from_slice(s);
        }
    }

    #[inline(always)]
    fn same(&self, held: &[u8], out: &SegOut) -> bool {
        let held = self.view(held);
        let p = self.cfg.p;
        out.out_x == held.out_x
            && (out.out_last == 1) == held.out_last
            && (0..self.mask_bytes).all(|w| {
                let lanes = if p >= 8 * (w as u32 + 1) { 0xff } else { (1u8 << (p % 8)) - 1 };
                let on = out.mask[w] & lanes;
                let word = |pix: &[u8]| u64::from_le_bytes(pix[8 * w..8 * w + 8].try_into().expect("8 bytes"));
                on == held.mask[w] & lanes && (word(&out.pix) ^ word(held.pix)) & BYTE_MASK[on as usize] == 0
            })
    }

    fn describe_change(&self, held: &[u8], out: &SegOut) -> String {
        format!("segment at x = {} changed while waiting for out_ready (now x = {})", self.view(held).out_x, out.out_x)
    }

    fn blame(&self, _k: usize, stim: &Stim) -> (Option<usize>, String) {
        (Some(stim.triangle), describe(stim))
    }
}

/// The scoreboard of a segment shader, on the checking thread: every segment against golden,
/// then to `paint`.
struct SegCheck<'a, F> {
    unit: &'a SegUnit,
    stims: &'a [Stim],
    /// The span whose golden row `row` holds (see [`golden_row`]).
    row_of: Option<usize>,
    row: &'a mut Frame,
    paint: F,
}

impl<F: FnMut(&Stim, &SegView) + Send> Check for SegCheck<'_, F> {
    #[inline]
    fn check(&mut self, k: usize, j: u32, rec: &[u8], report: &mut Report) {
        let (cfg, stim) = (&self.unit.cfg, &self.stims[k]);
        if self.row_of != Some(k) {
            self.row.write_span(0, &stim.span, cfg.frac);
            self.row_of = Some(k);
        }
        let out = self.unit.view(rec);
        let seg = segment(cfg, &stim.span, j);
        match agrees(&out, &stim.span, &seg, self.row.pixels(), cfg.p) {
            Some(pixels) => {
                report.segments += 1;
                report.pixels += pixels;
            }
            None => check_lanes(cfg, stim, &seg, &out, report),
        }
        (self.paint)(stim, &out);
    }
}

/// The segment lane by lane against golden, saying what disagrees.
#[cold]
#[inline(never)]
pub(crate) fn check_lanes(cfg: &Config, stim: &Stim, seg: &Segment, out: &SegView, report: &mut Report) {
    let mut problems = Vec::new();
    if out.out_x != seg.x {
        problems.push(format!("out_x expected {}, got {}", seg.x, out.out_x));
    }
    if out.out_last != seg.last {
        problems.push(format!("out_last expected {}, got {}", seg.last as u8, out.out_last as u8));
    }
    let mut pixels = 0;
    for i in 0..cfg.p {
        match seg.lane_pixel(i) {
            Some(j) => {
                pixels += 1;
                if !out.lane_enabled(i) {
                    problems.push(format!("lane {i} (pixel {j}) masked off"));
                } else {
                    let want = stim.span.pixel(j, cfg.frac);
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

/// A segment-shader model under test with its driver.
pub struct SegmentCosim {
    info: &'static ModelInfo<SegIn, SegOut>,
    unit: SegUnit,
    driver: Driver<SegUnit>,
    /// Golden's row of the span being checked (see [`golden_row`]), kept between streams.
    row: Frame,
}

impl SegmentCosim {
    pub fn new(info: &'static ModelInfo<SegIn, SegOut>, seed: u64, traffic: Traffic) -> SegmentCosim {
        let cfg = info.cfg;
        SegmentCosim {
            info,
            unit: SegUnit::new(cfg),
            driver: Driver::new(Rtl::new(info, seed), TrafficGen::new(traffic, seed)),
            row: golden_row(&cfg),
        }
    }

    /// Adds [`Stress`] to the traffic of every following [`SegmentCosim::stream`].
    pub fn set_stress(&mut self, stress: Stress) {
        self.driver.stress = stress;
    }

    /// Writes the first failure's waveform into `dir` (`None`: none), whatever COSIM_TRACE says
    /// ([`crate::waveform`]). The model gets two clocks of reset, where the replay will start.
    pub fn set_waveforms(&mut self, dir: Option<std::path::PathBuf>) {
        self.driver.set_waveforms(dir);
    }

    pub fn info(&self) -> &'static ModelInfo<SegIn, SegOut> {
        self.info
    }

    /// Clocks the model has run since it was built, reset clocks included: the clock numbers of
    /// mismatch messages and waveforms (the last stream's last clock is this minus one).
    pub fn clock(&self) -> u64 {
        self.driver.clock()
    }

    /// Streams `stims` through the model, checking every segment against golden; `paint` gets
    /// each checked segment that left the model, with its span, in order (on the checking
    /// thread). Panics, before the model sees anything, on a span its ports cannot take (see
    /// [`SegmentCosim::try_stream`]).
    pub fn stream(&mut self, stims: &[Stim], report: &mut Report, paint: impl FnMut(&Stim, &SegView) + Send) {
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
    pub fn try_stream(
        &mut self,
        stims: &[Stim],
        report: &mut Report,
        paint: impl FnMut(&Stim, &SegView) + Send,
    ) -> Result<(), SpanRejected> {
        let cfg = self.unit.cfg;
        for (index, s) in stims.iter().enumerate() {
            s.span.check(&cfg).map_err(|error| SpanRejected { index, triangle: s.triangle, y: s.y, error })?;
        }
        let check = SegCheck { unit: &self.unit, stims, row_of: None, row: &mut self.row, paint };
        self.driver.stream(&self.unit, stims, report, check);
        Ok(())
    }

    /// Sets up `triangles` (numbered from `first`), streams their spans, paints the segments and
    /// compares the frame with golden's and with the f64 reference.
    pub fn run_triangles(&mut self, screen: &Screen, triangles: &[Triangle], first: usize, report: &mut Report) {
        let cfg = self.unit.cfg;
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

/// The row golden's pixels of a span are written into (`Frame::write_span`, SPEC §2's pixel
/// rule), once per span, so the scoreboard compares lanes with memory instead of deriving every
/// pixel again. Only the span's own pixels are written; the rest is stale, and it lies in
/// masked lanes, which are don't-care. P pixels wider than the screen, so a segment at the
/// last x stays inside.
pub(crate) fn golden_row(cfg: &Config) -> Frame {
    Frame::new(cfg.max_len() + cfg.p, 1)
}

/// The scoreboard's verdict on the way every segment should go: the number of
/// in-span lanes when x, last, the mask and every in-span pixel agree with golden, `None` at
/// the first disagreement, which [`check_lanes`] then describes lane by lane.
///
/// Golden enables lanes `[lo, hi)`, lane i carrying span pixel `j = x + i - x0` (SPEC §3: lane
/// i is the pixel at screen x `out_x + i`). Golden's `Segment::lane_pixel` is affine in the
/// lane, so the range is confirmed by asking golden at both ends and just outside them; then
/// the mask is compared a byte at a time and the pixels eight lanes at a time with the span's
/// golden `row` from `out_x` on, masked lanes ignored.
#[inline]
pub(crate) fn agrees(out: &SegView, span: &Span, seg: &Segment, row: &[u8], p: u32) -> Option<u64> {
    if out.out_x != seg.x || out.out_last != seg.last {
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
        return (out.mask[0] & ((1u16 << p) - 1) as u8 == on && (word(out.pix) ^ word(row)) & BYTE_MASK[on as usize] == 0)
            .then_some((hi - lo) as u64);
    }
    for c in 0..(p / 8) as usize {
        let on = lanes_on(8 * c as u32);
        let word = |b: &[u8]| u64::from_le_bytes(b[8 * c..8 * c + 8].try_into().expect("8 lanes"));
        if out.mask[c] != on || (word(out.pix) ^ word(row)) & BYTE_MASK[on as usize] != 0 {
            return None;
        }
    }
    Some((hi - lo) as u64)
}

pub(crate) fn describe(s: &Stim) -> String {
    format!("span y = {} x0 = {} len = {} i0 = {} di = {}", s.y, s.span.x0, s.span.len, s.span.i0, s.span.di)
}

#[cfg(test)]
mod tests {
    use super::*;
    use golden::rng::SeedRng;
    use golden::segment::segments;
    use golden::Align;
    use rand::{Rng, SeedableRng};

    /// Golden's segment as the model would offer it: in-span lanes enabled with their pixels,
    /// the other lanes off, holding `junk`.
    fn offered(cfg: &Config, span: &Span, seg: &Segment, junk: u8) -> ([u8; 256], [u8; 32]) {
        let (mut pix, mut mask) = ([junk; 256], [0u8; 32]);
        for i in 0..cfg.p {
            if let Some(j) = seg.lane_pixel(i) {
                pix[i as usize] = span.pixel(j, cfg.frac);
                mask[(i / 8) as usize] |= 1 << (i % 8);
            }
        }
        (pix, mask)
    }

    /// The scoreboard's fast path (`agrees`) is `check_lanes` made fast: on golden's own segment
    /// both pass and count the same pixels, whatever the masked-off lanes hold; and every single
    /// corruption (a pixel of an enabled lane, a mask bit, `out_x`, `out_last`) fails both.
    #[test]
    fn agrees_is_check_lanes_fast() {
        let mut rng = SeedRng::seed_from_u64(13);
        for p in [1, 2, 4, 8, 16, 64, 256] {
            for align in Align::ALL {
                let cfg = Config { p, align, ..Config::default() };
                let mut row = golden_row(&cfg);
                let half = 1i32 << (cfg.dw() - 1);
                for _ in 0..60 {
                    let x0 = rng.gen_range(0..cfg.max_len());
                    let len = rng.gen_range(1..=(cfg.max_len() - x0).min(4 * p + 3));
                    let span = Span { x0, len, i0: rng.gen_range(0..1 << cfg.iw()), di: rng.gen_range(-half..half) };
                    let stim = Stim { triangle: 0, y: 0, span };
                    row.write_span(0, &span, cfg.frac);
                    for seg in segments(&cfg, &span) {
                        let check = |pix: &[u8], mask: &[u8], x: u32, last: bool| {
                            let view = SegView { out_x: x, out_last: last, pix, mask };
                            let mut report = Report::default();
                            check_lanes(&cfg, &stim, &seg, &view, &mut report);
                            (agrees(&view, &span, &seg, row.pixels(), p), report.ok().then_some(report.pixels))
                        };
                        let (pix, mask) = offered(&cfg, &span, &seg, rng.gen());
                        let (fast, slow) = check(&pix, &mask, seg.x, seg.last);
                        assert!(fast.is_some() && fast == slow, "p {p} {align} {span:?} segment {}: {fast:?} {slow:?}", seg.index);
                        let on: Vec<u32> = (0..p).filter(|&i| seg.lane_pixel(i).is_some()).collect();
                        let lane = on[rng.gen_range(0..on.len())] as usize;
                        let mut bad = pix;
                        bad[lane] ^= 1 << rng.gen_range(0..8);
                        assert_eq!(check(&bad, &mask, seg.x, seg.last), (None, None), "pixel of lane {lane}");
                        let bit = rng.gen_range(0..p) as usize;
                        let mut bad = mask;
                        bad[bit / 8] ^= 1 << (bit % 8);
                        assert_eq!(check(&pix, &bad, seg.x, seg.last), (None, None), "mask bit {bit}");
                        assert_eq!(check(&pix, &mask, seg.x ^ 1, seg.last), (None, None), "out_x");
                        assert_eq!(check(&pix, &mask, seg.x, !seg.last), (None, None), "out_last");
                    }
                }
            }
        }
    }
}
