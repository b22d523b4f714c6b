//! Co-simulation of the triangle front-end (SPEC §6): triangles stream into `tri_frontend`
//! (every span compared with `golden::frontend`) or into `tri_shader_p<P>` (every segment and
//! its `y` compared with golden's segments of golden's spans, then the frame with golden's frame,
//! the f64 reference, and "each pixel written by at most one triangle").
//!
//! The same driver as the span-fed shader ([`crate::driver`]): random input gaps and output
//! backpressure, the protocol monitor, the scoreboard on a second thread. A triangle is the
//! driver's input item; it owes its spans (or segments), and its guard-band `err` pulse is
//! counted against golden's.

use crate::driver::{Check, Driver, Stress, Unit, DRAIN_CLOCKS};
use crate::ffi::{to_port, FeOut, ModelInfo, Rtl, TriIn, TriSegOut};
use crate::report::{Mismatch, Report};
use crate::segment::{agrees, check_lanes, describe, golden_row, SegView, Stim};
use crate::traffic::{Traffic, TrafficGen};
use golden::frontend::{FixedTriangle, FrontEnd, Outcome};
use golden::raster::{compare, reference_triangle, Frame, RefFrame};
use golden::segment::segment;
use golden::Span;

/// A triangle with golden's verdict: its spans are `spans[first..first + count]`.
#[derive(Clone, Copy, Debug)]
pub struct TriStim {
    pub triangle: usize,
    pub tri: FixedTriangle,
    pub outcome: Outcome,
    pub first: usize,
    pub count: u32,
    /// Segments its spans make in the shader.
    pub segments: u32,
    /// Block writes its spans make in the writer (SPEC §7).
    pub writes: u32,
}

/// Golden's answer for a list of triangles.
#[derive(Clone)]
pub struct Expected {
    pub fe: FrontEnd,
    pub stims: Vec<TriStim>,
    /// `(y, span)` of every triangle, in order.
    pub spans: Vec<(u32, Span)>,
}

impl Expected {
    pub fn new(fe: FrontEnd, tris: &[FixedTriangle]) -> Expected {
        let mut spans = Vec::new();
        let mut stims = Vec::with_capacity(tris.len());
        // Every front-end screen is one the writer can address (W <= 2^XW).
        let writer = golden::writer::Writer::new(fe.cfg, fe.screen).expect("the front-end's screen");
        for (k, t) in tris.iter().enumerate() {
            let first = spans.len();
            let outcome = fe.spans(t, |y, s| spans.push((y, s)));
            let segments = spans[first..].iter().map(|(_, s)| fe.cfg.segment_count(s.x0, s.len)).sum();
            let writes = spans[first..].iter().map(|(_, s)| writer.write_count(s)).sum();
            stims.push(TriStim { triangle: k, tri: *t, outcome, first, count: (spans.len() - first) as u32, segments, writes });
        }
        Expected { fe, stims, spans }
    }

    pub fn guard_drops(&self) -> u64 {
        self.stims.iter().filter(|s| s.outcome == Outcome::Guard).count() as u64
    }
}

pub(crate) fn load(fe: &FrontEnd, input: &mut TriIn, t: &FixedTriangle) {
    let w = fe.widths();
    for k in 0..3 {
        input.x[k] = to_port(t.x[k], w.cx);
        input.y[k] = to_port(t.y[k], w.cy);
        input.i[k] = t.i[k];
    }
}

fn blame(s: &TriStim) -> (Option<usize>, String) {
    (Some(s.triangle), format!("{:?}", s.tri))
}

/// `tri_frontend`: a span's record is y, x0, len, I0, dI (5 words).
struct FeUnit {
    fe: FrontEnd,
    /// Clocks after the last owed output in which a dropped triangle's `err` pulse may still
    /// come: the walker may step through up to H rows that yield nothing (a sliver, a triangle
    /// clipped at the right) before set-up reaches it, then its latency.
    drain: u64,
}

impl Unit for FeUnit {
    type In = TriIn;
    type Out = FeOut;
    type Span = TriStim;

