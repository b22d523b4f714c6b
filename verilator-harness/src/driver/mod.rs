//! The clock loop every streaming unit shares (SPEC §3's valid/ready on both sides), with its
//! scoreboard on a second thread.
//!
//! The driving thread does only what must happen clock by clock: draw the traffic, put a span
//! on the ports and hold it until taken, step the model, watch the protocol (an output offered
//! and not taken stays, unchanged; `out_valid` is low right after a reset), count what each
//! accepted span still owes, and copy every output transfer into a compact record. Records go
//! in batches over a bounded channel to the checking thread, which compares each with golden
//! (the expensive part: golden's segments and rows, the f64 references). On two cores the
//! model then runs at 0.8 to 0.9 of its speed in a bare C++ testbench (`scripts/bench-cosim`);
//! the order of checks, and therefore every report, is the same as in one thread.
//!
//! With waveforms on ([`crate::waveform`]), the driver also keeps a tape of its model's inputs,
//! and the first mismatch of the run names the FST file of its clocks and its clock.
//!
//! The clock loop (`drive`) keeps its state in named parts, each with its own tests:
//! the `pacer` decides each clock's traffic, the `monitor` checks the handshake and notices a
//! hung model, the `scoreboard` counts what each span still owes, and the `checker`'s
//! outbox carries the records to the checking thread. A unit plugs in through `unit`'s traits.

mod checker;
mod monitor;
mod pacer;
mod scoreboard;
mod unit;

pub use pacer::Stress;
pub use unit::DRAIN_CLOCKS;
pub(crate) use unit::{Check, Unit};

use crate::ffi::{Control, Handshake, Rtl};
use crate::report::{Mismatch, Report};
use crate::tape::{NoTape, Recorder, Tape};
use crate::traffic::TrafficGen;
use crate::waveform::{TraceError, Waveform, AFTER, BEFORE};
use checker::{channels, consume, Link, Outbox};
use monitor::{Monitor, Stall, STALL_LIMIT};
use pacer::Pacer;
use scoreboard::Scoreboard;
use std::path::PathBuf;

/// A unit under test: the model, its traffic and its stress. Written every clock, so aligned
/// to whole cache lines: nothing the checking thread writes may sit beside it.
#[repr(align(128))]
pub(crate) struct Driver<U: Unit> {
    rtl: Rtl<U::In, U::Out>,
    rng: TrafficGen,
    pub stress: Stress,
    input: U::In,
    output: U::Out,
    /// Clocks the model has run since it was built, reset clocks included: the clock numbers of
    /// mismatch messages and waveforms. Brought up to date when a stream ends (the clock loop
    /// counts in `Report::cycles`).
    clock: u64,
    /// Where the first failure's waveform goes ([`crate::waveform`]).
    waves: Waves,
    /// The inputs since the last reset, while a waveform may still be needed.
    tape: Option<Box<Tape<U::In>>>,
}

/// What a driver does about waveforms.
enum Waves {
    Off,
    /// On a failure, replay the tape into the model's traced twin and write the window to this
    /// folder (COSIM_TRACE).
    OnFailure(PathBuf),
    /// The model is the traced twin, writing every clock (`--trace`): name its file.
    Live,
    /// The first failure has been described (one waveform per model).
    Done,
}

impl<U: Unit> Driver<U> {
    /// The model in reset for two clocks. Waveforms are on when the model is traced
    /// (`--trace`) or COSIM_TRACE is set ([`crate::waveform::failure_dir`]).
    pub fn new(rtl: Rtl<U::In, U::Out>, rng: TrafficGen) -> Self {
        let waves = match (rtl.waves(), crate::waveform::failure_dir()) {
            (Some(_), _) => Waves::Live,
            (None, Some(dir)) => Waves::OnFailure(dir.to_path_buf()),
            (None, None) => Waves::Off,
        };
        let mut d =
            Driver { rtl, rng, stress: Stress::NONE, input: U::In::default(), output: U::Out::default(), clock: 0, waves, tape: None };
        d.start_tape();
        d.reset();
        d
    }

    /// Clocks the model has run since it was built, reset clocks included (the numbers of
    /// mismatch messages and waveforms); after a stream, its last clock is this minus one.
    pub fn clock(&self) -> u64 {
        self.clock
    }

