//! segshade's Verilog generator: every module of SPEC §3 for one configuration, with its
//! manifest and FuseSoC core. The binary (`hdl-gen`) is a thin clap front end over this.

pub mod axis;
pub mod bfpi;
pub mod board;
pub mod formal;
pub mod frontend;
pub mod manifest;
pub mod output;
pub mod report;
pub mod rom;
pub mod segment;
pub mod specular;
pub mod testbench;
pub mod verilog;
pub mod wrapper;
pub mod writer;

pub use axis::Bus;
pub use bfpi::BfpiArch;
use golden::Config;

pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// Module names of one configuration, with the user's prefix applied.
#[derive(Clone, Debug)]
pub struct Names {
    pub prefix: String,
    pub bfpi: String,
    pub segment: String,
    /// SPEC §6's front-end (set-up and edge walker), and the chain of it with the shader.
    pub frontend: String,
    pub top: String,
    /// SPEC §7's segment writer, and the chain from triangles to memory.
    pub writer: String,
    pub fb_top: String,
}

impl Names {
    pub fn new(prefix: &str, cfg: &Config) -> Names {
        Names {
            prefix: prefix.to_string(),
            bfpi: format!("{prefix}bfpi_p{}", cfg.p),
            segment: format!("{prefix}segment_shader_p{}", cfg.p),
            frontend: format!("{prefix}tri_frontend"),
            top: format!("{prefix}tri_shader_p{}", cfg.p),
            writer: format!("{prefix}fb_writer_p{}", cfg.p),
            fb_top: format!("{prefix}tri_fb_p{}", cfg.p),
        }
    }
}

/// A module-name prefix that would not keep every name a plain Verilog identifier.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("prefix '{0}' is not a Verilog identifier start (letters, digits, '_', not starting with a digit)")]
pub struct PrefixError(pub String);

/// A module-name prefix must keep every name a plain Verilog identifier.
pub fn check_prefix(prefix: &str) -> Result<(), PrefixError> {
    let ok = prefix.chars().enumerate().all(|(k, c)| c == '_' || c.is_ascii_alphabetic() || (k > 0 && c.is_ascii_digit()));
    if ok {
        Ok(())
    } else {
        Err(PrefixError(prefix.to_string()))
    }
}

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
    /// Register stages added for clock rate (`--pipeline`); level 0 is SPEC's seed structure.
    pub pipeline: golden::pipeline::Pipeline,
    /// `--bus`: SPEC's ports only, or AXI4-Stream wrappers of the streaming tops as well.
    pub bus: Bus,
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
            .with_di(self.fe_di);
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

/// One output file, name relative to the output folder.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GeneratedFile {
    pub name: String,
    pub contents: String,
}

/// Every file of one configuration, in a fixed order. Pure: no clock, no environment.
pub fn generate(opts: &Options) -> Vec<GeneratedFile> {
    let names = Names::new(&opts.prefix, &opts.cfg);
    let mut modules: Vec<verilog::Module> = bfpi::module_for(&opts.cfg, &names, opts.bfpi_arch).into_iter().collect();
    modules.push(segment::module_with(&opts.cfg, &names, opts.bfpi_arch, opts.pipeline));
    // The CLI validates the screen; a library caller with a bad one gets no front-end.
    if let (Ok(fe), Ok(w)) = (opts.frontend(), opts.writer()) {
        modules.push(frontend::module(&fe, &names));
        modules.push(frontend::top_module(&fe, &names));
        modules.push(writer::module(&w, &names));
        modules.push(writer::top_module(&fe, &w, &names));
    }
    let unit = opts.specular_unit();
    let spec = specular::SpecNames::new(&opts.prefix);
    modules.extend(specular::modules(&opts.cfg, &unit, &spec));
    let wrappers = match opts.bus {
        Bus::Native => Vec::new(),
        Bus::Axis => axis::wrappers(&modules, &names, &spec),
    };
    for w in &wrappers {
        let core = modules.iter().find(|m| m.name == w.wraps).expect("a wrapper wraps a generated module");
        modules.push(axis::module(w, core));
    }
    let mut files: Vec<GeneratedFile> =
        modules.iter().map(|m| GeneratedFile { name: format!("{}.v", m.name), contents: m.render() }).collect();
    // The BFPI's proof reference rides in its file (scripts/prove).
    if let Some(f) = files.iter_mut().find(|f| f.name == format!("{}.v", names.bfpi)) {
        f.contents.push_str(&bfpi::properties::bfpi_reference(&opts.cfg, &names.bfpi).render_formal());
    }
    for (name, rom) in [(golden::rom::BRDF_HEX, unit.brdf_rom()), (golden::rom::NK_HEX, unit.nk_rom())] {
        files.push(GeneratedFile { name: name.into(), contents: rom.to_hex() });
    }
    files
        .push(GeneratedFile { name: manifest::MANIFEST_FILE.into(), contents: manifest::render(opts, &names, &modules, &unit, &wrappers) });
    files.push(GeneratedFile { name: manifest::CORE_FILE.into(), contents: manifest::core_file(opts, &names, &modules, &wrappers) });
    files
}