    fn record_bytes(&self) -> usize {
        20
    }
    fn load(&self, input: &mut TriIn, s: &TriStim) {
        load(&self.fe, input, &s.tri)
    }
    fn owed(&self, s: &TriStim) -> u32 {
        s.count
    }
    fn record(&self, out: &FeOut, rec: &mut [u8]) {
        for (k, v) in [out.out_y, out.out_x, out.out_len, out.out_i0, out.out_di].iter().enumerate() {
            rec[4 * k..4 * k + 4].copy_from_slice(&v.to_le_bytes());
        }
    }
    fn same(&self, held: &[u8], out: &FeOut) -> bool {
        let mut now = [0u8; 20];
        self.record(out, &mut now);
        now == held
    }
    fn describe_change(&self, held: &[u8], out: &FeOut) -> String {
        format!("span changed while waiting for out_ready: {held:?} -> y = {} x = {}", out.out_y, out.out_x)
    }
    fn drain_clocks(&self) -> u64 {
        self.drain
    }
    fn pulse(&self, out: &FeOut) -> bool {
        out.err == 1
    }
    fn blame(&self, _k: usize, s: &TriStim) -> (Option<usize>, String) {
        blame(s)
    }
}

struct FeCheck<'a> {
    exp: &'a Expected,
}

impl Check for FeCheck<'_> {
    fn check(&mut self, k: usize, j: u32, rec: &[u8], report: &mut Report) {
        let st = &self.exp.stims[k];
        let (y, s) = self.exp.spans[st.first + j as usize];
        let dw = self.exp.fe.cfg.dw();
        let word = |n: usize| u32::from_le_bytes(rec[4 * n..4 * n + 4].try_into().expect("4 bytes"));
        let want = [y, s.x0, s.len, s.i0, to_port(s.di as i64, dw)];
        let got = [word(0), word(1), word(2), word(3), word(4)];
        // The driver counts accepted triangles in `spans`; the front-end's outputs are spans.
        report.segments += 1;
        report.pixels += s.len as u64;
        if got != want {
            report.mismatch(Mismatch {
                triangle: Some(st.triangle),
                context: format!("span {j} of {:?}", st.tri),
                what: format!("expected (y, x0, len, i0, di bits) {want:?}, got {got:?}"),
            });
        }
    }
}

/// `tri_shader_p<P>`: a segment's record is y, x | last << 31, the mask bytes, the pixels.
struct TsUnit {
    fe: FrontEnd,
    mask_bytes: usize,
    /// As [`FeUnit`]'s.
    drain: u64,
}

impl TsUnit {
    fn view<'a>(&self, rec: &'a [u8]) -> (u32, SegView<'a>) {
        let y = u32::from_le_bytes(rec[..4].try_into().expect("4 bytes"));
        let head = u32::from_le_bytes(rec[4..8].try_into().expect("4 bytes"));
        let (mask, pix) = rec[8..].split_at(self.mask_bytes);
        (y, SegView { out_x: head & !(1 << 31), out_last: head >> 31 == 1, pix, mask })
    }
}

impl Unit for TsUnit {
    type In = TriIn;
    type Out = TriSegOut;
    type Span = TriStim;

    fn record_bytes(&self) -> usize {
        8 + self.mask_bytes + self.fe.cfg.p.next_multiple_of(8) as usize
    }
    fn load(&self, input: &mut TriIn, s: &TriStim) {
        load(&self.fe, input, &s.tri)
    }
    fn owed(&self, s: &TriStim) -> u32 {
        s.segments
    }
    fn record(&self, out: &TriSegOut, rec: &mut [u8]) {
        rec[..4].copy_from_slice(&out.out_y.to_le_bytes());
        rec[4..8].copy_from_slice(&(out.out_x | (out.out_last as u32) << 31).to_le_bytes());
        let (mask, pix) = rec[8..].split_at_mut(self.mask_bytes);
        mask.copy_from_slice(&out.mask[..self.mask_bytes]);
        pix.copy_from_slice(&out.pix[..pix.len()]);
    }
    fn same(&self, held: &[u8], out: &TriSegOut) -> bool {
        // Pixels of masked lanes are don't-care.
        let (y, h) = self.view(held);
        let p = self.fe.cfg.p;
        y == out.out_y
            && h.out_x == out.out_x
            && h.out_last == (out.out_last == 1)
            && (0..p).all(|i| {
                let on = h.lane_enabled(i);
                on == (out.mask[(i / 8) as usize] >> (i % 8) & 1 == 1) && (!on || h.pix[i as usize] == out.pix[i as usize])
            })
    }
    fn describe_change(&self, held: &[u8], out: &TriSegOut) -> String {
        let (y, h) = self.view(held);
        format!("segment (y {y}, x {}) changed while waiting for out_ready (now y {}, x {})", h.out_x, out.out_y, out.out_x)
    }
    fn drain_clocks(&self) -> u64 {
        self.drain
    }
    fn pulse(&self, out: &TriSegOut) -> bool {
        out.err == 1
    }
    fn blame(&self, _k: usize, s: &TriStim) -> (Option<usize>, String) {
        blame(s)
    }
}

