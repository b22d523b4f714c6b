//! [`SpecularPlan`]: every width, table geometry and pipeline stage of the specular unit, as
//! data, so the generator, the manifest and the model read one definition.
//!
//! Sizing. Each table samples `cos^k` uniformly over `[0, end_k)`, `end_k` being where
//! `cos^k` falls to 0.0049: past it the unit outputs 0, which SPEC §4 allows outside the
//! epicentre (`approx <= 0.005 C`). Entry `i` holds the midrange of `cos^k` over its bin
//! (the constant with the least worst-case error on a monotone curve). A table needs
//! enough entries that the bin error plus word rounding stays inside SPEC §4: tight
//! (0.25% relative) up to the epicentre's edge of its n, loose (0.5% of C) beyond. Uniform
//! steps make the epicentre edge the binding point, so every table ends up with a few
//! hundred entries whatever k is. The word width W and the width of M trade against the
//! entry count; the plan takes the pair with the fewest ROM bits (BRDF plus n-table).
//!
//! Tables are packed back to back (`base[sel] + idx`) instead of on one-hot or binary
//! top address bits, so no entry is wasted on padding to a power of two.
//!
//! Every plan is checked exhaustively before it is returned ([`SpecularPlan::verify`]):
//! for every valid n and every ROM bin, the exact range of `theta` codes the integer
//! datapath maps to that bin is computed, and the SPEC §4 bound is checked at its ends
//! (the error of a constant against a monotone curve peaks at an end). The check is made
//! C-independent: `|q - f| <= tol(f) + 1.5/65535` covers every C because the output
//! rounding adds at most 0.5/256 and C < 256. A table that fails grows by 0.5% and is
//! checked again.

use super::contract::{INSIDE_REL, K_MAX, NK_DEPTH, N_MIN, OUTSIDE_REL, THETA_FRAC};
use super::decoder::{Decoder, DecoderError, KRange, KSetError};
use super::reference::{cos_k, epicentre_arg, epicentre_code};
use crate::pipeline::{PipeReg, PipeStage, Pipeline};
use crate::rom::{addr_bits, Rom};
use serde::{Deserialize, Serialize};
use std::ops::RangeInclusive;

/// Bits of |theta| below 2^-20 rad never reach the multiplier: 2^-20 rad is under 1% of a
/// table step even at n = 1000, and it keeps the multiplier's theta side at 24 bits.
pub const THETA_DROP: u32 = 8;
/// Widths of M in the n-table word the sizing considers. Fewer bits shrink the n-table
/// and the multiplier but move the index, which the BRDF tables pay for in entries.
pub const NK_MANT_RANGE: RangeInclusive<u32> = 12..=18;
/// `cos^k` value at which every table ends.
pub const TABLE_END: f64 = 0.0049;
/// BRDF word widths the sizing considers.
pub const WORD_BITS_RANGE: RangeInclusive<u32> = 8..=16;
/// Longest table the sizing allows: beyond this the word width, not the step, is wrong.
pub const MAX_TABLE_LEN: u32 = 1 << 14;
/// Share of the SPEC §4 tolerance the analytic sizing spends; the rest covers what its
/// first-order model ignores (curvature, the dropped theta bits). The exhaustive check
/// has the last word either way.
const SIZE_MARGIN: f64 = 0.97;
/// The absolute part of SPEC §4 left after the 0.5/256 output rounding, per unit of C at
/// the largest C (65535/256): `(2/256 - 0.5/256) / (65535/256)`.
pub(super) const C_ABS_SLACK: f64 = 1.5 / 65535.0;

/// One BRDF table.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TablePlan {
    pub k: u32,
    /// First BRDF ROM address of the table.
    pub base: u32,
    /// Entries; `idx >= len` outputs 0.
    pub len: u32,
    /// Argument (rad) covered by one entry; entry i covers `[i*step, (i+1)*step)`.
    pub step: f64,
    /// `idx = (mag * M) >> shift`.
    pub shift: u32,
    /// Largest `sqrt(n/k) * epicentre(n)` among the table's n: where the tight tolerance ends.
    pub epicentre_arg: f64,
}

impl TablePlan {
    /// The argument where the table ends (and the output drops to 0).
    pub fn end_arg(&self) -> f64 {
        self.len as f64 * self.step
    }
}

