//! Co-simulation of SPEC §7's block video memory: segments with their `y` stream into
//! `fb_writer_p<P>`, or triangles into `tri_fb_p<P>`, and a memory model sits behind the write
//! port with random stalls (the driver's `out_ready` is `mem_ready`).
//!
//! Every write is compared with golden's (`golden::writer`): address, enables, and the pixels
//! under the enables. Independently of golden, the scoreboard fails a write with no enable, a
//! pixel written twice within one span, and an address outside the memory; the memory it fills
//! is then compared, as a frame, with golden's frame and the f64 reference.

use crate::driver::{Check, Driver, Stress, Unit};
use crate::ffi::{ModelInfo, Rtl, TriIn, WrIn, WrOut};
use crate::frontend::{Expected, TriStim};
use crate::report::{Mismatch, Report};
use crate::traffic::{Traffic, TrafficGen};
use golden::frontend::FrontEnd;
use golden::raster::Frame;
use golden::segment::segment;
use golden::writer::{BlockWrite, Memory, Writer};
use golden::Span;

/// A segment with its span: the writer's input item.
#[derive(Clone, Debug)]
pub struct SegStim {
    /// Index of the span in the run.
    pub span_index: usize,
    /// The triangle the span belongs to, if any (the memory's ownership test, see
    /// [`MemoryCheck::owner`]).
    pub triangle: Option<usize>,
    pub y: u32,
    pub span: Span,
    /// Segment index within the span.
    pub s: u32,
    /// The lanes as a segment shader's RTL put them out (P pixel bytes, then the mask bytes);
    /// `None`: golden's pixels, garbage in the masked lanes.
    pub lanes: Option<Box<[u8]>>,
}

/// The segments of `spans` (with their rows), in order: what the segment shader hands the writer.
pub fn segment_stims(w: &Writer, spans: &[(u32, Span)]) -> Vec<SegStim> {
    let mut out = Vec::new();
    for (k, (y, span)) in spans.iter().enumerate() {
        for s in 0..w.cfg.segment_count(span.x0, span.len) {
            out.push(SegStim { span_index: k, triangle: None, y: *y, span: *span, s, lanes: None });
        }
    }
    out
}

/// A write's record: address, enable bytes, the P pixels.
fn record(out: &WrOut, mask_bytes: usize, p: u32, rec: &mut [u8]) {
    rec[..4].copy_from_slice(&out.mem_addr.to_le_bytes());
    rec[4..4 + mask_bytes].copy_from_slice(&out.we[..mask_bytes]);
    rec[4 + mask_bytes..].copy_from_slice(&out.data[..p as usize]);
}

fn record_bytes(p: u32) -> usize {
    4 + p.div_ceil(8) as usize + p as usize
}

/// A record as a [`BlockWrite`].
fn decode(rec: &[u8], p: u32) -> BlockWrite {
    let mb = p.div_ceil(8) as usize;
    let mut w = BlockWrite { addr: u32::from_le_bytes(rec[..4].try_into().expect("4 bytes")), we: [0; 4], pix: [0; 256] };
    for i in 0..p {
        if rec[4 + (i / 8) as usize] >> (i % 8) & 1 == 1 {
            w.we[(i / 64) as usize] |= 1 << (i % 64);
        }
    }
    w.pix[..p as usize].copy_from_slice(&rec[4 + mb..4 + mb + p as usize]);
    w
}

/// Whether two writes agree where it matters: address, enables, pixels under the enables.
fn same_write(a: &BlockWrite, b: &BlockWrite, p: u32) -> bool {
    a.addr == b.addr && a.we == b.we && (0..p).all(|i| !a.enabled(i) || a.pix[i as usize] == b.pix[i as usize])
}

/// [`Unit::same`] for a memory port: the write offered before, still offered unchanged.
fn same_port(p: u32, held: &[u8], out: &WrOut) -> bool {
    let mut now = vec![0u8; record_bytes(p)];
    record(out, p.div_ceil(8) as usize, p, &mut now);
    same_write(&decode(held, p), &decode(&now, p), p)
}

