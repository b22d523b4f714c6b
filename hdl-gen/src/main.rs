//! `hdl-gen`: the command line of the segshade generator.

use anyhow::{bail, Context};
use clap::{Parser, Subcommand};
use golden::rom::RomFormat;
use hdl_gen::cli::{BrdfArgs, ConfigArgs, ModelArgs};
use hdl_gen::{generate, output, Options};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "hdl-gen", version, about = "Generate segment-shading hardware (Verilog-2005) and its ROM images")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Write every module of one configuration, manifest.json and a FuseSoC core into a folder.
    ///
    /// The folder is generate's own: it must be new, empty, or hold only the files an earlier
    /// generate wrote there (the ones its manifest.json lists, and manifest.json and the core).
    /// Those are replaced, and the ones the new configuration does not have are removed, so the
    /// folder always holds one configuration. A folder holding anything else is refused and left
    /// as it is.
    Generate {
        #[command(flatten)]
        model: ModelArgs,
        /// Screen width of the triangle front-end (tri_frontend, tri_shader_p<P>), at most 2^XW
        /// and 2^F pixels. Default: 640, or the widest the configuration allows when less.
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65536))]
        width: Option<u32>,
        /// Screen height of the triangle front-end (1..65536). Default: 480.
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65536))]
        height: Option<u32>,
        /// Output folder (created if missing; see above for one that exists).
        #[arg(long)]
        out: PathBuf,
    },
    /// Print or write one of the specular unit's ROM images.
    Rom {
        /// Which image: the BRDF tables or the n-table.
        #[arg(long, value_enum)]
        table: RomTable,
        /// $readmemh hex, Intel MIF or Xilinx COE.
        #[arg(long, value_enum, default_value_t = RomFormat::Hex)]
        format: RomFormat,
        #[command(flatten)]
        brdf: BrdfArgs,
        /// File to write (standard output without it).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Write a synthesis harness for one generated module: every input and output registered,
    /// talking to the outside through three pins (used by scripts/synth).
    SynthWrapper {
        /// A folder written by `generate` (its manifest.json lists the module's ports).
        #[arg(long)]
        rtl: PathBuf,
        /// The module to wrap, as named in manifest.json; given more than once, the modules sit
        /// side by side in one harness (one design to place, as one device must hold them).
        #[arg(long, required = true)]
        module: Vec<String>,
        /// The Verilog file to write; the harness module is `<module>_synth` (`<A>_<B>_synth` for
        /// several).
        #[arg(long)]
        out: PathBuf,
        /// Register the block's outputs before the XOR tree, or fold them directly (a flip-flop
        /// fewer per output bit, for a design that only fits without them; never a better Fmax).
        #[arg(long, value_enum, default_value_t)]
        outputs: hdl_gen::tools::wrapper::Outputs,
    },
    /// Write a self-checking Verilog-2005 testbench of the segment shader and of the specular
    /// unit, with vectors from the golden model, beside the generated RTL (runs in Icarus).
    Testbench {
        #[command(flatten)]
        config: ConfigArgs,
        #[command(flatten)]
        brdf: BrdfArgs,
        /// Spans per block (1..1000000).
        #[arg(long, default_value_t = 1000, value_parser = clap::value_parser!(u32).range(1..=hdl_gen::tools::testbench::MAX_VECTORS as i64))]
        vectors: u32,
        /// Seed of the vectors and of the bench's traffic pattern.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Output folder (created if missing).
        #[arg(long)]
        out: PathBuf,
    },
    /// Print the name of the module a generated folder holds in a role (scripts read the
    /// manifest through this, not through a JSON parser of their own); exit 2 when it has none.
    Manifest {
        /// A folder written by `generate`.
        #[arg(long)]
        rtl: PathBuf,
        /// The module's role in the chain (manifest.json's `role`).
        #[arg(long, value_enum)]
        role: hdl_gen::manifest::Role,
    },
    /// Measure the generated hardware against its references.
    Report {
        #[command(subcommand)]
        report: Report,
    },
}

#[derive(Subcommand)]
enum Report {
    /// The specular unit's max relative error inside the epicentre per n range (SPEC §4):
    /// its approximation, the patent's and the cos^2 prototype's, and the RTL's total error.
    Accuracy {
        #[command(flatten)]
        brdf: BrdfArgs,
        /// Also draw the error against n into this SVG file.
        #[arg(long)]
        svg: Option<PathBuf>,
    },
}

/// The command line, every subcommand reading a negative number as a value (which its flag's
/// range then rejects by name) rather than as an unknown flag.
fn parse_cli() -> Cli {
    use clap::{CommandFactory, FromArgMatches};
    fn negatives(c: clap::Command) -> clap::Command {
        c.allow_negative_numbers(true).mut_subcommands(negatives)
    }
    Cli::from_arg_matches(&negatives(Cli::command()).get_matches()).unwrap_or_else(|e| e.exit())
}

/// `rom --table`: which of the specular unit's ROM images.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
enum RomTable {
    /// The BRDF tables.
    Brdf,
    /// The n-table (k and the table per n).
    Nk,
}