/// Where an exhaustive check found a table short of SPEC §4.
#[derive(Clone, Debug, PartialEq)]
pub struct TableFailure {
    pub table: usize,
    pub n: u32,
    /// |theta| code (Q3.28) of the failing point.
    pub code: u64,
    pub inside: bool,
    /// `cos^k` there and the table value `(w+1)/2^W` the unit uses.
    pub curve: f64,
    pub table_value: f64,
}

/// The whole specular unit configuration.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpecularPlan {
    pub decoder: Decoder,
    pub tables: Vec<TablePlan>,
    /// BRDF word width W; word w stands for `(w+1)/2^W`.
    pub word_bits: u32,
    /// |theta| is shifted right by this before the multiplier.
    pub theta_drop: u32,
    /// Width of `mag = |theta| >> theta_drop` (|theta| <= 2^31 needs 32 bits before).
    pub mag_bits: u32,
    /// Width of M.
    pub nk_mant_bits: u32,
    /// Width of the table select in the n-table word.
    pub sel_bits: u32,
    /// Register stages added for clock rate (`--pipeline`): they change when, not what.
    #[serde(default)]
    pub pipeline: Pipeline,
}

/// Everything a generator or manifest needs about a plan, derived values included, flat.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpecularGeometry {
    pub ks: Vec<u32>,
    pub k_ranges: Vec<KRange>,
    pub tables: Vec<TablePlan>,
    pub brdf_word_bits: u32,
    pub brdf_depth: u32,
    pub brdf_addr_bits: u32,
    pub brdf_bits: u64,
    pub index_bits: u32,
    pub nk_depth: u32,
    pub nk_width: u32,
    pub nk_mant_bits: u32,
    pub nk_sel_bits: u32,
    pub nk_bits: u64,
    pub theta_drop: u32,
    pub mag_bits: u32,
    pub mag_frac: u32,
    pub prod_bits: u32,
    pub latency: u32,
    pub stages: Vec<PipeStage>,
    /// Worst f64 approximation error inside an epicentre, and its n.
    pub approx_error: (f64, u32),
}

/// Where `cos^k` reaches [`TABLE_END`].
pub fn table_end(k: u32) -> f64 {
    TABLE_END.powf(1.0 / k as f64).acos()
}

/// Entries a uniform table of `cos^k` needs, from first-order error estimates within
/// `SIZE_MARGIN` of SPEC §4: bin error `|f'| step / 2`, word rounding `2^-(W+1)`, and the
/// index error from rounding M (relative `m_err`, moving the argument by `m_err * x`).
/// Checked on a grid that includes the epicentre edge and the inflection point. `None` if
/// the word or M is too narrow for the tolerance at all.
pub(super) fn analytic_len(k: u32, epicentre_arg: f64, word_bits: u32, m_err: f64) -> Option<u32> {
    let end = table_end(k);
    let word_err = 0.5 / (1u64 << word_bits) as f64;
    let inflection = if k > 1 { (1.0 / ((k - 1) as f64).sqrt()).atan() } else { end };
    let grid = (0..=256).map(|i| end * i as f64 / 256.0);
    let mut step = f64::INFINITY;
    for x in grid.chain([epicentre_arg.min(end), inflection.min(end)]) {
        let f = cos_k(k, x);
        let slope = k as f64 * x.cos().powi(k as i32 - 1) * x.sin();
        let tol = if x <= epicentre_arg { INSIDE_REL * f } else { OUTSIDE_REL };
        let budget = SIZE_MARGIN * tol - word_err - slope * x * m_err;
        if budget <= 0.0 {
            return None;
        }
        if slope > 0.0 {
            step = step.min(2.0 * budget / slope);
        }
    }
    let len = (end / step).ceil() as u32;
    (len <= MAX_TABLE_LEN).then_some(len.max(2))
}