    /// Failure waveforms into `dir` (`None`: off) from now on, whatever COSIM_TRACE says; two
    /// clocks of reset start the tape. No effect on a traced model (`--trace`).
    pub fn set_waveforms(&mut self, dir: Option<PathBuf>) {
        if matches!(self.waves, Waves::Live) {
            return;
        }
        self.waves = dir.map_or(Waves::Off, Waves::OnFailure);
        self.start_tape();
        self.reset();
    }

    /// A new tape, starting with the next clock, when waveforms need one: a traced model's file
    /// needs the output clocks, a failure's replay every input (into the model's twin, built
    /// when a failure first needs it).
    fn start_tape(&mut self) {
        let needed = match self.waves {
            Waves::Live | Waves::OnFailure(_) => true,
            Waves::Off | Waves::Done => false,
        };
        self.tape = needed.then(|| Box::new(Tape::new(self.clock)));
    }

    /// Two clocks of reset with the inputs idle.
    pub fn reset(&mut self) {
        match self.tape.take() {
            Some(mut tape) => {
                self.reset_with(&mut *tape);
                self.tape = Some(tape);
            }
            None => self.reset_with(&mut NoTape),
        }
    }

    fn reset_with(&mut self, rec: &mut impl Recorder<U::In>) {
        self.input = U::In::default();
        self.input.set_control(true, false, false);
        rec.reset(self.clock);
        for _ in 0..2 {
            self.rtl.step_into(&self.input, &mut self.output);
            rec.clock(self.clock, &self.input);
            self.clock += 1;
        }
    }

