//! Register stages for clock rate (`hdl-gen generate --pipeline N`).
//!
//! Pipelining changes no value: at every level each block computes what its golden model says.
//! It changes when a value appears (the latency) and which registers exist. This module states
//! the stage structure once, as data: the generator prints it into each module's header and the
//! manifest, the harness and the throughput models take their latencies from it, and the
//! blocks' plans ([`crate::segment::stages`], [`crate::specular::SpecularPlan::stages`]) are built
//! from it.
//!
//! Every stage of every block moves on one stall signal (the output register is free), so a
//! stall holds every stage and the throughput is the same at every level: one segment or pixel
//! per clock, no bubble between spans.

use crate::frontend::I0Form;
use serde::{Deserialize, Serialize};

/// One register of a pipeline stage.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct PipeReg {
    pub name: String,
    pub bits: u32,
    pub format: String,
}

impl PipeReg {
    pub fn new(name: &str, bits: u32, format: &str) -> PipeReg {
        PipeReg { name: name.into(), bits, format: format.into() }
    }
}

/// One register stage: the logic in front of it and what it holds.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct PipeStage {
    pub stage: u32,
    pub name: String,
    pub logic: String,
    pub regs: Vec<PipeReg>,
}

/// Numbers `(name, logic, regs)` in order: stage i is register stage i from the input.
pub fn numbered(body: Vec<(&str, String, Vec<PipeReg>)>) -> Vec<PipeStage> {
    body.into_iter().enumerate().map(|(i, (name, logic, regs))| PipeStage { stage: i as u32, name: name.into(), logic, regs }).collect()
}

/// How many register stages the generator adds for clock rate, the same level for every block:
///
/// | level | segment shader | specular unit | front-end set-up |
/// |--:|---|---|---|
/// | 0 | as SPEC's seed: 2 stages | 5 stages | CALC in one clock |
/// | 1 | + a span register; the BFPI's multiples and the last-segment flag registered | + both multiplies split into registered 4-bit partial products and their sum; the BRDF address registered before the ROM, both ROMs' words registered before any arithmetic: 10 stages | CALC in five clocks ([`SETUP_STAGES`]), overlapped with the dividers; the span path in eight ([`I0_STAGES`]) instead of two, behind the walker's row registered and its span's ends registered ([`Pipeline::row_stages`], the reciprocal `I0`) |
/// | 2 | + the lane sums registered before round and clamp | as level 1, the partial products in shift-and-add logic instead of `*` (no multiplier; [`Pipeline::logic_products`]) | as level 1 |
/// | 3 | + no clock with two adders in a row: the BFPI's first adder level formed as the span enters its register, the rest when it starts; each lane's sum split at the binary point (high part and the fraction's carry registered, joined before the clamp) | as level 2 | as level 1 |
///
/// Level 0 is the default: the smallest circuit and the shortest latency, for the shader and
/// the specular unit byte for byte the RTL every earlier release generated (the front-end's is
/// the staged description with no register between its steps). `docs/fpga.md` gives each
/// level's area and Fmax.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(try_from = "u32", into = "u32")]
pub struct Pipeline(u32);

/// A pipeline level above [`Pipeline::MAX`] (a manifest's `parameters.pipeline`, say).
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("pipeline level {0} is above the deepest, {max}", max = Pipeline::MAX)]
pub struct PipelineError(pub u32);

impl TryFrom<u32> for Pipeline {
    type Error = PipelineError;
    fn try_from(level: u32) -> Result<Pipeline, PipelineError> {
        Pipeline::new(level).ok_or(PipelineError(level))
    }
}

impl From<Pipeline> for u32 {
    fn from(p: Pipeline) -> u32 {
        p.0
    }
}

impl Pipeline {
    /// The deepest level.
    pub const MAX: u32 = 3;
    /// SPEC's seed structure, no added stage.
    pub const NONE: Pipeline = Pipeline(0);

    /// Level `level`; panics above [`Pipeline::MAX`] (for constants and generated tables).
    pub const fn at(level: u32) -> Pipeline {
        assert!(level <= Self::MAX, "pipeline level above Pipeline::MAX");
        Pipeline(level)
    }

    /// Level `level`, or `None` above [`Pipeline::MAX`].
    pub fn new(level: u32) -> Option<Pipeline> {
        (level <= Self::MAX).then_some(Pipeline(level))
    }

    pub fn level(self) -> u32 {
        self.0
    }

    /// Every level, shallowest first.
    pub fn all() -> impl Iterator<Item = Pipeline> {
        (0..=Self::MAX).map(Pipeline)
    }