fn describe_port_change(p: u32, held: &[u8], out: &WrOut) -> String {
    format!("write (addr {}) changed while mem_ready was low (now addr {})", decode(held, p).addr, out.mem_addr)
}

fn describe_write(w: &BlockWrite, p: u32) -> String {
    let lanes: Vec<String> = (0..p).filter(|&i| w.enabled(i)).map(|i| format!("{i}:{}", w.pix[i as usize])).collect();
    format!("addr {} lanes [{}]", w.addr, lanes.join(" "))
}

/// `fb_writer_p<P>`.
struct WrUnit {
    w: Writer,
}

impl Unit for WrUnit {
    type In = WrIn;
    type Out = WrOut;
    type Span = SegStim;

    fn record_bytes(&self) -> usize {
        record_bytes(self.w.cfg.p)
    }
    fn load(&self, input: &mut WrIn, st: &SegStim) {
        let cfg = &self.w.cfg;
        let (p, mb) = (cfg.p as usize, cfg.p.div_ceil(8) as usize);
        let seg = segment(cfg, &st.span, st.s);
        input.in_x = seg.x;
        input.in_y = st.y;
        input.in_last = seg.last as u8;
        if let Some(lanes) = &st.lanes {
            input.pix[..p].copy_from_slice(&lanes[..p]);
            input.mask[..mb].copy_from_slice(&lanes[p..p + mb]);
            return;
        }
        input.mask = [0; 32];
        for i in 0..cfg.p {
            input.pix[i as usize] = match seg.lane_pixel(i) {
                Some(j) => {
                    input.mask[(i / 8) as usize] |= 1 << (i % 8);
                    st.span.pixel(j, cfg.frac)
                }
                // Masked lanes carry garbage: a writer that writes them writes it.
                None => (st.span_index as u32 * 31 + i * 7 + 0x5a) as u8,
            };
        }
    }
    fn owed(&self, st: &SegStim) -> u32 {
        self.w.owed(&st.span, st.s)
    }
    fn record(&self, out: &WrOut, rec: &mut [u8]) {
        record(out, self.w.cfg.p.div_ceil(8) as usize, self.w.cfg.p, rec)
    }
    fn same(&self, held: &[u8], out: &WrOut) -> bool {
        same_port(self.w.cfg.p, held, out)
    }
    fn describe_change(&self, held: &[u8], out: &WrOut) -> String {
        describe_port_change(self.w.cfg.p, held, out)
    }
    fn blame(&self, _k: usize, st: &SegStim) -> (Option<usize>, String) {
        (None, format!("span {} (y {}, {:?}) segment {}", st.span_index, st.y, st.span, st.s))
    }
}

/// The memory behind the port and the checks that need no golden: what every write leaves.
pub struct MemoryCheck {
    pub memory: Memory,
    /// Per screen pixel, the triangle whose pixel is visible: a write of another triangle's
    /// pixel leaves memory as it is. A depth pre-pass resolved on the host, then a depth test
    /// "equal" at the memory (how `render` keeps hidden surfaces hidden); `None`: every write lands.
    pub owner: Option<Vec<u32>>,
    /// Per pixel of the memory: the span (run-wide number) that last wrote it, and writes.
    last_span: Vec<u64>,
    pub writes: Vec<u8>,
}

impl MemoryCheck {
    pub fn new(w: Writer) -> MemoryCheck {
        let n = (w.blocks() * w.cfg.p) as usize;
        MemoryCheck { memory: Memory::new(w), owner: None, last_span: vec![u64::MAX; n], writes: vec![0; n] }
    }

