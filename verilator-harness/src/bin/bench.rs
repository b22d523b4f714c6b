//! `bench`: the harness's side of `scripts/bench-cosim`.
//!
//! * `bench gen`: writes a stimulus file and an expected-output file (both little-endian
//!   binary, laid out below) for the segment shader (spans from golden set-up of random
//!   triangles) or the specular unit (random spans from golden specular set-up). The native
//!   C++ testbench (`bench/native_tb.cpp`) and the cocotb test (`bench/cocotb/test_bench.py`)
//!   read the same two files.
//! * `bench harness`: reads a stimulus file and streams it through the harness exactly as users
//!   run it (`SegmentCosim::stream` / `SpecularCosim::stream`, golden comparison on), timing
//!   only the streaming loop. Prints one `RESULT` line.
//! * `bench info`: where this build's models came from: for the segment shader at P and the
//!   specular unit, the Verilog build.rs verilated (so the native and cocotb benches simulate
//!   the very same files) and how long build.rs took to verilate and compile each.
//!
//! Stimulus file: a 64-byte header
//!   `magic "SSBSTIM1", u32 design (0 segment, 1 specular), u32 p, u32 xorshift32 start state,
//!    u32 valid_thr, u32 ready_thr, u32 spans, u64 outputs, u64 seed, u32 expected record bytes,
//!    u32 in_di width`, zero padding,
//! then one 32-byte record per span: `u32 port[5], u32 outputs, u32 triangle, u32 y`, the ports
//! being `in_x, in_len, in_i0, in_di, 0` (segment) or `in_c, in_n, in_theta0, in_dtheta, in_len`
//! (specular), as the port bits. `outputs` is the number of segments (pixels) the span yields.
//! Expected file: a 24-byte header `magic "SSBEXPT1", u32 design, u32 record bytes, u64 records`,
//! then one record per output in order: segment `u32 out_x | out_last << 31, u8 mask[ceil(p/8)],
//! u8 pix[p]` (masked lanes 0), zero-padded to a multiple of 4; specular `u16 out_spec,
//! u8 out_err, u8 out_last`. The traffic is `verilator_harness::traffic`, from the header's state
//! and thresholds.

use clap::{Parser, Subcommand, ValueEnum};
use golden::rng::SeedRng;
use golden::segment::segments;
use golden::setup::{triangle_spans, Screen};
use golden::specular::SpecularSpan;
use golden::{Align, Span};
use rand::SeedableRng;
use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;
use verilator_harness::cosim::{Report, SegmentCosim, Stim};
use verilator_harness::ffi::{segment_model, specular_unit, to_port, SPECULAR_MODELS};
use verilator_harness::ondemand;
use verilator_harness::specular::{random_span, SpecularCosim};
use verilator_harness::stimulus::random_triangle;
use verilator_harness::traffic::{state_of, Traffic};

const STIM_MAGIC: &[u8; 8] = b"SSBSTIM1";
const EXPECT_MAGIC: &[u8; 8] = b"SSBEXPT1";
const HEADER: usize = 64;

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum, Debug)]
enum Design {
    Segment,
    Specular,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum, Debug)]
enum TrafficArg {
    Random,
    Full,
}

#[derive(Parser)]
#[command(about = "Stimulus files and harness timing for scripts/bench-cosim")]
struct Args {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Write PREFIX.stim and PREFIX.expect.
    Gen {
        #[arg(long, value_enum)]
        design: Design,
        /// Segment width (segment shader, span alignment).
        #[arg(long, default_value_t = 8)]
        p: u32,
        /// Spans to write.
        #[arg(long)]
        spans: usize,
        #[arg(long, default_value_t = 1)]
        seed: u64,
        #[arg(long, value_enum, default_value = "random")]
        traffic: TrafficArg,
        /// Output path prefix.
        #[arg(long)]
        out: PathBuf,
    },
    /// The RTL folder and build time of the models the benchmark uses.
    Info {
        #[arg(long, default_value_t = 8)]
        p: u32,
    },
    /// Stream a stimulus file through the harness with the golden comparison on; time the loop.
    Harness {
        stim: PathBuf,
        /// Only the first N spans (0: all).
        #[arg(long, default_value_t = 0)]
        limit: usize,
    },
}