fn main() -> ExitCode {
    match run(parse_cli().command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // The context (a flag, a file) and the library's message, on one line.
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}

/// Largest manifest.json read. The largest `generate` writes is 107,751 bytes (`generate --p 256
/// --bus axis --pipeline 3 --frac 20 --xbits 16 --brdf-k auto --max-rel-error 1%`); a file past
/// this limit is no manifest of ours, and is not read whole.
const MAX_MANIFEST_BYTES: u64 = 16 << 20;

/// A manifest.json's text, read no further than [`MAX_MANIFEST_BYTES`].
fn read_manifest(path: &std::path::Path) -> anyhow::Result<String> {
    use std::io::Read;
    let mut text = String::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(MAX_MANIFEST_BYTES + 1).read_to_string(&mut text))
        .with_context(|| format!("cannot read {}", path.display()))?;
    if text.len() as u64 > MAX_MANIFEST_BYTES {
        bail!("{}: larger than {} MiB, not a manifest generate wrote", path.display(), MAX_MANIFEST_BYTES >> 20);
    }
    Ok(text)
}

/// The files an earlier `generate` wrote into `dir`, by its manifest.json: the modules' files,
/// the ROM images, the manifest and the core. None without a manifest that reads as one.
fn owned_files(dir: &std::path::Path) -> Vec<String> {
    let Ok(text) = read_manifest(&dir.join(hdl_gen::manifest::MANIFEST_FILE)) else { return Vec::new() };
    let Ok(m) = hdl_gen::manifest::Manifest::parse(&text) else { return Vec::new() };
    let mut names: Vec<String> = m.modules.iter().map(|e| e.file.clone()).collect();
    names.extend([&m.specular.brdf_rom.file, &m.specular.nk_rom.file].map(String::clone));
    names.extend([hdl_gen::manifest::MANIFEST_FILE, hdl_gen::manifest::CORE_FILE].map(String::from));
    names
}

fn run(command: Command) -> anyhow::Result<()> {
    match command {
        Command::Generate { model, width, height, out } => {
            let default = Options::default_screen(&model.options(None)?.cfg);
            let screen = golden::setup::Screen { width: width.unwrap_or(default.width), height: height.unwrap_or(default.height) };
            let opts = model.options(Some(screen))?;
            output::write_owned(&out, &generate(&opts), &owned_files(&out))?;
            eprintln!("wrote {}", out.display());
        }
        Command::Rom { table, format, brdf, out } => {
            let unit = Options { brdf: brdf.plan()?, ..Options::default() }.specular_unit();
            let rom = match table {
                RomTable::Brdf => unit.brdf_rom(),
                RomTable::Nk => unit.nk_rom(),
            };
            let text = rom.to_text(format);
            match out {
                Some(path) => {
                    output::write_one(&path, text.as_bytes())?;
                    eprintln!("wrote {}", path.display());
                }
                None => print!("{text}"),
            }
        }
        Command::SynthWrapper { rtl, module, out, outputs } => {
            let path = rtl.join(hdl_gen::manifest::MANIFEST_FILE);
            let text = read_manifest(&path)?;
            let blocks = module
                .into_iter()
                .map(|m| Ok((m.clone(), hdl_gen::tools::wrapper::ports_from_manifest(&text, &m)?)))
                .collect::<Result<Vec<_>, hdl_gen::tools::wrapper::WrapperError>>()?;
            output::check_not_input(&out, &[&path])?;
            output::write_one(&out, hdl_gen::tools::wrapper::modules(&blocks, outputs)?.render().as_bytes())?;
            eprintln!("wrote {}", out.display());
        }
        Command::Manifest { rtl, role } => {
            let path = rtl.join(hdl_gen::manifest::MANIFEST_FILE);
            let manifest = hdl_gen::manifest::Manifest::parse(&read_manifest(&path)?).with_context(|| path.display().to_string())?;
            match manifest.by_role(role) {
                Some(m) => println!("{}", m.name),
                None => {
                    let name = clap::ValueEnum::to_possible_value(&role).map(|v| v.get_name().to_string()).unwrap_or_default();
                    bail!("{} lists no module in the role {name}", path.display())
                }
            }
        }
        Command::Testbench { config, brdf, vectors, seed, out } => {
            let opts = config.options(&brdf)?;
            output::write_all(&out, &hdl_gen::tools::testbench::testbench(&opts, vectors, seed)?)?;
            eprintln!("wrote {}", out.display());
        }
        Command::Report { report: Report::Accuracy { brdf, svg } } => {
            let unit = Options { brdf: brdf.plan()?, ..Options::default() }.specular_unit();
            let report = hdl_gen::tools::report::AccuracyReport::measure(&unit);
            // The file first: a failed write then leaves no table behind either.
            if let Some(path) = &svg {
                output::write_one(path, report.svg().as_bytes())?;
                eprintln!("wrote {}", path.display());
            }
            print!("{}", report.table());
        }
    }
    Ok(())
}