/// Walks golden's spans of each triangle segment by segment as the records arrive (in order;
/// a triangle cut by a reset stops early and the next record belongs to a later one).
struct TsCheck<'a, F> {
    unit: &'a TsUnit,
    exp: &'a Expected,
    at: Option<(usize, usize, u32)>,
    row_of: Option<usize>,
    row: &'a mut Frame,
    paint: F,
}

impl<F: FnMut(usize, u32, &SegView) + Send> Check for TsCheck<'_, F> {
    fn check(&mut self, k: usize, _j: u32, rec: &[u8], report: &mut Report) {
        let cfg = &self.unit.fe.cfg;
        let st = &self.exp.stims[k];
        let (mut span_i, mut seg_s) = match self.at {
            Some((kk, i, s)) if kk == k => (i, s),
            _ => (st.first, 0),
        };
        let (y, span) = self.exp.spans[span_i];
        let (out_y, out) = self.unit.view(rec);
        let stim = Stim { triangle: st.triangle, y, span };
        if self.row_of != Some(span_i) {
            self.row.write_span(0, &span, cfg.frac);
            self.row_of = Some(span_i);
        }
        let seg = segment(cfg, &span, seg_s);
        if out_y != y {
            report.mismatch(Mismatch {
                triangle: Some(st.triangle),
                context: describe(&stim),
                what: format!("out_y expected {y}, got {out_y}"),
            });
        }
        match agrees(&out, &span, &seg, self.row.pixels(), cfg.p) {
            Some(pixels) => {
                report.segments += 1;
                report.pixels += pixels;
            }
            None => check_lanes(cfg, &stim, &seg, &out, report),
        }
        (self.paint)(st.triangle, out_y, &out);
        seg_s += 1;
        if seg_s == cfg.segment_count(span.x0, span.len) {
            (span_i, seg_s) = (span_i + 1, 0);
        }
        self.at = Some((k, span_i, seg_s));
    }
}

/// See [`FeUnit::drain`].
pub fn drain_clocks(latency: u32, fe: &FrontEnd) -> u64 {
    fe.screen.height as u64 + latency as u64 + DRAIN_CLOCKS
}

/// Streams triangles through `tri_frontend` and compares every span with golden's. In the
/// report, `spans` counts the triangles the model accepted and `segments` the spans it output.
pub fn run_frontend(info: &'static ModelInfo<TriIn, FeOut>, seed: u64, traffic: Traffic, stress: Stress, tris: &[FixedTriangle]) -> Report {
    let fe = info.frontend();
    run_expected(info, seed, traffic, stress, &Expected::new(fe, tris))
}

/// Drives `tris` but judges the output by `exp`, golden's answer for other triangles: the
/// negative control of the scoreboard (the report must not be clean).
pub fn run_frontend_against(info: &'static ModelInfo<TriIn, FeOut>, seed: u64, tris: &[FixedTriangle], exp: &Expected) -> Report {
    let mut exp = exp.clone();
    for (s, t) in exp.stims.iter_mut().zip(tris) {
        s.tri = *t;
    }
    run_expected(info, seed, Traffic::RANDOM, Stress::NONE, &exp)
}

fn run_expected(info: &'static ModelInfo<TriIn, FeOut>, seed: u64, traffic: Traffic, stress: Stress, exp: &Expected) -> Report {
    let fe = exp.fe;
    let tris = &exp.stims;
    let unit = FeUnit { fe, drain: drain_clocks(info.latency, &fe) };
    let mut driver = Driver::new(Rtl::new(info, seed), TrafficGen::new(traffic, seed));
    driver.stress = stress;
    let mut report = Report::default();
    driver.stream(&unit, &exp.stims, &mut report, FeCheck { exp });
    report.triangles = tris.len();
    if stress.reset == 0.0 && report.pulses != exp.guard_drops() {
        report.mismatch(Mismatch {
            triangle: None,
            context: "err".into(),
            what: format!("{} guard-band pulses, golden drops {} triangles", report.pulses, exp.guard_drops()),
        });
    }
    report
}

/// What a chained run leaves: the report and the RTL's frame with per-pixel write counts.
pub struct ChainRun {
    pub report: Report,
    pub frame: Frame,
    pub writes: Vec<u8>,
}

/// Streams triangles through `tri_shader_p<P>`: every segment and its y against golden, then
/// the painted frame against golden's spans and the f64 reference, and no pixel written twice.
pub fn run_chain(info: &'static ModelInfo<TriIn, TriSegOut>, seed: u64, traffic: Traffic, tris: &[FixedTriangle]) -> ChainRun {
    run_chain_at(info, seed, traffic, tris, 0)
}

