//! segshade's Verilog generator: every module of SPEC §3 for one configuration, with its
//! manifest and FuseSoC core. The binary (`hdl-gen`) is a thin clap front end over this.

pub mod bfpi;
pub mod manifest;
pub mod output;
pub mod report;
pub mod rom;
pub mod segment;
pub mod specular;
pub mod testbench;
pub mod verilog;
pub mod wrapper;

pub use bfpi::BfpiArch;
use golden::Config;

pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// Module names of one configuration, with the user's prefix applied.
#[derive(Clone, Debug)]
pub struct Names {
    pub prefix: String,
    pub bfpi: String,
    pub segment: String,
}

impl Names {
    pub fn new(prefix: &str, cfg: &Config) -> Names {
        Names {
            prefix: prefix.to_string(),
            bfpi: format!("{prefix}bfpi_p{}", cfg.p),
            segment: format!("{prefix}segment_shader_p{}", cfg.p),
        }
    }
}

/// A module-name prefix must keep every name a plain Verilog identifier.
pub fn check_prefix(prefix: &str) -> Result<(), String> {
    let ok = prefix.chars().enumerate().all(|(k, c)| c == '_' || c.is_ascii_alphabetic() || (k > 0 && c.is_ascii_digit()));
    if ok {
        Ok(())
    } else {
        Err(format!("prefix '{prefix}' is not a Verilog identifier start (letters, digits, '_', not starting with a digit)"))
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
}

impl Options {
    /// The specular unit these options describe, with its ROM images.
    pub fn specular_unit(&self) -> golden::specular::SpecularUnit {
        match &self.brdf {
            Some(plan) => golden::specular::SpecularUnit::new(plan.clone()),
            None => golden::specular::SpecularUnit::default(),
        }
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
    modules.push(segment::module_with(&opts.cfg, &names, opts.bfpi_arch));
    let unit = opts.specular_unit();
    modules.extend(specular::modules(&opts.cfg, &unit, &specular::SpecNames::new(&opts.prefix)));
    let mut files: Vec<GeneratedFile> = modules
        .iter()
        .map(|m| GeneratedFile { name: format!("{}.v", m.name), contents: m.render() })
        .collect();
    for (name, rom) in [(golden::rom::BRDF_HEX, unit.brdf_rom()), (golden::rom::NK_HEX, unit.nk_rom())] {
        files.push(GeneratedFile { name: name.into(), contents: rom.to_hex() });
    }
    files.push(GeneratedFile { name: "manifest.json".into(), contents: manifest::render(opts, &names, &modules, &unit) });
    files.push(GeneratedFile { name: manifest::CORE_FILE.into(), contents: manifest::core_file(opts, &names, &modules) });
    files
}