    /// Streams `spans` through the model, `check` judging every output on a second thread;
    /// the driver's counts, protocol findings and the checker's verdicts all land in `report`.
    /// With waveforms on, the run's first mismatch names its waveform ([`Driver::waveform`]).
    pub fn stream(&mut self, unit: &U, spans: &[U::Span], report: &mut Report, check: impl Check) {
        let (link, rx, back_tx) = channels();
        // Mismatches the driver finds are added to `report` after these.
        let (kept, before) = (report.mismatches.len(), report.mismatch_count);
        let mut tape = self.tape.take();
        if let Some(t) = tape.as_deref_mut() {
            t.new_stream();
        }
        let (mut checked, first_bad) = std::thread::scope(|s| {
            // The checker's state (its checker, its report) lives on its own thread: written
            // for every output, it must share no cache line with the driver's.
            let checker = s.spawn(move || consume(rx, back_tx, unit.record_bytes(), check));
            let rng = self.rng.clone();
            // The clock loop for each case, so none pays for what it does not do.
            match (self.stress == Stress::NONE, tape.as_deref_mut()) {
                (true, None) => self.drive(Pacer::<false>::new(self.stress, rng), unit, spans, report, &link, &mut NoTape),
                (false, None) => self.drive(Pacer::<true>::new(self.stress, rng), unit, spans, report, &link, &mut NoTape),
                (true, Some(t)) => self.drive(Pacer::<false>::new(self.stress, rng), unit, spans, report, &link, t),
                (false, Some(t)) => self.drive(Pacer::<true>::new(self.stress, rng), unit, spans, report, &link, t),
            }
            // The checker's loop ends when its channel closes.
            drop(link);
            checker.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic))
        });
        if report.mismatch_count > before || !checked.ok() {
            self.describe_failure(tape.as_deref(), first_bad, kept, report, &mut checked);
        }
        self.tape = match self.waves {
            Waves::Done => None,
            _ => tape.map(|mut t| {
                t.end_stream();
                t
            }),
        };
        report.absorb(checked);
    }

    /// The run's first failure (this stream's first mismatch, in clock order, if the run had none
    /// before) names its waveform, or why there is none. `first_bad`: the checker's first failing
    /// output; `kept`: where this stream's driver mismatches start in `report.mismatches`.
    #[cold]
    fn describe_failure(
        &mut self,
        tape: Option<&Tape<U::In>>,
        first_bad: Option<usize>,
        kept: usize,
        report: &mut Report,
        checked: &mut Report,
    ) {
        let tape = match (&self.waves, tape) {
            (Waves::Off | Waves::Done, _) => return,
            (_, Some(tape)) => tape,
            // Nothing was taped (a driver with waveforms on always tapes; kept for safety). The
            // note goes on this stream's first mismatch.
            (_, None) => {
                let note = format!("COSIM_TRACE: no waveform: {} kept no tape", self.rtl.info().tag);
                annotate(report.mismatches.get_mut(kept).or(checked.mismatches.first_mut()), &note);
                self.waves = Waves::Done;
                return;
            }
        };
        let by_driver = tape.found;
        let by_checker = first_bad.and_then(|n| tape.transfers.get(n).copied());
        let Some(clock) = by_driver.into_iter().chain(by_checker).min() else { return };
        let waveform = self.waveform(tape, clock);
        let note = match &waveform {
            Ok(w) => w.to_string(),
            Err(e) => format!("clock {clock}; COSIM_TRACE: no waveform: {e}"),
        };
        match by_driver == Some(clock) {
            true => annotate(report.mismatches.get_mut(kept), &note),
            false => annotate(checked.mismatches.first_mut(), &note),
        }
        report.waveforms.extend(waveform.ok());
        self.waves = Waves::Done;
    }

    /// The waveform of a failure in clock `clock`: the traced model's own file, or the tape's
    /// window around `clock` replayed into the model's twin, written and checked whole.
    #[cold]
    fn waveform(&self, tape: &Tape<U::In>, clock: u64) -> Result<Waveform, TraceError> {
        let dir = match &self.waves {
            Waves::Live => {
                let path = self.rtl.waves().expect("a traced model has a file").to_path_buf();
                return Ok(Waveform { path, clock, window: None });
            }
            Waves::OnFailure(dir) => dir,
            Waves::Off | Waves::Done => return Err(TraceError::Off),
        };
        let (first, last) = tape.clocks();
        let (from, to) = (clock.saturating_sub(BEFORE).max(first), (clock + AFTER).min(last));
        let info = self.rtl.info();
        std::fs::create_dir_all(dir).map_err(|error| TraceError::Io { path: dir.clone(), error })?;
        let path = dir.join(format!("{}-seed{}-clock{clock}.fst", info.tag, self.rtl.seed()));
        crate::ondemand::require_traced(info)?;
        let mut twin = Rtl::traced(info, self.rtl.seed())?;
        tape.replay(&mut twin, from, to, &path)?;
        drop(twin);
        let file = crate::waveform::check_fst(&path).map_err(TraceError::Unreadable)?;
        if (file.first, file.last) != (from, to) {
            return Err(TraceError::Window { path, held: (file.first, file.last), wanted: (from, to) });
        }
        Ok(Waveform { path, clock, window: Some((from, to)) })
    }

    /// The clock loop; full batches go to the checker over `link`. `rec` is told every clock's
    /// inputs, output transfers, resets and the driver's mismatches (nothing with waveforms off).
    fn drive<const STRESSED: bool>(
        &mut self,
        mut pacer: Pacer<STRESSED>,
        unit: &U,
        spans: &[U::Span],
        report: &mut Report,
        link: &Link,
        rec: &mut impl Recorder<U::In>,
    ) {
        let mut outbox = Outbox::new(link, unit.record_bytes());
        let (mut owed, mut monitor, mut stall) = (Scoreboard::default(), Monitor::new(unit.record_bytes()), Stall::default());
        // The next span to offer, whether it is on the ports, and the quiet clocks run after the
        // last output.
        let (mut next, mut offering, mut drain) = (0, false, 0);
        // The clock about to be stepped (reset clocks included).
        let mut clock = self.clock;
        loop {
            if next == spans.len() && owed.is_empty() {
                // Everything came out; a few more clocks must bring nothing.
                if drain == unit.drain_clocks() {
                    break;
                }
                drain += 1;
            }
            pacer.clock();
            if pacer.reset() {
                // Nothing transfers in a reset clock: the spans in flight are cut, the one
                // being offered stays offered.
                if monitor.reset() {
                    report.resets += 1;
                    report.cut_spans += owed.cut();
                    rec.reset(clock);
                }
                let ready = pacer.ready();
                self.input.set_control(true, offering, ready);
                self.rtl.step_into(&self.input, &mut self.output);
                rec.clock(clock, &self.input);
                report.cycles += 1;
                clock += 1;
                stall.reset();
                continue;
            }
            if !offering && next < spans.len() {
                offering = pacer.offer();
                if offering {
                    unit.load(&mut self.input, &spans[next]);
                    self.input.keep_data(false);
                }
            }
            let ready = pacer.ready();
            self.input.set_control(false, offering, ready);
            self.rtl.step_into(&self.input, &mut self.output);
            rec.clock(clock, &self.input);
            // The ports now hold this span's data: until the next span, the shim need not
            // write them again.
            self.input.keep_data(true);
            report.cycles += 1;
            let (now, out) = (clock, &self.output);
            clock += 1;
            report.pulses += unit.pulse(out) as u64;
            monitor.watch(unit, out, ready, |what| flag(rec, report, now, what));
            let mut progress = false;
            if out.out_valid() && ready {
                match owed.transfer() {
                    Some((k, j)) => {
                        progress = true;
                        rec.transfer(now);
                        if !outbox.push(k, j, |r| unit.record(out, r)) {
                            return;
                        }
                    }
                    // Output nobody asked for is no progress: a model that streams garbage
                    // while refusing input is declared hung, not followed forever.
                    None => flag(rec, report, now, "output with no span outstanding".into()),
                }
            }
            if offering && out.in_ready() {
                progress = true;
                owed.accept(next, unit.owed(&spans[next]));
                report.spans += 1;
                next += 1;
                offering = false;
                pacer.accepted();
            }
            if stall.hung(progress) {
                let (triangle, context) = match owed.oldest() {
                    Some(k) => unit.blame(k, &spans[k]),
                    None => (None, "idle".into()),
                };
                let what = format!("no transfer for {STALL_LIMIT} clocks (clock {now}); {} outputs still expected", owed.left());
                rec.found(now);
                report.mismatch(Mismatch { triangle, context, what });
                self.clock = clock;
                self.reset_with(rec);
                clock = self.clock;
                break;
            }
        }
        self.clock = clock;
        // The next stream goes on with the traffic where this one left it.
        self.rng = pacer.rng;
        outbox.flush();
    }
}