fn main() -> ExitCode {
    match Args::parse().cmd {
        Cmd::Gen { design, p, spans, seed, traffic, out } => {
            let traffic = match traffic {
                TrafficArg::Random => Traffic::RANDOM,
                TrafficArg::Full => Traffic::FULL,
            };
            match design {
                Design::Segment => gen_segment(p, spans, seed, traffic, &out),
                Design::Specular => gen_specular(spans, seed, traffic, &out),
            }
        }
        Cmd::Harness { stim, limit } => harness(&stim, limit),
        Cmd::Info { p } => info(p),
    }
}

/// `MODEL tag=... top=... rtl=DIR verilate=S compile=S total=S` per model, then the runtime's
/// `RUNTIME compile=S`: what build.rs recorded when it last built them (`OUT_DIR/obj/*/build.time`).
fn info(p: u32) -> ExitCode {
    let out = PathBuf::from(env!("OUT_DIR"));
    let times = |tag: &str| -> String {
        let text = std::fs::read_to_string(out.join("obj").join(tag).join("build.time")).unwrap_or_default();
        text.lines().filter_map(|l| l.split_once(' ')).map(|(k, v)| format!(" {k}={v}")).collect()
    };
    let Some(seg) = segment_model(p, Align::Span) else {
        eprintln!("error: no segment shader model for p = {p}");
        return ExitCode::from(2);
    };
    let mut models = vec![(seg.tag, seg.top)];
    models.extend(SPECULAR_MODELS.first().map(|m| (m.tag, m.top)));
    for (tag, top) in models {
        println!("MODEL tag={tag} top={top} rtl={}{}", out.join("rtl").join(tag).display(), times(tag));
    }
    println!("RUNTIME{}", times("runtime"));
    ExitCode::SUCCESS
}

struct Header {
    design: u32,
    p: u32,
    state: u32,
    valid_thr: u32,
    ready_thr: u32,
    spans: u32,
    outputs: u64,
    seed: u64,
    rec: u32,
    dw: u32,
}

impl Header {
    fn bytes(&self) -> [u8; HEADER] {
        let mut h = [0u8; HEADER];
        h[..8].copy_from_slice(STIM_MAGIC);
        let words = [self.design, self.p, self.state, self.valid_thr, self.ready_thr, self.spans];
        for (k, w) in words.iter().enumerate() {
            h[8 + 4 * k..12 + 4 * k].copy_from_slice(&w.to_le_bytes());
        }
        h[32..40].copy_from_slice(&self.outputs.to_le_bytes());
        h[40..48].copy_from_slice(&self.seed.to_le_bytes());
        h[48..52].copy_from_slice(&self.rec.to_le_bytes());
        h[52..56].copy_from_slice(&self.dw.to_le_bytes());
        h
    }

    fn parse(h: &[u8]) -> Header {
        assert_eq!(&h[..8], STIM_MAGIC, "not a bench stimulus file");
        let w = |k: usize| u32::from_le_bytes(h[8 + 4 * k..12 + 4 * k].try_into().unwrap());
        Header {
            design: w(0),
            p: w(1),
            state: w(2),
            valid_thr: w(3),
            ready_thr: w(4),
            spans: w(5),
            outputs: u64::from_le_bytes(h[32..40].try_into().unwrap()),
            seed: u64::from_le_bytes(h[40..48].try_into().unwrap()),
            rec: u32::from_le_bytes(h[48..52].try_into().unwrap()),
            dw: u32::from_le_bytes(h[52..56].try_into().unwrap()),
        }
    }
}

fn create(path: PathBuf) -> BufWriter<File> {
    BufWriter::with_capacity(1 << 20, File::create(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display())))
}

fn with_ext(prefix: &std::path::Path, ext: &str) -> PathBuf {
    let mut s = prefix.as_os_str().to_owned();
    s.push(ext);
    PathBuf::from(s)
}

/// PREFIX.stim and PREFIX.expect, each begun with its header.
fn create_pair(out: &std::path::Path, header: &Header) -> (BufWriter<File>, BufWriter<File>) {
    let mut sf = create(with_ext(out, ".stim"));
    let mut ef = create(with_ext(out, ".expect"));
    sf.write_all(&header.bytes()).unwrap();
    ef.write_all(&expect_header(header.design, header.rec, header.outputs)).unwrap();
    (sf, ef)
}