/// Why no plan meets SPEC §4 for a table set (or the set itself is wrong).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PlanError {
    #[error(transparent)]
    Decoder(#[from] DecoderError),
    #[error("BRDF word width {0} is outside {WORD_BITS_RANGE:?}")]
    WordBits(u32),
    #[error("no BRDF word width can meet SPEC §4")]
    NoWordWidth,
    #[error("table k = {k} cannot meet SPEC §4 with {word_bits}-bit words and {m_bits}-bit M")]
    Table { k: u32, word_bits: u32, m_bits: u32 },
    #[error("table k = {k} needs more than {m_bits} bits of M")]
    Mantissa { k: u32, m_bits: u32 },
    /// `--brdf-k auto` with a target that is no positive fraction.
    #[error("error target {0} must be positive")]
    AutoTarget(f64),
    /// `--brdf-k auto`: no set of at most `max_tables` tables (the search's limit) is that
    /// accurate.
    #[error(
        "no set of at most {max_tables} BRDF tables (k in 1..{K_MAX}) keeps the epicentre error within {:.3}%; \
         the best reachable is {:.3}% with k = {best_ks:?}",
        max_err * 100.0,
        best * 100.0
    )]
    Unreachable { max_tables: usize, max_err: f64, best: f64, best_ks: Vec<u32> },
}

impl From<KSetError> for PlanError {
    fn from(e: KSetError) -> PlanError {
        PlanError::Decoder(e.into())
    }
}

impl SpecularPlan {
    /// The default: the patent's k-set and ranges.
    pub fn patent() -> SpecularPlan {
        SpecularPlan::build(Decoder::patent(), None).expect("the patent configuration always fits")
    }

    /// `--brdf-k LIST`: each n on its least-error table.
    pub fn from_k_set(ks: &[u32]) -> Result<SpecularPlan, PlanError> {
        SpecularPlan::build(Decoder::least_error(ks)?, None)
    }

    /// Sizes, packs and verifies the tables for a decoder. `word_bits = None` lets the
    /// sizing pick W; W and the width of M are chosen for the fewest ROM bits (BRDF plus
    /// n-table).
    pub fn build(decoder: Decoder, word_bits: Option<u32>) -> Result<SpecularPlan, PlanError> {
        if let Some(w) = word_bits {
            if !WORD_BITS_RANGE.contains(&w) {
                return Err(PlanError::WordBits(w));
            }
        }
        let sel_bits = addr_bits(decoder.tables());
        // Per table: the largest epicentre argument, and the spread of sqrt(n) over its n,
        // which sets how small its smallest M gets.
        let shape: Vec<(f64, f64)> = (0..decoder.tables())
            .map(|t| {
                let k = decoder.ks()[t];
                let x = decoder.ns_of(t).map(|n| epicentre_arg(n, k)).fold(0.0, f64::max);
                let (lo, hi) = (decoder.ns_of(t).next().unwrap_or(1), decoder.ns_of(t).last().unwrap_or(1));
                (x, (hi as f64 / lo as f64).sqrt())
            })
            .collect();
        let mut candidates: Vec<(u64, u32, u32, Vec<u32>)> = Vec::new();
        for w in word_bits.map_or(WORD_BITS_RANGE, |w| w..=w) {
            for nw in NK_MANT_RANGE {
                let lens: Option<Vec<u32>> =
                    decoder.ks().iter().zip(&shape).map(|(&k, &(x, spread))| analytic_len(k, x, w, spread / (1u64 << nw) as f64)).collect();
                if let Some(l) = lens {
                    let bits = w as u64 * l.iter().map(|&l| l as u64).sum::<u64>() + NK_DEPTH as u64 * (sel_bits + nw) as u64;
                    candidates.push((bits, w, nw, l));
                }
            }
        }
        // Fewest bits first; on a tie the wider words (more accuracy for the same bits).
        candidates.sort_by_key(|&(bits, w, nw, _)| (bits, std::cmp::Reverse((w, nw))));
        let mut best: Option<SpecularPlan> = None;
        let mut last_err = PlanError::NoWordWidth;
        for (estimate, w, nw, lens) in candidates {
            if best.as_ref().is_some_and(|b| b.rom_bits() <= estimate) {
                break;
            }
            let x: Vec<f64> = shape.iter().map(|s| s.0).collect();
            match SpecularPlan::fit(&decoder, &x, w, nw, &lens) {
                Ok(p) if best.as_ref().is_none_or(|b| p.rom_bits() < b.rom_bits()) => best = Some(p),
                Ok(_) => {}
                Err(e) => last_err = e,
            }
        }
        best.ok_or(last_err)
    }