    /// Applies write `got` of span number `span` (run-wide, unique per span), reporting a
    /// write with no enable, an address outside the memory, a pixel this span already wrote.
    pub fn apply(&mut self, span: u64, got: &BlockWrite, context: impl Fn() -> String, triangle: Option<usize>, report: &mut Report) {
        let w = self.memory.writer;
        let p = w.cfg.p;
        if got.we.iter().all(|&m| m == 0) {
            report.mismatch(Mismatch { triangle, context: context(), what: format!("a write with no enable set (addr {})", got.addr) });
        }
        let mut kept = *got;
        if let (Some(owner), Some(t)) = (&self.owner, triangle) {
            let (bpr, width) = (w.blocks_per_row(), w.screen.width);
            for i in 0..p {
                let (x, y) = ((got.addr % bpr) * p + i, got.addr / bpr);
                if x >= width || y >= w.screen.height || owner[(y * width + x) as usize] != t as u32 {
                    kept.we[(i / 64) as usize] &= !(1 << (i % 64));
                }
            }
        }
        if let Err(e) = self.memory.apply(&kept) {
            report.mismatch(Mismatch { triangle, context: context(), what: e.to_string() });
            return;
        }
        let twice: Vec<u32> = (0..p)
            .filter(|&i| got.enabled(i))
            .filter(|&i| {
                let at = (got.addr * p + i) as usize;
                let again = self.last_span[at] == span;
                self.last_span[at] = span;
                self.writes[at] = self.writes[at].saturating_add(1);
                again
            })
            .collect();
        if !twice.is_empty() {
            report.mismatch(Mismatch {
                triangle,
                context: context(),
                what: format!("block {} lanes {twice:?} written twice within one span", got.addr),
            });
        }
    }

    /// Per-pixel write counts of the screen (lanes past the right edge dropped).
    pub fn screen_writes(&self) -> Vec<u8> {
        let w = self.memory.writer;
        let s = w.screen;
        let mut out = vec![0; (s.width * s.height) as usize];
        for y in 0..s.height {
            for x in 0..s.width {
                out[(y * s.width + x) as usize] = self.writes[(w.addr(x, y) * w.cfg.p + x % w.cfg.p) as usize];
            }
        }
        out
    }
}

struct WrCheck<'a> {
    w: Writer,
    stims: &'a [SegStim],
    mem: &'a mut MemoryCheck,
}

impl Check for WrCheck<'_> {
    fn check(&mut self, k: usize, j: u32, rec: &[u8], report: &mut Report) {
        let st = &self.stims[k];
        let p = self.w.cfg.p;
        let want = self.w.write(st.y, &st.span, st.s + j);
        let got = decode(rec, p);
        let context = || format!("span {} (y {}, {:?}) segment {} write {}", st.span_index, st.y, st.span, st.s, st.s + j);
        report.segments += 1;
        report.pixels += (0..p).filter(|&i| got.enabled(i)).count() as u64;
        if !same_write(&got, &want, p) {
            report.mismatch(Mismatch {
                triangle: None,
                context: context(),
                what: format!("expected {}, got {}", describe_write(&want, p), describe_write(&got, p)),
            });
        }
        self.mem.apply(st.span_index as u64, &got, context, st.triangle, report);
    }
}

/// What a writer run leaves: the report (`segments` counts writes) and the memory.
pub struct WriterRun {
    pub report: Report,
    pub mem: MemoryCheck,
}