fn stim_record(ports: [u32; 5], outputs: u32, triangle: u32, y: u32) -> [u8; 32] {
    let mut r = [0u8; 32];
    for (k, w) in ports.iter().chain(&[outputs, triangle, y]).enumerate() {
        r[4 * k..4 * k + 4].copy_from_slice(&w.to_le_bytes());
    }
    r
}

fn expect_header(design: u32, rec: u32, records: u64) -> [u8; 24] {
    let mut h = [0u8; 24];
    h[..8].copy_from_slice(EXPECT_MAGIC);
    h[8..12].copy_from_slice(&design.to_le_bytes());
    h[12..16].copy_from_slice(&rec.to_le_bytes());
    h[16..24].copy_from_slice(&records.to_le_bytes());
    h
}

fn seg_record_bytes(p: u32) -> u32 {
    (4 + p.div_ceil(8) + p).next_multiple_of(4)
}

fn gen_segment(p: u32, count: usize, seed: u64, traffic: Traffic, out: &std::path::Path) -> ExitCode {
    let info = match ondemand::options(p, Align::Span, None).and_then(|o| ondemand::segment(&o)) {
        Ok(info) => info,
        Err(e) => return ondemand::exit(&format!("--p {p}"), &e),
    };
    let cfg = info.cfg;
    let screen = Screen::default();
    let mut rng = SeedRng::seed_from_u64(seed);
    let mut stims: Vec<Stim> = Vec::with_capacity(count);
    let mut triangle = 0;
    while stims.len() < count {
        let t = random_triangle(&mut rng, &screen);
        let _ = triangle_spans(&cfg, &screen, &t, |y, span| stims.push(Stim { triangle, y, span }));
        triangle += 1;
    }
    stims.truncate(count);
    let rec = seg_record_bytes(p);
    let outputs: u64 = stims.iter().map(|s| cfg.segment_count(s.span.x0, s.span.len) as u64).sum();
    let header = Header {
        design: 0,
        p,
        state: state_of(seed),
        valid_thr: traffic.valid_thr(),
        ready_thr: traffic.ready_thr(),
        spans: count as u32,
        outputs,
        seed,
        rec,
        dw: cfg.dw(),
    };
    let (mut sf, mut ef) = create_pair(out, &header);
    let mut r = vec![0u8; rec as usize];
    let mut pixels = 0u64;
    for s in &stims {
        let Span { x0, len, i0, di } = s.span;
        let n = cfg.segment_count(x0, len);
        sf.write_all(&stim_record([x0, len, i0, to_port(di as i64, cfg.dw()), 0], n, s.triangle as u32, s.y)).unwrap();
        for seg in segments(&cfg, &s.span) {
            r.fill(0);
            r[..4].copy_from_slice(&(seg.x | (seg.last as u32) << 31).to_le_bytes());
            let mask_at = 4;
            let pix_at = 4 + p.div_ceil(8) as usize;
            for i in 0..p {
                if let Some(j) = seg.lane_pixel(i) {
                    r[mask_at + (i / 8) as usize] |= 1 << (i % 8);
                    r[pix_at + i as usize] = s.span.pixel(j, cfg.frac);
                    pixels += 1;
                }
            }
            ef.write_all(&r).unwrap();
        }
    }
    sf.flush().unwrap();
    ef.flush().unwrap();
    println!("wrote {} spans, {outputs} segments, {pixels} pixels ({})", count, info.tag);
    ExitCode::SUCCESS
}

fn gen_specular(count: usize, seed: u64, traffic: Traffic, out: &std::path::Path) -> ExitCode {
    let Some(info) = SPECULAR_MODELS.first() else {
        eprintln!("error: this build has no specular unit");
        return ExitCode::from(2);
    };
    let unit = specular_unit();
    let mut rng = SeedRng::seed_from_u64(seed);
    let spans: Vec<SpecularSpan> = (0..count).map(|_| random_span(&mut rng, info.cfg.max_len())).collect();
    let outputs: u64 = spans.iter().map(|s| s.len as u64).sum();
    let header = Header {
        design: 1,
        p: 1,
        state: state_of(seed),
        valid_thr: traffic.valid_thr(),
        ready_thr: traffic.ready_thr(),
        spans: count as u32,
        outputs,
        seed,
        rec: 4,
        dw: 32,
    };
    let (mut sf, mut ef) = create_pair(out, &header);
    for (k, s) in spans.iter().enumerate() {
        let ports = [s.c as u32, s.n as u32, to_port(s.theta0 as i64, 32), to_port(s.dtheta as i64, 32), s.len];
        sf.write_all(&stim_record(ports, s.len, k as u32, 0)).unwrap();
        for px in unit.span(s) {
            let mut r = [0u8; 4];
            r[..2].copy_from_slice(&px.spec.to_le_bytes());
            r[2] = px.err as u8;
            r[3] = px.last as u8;
            ef.write_all(&r).unwrap();
        }
    }
    sf.flush().unwrap();
    ef.flush().unwrap();
    println!("wrote {count} spans, {outputs} pixels ({})", info.tag);
    ExitCode::SUCCESS
}