    /// Grows each table from its estimate until the exhaustive check passes.
    fn fit(decoder: &Decoder, x_epi: &[f64], w: u32, nw: u32, lens: &[u32]) -> Result<SpecularPlan, PlanError> {
        let tables = decoder
            .ks()
            .iter()
            .zip(x_epi)
            .zip(lens)
            .map(|((&k, &x), &len)| TablePlan { k, base: 0, len, step: 0.0, shift: 0, epicentre_arg: x })
            .collect();
        let mut plan = SpecularPlan {
            decoder: decoder.clone(),
            tables,
            word_bits: w,
            theta_drop: THETA_DROP,
            mag_bits: 32 - THETA_DROP,
            nk_mant_bits: nw,
            sel_bits: addr_bits(decoder.tables()),
            pipeline: Pipeline::NONE,
        };
        // An index, not an iterator: the loop resizes `plan`'s tables as it goes.
        #[allow(clippy::needless_range_loop)]
        for t in 0..plan.tables.len() {
            loop {
                plan.resize(t, plan.tables[t].len)?;
                if plan.check_table(t).is_ok() {
                    break;
                }
                let len = plan.tables[t].len;
                // Far past the estimate, more entries are not what is missing (M or W is).
                if len >= MAX_TABLE_LEN || len > 2 * lens[t] {
                    return Err(PlanError::Table { k: plan.tables[t].k, word_bits: w, m_bits: nw });
                }
                plan.tables[t].len = (len + len.div_ceil(200)).min(MAX_TABLE_LEN);
            }
        }
        let mut base = 0;
        for t in &mut plan.tables {
            t.base = base;
            base += t.len;
        }
        Ok(plan)
    }

    /// Sets table t to `len` entries over `[0, table_end(k))` and picks the largest shift
    /// that keeps every M of the table within `nk_mant_bits`.
    fn resize(&mut self, t: usize, len: u32) -> Result<(), PlanError> {
        let k = self.tables[t].k;
        let step = table_end(k) / len as f64;
        self.tables[t].len = len;
        self.tables[t].step = step;
        let n_top = self.decoder.ns_of(t).last().unwrap_or(N_MIN);
        let limit = 1u64 << self.nk_mant_bits;
        let mut shift = ((limit - 1) as f64 / self.m_scale(t, n_top)).log2().floor() as i32 + 1;
        loop {
            shift -= 1;
            if shift < 0 {
                return Err(PlanError::Mantissa { k, m_bits: self.nk_mant_bits });
            }
            self.tables[t].shift = shift as u32;
            if self.m_in_table(t, n_top) < limit {
                return Ok(());
            }
        }
    }

    /// Table index per unit of `mag` for n on table t, before the 2^shift scaling.
    fn m_scale(&self, t: usize, n: u32) -> f64 {
        let tb = &self.tables[t];
        (n as f64 / tb.k as f64).sqrt() / tb.step / (1u64 << self.mag_frac()) as f64
    }

    fn m_in_table(&self, t: usize, n: u32) -> u64 {
        (self.m_scale(t, n) * (1u64 << self.tables[t].shift) as f64).round().max(1.0) as u64
    }

    /// Fraction bits of `mag`.
    pub fn mag_frac(&self) -> u32 {
        THETA_FRAC - self.theta_drop
    }
    /// M of n: `round(sqrt(n/k) / step * 2^(shift - mag_frac))`, at least 1; 0 for invalid n.
    pub fn m_of(&self, n: u32) -> u64 {
        self.decoder.table_of(n).map_or(0, |t| self.m_in_table(t, n))
    }
    /// n-table word: `{sel, M}`, sel in the top `sel_bits`. 0 (M = 0) marks an invalid n.
    pub fn nk_word(&self, n: u32) -> u64 {
        self.decoder.table_of(n).map_or(0, |t| (t as u64) << self.nk_mant_bits | self.m_in_table(t, n))
    }
    pub fn nk_width(&self) -> u32 {
        self.sel_bits + self.nk_mant_bits
    }
    pub fn nk_bits(&self) -> u64 {
        NK_DEPTH as u64 * self.nk_width() as u64
    }

