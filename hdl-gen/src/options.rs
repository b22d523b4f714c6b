//! What `generate` is asked for, and the generator's version the manifest records.

use crate::axis::Bus;
use crate::bfpi::BfpiArch;
use crate::frontend;
use golden::Config;

pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// What `generate` is asked for. `Options { cfg, ..Default::default() }` takes the defaults.
#[derive(Clone, Debug, Default)]
pub struct Options {
    pub cfg: Config,
    pub prefix: String,
    /// How the increments are formed: SPEC's shift-and-add BFPI, or a comparison form.
    pub bfpi_arch: BfpiArch,
    /// The specular unit's tables (`--brdf-k`); `None` is the patent's set and n ranges.
    pub brdf: Option<golden::specular::SpecularPlan>,
    /// The front-end's screen (`--width`, `--height`); `None`: [`Options::default_screen`].
    pub screen: Option<golden::setup::Screen>,
    /// Quotient bits per clock of the front-end's set-up dividers (`--fe-div-bits`); `None`:
    /// [`frontend::DEFAULT_DIV_BITS`].
    pub fe_div_bits: Option<u32>,
    /// Where the front-end's `dI` comes from (`--fe-di`); the default is once per triangle.
    pub fe_di: golden::frontend::DiMode,
    /// How the front-end forms each span's `I0` (`--fe-i0`); the default is today's reciprocal
    /// a row.
    pub fe_i0: golden::frontend::I0Form,
    /// How the front-end sets a triangle up (`--fe-setup`); the default is today's parallel CALC
    /// and dividers.
    pub fe_setup: golden::frontend::engine::SetupForm,
    /// How the front-end's span path forms a row's products (`--fe-span`); the default is a row
    /// a clock in parallel.
    pub fe_span: golden::frontend::SpanForm,
    /// Register stages added for clock rate (`--pipeline`); level 0 is SPEC's seed structure.
    pub pipeline: golden::pipeline::Pipeline,
    /// `--bus`: SPEC's ports only, or AXI4-Stream wrappers of the streaming tops as well.
    pub bus: Bus,
    /// `--target`: the device the options above were chosen for (recorded in the manifest; the
    /// choice itself is already in the fields).
    pub target: Option<crate::Target>,
}

impl Options {
    /// 640x480, narrowed to what the configuration can shade within 1 (2^XW and 2^F pixels).
    pub fn default_screen(cfg: &Config) -> golden::setup::Screen {
        let max = cfg.max_len().min(1 << cfg.frac.min(31));
        golden::setup::Screen { width: 640.min(max), height: 480 }
    }

    /// The front-end these options describe.
    pub fn frontend(&self) -> Result<frontend::Hw, golden::frontend::FrontEndError> {
        let fe = golden::frontend::FrontEnd::new(self.cfg, self.screen.unwrap_or_else(|| Options::default_screen(&self.cfg)))?
            .with_di(self.fe_di)
            .with_i0(self.fe_i0)
            .with_setup(self.fe_setup)
            .with_span(self.fe_span);
        Ok(frontend::Hw { fe, div_bits: self.fe_div_bits.unwrap_or(frontend::DEFAULT_DIV_BITS), pipeline: self.pipeline })
    }

    /// The segment writer of the front-end's screen (the same screen: the chain shares it).
    pub fn writer(&self) -> Result<golden::writer::Writer, golden::writer::WriterError> {
        golden::writer::Writer::new(self.cfg, self.screen.unwrap_or_else(|| Options::default_screen(&self.cfg)))
    }

    /// The specular unit these options describe, with its ROM images.
    pub fn specular_unit(&self) -> golden::specular::SpecularUnit {
        let plan = self.brdf.clone().unwrap_or_else(golden::specular::SpecularPlan::patent);
        golden::specular::SpecularUnit::new(plan.with_pipeline(self.pipeline))
    }
}
