//! `hdl-gen`: the command line of the segshade generator.

use anyhow::{bail, Context};
use clap::builder::{StringValueParser, TypedValueParser};
use clap::{Args, Parser, Subcommand};
use golden::frontend::{DiMode, I0Form};
use golden::rom::RomFormat;
use golden::specular::{parse_rel_error, BrdfK, SpecularPlan};
use golden::{Align, Config};
use hdl_gen::{check_prefix, generate, output, BfpiArch, Bus, Options};
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
        config: ConfigArgs,
        /// Increments: shift-add (SPEC's BFPI), or the comparison forms naive (`*` by constants)
        /// and tree (doubling tree in the shader, no BFPI) used by scripts/synth.
        #[arg(long = "bfpi-arch", value_enum, default_value_t = BfpiArch::ShiftAdd)]
        bfpi_arch: BfpiArch,
        #[command(flatten)]
        brdf: BrdfArgs,
        /// Screen width of the triangle front-end (tri_frontend, tri_shader_p<P>), at most 2^XW
        /// and 2^F pixels. Default: 640, or the widest the configuration allows when less.
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65536))]
        width: Option<u32>,
        /// Screen height of the triangle front-end (1..65536). Default: 480.
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65536))]
        height: Option<u32>,
        /// Quotient bits per clock of the front-end's set-up dividers: 1, 2 or 4. More bits,
        /// fewer set-up clocks per triangle (tiny triangles go faster), longer paths. Default: 4.
        #[arg(long = "fe-div-bits", value_parser = clap::builder::PossibleValuesParser::new(["1", "2", "4"]).map(|b| b.parse::<u32>().expect("a listed value")))]
        fe_div_bits: Option<u32>,
        /// Where the front-end's dI comes from: `triangle` (the constant-increment theorem, once
        /// per triangle) or `scanline` (classical Gouraud, a division per span from the edge
        /// intensities with the same divider: a comparison option, slower and larger).
        #[arg(long = "fe-di", value_enum, default_value_t = DiMode::Triangle)]
        fe_di: DiMode,
        /// How the front-end forms each span's I0: `reciprocal` (three wide products a row in
        /// the span path) or `incremental` (quotient and remainder over 2A stepped by adds per
        /// source of the span's left end; the reciprocal only at a source's first covered row, on
        /// one shared multiplier, the walker waiting meanwhile). Same spans bit for bit. The
        /// default stays `reciprocal` until the incremental form measures better (docs/design.md,
        /// issue 27). `incremental` takes `--fe-di triangle` only.
        #[arg(long = "fe-i0", value_enum, default_value_t = I0Form::Reciprocal)]
        fe_i0: I0Form,
        /// Register stages added for clock rate, 0..3 (golden::pipeline): 1 registers the span and
        /// the shader's increments, splits the specular unit's multiplies, and stages the
        /// front-end (CALC in five clocks, its span path in six), 2 also the shader's lane sums, 3 cuts the shader's adders
        /// so no clock has two in a row (same stages as 2). Values and throughput are the same at every
        /// level; latency grows (manifest.json). 0, the default: SPEC's seed structure, smallest
        /// and shortest (docs/fpga.md compares the levels).
        #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=golden::pipeline::Pipeline::MAX as i64))]
        pipeline: u32,
        /// Stream interfaces: `native` (SPEC's ports only) or `axis`, which also writes an
        /// AXI4-Stream wrapper `<module>_axis` of the segment shader, the front-end, its chain
        /// and the specular unit, with Vivado interface attributes (docs/axis.md).
        #[arg(long, value_enum, default_value_t = Bus::Native)]
        bus: Bus,
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
        /// The module to wrap, as named in manifest.json.
        #[arg(long)]
        module: String,
        /// The Verilog file to write; the harness module is `<module>_synth`.
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