    /// Midrange of `cos^k` over entry i's bin.
    pub fn brdf_value(&self, t: usize, i: u32) -> f64 {
        let tb = &self.tables[t];
        (cos_k(tb.k, i as f64 * tb.step) + cos_k(tb.k, (i + 1) as f64 * tb.step)) / 2.0
    }
    /// BRDF word: `round(v * 2^W) - 1` clamped to the word, so that `(w+1)/2^W` is v rounded
    /// to the nearest 2^-W and 1.0 fits in W bits. Non-increasing in i, like the curve.
    pub fn brdf_word(&self, t: usize, i: u32) -> u64 {
        let one = 1u64 << self.word_bits;
        let v = (self.brdf_value(t, i) * one as f64).round() as u64;
        v.clamp(1, one) - 1
    }
    pub fn brdf_depth(&self) -> u32 {
        self.tables.iter().map(|t| t.len).sum()
    }
    /// The BRDF ROM image: the tables packed back to back, table `t` at `base_t..base_t+len_t`,
    /// each word [`SpecularPlan::brdf_word`], so the sizing checks and this image agree by
    /// construction. The model looks its answers up in these words and every exporter writes
    /// them, so the RTL, the model and the files cannot drift apart.
    pub fn brdf_rom(&self) -> Rom {
        let mut words = Vec::with_capacity(self.brdf_depth() as usize);
        for (t, table) in self.tables.iter().enumerate() {
            debug_assert_eq!(words.len() as u32, table.base);
            words.extend((0..table.len).map(|i| self.brdf_word(t, i)));
        }
        Rom::new("specular_brdf_rom", self.word_bits, words)
    }
    /// The n-table ROM image: address `n`, word `{sel, M}` ([`SpecularPlan::nk_word`]); every n
    /// outside 1..=1000 holds 0, the invalid-n code.
    pub fn nk_rom(&self) -> Rom {
        let words = (0..NK_DEPTH as u32).map(|n| self.nk_word(n)).collect();
        Rom::new("specular_nk_rom", self.nk_width(), words)
    }
    pub fn brdf_bits(&self) -> u64 {
        self.brdf_depth() as u64 * self.word_bits as u64
    }
    /// Both ROMs: what the sizing minimises.
    pub fn rom_bits(&self) -> u64 {
        self.brdf_bits() + self.nk_bits()
    }
    pub fn brdf_addr_bits(&self) -> u32 {
        addr_bits(self.brdf_depth() as usize)
    }
    /// Width of the in-table index once `idx < len[sel]` is known.
    pub fn index_bits(&self) -> u32 {
        addr_bits(self.tables.iter().map(|t| t.len).max().unwrap_or(1) as usize)
    }
    /// Full width of `mag * M`; the range cut compares all of it.
    pub fn prod_bits(&self) -> u32 {
        self.mag_bits + self.nk_mant_bits
    }
    /// Low product bits no table's index reaches (the smallest table shift): stage 2 registers
    /// only the `prod_bits() - prod_drop()` bits above them.
    pub fn prod_drop(&self) -> u32 {
        self.tables.iter().map(|t| t.shift).min().unwrap_or(0)
    }

    /// This plan with the register stages of `pipeline`.
    pub fn with_pipeline(self, pipeline: Pipeline) -> SpecularPlan {
        SpecularPlan { pipeline, ..self }
    }

    /// Multiplier operand bits per partial product when the multiplies are split in two stages
    /// (`Pipeline::split_multiplies`): each partial is a small multiply, their sum a short tree.
    pub const MUL_CHUNK: u32 = 4;

    /// A span transferred in clock t has its first pixel valid in clock t + latency: one clock
    /// per register stage (the same convention as the segment shader's).
    pub fn latency(&self) -> u32 {
        self.stages().len() as u32
    }