impl WriterRun {
    /// The memory as a frame, against golden's frame of the same spans (equal), and no pixel
    /// past the right edge written.
    pub fn check_frame(&mut self, spans: &[(u32, Span)]) -> Frame {
        let w = self.mem.memory.writer;
        let mut gold = Frame::new(w.screen.width, w.screen.height);
        for (y, s) in spans {
            gold.write_span(*y, s, w.cfg.frac);
        }
        let frame = self.mem.memory.frame();
        if let Some(at) = (0..gold.pixels().len()).find(|&i| {
            frame.get(i as u32 % w.screen.width, i as u32 / w.screen.width)
                != gold.get(i as u32 % w.screen.width, i as u32 / w.screen.width)
        }) {
            let (x, y) = (at as u32 % w.screen.width, at as u32 / w.screen.width);
            self.report.mismatch(Mismatch {
                triangle: None,
                context: format!("memory pixel ({x}, {y})"),
                what: format!("golden {:?}, memory {:?}", gold.get(x, y), frame.get(x, y)),
            });
        }
        if self.mem.memory.wrote_off_screen() {
            self.report.mismatch(Mismatch {
                triangle: None,
                context: "memory".into(),
                what: "a pixel past the screen's right edge was written".into(),
            });
        }
        frame
    }
}

/// Streams the segments of `spans` (each with its row) through `fb_writer_p<P>` into a memory
/// model, comparing every write with golden's.
pub fn run_writer(info: &'static ModelInfo<WrIn, WrOut>, seed: u64, traffic: Traffic, stress: Stress, spans: &[(u32, Span)]) -> WriterRun {
    run_writer_against(info, seed, traffic, stress, spans, Writer::new(info.cfg, info.screen).expect("the model's screen"))
}

/// [`run_writer`], judged by golden's writer `w` (another screen: the negative control).
pub fn run_writer_against(
    info: &'static ModelInfo<WrIn, WrOut>,
    seed: u64,
    traffic: Traffic,
    stress: Stress,
    spans: &[(u32, Span)],
    w: Writer,
) -> WriterRun {
    run_segments(info, seed, traffic, stress, &segment_stims(&w, spans), w, None)
}

/// Streams `stims` through `fb_writer_p<P>` into a memory model (with `owner`'s test, if any),
/// every write judged by golden's writer `w`.
pub fn run_segments(
    info: &'static ModelInfo<WrIn, WrOut>,
    seed: u64,
    traffic: Traffic,
    stress: Stress,
    stims: &[SegStim],
    w: Writer,
    owner: Option<Vec<u32>>,
) -> WriterRun {
    let unit = WrUnit { w };
    let mut driver = Driver::new(Rtl::new(info, seed), TrafficGen::new(traffic, seed));
    driver.stress = stress;
    let mut report = Report::default();
    let mut mem = MemoryCheck::new(w);
    mem.owner = owner;
    driver.stream(&unit, stims, &mut report, WrCheck { w, stims, mem: &mut mem });
    WriterRun { report, mem }
}

/// `tri_fb_p<P>`: triangles in, block writes out.
struct TwUnit {
    w: Writer,
    fe: FrontEnd,
    /// As the front-end's (see `frontend::drain_clocks`).
    drain: u64,
}

impl Unit for TwUnit {
    type In = TriIn;
    type Out = WrOut;
    type Span = TriStim;

    fn record_bytes(&self) -> usize {
        record_bytes(self.w.cfg.p)
    }
    fn load(&self, input: &mut TriIn, s: &TriStim) {
        crate::frontend::load(&self.fe, input, &s.tri)
    }
    fn owed(&self, s: &TriStim) -> u32 {
        s.writes
    }
    fn record(&self, out: &WrOut, rec: &mut [u8]) {
        record(out, self.w.cfg.p.div_ceil(8) as usize, self.w.cfg.p, rec)
    }
    fn same(&self, held: &[u8], out: &WrOut) -> bool {
        same_port(self.w.cfg.p, held, out)
    }
    fn describe_change(&self, held: &[u8], out: &WrOut) -> String {
        describe_port_change(self.w.cfg.p, held, out)
    }
    fn drain_clocks(&self) -> u64 {
        self.drain
    }
    fn pulse(&self, out: &WrOut) -> bool {
        out.err == 1
    }
    fn blame(&self, _k: usize, s: &TriStim) -> (Option<usize>, String) {
        (Some(s.triangle), format!("{:?}", s.tri))
    }
}

