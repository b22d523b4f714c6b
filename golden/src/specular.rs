//! The specular unit (SPEC §1 "Specular unit", §3 `specular_unit`, §4): bit-exact model,
//! its configuration, the host set-up that feeds it and the f64 references it is judged by.
//!
//! Per pixel `j` of a span the unit computes `theta_j = theta0 + j*dtheta` and
//! `out = C * cos^k(sqrt(n/k) * |theta_j|)` with `k = k(n)` from a small set of tables.
//! [`SpecularPlan`] holds every width; with the default plan (W = 12, M 16 bits):
//!
//! ```text
//!  theta_j (sQ3.28) ──|.|──>>8──> mag (UQ3.20, 24 b) ──┐
//!                                                     × ──> prod (40 b) ──>>shift[sel]──> idx ──┬─> BRDF ROM[base[sel]+idx] ─> w
//!  n ──> NK ROM[n] = {sel, M} ─────────────────────> M ┘                 idx >= len[sel] ─> cut
//!  out = cut|err ? 0 : (C * (w + 1) + 2^(W-1)) >> W                       (UQ8.8)
//! ```
//!
//! Every rounding, exactly:
//! * `theta_j`: exact modulo 2^32 (the 32-bit accumulator, [`theta_at`]).
//! * `mag = |theta_j| >> theta_drop`: exact magnitude (2^31 for -2^31), then floor.
//! * `M = round(sqrt(n/k) / step * 2^(shift - mag_frac))`, at least 1 ([`SpecularPlan::m_of`]);
//!   `M = 0` is reserved for an invalid n, which outputs 0 with `out_err = 1`.
//! * `idx = floor(mag * M / 2^shift)`, exact; `idx >= len` outputs 0, which also covers
//!   `arg >= pi/2` since every table ends before it.
//! * BRDF word `w = round(v * 2^W) - 1` for the bin's midrange v; it stands for `(w+1)/2^W`,
//!   so 1.0 fits in W bits ([`SpecularPlan::brdf_word`]).
//! * `out = floor((C * (w + 1) + 2^(W-1)) / 2^W)`: round half up, never above C.
//!
//! `M` folds `sqrt(n/k)` and the table's argument step into one number, so the one
//! argument multiplier yields the ROM index directly.

mod accuracy;
mod auto;
mod contract;
mod decoder;
pub mod geometry;
mod plan;
pub mod reference;
pub mod setup;
mod unit;

// This file only names the unit's parts: the files below import each other, never this one, so
// no import runs in a circle through it (scripts/import-cycles).
pub use crate::pipeline::{PipeReg, PipeStage};
pub use accuracy::{accuracy_of, accuracy_table, AccuracySummary, NAccuracy};
pub use auto::{auto_plan, best_reachable, MAX_AUTO_TABLES};
pub use contract::{n_valid, tolerance, ABS_TOL, C_FRAC, INSIDE_REL, K_MAX, NK_DEPTH, N_BITS, N_MAX, N_MIN, OUTSIDE_REL, THETA_FRAC};
pub use decoder::{check_k_set, parse_rel_error, BrdfK, BrdfKError, Decoder, DecoderError, DecoderRepr, KRange, KSetError, TargetError};
pub use geometry::{SpanEnds, Vec3};
pub use plan::{
    table_end, PlanError, SpecularGeometry, SpecularPlan, TableFailure, TablePlan, NK_MANT_RANGE, TABLE_END, THETA_DROP, WORD_BITS_RANGE,
};
pub use setup::{setup_span, Fallbacks, SpecularSetup};
pub use unit::{span_overflows, theta_at, SpecPixel, SpecularSpan, SpecularUnit};