    /// The register stages, in order. Stage 0 is the accumulator; a stall (out_ready low with
    /// a valid output) holds every stage, ROM output registers included.
    pub fn stages(&self) -> Vec<PipeStage> {
        let reg = |name: &str, bits: u32, format: &str| PipeReg { name: name.into(), bits, format: format.into() };
        let (w, drop) = (self.word_bits, self.theta_drop);
        let split = self.pipeline.split_multiplies();
        let chunks = |bits: u32| bits.div_ceil(Self::MUL_CHUNK);
        let mut body = vec![
            (
                "issue",
                "theta <= accept ? in_theta0 : theta + dtheta (32-bit wrap); \
                 span registers hold C, n, dtheta and the pixel down-counter"
                    .to_string(),
                vec![reg("theta", 32, "sQ3.28"), reg("n", 10, "uint")],
            ),
            (
                "abs_nk",
                format!("mag = |theta| >> {drop} (|-2^31| = 2^31 exact); n-table ROM registered read at n"),
                vec![reg("mag", self.mag_bits, &format!("UQ3.{}", self.mag_frac())), reg("nk", self.nk_width(), "{sel, M}")],
            ),
        ];
        let (mc, cc) = (chunks(self.nk_mant_bits), chunks(w));
        let how = if self.pipeline.logic_products() { " in shifts and adds" } else { "" };
        if split {
            body.push((
                "nk_q",
                "mag and the n-table word registered off the ROM's output".to_string(),
                vec![reg("mag", self.mag_bits, &format!("UQ3.{}", self.mag_frac())), reg("nk", self.nk_width(), "{sel, M}")],
            ));
            body.push((
                "arg_part",
                format!("pp_k = mag * M[4k +: 4], k < {mc}{how}; err = (M == 0)"),
                vec![
                    reg("pp", mc * (self.mag_bits + Self::MUL_CHUNK), &format!("{mc} x uint")),
                    reg("sel", self.sel_bits, "uint"),
                    reg("err", 1, "flag"),
                ],
            ));
        }
        body.push((
            "arg_mul",
            if split {
                "prod = sum_k pp_k << 4k (a balanced tree)".to_string()
            } else {
                "prod = mag * M (unsigned); err = (M == 0)".to_string()
            },
            vec![
                reg("prod", self.prod_bits() - self.prod_drop(), &format!("uint, prod >> {}", self.prod_drop())),
                reg("sel", self.sel_bits, "uint"),
                reg("err", 1, "flag"),
            ],
        ));
        let index = "idx = prod >> shift[sel]; cut = err | (idx >= len[sel])";
        if split {
            body.push((
                "brdf_addr",
                format!("{index}; addr = base[sel] + idx"),
                vec![reg("addr", self.brdf_addr_bits(), "uint"), reg("cut", 1, "flag"), reg("err", 1, "flag")],
            ));
            body.push((
                "brdf",
                "BRDF ROM registered read at addr".to_string(),
                vec![reg("w", w, &format!("(w+1)/2^{w}")), reg("cut", 1, "flag"), reg("err", 1, "flag")],
            ));
            body.push((
                "brdf_q",
                "w registered off the ROM's output, whose clock-to-out then stays out of the multiply".to_string(),
                vec![reg("w", w, &format!("(w+1)/2^{w}")), reg("cut", 1, "flag"), reg("err", 1, "flag")],
            ));
            body.push((
                "c_part",
                format!("cp_k = C * w[4k +: 4], k < {cc}{how} (C * (w + 1) = C * w + C)"),
                vec![reg("cp", cc * (16 + Self::MUL_CHUNK), &format!("{cc} x uint")), reg("cut", 1, "flag"), reg("err", 1, "flag")],
            ));
        } else {
            body.push((
                "brdf",
                format!("{index}; BRDF ROM registered read at base[sel] + idx"),
                vec![reg("w", w, &format!("(w+1)/2^{w}")), reg("cut", 1, "flag"), reg("err", 1, "flag")],
            ));
        }
        body.push((
            "c_mul",
            if split {
                format!("out_spec = cut ? 0 : (sum_k cp_k << 4k + C + 2^{}) >> {w}", w - 1)
            } else {
                format!("out_spec = cut ? 0 : (C * (w + 1) + 2^{}) >> {w}", w - 1)
            },
            vec![reg("out_spec", 16, "UQ8.8"), reg("out_err", 1, "flag")],
        ));
        let last = body.len() - 1;
        body.into_iter()
            .enumerate()
            .map(|(i, (name, logic, mut regs))| {
                // Each pixel carries its C and stream flags down the pipe with it.
                if i < last {
                    regs.extend([reg("c", 16, "UQ8.8"), reg("last", 1, "flag"), reg("valid", 1, "flag")]);
                } else {
                    regs.extend([reg("out_last", 1, "flag"), reg("out_valid", 1, "flag")]);
                }
                PipeStage { stage: i as u32, name: name.into(), logic, regs }
            })
            .collect()
    }

