//! Waveforms ([`verilator_harness::waveform`]): a planted fault's mismatch names an FST file of
//! the failing window and its clock, and the file parses and holds the top-level ports around
//! that clock; `cosim --trace` writes a whole run, and refuses a folder it cannot make.
//!
//! The fault is planted at the FFI: a copy of `seg_p2_span`'s model whose step flips a pixel bit
//! of one output transfer, with the real model's traced twin (built on demand the first time,
//! a few seconds, then cached under target/). The mutant through COSIM_RTL_DIR, a real RTL
//! fault replayed into its own twin, is `scripts/check-rtl-dir --trace`.

use golden::rng::SeedRng;
use golden::setup::{triangle_spans, Screen};
use golden::Align;
use rand::SeedableRng;
use std::collections::HashMap;
use std::ffi::c_void;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::OnceLock;
use verilator_harness::ffi::{ModelInfo, SegIn, SegOut};
use verilator_harness::registry::require_segment_model;
use verilator_harness::segment::{Report, SegmentCosim, Stim, Stress, Traffic};
use verilator_harness::stimulus::random_triangle;
use verilator_harness::waveform::{check_fst, AFTER, BEFORE, TIME_PER_CLOCK};

/// The transfer whose lane-0 pixel the mutant flips (counted from its construction).
const FLIP_AT: u32 = 1500;

type Step = unsafe extern "C" fn(*mut c_void, *const SegIn, *mut SegOut);
static REAL_STEP: OnceLock<Step> = OnceLock::new();
static TRANSFERS: AtomicU32 = AtomicU32::new(0);

/// The real model's clock, then bit 0 of lane 0's pixel flipped in the [`FLIP_AT`]-th output
/// transfer (span alignment at P = 2: lane 0 is always in its span), which the scoreboard then
/// sees in every run, by construction.
unsafe extern "C" fn flipped_step(h: *mut c_void, i: *const SegIn, o: *mut SegOut) {
    let real = REAL_STEP.get().expect("set before the mutant runs");
    unsafe {
        real(h, i, o);
        // A clock with `rst` high transfers nothing (the harness ignores its outputs, as the
        // hardware's consumer would): counting it, a fault planted there went unseen under
        // stress resets (COSIM_SEED=1795593422465073190).
        if (*i).rst == 0 && (*o).out_valid == 1 && (*i).out_ready == 1 && TRANSFERS.fetch_add(1, Ordering::Relaxed) + 1 == FLIP_AT {
            (*o).pix[0] ^= 1;
        }
    }
}

