//! The command-line options of one `generate` configuration, as clap `Args`: the one definition
//! of the flags that `hdl-gen generate` and the co-simulation binaries (`cosim`, `render`,
//! `sweep`, `bench gen`) share. Each binary flattens [`ModelArgs`] into its own arguments, so a
//! flag, its range and its help read alike everywhere, and a value one refuses, all refuse.
//! `--width`/`--height` are each program's own: `generate`'s default to the configuration's
//! widest screen up to 640 × 480, the binaries' also bound the random triangles.

use crate::{check_prefix, BfpiArch, Bus, Options, Target};
use clap::builder::{StringValueParser, TypedValueParser};
use clap::Args;
use golden::frontend::engine::SetupForm;
use golden::frontend::{DiMode, I0Form, SpanForm};
use golden::pipeline::Pipeline;
use golden::setup::Screen;
use golden::specular::{parse_rel_error, BrdfK, PlanError, SpecularPlan};
use golden::{Align, Config, ConfigError};

/// A configuration the flags describe but `generate` refuses (the ranges clap checks, it refuses
/// itself). Its message names the flag.
#[derive(Debug, thiserror::Error)]
pub enum ArgsError {
    #[error("{0}")]
    Config(#[from] ConfigError),
    #[error("--max-rel-error goes with --brdf-k auto")]
    RelErrorWithList,
    #[error("--brdf-k {choice}: {source}")]
    Brdf { choice: BrdfK, source: PlanError },
    #[error("{}", crate::segment::TREE_UNPIPELINED)]
    TreeUnpipelined,
    #[error("--fe-i0 incremental takes --fe-di triangle: the per-scanline dI needs the reciprocal's I0 at every span's last pixel")]
    IncrementalScanline,
    #[error("--fe-setup {0} takes --fe-di triangle and --fe-i0 reciprocal (only ice40-hx8k also takes incremental): its engine computes the per-triangle set-up only")]
    EngineForm(&'static str),
    #[error("--fe-span sequential takes --fe-setup ice40-hx8k or ice40-up5k and --fe-i0 reciprocal: its unit serves the reciprocal I0 behind a sequential set-up engine")]
    SequentialSpan,
    #[error("--width/--height: {0}")]
    Screen(#[from] golden::frontend::FrontEndError),
}

/// The segment width and its alignment: what names a model (`seg_p8_span`).
#[derive(Args, Clone, Debug)]
pub struct SegArgs {
    /// Segment width: pixels per clock, a power of two in 1..256.
    #[arg(long, default_value_t = golden::format::DEFAULT_P,
          value_parser = clap::value_parser!(u32).try_map(|p| golden::format::check_p(p).map(|()| p)))]
    pub p: u32,
    /// Segmentation: span (the seed's) or screen (segments on multiples of P).
    #[arg(long, value_enum, default_value_t = Align::Span)]
    pub align: Align,
}

/// The formats and the module prefix.
#[derive(Args, Clone, Debug)]
pub struct FormatArgs {
    /// Fraction bits F of the intensity format UQ8.F (4..20).
    #[arg(long = "frac", default_value_t = golden::format::DEFAULT_FRAC, value_parser = clap::value_parser!(u32).range(4..=20))]
    pub frac: u32,
    /// Screen-x bits XW (4..16).
    #[arg(long = "xbits", default_value_t = golden::format::DEFAULT_XBITS, value_parser = clap::value_parser!(u32).range(4..=16))]
    pub xbits: u32,
    /// String prepended to every module name.
    #[arg(long, default_value = "", value_parser = StringValueParser::new().try_map(|s| check_prefix(&s).map(|()| s)))]
    pub prefix: String,
}

/// The configuration and module prefix (`generate`'s, `testbench`'s).
#[derive(Args, Clone, Debug)]
pub struct ConfigArgs {
    #[command(flatten)]
    pub seg: SegArgs,
    #[command(flatten)]
    pub format: FormatArgs,
}

impl ConfigArgs {
    /// Options for this configuration with the table set `brdf`; the rest default.
    pub fn options(&self, brdf: &BrdfArgs) -> Result<Options, ArgsError> {
        let cfg = Config::new(self.seg.p, self.format.frac, self.format.xbits, self.seg.align)?;
        Ok(Options { cfg, prefix: self.format.prefix.clone(), brdf: brdf.plan()?, ..Options::default() })
    }
}

/// The specular unit's table set, shared by every command that builds the unit.
#[derive(Args, Clone, Debug)]
pub struct BrdfArgs {
    /// BRDF table set: a list of k (ascending, 1..64; each n then takes its least-error table),
    /// or `auto` to choose the set with the least ROM that meets --max-rel-error.
    /// Default: the patent's 1,2,4,16 with its n ranges.
    #[arg(long = "brdf-k")]
    pub brdf_k: Option<BrdfK>,
    /// With `--brdf-k auto`: largest relative error of the approximation inside the epicentre,
    /// as a fraction (0.01) or a percentage (1%).
    #[arg(long = "max-rel-error", value_parser = parse_rel_error, requires = "brdf_k")]
    pub max_rel_error: Option<f64>,
}

impl BrdfArgs {
    /// The plan, or `None` for the patent's own (the default).
    pub fn plan(&self) -> Result<Option<SpecularPlan>, ArgsError> {
        let choice = match (&self.brdf_k, self.max_rel_error) {
            (None, _) => return Ok(None),
            (Some(BrdfK::Auto { .. }), Some(e)) => BrdfK::Auto { max_err: e },
            (Some(BrdfK::List(_)), Some(_)) => return Err(ArgsError::RelErrorWithList),
            (Some(b), None) => b.clone(),
        };
        SpecularPlan::from_brdf_k(&choice).map(Some).map_err(|source| ArgsError::Brdf { choice, source })
    }
}

/// Every option of one `generate` configuration but P, the alignment, the screen
/// (`--width`/`--height`, each program's own) and the output folder: what `sweep` applies to
/// every P and alignment it sweeps.
#[derive(Args, Clone, Debug)]
pub struct VariantArgs {
    #[command(flatten)]
    pub format: FormatArgs,
    /// Increments: shift-add (SPEC's BFPI), or the comparison forms naive (`*` by constants)
    /// and tree (doubling tree in the shader, no BFPI) used by scripts/synth.
    #[arg(long = "bfpi-arch", value_enum, default_value_t = BfpiArch::ShiftAdd)]
    pub bfpi_arch: BfpiArch,
    #[command(flatten)]
    pub brdf: BrdfArgs,
    /// Quotient bits per clock of the front-end's set-up dividers: 1, 2 or 4. More bits,
    /// fewer set-up clocks per triangle (tiny triangles go faster), longer paths. Default: 4,
    /// or the target's choice.
    #[arg(long = "fe-div-bits", value_parser = clap::builder::PossibleValuesParser::new(["1", "2", "4"]).map(|b| b.parse::<u32>().expect("a listed value")))]
    pub fe_div_bits: Option<u32>,
    /// Where the front-end's dI comes from: `triangle` (the constant-increment theorem, once
    /// per triangle) or `scanline` (classical Gouraud, a division per span from the edge
    /// intensities with the same divider: a comparison option, slower and larger).
    #[arg(long = "fe-di", value_enum, default_value_t = DiMode::Triangle)]
    pub fe_di: DiMode,
    /// How the front-end forms each span's I0: `reciprocal` (three wide products a row in
    /// the span path) or `incremental` (quotient and remainder over 2A stepped by adds per
    /// source of the span's left end; the reciprocal only at a source's first covered row, on
    /// one shared multiplier, the walker waiting meanwhile). Same spans bit for bit. The
    /// default stays `reciprocal` until the incremental form measures better (docs/design.md,
    /// issue 27). `incremental` takes `--fe-di triangle` only. Default: `reciprocal`, or the
    /// target's choice.
    #[arg(long = "fe-i0", value_enum)]
    pub fe_i0: Option<I0Form>,
    /// How the front-end sets a triangle up: `parallel` (CALC's products in one clock and
    /// eight dividers, the default) or the shared set-up engine on a device's plan, `ecp5-25f`,
    /// `ice40-up5k` or `ice40-hx8k` (golden's `Plan`: a few shared multipliers and dividers
    /// sequenced over several clocks a triangle, behind a set-up result queue; docs/design.md).
    /// Same spans bit for bit. The engine forms take `--fe-di triangle --fe-i0 reciprocal` (`ice40-hx8k` also `--fe-i0 incremental`).
    /// Default: `parallel`, or the target's choice.
    #[arg(long = "fe-setup", value_enum)]
    pub fe_setup: Option<SetupForm>,
    /// How the front-end's span path forms a covered row's three I0 products: `parallel` (a
    /// row a clock, the products in tiles or logic) or `sequential` (one shift-add unit, a few
    /// dozen clocks a covered row, the walker waiting; the iCE40s' choice, with their
    /// sequential engines and `--fe-i0 reciprocal`). Same spans bit for bit. Default:
    /// `parallel`, or the target's choice.
    #[arg(long = "fe-span", value_enum)]
    pub fe_span: Option<SpanForm>,
    /// Register stages added for clock rate, 0..3 (golden::pipeline): 1 registers the span and
    /// the shader's increments, splits the specular unit's multiplies, and stages the
    /// front-end (CALC in five clocks, its span path in eight), 2 also the shader's lane sums, 3 cuts the shader's adders
    /// so no clock has two in a row (same stages as 2). Values and throughput are the same at every
    /// level; latency grows (manifest.json). 0, the default: SPEC's seed structure, smallest
    /// and shortest (docs/fpga.md compares the levels). Or the target's choice.
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=Pipeline::MAX as i64))]
    pub pipeline: Option<u32>,
    /// The FPGA to generate for: chooses the front-end's form, the pipeline level and the
    /// dividers' rate that measured best on that device (docs/design.md, "Targets"). Flags given
    /// with it still override its choices.
    #[arg(long, value_enum)]
    pub target: Option<Target>,
    /// Stream interfaces: `native` (SPEC's ports only) or `axis`, which also writes an
    /// AXI4-Stream wrapper `<module>_axis` of the segment shader, the front-end, its chain
    /// and the specular unit, with Vivado interface attributes (docs/axis.md).
    #[arg(long, value_enum, default_value_t = Bus::Native)]
    pub bus: Bus,
}

