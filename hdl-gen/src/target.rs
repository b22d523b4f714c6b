//! `--target`: the FPGA a configuration is generated for (issue 27). A target only chooses
//! defaults for the options that trade area, clock rate and set-up clocks (the front-end's
//! form, the pipeline level, the dividers' rate); a flag the user gives still wins, and every
//! other option keeps its own default. The choices are the measured best for each device
//! (docs/design.md, "Targets"; figures in docs/fpga.md), so they change when a measurement does.

use golden::frontend::I0Form;
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

/// The options a target chooses; `None` fields stay at the option's own default.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Choice {
    /// `--pipeline`.
    pub pipeline: u32,
    /// `--fe-div-bits`.
    pub fe_div_bits: u32,
    /// `--fe-i0`.
    pub fe_i0: I0Form,
}

impl Target {
    /// What this target chooses, from the measured `tri_frontend` on an ECP5-85F (docs/fpga.md;
    /// docs/design.md, "Targets"): `--pipeline 1` on every device (the set-up's CALC in five
    /// clocks: 18.2 MHz at level 0, 47-48 MHz at level 1); on the ECP5 two quotient bits a clock
    /// (47.5 MHz, 13 set-up clocks a triangle: about the rows a ~100 px triangle walks, so the
    /// most such triangles a second of the measured forms, at 9,134 LUT4), on the iCE40s one
    /// (4,916 LUT4, the smallest, at 24 clocks); the reciprocal `I0` everywhere (the
    /// incremental form is larger on one shared multiplier).
    pub fn choice(self) -> Choice {
        let fe_div_bits = match self {
            Target::Ecp5_25f => 2,
            Target::Ice40Hx8k | Target::Ice40Up5k => 1,
        };
        Choice { pipeline: 1, fe_div_bits, fe_i0: I0Form::Reciprocal }
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
