//! The co-simulation threads of a render: one segment shader (or front-end chain, or writer)
//! per colour channel and one specular unit, each on its own thread at full rate, and the
//! golden images made from the same spans and the same ownership.

use super::image::{compose, memory_image};
use super::visibility::Job;
use crate::driver::{Stress, DRAIN_CLOCKS};
use crate::ffi::{ModelInfo, SegIn, SegOut, SpecIn, SpecOut, TriIn, TriSegOut, WrIn, WrOut};
use crate::frontend::{stream_chain, Expected};
use crate::registry::unit_of;
use crate::report::Report;
use crate::segment::{SegView, SegmentCosim, Stim};
use crate::specular::SpecularCosim;
use crate::traffic::Traffic;
use crate::writer::{run_segments, stream_fb, SegStim};
use golden::frontend::FrontEnd;
use golden::writer::Writer;
use golden::Span;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

/// The models' seed: a render is the same picture every run.
const SEED: u64 = 1;

/// What a render produced.
#[derive(Debug)]
pub struct Outcome {
    /// Channels interleaved per pixel (1 or 3 bytes), row-major.
    pub rtl: Vec<u8>,
    pub golden: Vec<u8>,
    /// With the RTL front-end: the image of the host's set-up, to compare with.
    pub host: Option<Vec<u8>>,
    /// Per pixel, how many enabled output lanes of the (first) segment shader wrote it.
    pub coverage: Vec<u16>,
    /// One report per channel's segment shader.
    pub segment: Vec<Report>,
    pub specular: Option<Report>,
    /// With `Chain::HostToMemory`, one report per channel's segment writer.
    pub writer: Vec<Report>,
}

impl Outcome {
    /// Pixels where the RTL image differs from golden's.
    pub fn differing_pixels(&self, channels: usize) -> u64 {
        self.rtl.chunks(channels).zip(self.golden.chunks(channels)).filter(|(a, b)| a != b).count() as u64
    }
    /// Every co-simulation check passed.
    pub fn cosim_ok(&self) -> bool {
        self.segment.iter().chain(&self.writer).all(Report::ok) && self.specular.as_ref().is_none_or(Report::ok)
    }
}

/// Clocks from the first span offered to the last output, without the co-simulation's quiet
/// clocks after it ([`DRAIN_CLOCKS`]).
pub fn busy_cycles(r: &Report) -> u64 {
    r.cycles.saturating_sub(DRAIN_CLOCKS)
}