/// [`run_chain`] with the triangles numbered from `first` in the report (batches of one run).
pub fn run_chain_at(
    info: &'static ModelInfo<TriIn, TriSegOut>,
    seed: u64,
    traffic: Traffic,
    tris: &[FixedTriangle],
    first: usize,
) -> ChainRun {
    let (cfg, screen) = (info.cfg, info.screen);
    let fe = info.frontend();
    let mut exp = Expected::new(fe, tris);
    for s in &mut exp.stims {
        s.triangle += first;
    }
    let mut frame = Frame::new(screen.width, screen.height);
    let mut writes = vec![0u8; (screen.width * screen.height) as usize];
    let paint = |_t: usize, y: u32, out: &SegView| {
        for i in 0..cfg.p {
            let x = out.out_x + i;
            if out.lane_enabled(i) && x < screen.width && y < screen.height {
                frame.set(x, y, out.pix[i as usize]);
                let w = &mut writes[(y * screen.width + x) as usize];
                *w = w.saturating_add(1);
            }
        }
    };
    let mut report = stream_chain(info, seed, traffic, &exp, paint);
    check_frame(&exp, &frame, &writes, &mut report);
    ChainRun { report, frame, writes }
}

/// Streams golden's `exp` through `tri_shader_p<P>`, checking every segment and `y` and the
/// guard-band pulses; `paint(triangle, y, segment)` gets every checked segment, in order.
pub fn stream_chain(
    info: &'static ModelInfo<TriIn, TriSegOut>,
    seed: u64,
    traffic: Traffic,
    exp: &Expected,
    paint: impl FnMut(usize, u32, &SegView) + Send,
) -> Report {
    let cfg = info.cfg;
    let unit = TsUnit { fe: exp.fe, mask_bytes: cfg.p.div_ceil(8) as usize, drain: drain_clocks(info.latency, &exp.fe) };
    let mut driver = Driver::new(Rtl::new(info, seed), TrafficGen::new(traffic, seed));
    let mut report = Report::default();
    let mut row = golden_row(&cfg);
    let check = TsCheck { unit: &unit, exp, at: None, row_of: None, row: &mut row, paint };
    driver.stream(&unit, &exp.stims, &mut report, check);
    report.triangles = exp.stims.len();
    if report.pulses != exp.guard_drops() {
        report.mismatch(Mismatch {
            triangle: None,
            context: "err".into(),
            what: format!("{} guard-band pulses, golden drops {} triangles", report.pulses, exp.guard_drops()),
        });
    }
    report
}

/// The RTL frame against golden's spans (equal), the f64 reference (SPEC §6: within 1, same
/// coverage), and no pixel written by two triangles (meaningful when they do not overlap).
pub(crate) fn check_frame(exp: &Expected, frame: &Frame, writes: &[u8], report: &mut Report) {
    let (cfg, screen) = (&exp.fe.cfg, exp.fe.screen);
    let mut gold = Frame::new(screen.width, screen.height);
    let mut reference = RefFrame::new(screen.width, screen.height);
    for st in &exp.stims {
        for (y, s) in &exp.spans[st.first..st.first + st.count as usize] {
            gold.write_span(*y, s, cfg.frac);
        }
        if st.outcome != Outcome::Guard {
            if let Err(e) = reference_triangle(&screen, &st.tri.to_triangle(cfg.frac), &mut reference) {
                report.mismatch(Mismatch { triangle: Some(st.triangle), context: "f64 reference".into(), what: e.to_string() });
            }
        }
    }
    if let Some(at) = (0..writes.len()).find(|&i| frame.pixels()[i] != gold.pixels()[i]) {
        let (x, y) = (at as u32 % screen.width, at as u32 / screen.width);
        report.mismatch(Mismatch {
            triangle: None,
            context: format!("frame pixel ({x}, {y})"),
            what: format!("golden {:?}, RTL {:?}", gold.get(x, y), frame.get(x, y)),
        });
    }
    let cmp = compare(frame, &reference);
    report.max_error = report.max_error.max(cmp.max_error);
    if !cmp.passed() {
        report.mismatch(Mismatch { triangle: None, context: "frame against the f64 reference".into(), what: cmp.to_string() });
    }
}

// Golden's generators (golden::stimulus), where the suites and binaries import them.
pub use golden::stimulus::{fixed_mesh as mesh, random_fixed_triangles as random_triangles};