impl VariantArgs {
    /// The options of P and `align` with these flags, on `screen` (`None`:
    /// [`Options::default_screen`]), checked as `generate` checks them.
    pub fn options(&self, p: u32, align: Align, screen: Option<Screen>) -> Result<Options, ArgsError> {
        let config = ConfigArgs { seg: SegArgs { p, align }, format: self.format.clone() };
        let opts = config.options(&self.brdf)?;
        // A flag given wins over the target's choice, which wins over the option's default.
        let choice = self.target.map(Target::choice);
        let pipeline = self.pipeline.or(choice.map(|c| c.pipeline)).unwrap_or(0);
        let pipeline = Pipeline::new(pipeline).expect("clap checked the range; the targets' levels exist");
        let fe_i0 = self.fe_i0.or(choice.map(|c| c.fe_i0)).unwrap_or_default();
        let fe_setup = self.fe_setup.or(choice.map(|c| c.fe_setup)).unwrap_or_default();
        if pipeline.span_stage() && self.bfpi_arch == BfpiArch::Tree {
            return Err(ArgsError::TreeUnpipelined);
        }
        if fe_i0 == I0Form::Incremental && self.fe_di == DiMode::Scanline {
            return Err(ArgsError::IncrementalScanline);
        }
        // The HX8K's sequential engine takes the incremental I0 too (its span path has no product).
        let i0_ok = fe_i0 == I0Form::Reciprocal || fe_setup == SetupForm::Ice40Hx8k;
        if fe_setup != SetupForm::Parallel && (!i0_ok || self.fe_di != DiMode::Triangle) {
            return Err(ArgsError::EngineForm(fe_setup.name()));
        }
        // The sequential span path serves the reciprocal I0 behind a sequential engine: a target's
        // choice of it gives way where a flag chose another set-up or I0; a flag asking for it there
        // is refused.
        let seq_ok = matches!(fe_setup, SetupForm::Ice40Hx8k | SetupForm::Ice40Up5k) && fe_i0 == I0Form::Reciprocal;
        let fe_span = match self.fe_span {
            Some(SpanForm::Sequential) if !seq_ok => return Err(ArgsError::SequentialSpan),
            Some(s) => s,
            None => choice.map(|c| c.fe_span).filter(|_| seq_ok).unwrap_or_default(),
        };
        let opts = Options {
            bfpi_arch: self.bfpi_arch,
            screen,
            fe_div_bits: self.fe_div_bits.or(choice.and_then(|c| c.fe_div_bits)),
            fe_di: self.fe_di,
            fe_i0,
            fe_setup,
            fe_span,
            pipeline,
            bus: self.bus,
            target: self.target,
            ..opts
        };
        opts.frontend()?;
        Ok(opts)
    }
}