/// Which RTL draws a render's diffuse channels, and where their pixels land.
#[derive(Clone, Copy)]
pub enum Chain {
    /// The host's set-up: spans into one `segment_shader_p<P>` per channel; the harness paints
    /// the segments.
    Host,
    /// The host's set-up, and each channel's RTL segments then stream through `fb_writer_p<P>`
    /// into a memory model: the image is read out of memory.
    HostToMemory(&'static ModelInfo<WrIn, WrOut>),
    /// The RTL front-end: triangles into `tri_shader_p<P>`.
    Rtl(&'static ModelInfo<TriIn, TriSegOut>),
    /// The whole RTL chain: triangles into `tri_fb_p<P>`, the image read out of memory.
    RtlToMemory(&'static ModelInfo<TriIn, WrOut>),
}

impl Chain {
    /// The front-end's configuration and screen, when the RTL sets up the triangles.
    fn frontend(self) -> Option<FrontEnd> {
        match self {
            Chain::Host | Chain::HostToMemory(_) => None,
            Chain::Rtl(m) => Some(m.frontend()),
            Chain::RtlToMemory(m) => Some(m.frontend()),
        }
    }
}

/// Streams `job` through one `seg` model per channel and, when the job has specular spans, the
/// `spec` model, all at full rate on their own threads; builds the RTL and golden images.
/// `progress` is called now and then on the calling thread with the fraction done.
pub fn run(
    job: &Job,
    seg: &'static ModelInfo<SegIn, SegOut>,
    spec: Option<&'static ModelInfo<SpecIn, SpecOut>>,
    progress: impl FnMut(f64),
) -> Outcome {
    run_with(job, seg, Chain::Host, spec, progress)
}

/// [`run`] through `chain`. With the RTL front-end the RTL image must equal golden's front-end
/// image, and `Outcome::host` holds the host-set-up image to compare with. Through memory,
/// hidden surfaces stay hidden by the memory model's ownership test ([`MemoryCheck::owner`]),
/// the host's depth pre-pass, and the image is what memory holds.
///
/// [`MemoryCheck::owner`]: crate::writer::MemoryCheck::owner
pub fn run_with(
    job: &Job,
    seg: &'static ModelInfo<SegIn, SegOut>,
    chain: Chain,
    spec: Option<&'static ModelInfo<SpecIn, SpecOut>>,
    mut progress: impl FnMut(f64),
) -> Outcome {
    let exps: Option<Vec<Expected>> = chain.frontend().map(|fe| job.tris.iter().map(|t| Expected::new(fe, t)).collect());
    let exps = &exps;
    let screen = job.screen;
    let (width, npix) = (screen.width, (screen.width * screen.height) as usize);
    let channels = job.channels();
    let with_spec = !job.specular.is_empty() && spec.is_some();
    let total = (job.shaded_pixels() * (channels as u64 + with_spec as u64)).max(1);
    let done = AtomicU64::new(0);
    let owner = &job.owner;

    let (diffuse, coverage, segment, writer, spec_out) = std::thread::scope(|s| {
        let seg_threads: Vec<_> = job
            .stims
            .iter()
            .enumerate()
            .map(|(c, _)| {
                let done = &done;
                s.spawn(move || channel(job, seg, chain, exps, c, done))
            })
            .collect();
        let spec_thread = spec.filter(|_| with_spec).map(|info| {
            let done = &done;
            s.spawn(move || {
                let mut out = vec![0u16; npix];
                let mut sim = SpecularCosim::new(info, unit_of(info), SEED, Traffic::FULL);
                let mut report = Report { triangles: job.drawn, ..Report::default() };
                let stims = &job.stims[0];
                sim.stream_with(&job.specular, &mut report, |k, j, o| {
                    let st = &stims[k];
                    let idx = (st.y * width + st.span.x0 + j) as usize;
                    if owner[idx] == st.triangle as u32 {
                        out[idx] = o.out_spec;
                    }
                    done.fetch_add(1, Ordering::Relaxed);
                });
                (out, report)
            })
        });
        while !(seg_threads.iter().all(|t| t.is_finished()) && spec_thread.as_ref().is_none_or(|t| t.is_finished())) {
            progress(done.load(Ordering::Relaxed) as f64 / total as f64);
            std::thread::sleep(Duration::from_millis(10));
        }
        progress(1.0);
        let mut diffuse = Vec::new();
        let mut coverage = Vec::new();
        let mut reports = Vec::new();
        let mut writers = Vec::new();
        for (c, t) in seg_threads.into_iter().enumerate() {
            let (img, cov, report, writer) = t.join().expect("segment co-simulation thread panicked");
            if c == 0 {
                coverage = cov;
            }
            writers.extend(writer);
            diffuse.push(img);
            reports.push(report);
        }
        let spec_out = spec_thread.map(|t| t.join().expect("specular co-simulation thread panicked"));
        (diffuse, coverage, reports, writers, spec_out)
    });

    let GoldenImages { host_diffuse, gold_diffuse, gold_spec } = golden_images(job, seg.cfg.frac, exps, spec.filter(|_| with_spec));
    let (spec_img, spec_report) = match spec_out {
        Some((img, r)) => (Some(img), Some(r)),
        None => (None, None),
    };
    Outcome {
        rtl: compose(&diffuse, spec_img.as_deref(), owner),
        golden: compose(&gold_diffuse, gold_spec.as_deref(), owner),
        host: exps.is_some().then(|| compose(&host_diffuse, gold_spec.as_deref(), owner)),
        coverage,
        segment,
        specular: spec_report,
        writer,
    }
}

/// One channel's co-simulation thread: its image (the RTL's pixels on the pixels each triangle
/// owns), the first channel's coverage, its report and, through memory, its writer's report.
fn channel(
    job: &Job,
    seg: &'static ModelInfo<SegIn, SegOut>,
    chain: Chain,
    exps: &Option<Vec<Expected>>,
    c: usize,
    done: &AtomicU64,
) -> (Vec<u8>, Vec<u16>, Report, Option<Report>) {
    let screen = job.screen;
    let (width, npix) = (screen.width, (screen.width * screen.height) as usize);
    let p = seg.cfg.p;
    let owner = &job.owner;
    let stims = &job.stims[c];
    let mut img = vec![0u8; npix];
    let mut cov = if c == 0 { vec![0u16; npix] } else { Vec::new() };
    let mut paint = |triangle: usize, y: u32, out: &SegView| {
        let mut n = 0;
        for i in (0..p).filter(|&i| out.lane_enabled(i)) {
            let x = out.out_x + i;
            if x >= width {
                continue;
            }
            let idx = (y * width + x) as usize;
            n += 1;
            if c == 0 {
                cov[idx] = cov[idx].saturating_add(1);
            }
            if owner[idx] == triangle as u32 {
                img[idx] = out.pix[i as usize];
            }
        }
        done.fetch_add(n, Ordering::Relaxed);
    };
    // Through memory the paint only counts: the image is read out of memory.
    let to_memory = matches!(chain, Chain::HostToMemory(_) | Chain::RtlToMemory(_));
    let mut lanes: Vec<SegStim> = Vec::new();
    let report = match (chain, exps) {
        (Chain::Rtl(info), Some(exps)) => stream_chain(info, SEED + c as u64, Traffic::FULL, &exps[c], paint),
        (Chain::RtlToMemory(info), Some(exps)) => {
            let run = stream_fb(info, SEED + c as u64, Traffic::FULL, &exps[c], Some(owner.clone()));
            done.fetch_add(run.report.pixels, Ordering::Relaxed);
            img = memory_image(&run.frame);
            if c == 0 {
                cov = run.mem.screen_writes().into_iter().map(u16::from).collect();
            }
            run.report
        }
        _ => {
            let mut sim = SegmentCosim::new(seg, SEED + c as u64, Traffic::FULL);
            let mut report = Report { triangles: job.drawn, ..Report::default() };
            // (span number, segment index) of the last segment; a span's
            // segments come one after another, so a new `&Stim` is a new span.
            let mut at: Option<(usize, usize, u32)> = None;
            sim.stream(stims, &mut report, |stim, out| {
                if to_memory {
                    // The RTL's segments, as they came out, go on to the writer.
                    let addr = stim as *const Stim as usize;
                    let (span_index, s) = match at {
                        Some((prev, k, s)) if prev == addr => (k, s + 1),
                        Some((_, k, _)) => (k + 1, 0),
                        None => (0, 0),
                    };
                    at = Some((addr, span_index, s));
                    let mut l = out.pix[..p as usize].to_vec();
                    l.extend_from_slice(&out.mask[..p.div_ceil(8) as usize]);
                    let lanes_of = Some(l.into_boxed_slice());
                    lanes.push(SegStim { span_index, triangle: Some(stim.triangle), y: stim.y, span: stim.span, s, lanes: lanes_of });
                }
                paint(stim.triangle, stim.y, out)
            });
            report
        }
    };
    let writer = match chain {
        Chain::HostToMemory(info) => {
            let w = Writer::new(info.cfg, screen).expect("the job's screen fits the writer");
            let run = run_segments(info, SEED + c as u64, Traffic::FULL, Stress::NONE, &lanes, w, Some(owner.clone()));
            img = memory_image(&run.mem.memory.frame());
            Some(run.report)
        }
        _ => None,
    };
    (img, cov, report, writer)
}

/// Golden's images from the same spans and the same ownership: the host's spans, and with the
/// RTL front-end golden's front-end spans (the host's image then kept beside); the specular
/// channel from golden's unit.
fn golden_images(job: &Job, frac: u32, exps: &Option<Vec<Expected>>, spec: Option<&ModelInfo<SpecIn, SpecOut>>) -> GoldenImages {
    let screen = job.screen;
    let (width, npix) = (screen.width, (screen.width * screen.height) as usize);
    let channels = job.channels();
    let owner = &job.owner;
    let paint_golden = |spans: &mut dyn Iterator<Item = (usize, u32, Span)>, img: &mut [u8]| {
        for (triangle, y, span) in spans {
            for j in 0..span.len {
                let idx = (y * width + span.x0 + j) as usize;
                if owner[idx] == triangle as u32 {
                    img[idx] = span.pixel(j, frac);
                }
            }
        }
    };
    let mut host_diffuse = vec![vec![0u8; npix]; channels];
    for (c, stims) in job.stims.iter().enumerate() {
        paint_golden(&mut stims.iter().map(|s| (s.triangle, s.y, s.span)), &mut host_diffuse[c]);
    }
    let gold_diffuse = match exps {
        Some(exps) => {
            let mut g = vec![vec![0u8; npix]; channels];
            for (c, exp) in exps.iter().enumerate() {
                let mut it = exp
                    .stims
                    .iter()
                    .flat_map(|st| exp.spans[st.first..st.first + st.count as usize].iter().map(move |&(y, s)| (st.triangle, y, s)));
                paint_golden(&mut it, &mut g[c]);
            }
            g
        }
        None => host_diffuse.clone(),
    };
    let gold_spec = spec.map(|info| {
        let unit = unit_of(info);
        let mut out = vec![0u16; npix];
        for (st, sp) in job.stims[0].iter().zip(&job.specular) {
            for (j, px) in unit.span(sp).enumerate() {
                let idx = (st.y * width + st.span.x0 + j as u32) as usize;
                if owner[idx] == st.triangle as u32 {
                    out[idx] = px.spec;
                }
            }
        }
        out
    });
    GoldenImages { host_diffuse, gold_diffuse, gold_spec }
}

/// Golden's images: per channel from the host's spans and from the ones the render drew, and
/// the specular channel.
struct GoldenImages {
    host_diffuse: Vec<Vec<u8>>,
    gold_diffuse: Vec<Vec<u8>>,
    gold_spec: Option<Vec<u16>>,
}
