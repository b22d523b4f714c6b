//! `hdl-gen`: the command line of the segshade generator.

use clap::{Parser, Subcommand};
use golden::{Align, Config};
use hdl_gen::{check_prefix, generate, output, Options};
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
    Generate {
        /// Segment width: pixels per clock, a power of two in 1..256.
        #[arg(long, default_value_t = golden::format::DEFAULT_P, value_parser = parse_p)]
        p: u32,
        /// Fraction bits F of the intensity format UQ8.F (4..20).
        #[arg(long = "frac", default_value_t = golden::format::DEFAULT_FRAC, value_parser = clap::value_parser!(u32).range(4..=20))]
        frac: u32,
        /// Screen-x bits XW (4..16).
        #[arg(long = "xbits", default_value_t = golden::format::DEFAULT_XBITS, value_parser = clap::value_parser!(u32).range(4..=16))]
        xbits: u32,
        /// Segmentation: span (the seed's) or screen (segments on multiples of P).
        #[arg(long, default_value = "span", value_parser = ["span", "screen"])]
        align: String,
        /// String prepended to every module name.
        #[arg(long, default_value = "", value_parser = parse_prefix)]
        prefix: String,
        /// Output folder (created if missing).
        #[arg(long)]
        out: PathBuf,
    },
}

fn parse_p(s: &str) -> Result<u32, String> {
    let p: u32 = s.parse().map_err(|_| format!("'{s}' is not a whole number"))?;
    golden::format::check_p(p)?;
    Ok(p)
}

fn parse_prefix(s: &str) -> Result<String, String> {
    check_prefix(s)?;
    Ok(s.to_string())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Generate { p, frac, xbits, align, prefix, out } => {
            let align: Align = align.parse().expect("clap checked the alignment");
            Config::new(p, frac, xbits, align)
                .and_then(|cfg| output::write_all(&out, &generate(&Options { cfg, prefix })))
                .map(|()| eprintln!("wrote {}", out.display()))
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