/// `seg_p2_span` with its traced twin (built on demand the first time, then cached), for a test
/// that needs them (see `ffi::require`).
fn traced_p2(what: &str) -> Option<&'static ModelInfo<SegIn, SegOut>> {
    let info = require_segment_model(2, Align::Span, what)?;
    verilator_harness::ondemand::require_traced(info).unwrap_or_else(|e| panic!("{what}: {e}"));
    Some(info)
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("waveforms-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A waveform file as GTKWave's `fst2vcd` reads it (Debian's gtkwave; `./scripts/test` installs
/// it): the top-level ports (the variables of the outermost scope) and their values over time.
struct Ports {
    /// Name and VCD identifier.
    ports: Vec<(String, String)>,
    /// Each identifier's changes: (time, value bits).
    changes: HashMap<String, Vec<(u64, String)>>,
    /// The first and last clock in the file.
    first: u64,
    last: u64,
}

impl Ports {
    fn read(path: &Path) -> Ports {
        let out = Command::new("fst2vcd").arg(path).output().unwrap_or_else(|e| {
            panic!("fst2vcd: {e} (it comes with Debian's gtkwave: apt-get install -y gtkwave; ./scripts/test installs it)")
        });
        assert!(out.status.success(), "fst2vcd {}: {}", path.display(), String::from_utf8_lossy(&out.stderr));
        let text = String::from_utf8(out.stdout).expect("VCD is text");
        let (mut depth, mut ports, mut changes, mut times) = (0, Vec::new(), HashMap::<String, Vec<(u64, String)>>::new(), Vec::new());
        let mut t = 0;
        for line in text.lines() {
            let words: Vec<&str> = line.split_whitespace().collect();
            match words.as_slice() {
                ["$scope", ..] => depth += 1,
                ["$upscope", ..] => depth -= 1,
                ["$var", _, _, id, name, ..] if depth == 1 => ports.push((name.to_string(), id.to_string())),
                [w] if w.starts_with('#') => {
                    t = w[1..].parse().expect("a time");
                    times.push(t);
                }
                [v, id] if v.starts_with('b') => changes.entry(id.to_string()).or_default().push((t, v[1..].to_string())),
                [v] if !v.starts_with('$') && v.len() > 1 => {
                    let (bit, id) = v.split_at(1);
                    changes.entry(id.to_string()).or_default().push((t, bit.to_string()));
                }
                _ => {}
            }
        }
        let (first, last) = (times.first().copied().unwrap_or(0), times.last().copied().unwrap_or(0));
        Ports { ports, changes, first: first / TIME_PER_CLOCK, last: last / TIME_PER_CLOCK }
    }

    /// The value of `port` in clock `clock`, as its rising edge sees it (t = 10 `clock`).
    fn at(&self, port: &str, clock: u64) -> Option<&str> {
        let id = &self.ports.iter().find(|(name, _)| name == port)?.1;
        let t = clock * TIME_PER_CLOCK;
        self.changes.get(id)?.iter().take_while(|(time, _)| *time <= t).last().map(|(_, v)| v.as_str())
    }

    /// [`Ports::at`] as a number.
    fn value(&self, port: &str, clock: u64) -> Option<u64> {
        u64::from_str_radix(self.at(port, clock)?, 2).ok()
    }
}

/// The ports SPEC §3 gives `segment_shader_p<P>`.
const PORTS: [&str; 14] = [
    "clk",
    "rst",
    "in_valid",
    "in_ready",
    "in_x",
    "in_len",
    "in_i0",
    "in_di",
    "out_valid",
    "out_ready",
    "out_x",
    "out_pix",
    "out_mask",
    "out_last",
];

fn assert_ports(ports: &Ports, path: &Path) {
    let names: Vec<&str> = ports.ports.iter().map(|(name, _)| name.as_str()).collect();
    for p in PORTS {
        assert!(names.contains(&p), "{}: no top-level port {p} (has {names:?})", path.display());
    }
}

/// Without stress the window is BEFORE clocks before the fault to AFTER after; with resets
/// (`Stress::HARSH`, one about every 500 clocks) the replay runs through them, from the last
/// reset before the failing stream.
#[test]
fn a_planted_fault_names_its_window() {
    let Some(real) = traced_p2("waveforms: planted fault") else { return };
    REAL_STEP.set(real.step_fn()).expect("one mutant");
    // SAFETY: flipped_step calls the model's own step with the same arguments, then edits its output.
    let mutant: &'static ModelInfo<SegIn, SegOut> = Box::leak(Box::new(unsafe { real.with_step(flipped_step) }));
    let seed = verilator_harness::seed("a_planted_fault_names_its_window");
    for stress in [Stress::NONE, Stress::HARSH] {
        TRANSFERS.store(0, Ordering::Relaxed);
        planted_fault(mutant, seed, stress);
    }
}

fn planted_fault(mutant: &'static ModelInfo<SegIn, SegOut>, seed: u64, stress: Stress) {
    let dir = scratch("fault");
    let screen = Screen::default();
    let mut rng = SeedRng::seed_from_u64(seed);
    let mut sim = SegmentCosim::new(mutant, seed, Traffic::RANDOM);
    sim.set_stress(stress);
    sim.set_waveforms(Some(dir.clone()));
    let mut report = Report::default();
    // Streams of 20 triangles' spans (no frame checks: under stress, spans a reset cuts short
    // leave holes in the frame), at least 20 of them and then until the run has passed the
    // planted fault and, under stress, seen a reset: so both hold for every seed. Each stream
    // ends with DRAIN_CLOCKS clocks, each drawing a reset with probability 0.002 under
    // Stress::HARSH, so the cap of 10,000 streams is hit with probability <= 0.998^30000 = e^-60.
    // `ends`: each stream's last clock.
    let (mut first, mut ends) = (0, Vec::new());
    while first < 400 || TRANSFERS.load(Ordering::Relaxed) <= FLIP_AT || (stress != Stress::NONE && report.resets == 0) {
        assert!(
            first < 200_000,
            "{} transfers and {} resets in {} streams (seed {seed})",
            TRANSFERS.load(Ordering::Relaxed),
            report.resets,
            first / 20
        );
        let mut stims = Vec::new();
        for triangle in first..first + 20 {
            let t = random_triangle(&mut rng, &screen);
            triangle_spans(&mutant.cfg, &screen, &t, |y, span| stims.push(Stim { triangle, y, span })).expect("set-up");
        }
        sim.stream(&stims, &mut report, |_, _| {});
        ends.push(sim.clock() - 1);
        first += 20;
    }
    assert!(!report.ok(), "the planted fault was not caught");
    assert_eq!(report.waveforms.len(), 1, "one waveform per model: {:?}", report.waveforms);
    let w = &report.waveforms[0];
    let (clock, path) = (w.clock, &w.path);
    assert!(path.starts_with(&dir) && path.exists(), "{}", path.display());

    // The first mismatch's message names the file and the clock. It is the scoreboard's (the
    // flipped pixel), or the protocol monitor's when the segment had been held a clock before.
    let all: Vec<String> = report.mismatches.iter().map(ToString::to_string).collect();
    let named: Vec<&String> = all.iter().filter(|m| m.contains(&path.display().to_string())).collect();
    assert_eq!(named.len(), 1, "{all:#?}");
    assert!(named[0].contains(&format!("clock {clock}")), "{}", named[0]);
    let lane = all.iter().find(|m| m.contains("lane 0 (pixel")).unwrap_or_else(|| panic!("{all:#?}"));
    let expected: u64 = lane.split("expected ").nth(1).and_then(|s| s.split(',').next()).and_then(|s| s.parse().ok()).expect(lane);

    let ports = Ports::read(path);
    assert_ports(&ports, path);
    assert_eq!(w.window, Some((ports.first, ports.last)));
    let summary = check_fst(path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((summary.first, summary.last), (ports.first, ports.last), "the harness's check and fst2vcd agree");
    // By construction: the fault is output transfer FLIP_AT, and each transfer takes a clock.
    assert!(clock > BEFORE + 2, "clock {clock}: the fault should come later");
    // The window ends AFTER clocks after the fault, or with the fault's stream if that is sooner.
    let stream_end = ends.iter().copied().find(|&e| e >= clock).expect("the fault's stream");
    if stress == Stress::NONE {
        assert_eq!((ports.first, ports.last), (clock - BEFORE, (clock + AFTER).min(stream_end)), "the window");
    } else {
        assert!(ports.first >= clock - BEFORE && ports.last <= clock + AFTER && ports.last > clock, "{:?}", w.window);
    }
    // At the clock named, the twin (the real RTL) hands over the segment the mutant corrupted:
    // a transfer, lane 0 holding the pixel golden expected.
    for c in [ports.first, clock, ports.last] {
        assert_eq!(ports.at("clk", c), Some("0"), "clk low at t = 10 N");
        assert!(PORTS.iter().all(|p| ports.at(p, c).is_some()), "every port has a value in clock {c}");
    }
    assert_eq!((ports.value("out_valid", clock), ports.value("out_ready", clock)), (Some(1), Some(1)), "a transfer in clock {clock}");
    assert_eq!(ports.value("out_pix", clock).map(|v| v & 0xff), Some(expected), "lane 0 in clock {clock}");
    assert_eq!(ports.value("rst", clock), Some(0));
    let _ = std::fs::remove_dir_all(&dir);
}

const COSIM: &str = env!("CARGO_BIN_EXE_cosim");

/// `cosim --trace DIR` writes the whole run of a model's twin from its first clock, and refuses,
/// with exit status 2 and one message, a DIR it cannot make.
#[test]
fn cosim_trace_writes_the_whole_run() {
    let Some(info) = traced_p2("waveforms: cosim --trace") else { return };
    let dir = scratch("cosim");
    let args = ["--p", "2", "--align", "span", "--triangles", "30", "--seed", "7", "--trace"];
    let out = Command::new(COSIM).args(args).arg(&dir).output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}{}", String::from_utf8_lossy(&out.stderr));
    let path = dir.join(format!("{}-seed7.fst", info.tag));
    assert!(stdout.contains(&format!("waveform:   {}", path.display())), "{stdout}");
    let cycles: u64 = stdout.lines().find_map(|l| l.strip_prefix("cycles:")).and_then(|c| c.trim().parse().ok()).expect(&stdout);
    let ports = Ports::read(&path);
    assert_ports(&ports, &path);
    // The reset's two clocks, the run's, and its last clock's edge.
    assert_eq!((ports.first, ports.last), (0, cycles + 2 - 1), "every clock of the run");
    assert_eq!(ports.value("rst", 0), Some(1));

    // Negative control: DIR under a regular file cannot be made.
    let file = dir.join("a-file");
    std::fs::write(&file, "x").unwrap();
    let out = Command::new(COSIM).args(["--p", "2", "--triangles", "1", "--trace"]).arg(file.join("waves")).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.starts_with("error: --trace: ") && err.contains("a-file") && err.lines().count() == 1, "{err}");
    assert!(out.stdout.is_empty());
    let _ = std::fs::remove_dir_all(&dir);
}
