//! segshade's Verilog generator: every module of SPEC §3 for one configuration, with its
//! manifest and FuseSoC core. The binary (`hdl-gen`) is a thin clap front end over this.

pub mod axis;
pub mod bfpi;
pub mod board;
pub mod cli;
pub mod formal;
pub mod frontend;
pub mod input;
pub mod manifest;
mod names;
mod options;
pub mod output;
pub mod rom;
pub mod segment;
pub mod specular;
mod target;
pub mod tools;
pub mod verilog;
pub mod widths;
pub mod writer;

pub use axis::Bus;
pub use bfpi::BfpiArch;
pub use names::{check_prefix, Names, PrefixError};
pub use options::{Options, VERSION};
pub use output::GeneratedFile;
pub use target::{Choice, Target};

/// Every file of one configuration, in a fixed order. Pure: no clock, no environment.
pub fn generate(opts: &Options) -> Vec<GeneratedFile> {
    let names = Names::new(&opts.prefix, &opts.cfg);
    let mut modules: Vec<verilog::Module> = bfpi::module_for(&opts.cfg, &names, opts.bfpi_arch).into_iter().collect();
    modules.push(segment::module_with(&opts.cfg, &names, opts.bfpi_arch, opts.pipeline));
    // The CLI validates the screen; a library caller with a bad one gets no front-end.
    if let (Ok(fe), Ok(w)) = (opts.frontend(), opts.writer()) {
        modules.push(frontend::module(&fe, &names));
        modules.extend(frontend::submodules(&fe, &names));
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