/// Walks golden's spans of each triangle write by write as the records arrive.
struct TwCheck<'a> {
    w: Writer,
    exp: &'a Expected,
    /// (triangle, span index, write index within the span)
    at: Option<(usize, usize, u32)>,
    mem: &'a mut MemoryCheck,
}

impl Check for TwCheck<'_> {
    fn check(&mut self, k: usize, _j: u32, rec: &[u8], report: &mut Report) {
        let p = self.w.cfg.p;
        let st = &self.exp.stims[k];
        let (mut span_i, mut wi) = match self.at {
            Some((kk, i, n)) if kk == k => (i, n),
            _ => (st.first, 0),
        };
        let (y, span) = self.exp.spans[span_i];
        let want = self.w.write(y, &span, wi);
        let got = decode(rec, p);
        let context = || format!("span (y {y}, {span:?}) write {wi}");
        report.segments += 1;
        report.pixels += (0..p).filter(|&i| got.enabled(i)).count() as u64;
        if !same_write(&got, &want, p) {
            report.mismatch(Mismatch {
                triangle: Some(st.triangle),
                context: context(),
                what: format!("expected {}, got {}", describe_write(&want, p), describe_write(&got, p)),
            });
        }
        self.mem.apply(span_i as u64, &got, context, Some(st.triangle), report);
        wi += 1;
        if wi == self.w.write_count(&span) {
            (span_i, wi) = (span_i + 1, 0);
        }
        self.at = Some((k, span_i, wi));
    }
}

/// What a chained run leaves: the report (`segments` counts writes), the memory and its frame.
pub struct FbRun {
    pub report: Report,
    pub mem: MemoryCheck,
    pub frame: Frame,
}

/// Streams triangles through `tri_fb_p<P>` into the memory model: every write against golden's,
/// the guard-band pulses, then the memory as a frame against golden's frame and the f64
/// reference, and no pixel written by two triangles (meaningful when none overlap).
pub fn run_fb(info: &'static ModelInfo<TriIn, WrOut>, seed: u64, traffic: Traffic, tris: &[golden::frontend::FixedTriangle]) -> FbRun {
    let fe = info.frontend();
    let exp = Expected::new(fe, tris);
    let mut run = stream_fb(info, seed, traffic, &exp, None);
    crate::frontend::check_frame(&exp, &run.frame, &run.mem.screen_writes(), &mut run.report);
    run
}

/// Streams golden's `exp` through `tri_fb_p<P>` into a memory model (with `owner`'s test, if
/// any): every write and the guard-band pulses against golden; `frame` is the memory's picture.
pub fn stream_fb(info: &'static ModelInfo<TriIn, WrOut>, seed: u64, traffic: Traffic, exp: &Expected, owner: Option<Vec<u32>>) -> FbRun {
    let fe = exp.fe;
    let w = Writer::new(fe.cfg, fe.screen).expect("the front-end's screen");
    let unit = TwUnit { w, fe, drain: crate::frontend::drain_clocks(info.latency, &fe) };
    let mut driver = Driver::new(Rtl::new(info, seed), TrafficGen::new(traffic, seed));
    let mut report = Report::default();
    let mut mem = MemoryCheck::new(w);
    mem.owner = owner;
    driver.stream(&unit, &exp.stims, &mut report, TwCheck { w, exp, at: None, mem: &mut mem });
    report.triangles = exp.stims.len();
    if report.pulses != exp.guard_drops() {
        report.mismatch(Mismatch {
            triangle: None,
            context: "err".into(),
            what: format!("{} guard-band pulses, golden drops {} triangles", report.pulses, exp.guard_drops()),
        });
    }
    if mem.memory.wrote_off_screen() {
        report.mismatch(Mismatch {
            triangle: None,
            context: "memory".into(),
            what: "a pixel past the screen's right edge was written".into(),
        });
    }
    let frame = mem.memory.frame();
    FbRun { report, mem, frame }
}
