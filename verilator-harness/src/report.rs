//! What a co-simulation run found: [`Report`]'s counts and its [`Mismatch`]es. Every unit's
//! driver and checker fill one; nothing here knows a unit or a model.

use crate::waveform::Waveform;
use std::collections::BTreeSet;
use std::fmt;

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

/// Counts of one run; [`Report::absorb`] adds another run's.
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
    /// Side pulses the unit raised (the front-end's guard-band `err`).
    pub pulses: u64,
    /// The waveforms written for failures (COSIM_TRACE, `--trace`: [`crate::waveform`]), each
    /// also named in its mismatch's message.
    pub waveforms: Vec<Waveform>,
}

const KEEP_MISMATCHES: usize = 20;

impl Report {
    /// Adds `other`'s counts and mismatches to this report's (its mismatches after these).
    pub fn absorb(&mut self, other: Report) {
        self.triangles += other.triangles;
        self.spans += other.spans;
        self.segments += other.segments;
        self.pixels += other.pixels;
        self.cycles += other.cycles;
        self.failed.extend(other.failed);
        self.mismatch_count += other.mismatch_count;
        let room = KEEP_MISMATCHES.saturating_sub(self.mismatches.len());
        self.mismatches.extend(other.mismatches.into_iter().take(room));
        self.max_error = self.max_error.max(other.max_error);
        self.resets += other.resets;
        self.cut_spans += other.cut_spans;
        self.pulses += other.pulses;
        self.waveforms.extend(other.waveforms);
    }

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
    let mut msg =
        format!("{what}: {} mismatches (seed {seed}, replay with COSIM_SEED={seed}{})\n", report.mismatch_count, crate::soak::replay_env());
    for m in &report.mismatches {
        msg.push_str(&format!("  {m}\n"));
    }
    panic!("{msg}");
}