/// A breach of the protocol the driver found in clock `clock`: told to the tape (a waveform may
/// be needed) and reported.
#[cold]
fn flag<I>(rec: &mut impl Recorder<I>, report: &mut Report, clock: u64, what: String) {
    rec.found(clock);
    report.mismatch(Mismatch { triangle: None, context: format!("clock {clock}"), what });
}

/// Adds `note` to a mismatch's message, in brackets.
fn annotate(m: Option<&mut Mismatch>, note: &str) {
    if let Some(m) = m {
        m.what = format!("{} [{note}]", m.what);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ffi::{to_port, SegIn, SegOut};
    use crate::registry::require_segment_model;
    use crate::traffic::Traffic;
    use golden::{Align, Config, Span};
    use std::sync::{Arc, Mutex};

    /// The driver's view of a segment shader, as little as the driver needs: a record is
    /// `out_x | out_last << 31`, and `extra` segments are claimed beyond what golden says each
    /// span owes (a negative control: a unit that miscounts).
    struct Segments {
        cfg: Config,
        extra: i32,
    }

    impl Unit for Segments {
        type In = SegIn;
        type Out = SegOut;
        type Span = Span;
        fn record_bytes(&self) -> usize {
            4
        }
        fn load(&self, input: &mut SegIn, s: &Span) {
            (input.in_x, input.in_len, input.in_i0, input.in_di) = (s.x0, s.len, s.i0, to_port(s.di as i64, self.cfg.dw()));
        }
        fn owed(&self, s: &Span) -> u32 {
            (self.cfg.segment_count(s.x0, s.len) as i32 + self.extra).max(0) as u32
        }
        fn record(&self, out: &SegOut, rec: &mut [u8]) {
            rec.copy_from_slice(&(out.out_x | (out.out_last as u32) << 31).to_le_bytes());
        }
        fn same(&self, held: &[u8], out: &SegOut) -> bool {
            let mut now = [0; 4];
            self.record(out, &mut now);
            held == now
        }
        fn describe_change(&self, _held: &[u8], _out: &SegOut) -> String {
            "changed".into()
        }
        fn blame(&self, k: usize, _s: &Span) -> (Option<usize>, String) {
            (Some(k), format!("span {k}"))
        }
    }

    /// (span, output, record) of one output the checker got.
    type Got = (usize, u32, u32);

    /// Every output the checker got, in order.
    #[derive(Clone, Default)]
    struct Seen(Arc<Mutex<Vec<Got>>>);

    impl Check for Seen {
        fn check(&mut self, k: usize, j: u32, rec: &[u8], _report: &mut Report) {
            self.0.lock().unwrap().push((k, j, u32::from_le_bytes(rec.try_into().unwrap())));
        }
    }

    fn spans(n: u32) -> Vec<Span> {
        (0..n).map(|k| Span { x0: (k * 7) % 200, len: k % 23, i0: 100 << 12, di: 1 << 10 }).collect()
    }

    /// Runs `spans` through `seg_p2_span` with `unit` under `traffic` and `stress`; `None` when
    /// this build has no such model (COSIM_RTL_DIR).
    fn run(unit: &Segments, spans: &[Span], traffic: Traffic, stress: Stress) -> Option<(Report, Vec<Got>)> {
        let info = require_segment_model(2, Align::Span, "driver: its own tests")?;
        let mut d = Driver::<Segments>::new(Rtl::new(info, 3), TrafficGen::new(traffic, 3));
        d.set_waveforms(None);
        d.stress = stress;
        let (mut report, seen) = (Report::default(), Seen::default());
        d.stream(unit, spans, &mut report, seen.clone());
        let got = seen.0.lock().unwrap().clone();
        Some((report, got))
    }

    /// Every output golden owes reaches the checker once, in order (span by span, each span's
    /// outputs numbered from 0), with golden's x and last flag; the counts add up.
    #[test]
    fn every_owed_output_reaches_the_checker_in_order() {
        let cfg = Config { p: 2, ..Config::default() };
        let unit = Segments { cfg, extra: 0 };
        let s = spans(300);
        for traffic in [Traffic::FULL, Traffic::RANDOM] {
            let Some((report, got)) = run(&unit, &s, traffic, Stress::BURSTS) else { return };
            assert!(report.ok(), "{:?}", report.mismatches);
            assert_eq!(report.spans, s.len() as u64);
            let want: Vec<Got> = s
                .iter()
                .enumerate()
                .flat_map(|(k, sp)| golden::segment::segments(&cfg, sp).map(move |g| (k, g.index, g.x | (g.last as u32) << 31)))
                .collect();
            assert_eq!(got, want);
        }
    }

    /// With resets, a span cut short stops early and nothing of it comes later: per span the
    /// output numbers run 0, 1, 2, ... and spans come in order; resets and cuts are counted.
    #[test]
    fn resets_cut_spans_and_nothing_stale_follows() {
        let unit = Segments { cfg: Config { p: 2, ..Config::default() }, extra: 0 };
        let Some((report, got)) = run(&unit, &spans(2000), Traffic::RANDOM, Stress::HARSH) else { return };
        assert!(report.ok(), "{:?}", report.mismatches);
        assert!(report.resets > 0 && report.cut_spans > 0, "{report:?}");
        for w in got.windows(2) {
            let ((k0, j0, _), (k1, j1, _)) = (w[0], w[1]);
            assert!((k1 == k0 && j1 == j0 + 1) || (k1 > k0 && j1 == 0), "{:?} then {:?}", w[0], w[1]);
        }
    }

    /// Negative controls of the protocol monitor: a unit that owes one output too few sees
    /// output with no span outstanding; one that owes one too many sees the model stop, and the
    /// driver declares it hung instead of waiting forever.
    #[test]
    fn miscounted_outputs_are_mismatches() {
        let cfg = Config { p: 2, ..Config::default() };
        let s: Vec<Span> = spans(40).into_iter().filter(|s| s.len > 0).collect();
        let Some((few, _)) = run(&Segments { cfg, extra: -1 }, &s, Traffic::RANDOM, Stress::NONE) else { return };
        assert!(few.mismatches.iter().any(|m| m.what == "output with no span outstanding"), "{:?}", few.mismatches);
        let Some((many, _)) = run(&Segments { cfg, extra: 1 }, &s, Traffic::RANDOM, Stress::NONE) else { return };
        assert!(
            many.mismatches.iter().any(|m| m.what.starts_with(&format!("no transfer for {STALL_LIMIT} clocks"))),
            "{:?}",
            many.mismatches
        );
    }
}