    /// Segment shader: the span waits in its own register, and the increments (the BFPI's
    /// multiples of dI) and the last-segment flag are registered when the span starts, so the
    /// lanes' path begins at a register instead of behind the BFPI's adders.
    pub fn span_stage(self) -> bool {
        self.0 >= 1
    }

    /// Segment shader: the lane sums are registered between the add and the round/clamp.
    pub fn sum_stage(self) -> bool {
        self.0 >= 2
    }

    /// Segment shader: the same stages as level 2, with the adders cut so that no clock has two
    /// in a row (the span register holds the BFPI's first-level values, formed from the input's
    /// dI; the sum register holds each lane's high part and the carry out of its fraction bits).
    /// Level 2's limits were the BFPI's two adder levels (p >= 16) and the full-width lane add
    /// behind the accumulator's fan-out (p = 8).
    pub fn split_adds(self) -> bool {
        self.0 >= 3
    }

    /// Specular unit: the argument and C multiplies each become registered partial products
    /// (small multiplies by 4-bit slices) and a registered sum, the BRDF address (the table
    /// select's mux after the per-table index arithmetic) is registered before the ROM read,
    /// and each ROM's word is registered before any arithmetic (a block RAM's clock-to-out is
    /// long).
    pub fn split_multiplies(self) -> bool {
        self.0 >= 1
    }

    /// Specular unit: each split multiply's partial products written as shifts and adds (a
    /// balanced tree of the 4-bit slice's masked, shifted operands) instead of `*`, so that
    /// synthesis builds them in logic and not on the device's multipliers. On the ECP5-25F
    /// beside the chain, the level-1 form took 11 of the 28 MULT18X18D, and routing to the last
    /// free ones stretched its partial products to 13.8 ns (docs/fpga.md); logic places next
    /// to its registers. Same registers and latency as level 1.
    pub fn logic_products(self) -> bool {
        self.0 >= 2
    }

    /// Front-end: the set-up's CALC (area, orientation, rows, edge and plane terms, the
    /// dividers' operands) as [`SETUP_STAGES`] register stages instead of one clock. The stages
    /// form a queue in front of the dividers, so the next triangle's CALC overlaps the current
    /// one's division: the set-up's rate is unchanged and only the latency grows.
    pub fn calc_clocks(self) -> u32 {
        if self.0 >= 1 {
            SETUP_STAGES.len() as u32
        } else {
            1
        }
    }

    /// Front-end: the walker's row registered ([`ROW_STAGES`]) before the row's span is decided
    /// (the three edges' bounds compared, the pixel test, the span's ends), so the walker's
    /// clock is its edges' DDA and their bounds alone: no change of rate (the stages move on the
    /// one stall like every other), a clock of latency per stage. Not with the incremental `I0`,
    /// whose walker waits on the row's own span (a source's start), decided in the walker's
    /// clock.
    pub fn row_stage(self, i0: I0Form) -> bool {
        self.row_stages(i0) > 0
    }

    /// The row stages' count ([`Pipeline::row_stage`]): 0, or [`ROW_STAGES`]' two, the span's
    /// ends (the edges' pairwise compares and selects) registered before the pixel test and
    /// the span's start and length (they were one clock, 13.7 ns on the ECP5-25F; docs/fpga.md).
    pub fn row_stages(self, i0: I0Form) -> u32 {
        if self.0 >= 1 && i0 == I0Form::Reciprocal {
            ROW_STAGES.len() as u32
        } else {
            0
        }
    }
}

/// What the front-end's row stages ([`Pipeline::row_stages`]) hold, between the walker and the
/// span path's first logical stage ([`I0_STAGES`]), in order.
pub const ROW_STAGES: [&str; 2] = [
    "the walker's row: each edge's bound on it, clipped to the screen, with the row's sums",
    "the row's span ends: the least left-edge bound and the least right bound (the edges compared pairwise, then selected), with the row's sums",
];

/// The front-end's spans from the walker to the output, in logical stages: which boundaries
/// between them are registered. SPEC's seed structure (level 0) registers two, after `S2n` and
/// after the quotient estimate; from level 1 every one is, so each clock has one multiply, or
/// the adders joining a product's partial products, or two adders at most ([`I0_STAGES`]).
pub fn i0_registers(level: Pipeline) -> [bool; I0_STAGES.len() - 1] {
    if level.0 >= 1 {
        [true; I0_STAGES.len() - 1]
    } else {
        [false, false, false, true, false, true, false, false]
    }
}