/// The configuration and module prefix, shared by `generate` and `testbench`.
#[derive(Args)]
struct ConfigArgs {
    /// Segment width: pixels per clock, a power of two in 1..256.
    #[arg(long, default_value_t = golden::format::DEFAULT_P,
          value_parser = clap::value_parser!(u32).try_map(|p| golden::format::check_p(p).map(|()| p)))]
    p: u32,
    /// Fraction bits F of the intensity format UQ8.F (4..20).
    #[arg(long = "frac", default_value_t = golden::format::DEFAULT_FRAC, value_parser = clap::value_parser!(u32).range(4..=20))]
    frac: u32,
    /// Screen-x bits XW (4..16).
    #[arg(long = "xbits", default_value_t = golden::format::DEFAULT_XBITS, value_parser = clap::value_parser!(u32).range(4..=16))]
    xbits: u32,
    /// Segmentation: span (the seed's) or screen (segments on multiples of P).
    #[arg(long, value_enum, default_value_t = Align::Span)]
    align: Align,
    /// String prepended to every module name.
    #[arg(long, default_value = "", value_parser = StringValueParser::new().try_map(|s| check_prefix(&s).map(|()| s)))]
    prefix: String,
}

impl ConfigArgs {
    /// Options for this configuration with the table set `brdf`; the rest default.
    fn options(self, brdf: &BrdfArgs) -> anyhow::Result<Options> {
        let cfg = Config::new(self.p, self.frac, self.xbits, self.align)?;
        Ok(Options { cfg, prefix: self.prefix, brdf: brdf.plan()?, ..Options::default() })
    }
}

/// The specular unit's table set, shared by every command that builds the unit.
#[derive(Args)]
struct BrdfArgs {
    /// BRDF table set: a list of k (ascending, 1..64; each n then takes its least-error table),
    /// or `auto` to choose the set with the least ROM that meets --max-rel-error.
    /// Default: the patent's 1,2,4,16 with its n ranges.
    #[arg(long = "brdf-k")]
    brdf_k: Option<BrdfK>,
    /// With `--brdf-k auto`: largest relative error of the approximation inside the epicentre,
    /// as a fraction (0.01) or a percentage (1%).
    #[arg(long = "max-rel-error", value_parser = parse_rel_error, requires = "brdf_k")]
    max_rel_error: Option<f64>,
}

impl BrdfArgs {
    /// The plan, or `None` for the patent's own (the default).
    fn plan(&self) -> anyhow::Result<Option<SpecularPlan>> {
        let choice = match (&self.brdf_k, self.max_rel_error) {
            (None, _) => return Ok(None),
            (Some(BrdfK::Auto { .. }), Some(e)) => BrdfK::Auto { max_err: e },
            (Some(BrdfK::List(_)), Some(_)) => bail!("--max-rel-error goes with --brdf-k auto"),
            (Some(b), None) => b.clone(),
        };
        SpecularPlan::from_brdf_k(&choice).map(Some).with_context(|| format!("--brdf-k {choice}"))
    }
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
        Command::Generate { config, bfpi_arch, brdf, width, height, fe_div_bits, fe_di, fe_i0, pipeline, bus, out } => {
            let opts = config.options(&brdf)?;
            let default = Options::default_screen(&opts.cfg);
            let screen = golden::setup::Screen { width: width.unwrap_or(default.width), height: height.unwrap_or(default.height) };
            let pipeline = golden::pipeline::Pipeline::new(pipeline).expect("clap checked the range");
            if pipeline.span_stage() && bfpi_arch == BfpiArch::Tree {
                bail!(hdl_gen::segment::TREE_UNPIPELINED);
            }
            if fe_i0 == I0Form::Incremental && fe_di == DiMode::Scanline {
                bail!(
                    "--fe-i0 incremental takes --fe-di triangle: the per-scanline dI needs the reciprocal's I0 at every span's last pixel"
                );
            }
            let opts = Options { bfpi_arch, screen: Some(screen), fe_div_bits, fe_di, fe_i0, pipeline, bus, ..opts };
            opts.frontend().context("--width/--height")?;
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
            let ports = hdl_gen::tools::wrapper::ports_from_manifest(&text, &module)?;
            output::check_not_input(&out, &[&path])?;
            output::write_one(&out, hdl_gen::tools::wrapper::module(&module, &ports, outputs)?.render().as_bytes())?;
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