    pub fn geometry(&self) -> SpecularGeometry {
        SpecularGeometry {
            ks: self.decoder.ks().to_vec(),
            k_ranges: self.decoder.ranges(),
            tables: self.tables.clone(),
            brdf_word_bits: self.word_bits,
            brdf_depth: self.brdf_depth(),
            brdf_addr_bits: self.brdf_addr_bits(),
            brdf_bits: self.brdf_bits(),
            index_bits: self.index_bits(),
            nk_depth: NK_DEPTH as u32,
            nk_width: self.nk_width(),
            nk_mant_bits: self.nk_mant_bits,
            nk_sel_bits: self.sel_bits,
            nk_bits: self.nk_bits(),
            theta_drop: self.theta_drop,
            mag_bits: self.mag_bits,
            mag_frac: self.mag_frac(),
            prod_bits: self.prod_bits(),
            latency: self.latency(),
            stages: self.stages(),
            approx_error: self.decoder.max_error(),
        }
    }

    /// Exhaustive SPEC §4 check of every table (see the module comment).
    pub fn verify(&self) -> Result<(), TableFailure> {
        (0..self.tables.len()).try_for_each(|t| self.check_table(t))
    }

    /// The `|theta|` codes (Q3.28 magnitudes, 0..=2^31) split into the runs the datapath maps
    /// to one output: `(lo, hi, Some(i))` for ROM entry i of n's table, then `(lo, 2^31, None)`
    /// for the cut to 0, if any code reaches it. Empty for an invalid n.
    pub fn segments(&self, n: u32) -> Vec<(u64, u64, Option<u32>)> {
        let Some(t) = self.decoder.table_of(n) else { return Vec::new() };
        let (m, s, len) = (self.m_in_table(t, n), self.tables[t].shift, self.tables[t].len);
        let max_code = 1u64 << 31;
        // mag = code >> drop lands in entry i from mag = ceil(i << s / m) on.
        let first_code = |i: u64| ((i << s).div_ceil(m)) << self.theta_drop;
        let mut out = Vec::with_capacity(len as usize + 1);
        let mut lo = 0u64;
        for i in 0..len {
            let next = first_code(i as u64 + 1);
            if next > lo {
                out.push((lo, (next - 1).min(max_code), Some(i)));
            }
            lo = next;
            if lo > max_code {
                return out;
            }
        }
        out.push((lo, max_code, None));
        out
    }