fn read_stim(path: &std::path::Path) -> (Header, Vec<[u32; 8]>) {
    let mut f = BufReader::new(File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())));
    let mut h = [0u8; HEADER];
    f.read_exact(&mut h).unwrap();
    let header = Header::parse(&h);
    let mut recs = Vec::with_capacity(header.spans as usize);
    let mut r = [0u8; 32];
    for _ in 0..header.spans {
        f.read_exact(&mut r).unwrap();
        recs.push(std::array::from_fn(|k| u32::from_le_bytes(r[4 * k..4 * k + 4].try_into().unwrap())));
    }
    (header, recs)
}

/// The sign-extension of a `width`-bit port value.
fn from_port(v: u32, width: u32) -> i32 {
    ((v << (32 - width)) as i32) >> (32 - width)
}

/// CPU time of the process, every thread (Linux `CLOCK_PROCESS_CPUTIME_ID`): the harness's
/// driving and checking threads together, the cost a user pays in cores.
fn process_cpu() -> f64 {
    let mut t = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: clock_gettime fills the timespec we own; this clock exists on every Linux.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut t) };
    assert_eq!(rc, 0, "clock_gettime(CLOCK_PROCESS_CPUTIME_ID)");
    t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9
}

/// A timed region: wall seconds and the process's CPU seconds.
fn timed(f: impl FnOnce()) -> (f64, f64) {
    let (start, cpu) = (Instant::now(), process_cpu());
    f();
    (start.elapsed().as_secs_f64(), process_cpu() - cpu)
}

fn harness(path: &std::path::Path, limit: usize) -> ExitCode {
    let (h, mut recs) = read_stim(path);
    if limit > 0 {
        recs.truncate(limit);
    }
    assert_eq!(h.state, state_of(h.seed), "stimulus file: traffic state is not state_of(seed)");
    let traffic = Traffic { valid: h.valid_thr as f64 / 256.0, ready: h.ready_thr as f64 / 256.0 };
    let mut report = Report::default();
    let (tag, (secs, cpu)) = match h.design {
        0 => {
            let info = ondemand::options(h.p, Align::Span, None)
                .and_then(|o| ondemand::segment(&o))
                .unwrap_or_else(|e| panic!("the segment shader for p = {}: {e}", h.p));
            let stims: Vec<Stim> = recs
                .iter()
                .map(|r| Stim { triangle: r[6] as usize, y: r[7], span: Span { x0: r[0], len: r[1], i0: r[2], di: from_port(r[3], h.dw) } })
                .collect();
            let mut sim = SegmentCosim::new(info, h.seed, traffic);
            (info.tag, timed(|| sim.stream(&stims, &mut report, |_, _| {})))
        }
        1 => {
            let info = SPECULAR_MODELS.first().expect("no specular unit in this build");
            let spans: Vec<SpecularSpan> = recs
                .iter()
                .map(|r| SpecularSpan { c: r[0] as u16, n: r[1] as u16, theta0: r[2] as i32, dtheta: r[3] as i32, len: r[4] })
                .collect();
            let mut sim = SpecularCosim::new(info, specular_unit(), h.seed, traffic);
            (info.tag, timed(|| sim.stream(&spans, &mut report)))
        }
        d => panic!("unknown design {d}"),
    };
    for m in &report.mismatches {
        eprintln!("MISMATCH {m}");
    }
    println!(
        "RESULT impl=harness model={tag} spans={} clocks={} pixels={} secs={secs:.6} cpu={cpu:.6} mismatches={}",
        report.spans, report.cycles, report.pixels, report.mismatch_count
    );
    if report.ok() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    }
}
