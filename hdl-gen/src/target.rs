//! `--target`: the FPGA a configuration is generated for (issue 27). A target only chooses
//! defaults for the options that trade area, clock rate and set-up clocks (the front-end's
//! form, the pipeline level, the dividers' rate); a flag the user gives still wins, and every
//! other option keeps its own default. The choices are the measured best for each device
//! (docs/design.md, "Targets"; figures in docs/fpga.md), so they change when a measurement does.

use golden::frontend::{I0Form, SetupForm, SpanForm};
use serde::{Deserialize, Serialize};

/// A device family and size the generated chain is meant to fit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, clap::ValueEnum, Serialize, Deserialize)]
pub enum Target {
    /// Lattice LFE5U-25F (24k LUT4, 28 MULT18X18D), speed grade 6.
    #[value(name = "ecp5-25f")]
    #[serde(rename = "ecp5-25f")]
    Ecp5_25f,
    /// Lattice iCE40 HX8K (7,680 logic cells, no multiplier).
    #[value(name = "ice40-hx8k")]
    #[serde(rename = "ice40-hx8k")]
    Ice40Hx8k,
    /// Lattice iCE40 UP5K (5,280 logic cells, 8 SB_MAC16, SPRAM).
    #[value(name = "ice40-up5k")]
    #[serde(rename = "ice40-up5k")]
    Ice40Up5k,
}

/// The options a target chooses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Choice {
    /// `--pipeline`.
    pub pipeline: u32,
    /// `--fe-div-bits` (the parallel set-up's dividers; `None`: the option's default).
    pub fe_div_bits: Option<u32>,
    /// `--fe-i0`.
    pub fe_i0: I0Form,
    /// `--fe-setup`.
    pub fe_setup: SetupForm,
    /// `--fe-span`.
    pub fe_span: SpanForm,
}

impl Target {
    /// What this target chooses, from the measured `tri_frontend` (docs/fpga.md; docs/design.md,
    /// "Targets"): the shared set-up engine on the device's own plan, which is smaller than the
    /// parallel set-up on every device measured (ECP5, `--pipeline 1`: 5,015 LUT4 and 15
    /// MULT18X18D since stop 30, placed on the 25F at 82.0 MHz, against 9,134 LUT4 and 83
    /// MULT18X18D at 47.5 MHz on the 85F for the parallel form's best, which no 25F holds; iCE40:
    /// 11,120 SB_LUT4 on the HX8K's sequential engine against 38,337 without DSPs; 6,609 SB_LUT4
    /// and 12 SB_MAC16 on the UP5K's sequential engine against 8,719 and 81 with them) and
    /// sets a triangle up in fewer clocks than the parallel form at the same clock (12 against
    /// 13); `--pipeline 1` (the span path in stages: the parallel form's 18.2 MHz at level 0
    /// became 47-48 MHz) on the ECP5, 0 on the iCE40s with their sequential span path; the
    /// reciprocal `I0`, which the engine forms take.
    pub fn choice(self) -> Choice {
        let fe_setup = match self {
            Target::Ecp5_25f => SetupForm::Ecp5_25f,
            Target::Ice40Hx8k => SetupForm::Ice40Hx8k,
            Target::Ice40Up5k => SetupForm::Ice40Up5k,
        };
        // The iCE40s walk a covered row every few dozen clocks: their span path's products on one
        // shift-add unit, not in parallel logic (most of their front-end's LUTs, docs/fpga.md).
        let fe_span = match self {
            Target::Ecp5_25f => SpanForm::Parallel,
            Target::Ice40Hx8k | Target::Ice40Up5k => SpanForm::Sequential,
        };
        // Level 0 on the iCE40s: their span path is sequential, so level 1's span stages are gone
        // and its two row stages only cost flip-flops (HX8K tri_fb_p4 in its harness: 9,920 logic
        // cells at level 0 against 10,445 at level 1, docs/fpga.md); their p = 4 shader runs at
        // 85 MHz on the HX8K at level 0.
        let pipeline = match self {
            Target::Ecp5_25f => 1,
            Target::Ice40Hx8k | Target::Ice40Up5k => 0,
        };
        Choice { pipeline, fe_div_bits: None, fe_i0: I0Form::Reciprocal, fe_setup, fe_span }
    }

    /// The name `--target` takes.
    pub fn name(self) -> &'static str {
        match self {
            Target::Ecp5_25f => "ecp5-25f",
            Target::Ice40Hx8k => "ice40-hx8k",
            Target::Ice40Up5k => "ice40-up5k",
        }
    }
}

impl std::fmt::Display for Target {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