    fn check_table(&self, t: usize) -> Result<(), TableFailure> {
        let tb = &self.tables[t];
        let one = (1u64 << self.word_bits) as f64;
        let q: Vec<f64> = (0..tb.len).map(|i| (self.brdf_word(t, i) + 1) as f64 / one).collect();
        for n in self.decoder.ns_of(t) {
            let per_code = (n as f64 / tb.k as f64).sqrt() / (1u64 << THETA_FRAC) as f64;
            let edge = epicentre_code(n) as u64;
            let ok = |code: u64, q: f64| {
                let f = cos_k(tb.k, per_code * code as f64);
                let inside = code <= edge;
                let tol = if inside { INSIDE_REL * f } else { OUTSIDE_REL };
                if (q - f).abs() <= tol + C_ABS_SLACK {
                    Ok(())
                } else {
                    Err(TableFailure { table: t, n, code, inside, curve: f, table_value: q })
                }
            };
            for (lo, hi, i) in self.segments(n) {
                let q = i.map_or(0.0, |i| q[i as usize]);
                ok(lo, q)?;
                ok(hi, q)?;
                if lo <= edge && edge < hi {
                    ok(edge, q)?;
                    ok(edge + 1, q)?;
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn specular_plan_default_geometry() {
        let p = SpecularPlan::patent();
        // SPEC's budget is 64 Kbit; the packed tables need about half.
        assert!(p.brdf_bits() <= 36 * 1024, "{} bits", p.brdf_bits());
        assert_eq!(p.tables.iter().map(|t| t.k).collect::<Vec<_>>(), [1, 2, 4, 16]);
        assert_eq!((p.mag_bits, p.sel_bits), (24, 2));
        // The figures quoted in the specular module's diagram.
        assert_eq!((p.word_bits, p.nk_mant_bits), (12, 16));
        assert_eq!(p.prod_bits(), 24 + p.nk_mant_bits);
        assert_eq!(p.nk_width(), 2 + p.nk_mant_bits);
        let nw = p.nk_mant_bits;
        assert_eq!(p.latency(), 5);
        assert_eq!(p.stages().len(), 5);
        // `--pipeline 1`: both multiplies split in two stages, the BRDF address and word registered.
        let split = p.clone().with_pipeline(crate::pipeline::Pipeline::at(1));
        let names: Vec<String> = split.stages().into_iter().map(|s| s.name).collect();
        assert_eq!(names, ["issue", "abs_nk", "nk_q", "arg_part", "arg_mul", "brdf_addr", "brdf", "brdf_q", "c_part", "c_mul"]);
        assert_eq!(split.latency(), 10);
        assert_eq!(split.clone().with_pipeline(crate::pipeline::Pipeline::at(2)).latency(), 10, "level 2 adds nothing to the unit");
        for (t, tb) in p.tables.iter().enumerate() {
            assert!(tb.end_arg() < std::f64::consts::FRAC_PI_2);
            assert!(cos_k(tb.k, tb.end_arg()) <= TABLE_END * 1.0001);
            // M uses its width: the shift normalises each table's largest M.
            let ms: Vec<u64> = p.decoder.ns_of(t).map(|n| p.m_of(n)).collect();
            assert!(ms.iter().all(|&m| m < 1 << nw) && *ms.iter().max().unwrap() >= 1 << (nw - 1));
            assert!(*ms.iter().min().unwrap() >= 1 << (nw - 5), "table {t}: {ms:?}");
        }
        for n in [0u32, 1001, 1023] {
            assert_eq!(p.nk_word(n), 0);
        }
        assert_eq!(p.nk_word(1) >> nw, 0);
        assert_eq!(p.nk_word(1000) >> nw, 3);
        p.verify().unwrap();
    }

    #[test]
    fn specular_plan_words_are_monotone_and_start_at_one() {
        let p = SpecularPlan::patent();
        for (t, tb) in p.tables.iter().enumerate() {
            let w: Vec<u64> = (0..tb.len).map(|i| p.brdf_word(t, i)).collect();
            assert_eq!(w[0], (1 << p.word_bits) - 1, "entry 0 is 1.0");
            assert!(w.windows(2).all(|x| x[0] >= x[1]), "table {t} not monotone");
        }
    }

    #[test]
    fn specular_plan_any_k_set_builds_and_verifies() {
        for ks in [&[1u32][..], &[64], &[1, 64], &[7, 8], &[2, 3, 5, 8, 13, 21, 34, 55]] {
            let p = SpecularPlan::from_k_set(ks).unwrap();
            p.verify().unwrap();
            assert_eq!(p.decoder.ks(), ks);
        }
    }

    #[test]
    fn specular_plan_verify_catches_a_short_table() {
        let mut p = SpecularPlan::patent();
        let t = 3;
        let len = p.tables[t].len;
        p.resize(t, len * 3 / 4).unwrap();
        let f = p.check_table(t).unwrap_err();
        assert!(f.inside, "the epicentre edge binds first: {f:?}");
        // And a wide enough word width alone does not rescue it.
        assert_eq!(SpecularPlan::build(Decoder::patent(), Some(8)), Err(PlanError::NoWordWidth));
        assert_eq!(SpecularPlan::build(Decoder::patent(), Some(99)), Err(PlanError::WordBits(99)));
        let e = SpecularPlan::from_k_set(&[2, 1]).unwrap_err();
        assert_eq!(e, PlanError::Decoder(KSetError::NotAscending(vec![2, 1]).into()));
        assert_eq!(e.to_string(), "BRDF k set [2, 1] is not strictly ascending", "a k set's message as it is");
    }
}