/// The front-end's span path in logical stages, walker first, the output register after the last.
/// Each product is its tiles' partial products in one stage and the adders joining them in the
/// next, so at level 1 no clock has a tile and its adders in a row (the correction's product and
/// its sum in one clock were the 25F's critical path, docs/fpga.md).
pub const I0_STAGES: [&str; 9] = [
    "the walker: the row's bounds, clipped, and whether it has a covered pixel",
    "the partial products of (Gxn >> 8) lo, the plane's step to the first pixel (Gxn's low 8 bits are zero)",
    "their sum, Gxn lo modulo 2^(K-2)",
    "S2n = 2 (Tn + Gxn lo) + An modulo 2^(K-1)",
    "its top bits H = S2n >> t and the partial products of H Rn; S2n - 2An and S2n - 4An modulo 2^(AW+3)",
    "the quotient estimate q~ = (H Rn) >> (K - t), the quotient or up to two below it",
    "the partial products of q~ An modulo 2^(AW+2); q~ + 1 and q~ + 2",
    "their sum, doubled: q~ 2An modulo 2^(AW+3)",
    "I0 = q~ + (R >= 2An) + (R >= 4An), R = S2n - 2An q~: the correction, R >= 2k An the sign of (S2n - 2k An) - 2An q~",
];

/// The front-end set-up's CALC stages when it is pipelined, in order: what each clock computes
/// from the registers of the one before (the first from the vertex registers). At level 0 the
/// five are one clock. The last loads the dividers, drops or culls.
pub const SETUP_STAGES: [&str; 5] = [
    "guard band; vertex differences; bounding box and each edge's row extent, offset to pixel centres",
    "the area's and the plane's products; the first row, clipped; each edge's first row and its distance to the edge's vertex; the edges' signs; the last row with and without a bottom edge",
    "the area, its sign and magnitude; the plane's normal and |Nx|; the edge terms' products, unoriented; the top-left rule from the signs, and the last row",
    "each edge's active rows; cull; the edge dividers' dividends; |A|'s leading zeros; dI's dividend; the first-row sum's products",
    "the first-row sum and the plane terms, normalised, and An; the dividers loaded, or the triangle dropped or culled",
];

impl std::fmt::Display for Pipeline {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_above_the_deepest_are_refused() {
        assert_eq!(Pipeline::new(Pipeline::MAX).map(Pipeline::level), Some(Pipeline::MAX));
        assert_eq!(Pipeline::new(Pipeline::MAX + 1), None);
        assert_eq!(Pipeline::default(), Pipeline::NONE);
        // A file's level is checked as it is read, as a number.
        assert_eq!(serde_json::from_str::<Pipeline>("2").unwrap(), Pipeline::at(2));
        assert_eq!(serde_json::to_string(&Pipeline::at(1)).unwrap(), "1");
        let above = (Pipeline::MAX + 1).to_string();
        let e = serde_json::from_str::<Pipeline>(&above).unwrap_err().to_string();
        assert!(e.contains(&PipelineError(Pipeline::MAX + 1).to_string()), "{e}");
    }

    #[test]
    fn each_level_adds_to_the_one_before() {
        let flags = |p: Pipeline| {
            [
                p.span_stage(),
                p.sum_stage(),
                p.split_multiplies(),
                p.logic_products(),
                p.split_adds(),
                p.calc_clocks() > 1,
                p.row_stage(I0Form::Reciprocal),
            ]
        };
        let levels: Vec<_> = Pipeline::all().collect();
        for w in levels.windows(2) {
            let (a, b) = (flags(w[0]), flags(w[1]));
            assert!(a.iter().zip(&b).all(|(x, y)| !x || *y), "level {} drops a stage of level {}", w[1], w[0]);
            assert_ne!(a, b, "level {} adds nothing to level {}", w[1], w[0]);
        }
    }

    #[test]
    fn the_row_stage_is_the_reciprocal_forms_above_level_0() {
        assert!(Pipeline::all().all(|p| !p.row_stage(I0Form::Incremental)), "the incremental walker decides its row itself");
        assert!(!Pipeline::NONE.row_stage(I0Form::Reciprocal), "level 0 is SPEC's seed structure");
        assert!(Pipeline::all().skip(1).all(|p| p.row_stage(I0Form::Reciprocal)));
        assert!(Pipeline::all().all(|p| p.row_stage(I0Form::Reciprocal) == (p.row_stages(I0Form::Reciprocal) == ROW_STAGES.len() as u32)));
    }
}