/// Every option of one `generate` configuration but the screen and the output folder: the
/// model a binary runs.
#[derive(Args, Clone, Debug)]
pub struct ModelArgs {
    #[command(flatten)]
    pub seg: SegArgs,
    #[command(flatten)]
    pub variant: VariantArgs,
}

impl ModelArgs {
    /// The options these flags give, on `screen` (`None`: [`Options::default_screen`]).
    pub fn options(&self, screen: Option<Screen>) -> Result<Options, ArgsError> {
        self.variant.options(self.seg.p, self.seg.align, screen)
    }
}

/// The argument ids of [`ModelArgs`] (its field names: `p`, `pipeline`, `fe_div_bits`, ...), for
/// a binary that asks its `ArgMatches` which of them were typed on the command line.
pub fn model_arg_ids() -> Vec<String> {
    use clap::Args as _;
    ModelArgs::augment_args(clap::Command::new("model")).get_arguments().map(|a| a.get_id().to_string()).collect()
}

/// Those of [`model_arg_ids`] given on the command line (not left to their defaults), in the
/// subcommand's arguments when there is one (`bench gen`).
pub fn given_model_args(m: &clap::ArgMatches) -> Vec<String> {
    let m = m.subcommand().map_or(m, |(_, sub)| sub);
    let known: Vec<String> = m.ids().map(|i| i.to_string()).collect();
    model_arg_ids()
        .into_iter()
        .filter(|id| known.contains(id) && m.value_source(id) == Some(clap::parser::ValueSource::CommandLine))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        model: ModelArgs,
    }

    fn options(args: &[&str]) -> Options {
        let cli = Cli::try_parse_from(std::iter::once("t").chain(args.iter().copied())).expect("the flags parse");
        cli.model.options(None).expect("a configuration generate accepts")
    }

    /// A target fills the options it chooses; a flag beside it wins; without it every option is
    /// its own default (so the comparison below can fail).
    #[test]
    fn a_target_chooses_and_a_given_flag_overrides_it() {
        let plain = options(&[]);
        assert_eq!((plain.pipeline.level(), plain.fe_div_bits, plain.target, plain.fe_setup), (0, None, None, SetupForm::Parallel));
        for t in [Target::Ecp5_25f, Target::Ice40Hx8k, Target::Ice40Up5k] {
            let c = t.choice();
            let chosen = options(&["--target", t.name()]);
            assert_eq!(chosen.target, Some(t));
            assert_eq!(
                (chosen.pipeline.level(), chosen.fe_div_bits, chosen.fe_i0, chosen.fe_setup, chosen.fe_span),
                (c.pipeline, c.fe_div_bits, c.fe_i0, c.fe_setup, c.fe_span)
            );
            let over = options(&[
                "--target",
                t.name(),
                "--pipeline",
                "0",
                "--fe-setup",
                "parallel",
                "--fe-div-bits",
                "4",
                "--fe-i0",
                "incremental",
            ]);
            assert_eq!(
                (over.pipeline.level(), over.fe_div_bits, over.fe_i0, over.fe_setup),
                (0, Some(4), I0Form::Incremental, SetupForm::Parallel),
                "{t}"
            );
        }
        assert!(Cli::try_parse_from(["t", "--target", "ecp5-85f"]).is_err());
    }

    /// The iCE40 targets choose the sequential span path; `--fe-span parallel` overrides it, and
    /// it gives way to a flag's other set-up or I0; asked for where it cannot serve, one message.
    #[test]
    fn the_ice40_targets_choose_the_sequential_span_path() {
        for t in ["ice40-hx8k", "ice40-up5k"] {
            assert_eq!(options(&["--target", t]).fe_span, SpanForm::Sequential, "{t}");
            assert_eq!(options(&["--target", t, "--fe-span", "parallel"]).fe_span, SpanForm::Parallel, "{t}");
            assert_eq!(options(&["--target", t, "--fe-setup", "parallel"]).fe_span, SpanForm::Parallel, "{t}");
        }
        assert_eq!(options(&["--target", "ice40-hx8k", "--fe-i0", "incremental"]).fe_span, SpanForm::Parallel);
        assert_eq!(options(&["--target", "ecp5-25f"]).fe_span, SpanForm::Parallel);
        assert_eq!(options(&["--fe-setup", "ice40-up5k", "--fe-span", "sequential"]).fe_span, SpanForm::Sequential);
        for bad in [&["--fe-span", "sequential"][..], &["--target", "ecp5-25f", "--fe-span", "sequential"]] {
            let cli = Cli::try_parse_from(std::iter::once("t").chain(bad.iter().copied())).expect("the flags parse");
            assert!(matches!(cli.model.options(None), Err(ArgsError::SequentialSpan)), "{bad:?}");
        }
    }

    /// The HX8K's sequential engine takes the incremental I0 (its span path without a product);
    /// the other engines refuse it with one message.
    #[test]
    fn only_the_hx8k_engine_takes_the_incremental_i0() {
        let hx = options(&["--target", "ice40-hx8k", "--fe-i0", "incremental"]);
        assert_eq!((hx.fe_setup, hx.fe_i0), (SetupForm::Ice40Hx8k, I0Form::Incremental));
        for plan in ["ecp5-25f", "ice40-up5k"] {
            let cli = Cli::try_parse_from(["t", "--fe-setup", plan, "--fe-i0", "incremental"]).expect("the flags parse");
            let err = cli.model.options(None).expect_err("a pipelined engine with the incremental I0");
            assert!(matches!(err, ArgsError::EngineForm(p) if p == plan), "{plan}: {err}");
        }
    }
}
