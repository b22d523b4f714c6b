//! `board ulx3s-85f [--triangles FILE] [--p P] --out DIR`: writes the board top's RTL into
//! DIR/rtl, simulates it with Verilator, and writes DIR/tmds.bin (one whole frame of symbols)
//! and DIR/frame.png (the frame they decode to), checked against golden pixel for pixel.
//! Exit 0: equal; 1: the frame differs or is not valid DVI; 2: bad input.

use anyhow::Context;
use clap::{Parser, ValueEnum};
use segshade_board::{config, differences, expected, fixed, frame, png, rtl_files, sim};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Clone, Copy, ValueEnum)]
enum Board {
    /// Radiona ULX3S with the LFE5U-85F; DVI on its GPDI connector.
    #[value(name = "ulx3s-85f")]
    Ulx3s85f,
}

#[derive(Parser)]
#[command(about = "The segshade board top: RTL, simulation, and its DVI frame checked against golden")]
struct Args {
    board: Board,
    /// A triangle file (`render --triangles` format) drawn at power-up; default docs/triangles.txt.
    #[arg(long)]
    triangles: Option<PathBuf>,
    /// Pixels per block write of tri_fb_p<P>.
    #[arg(long, default_value_t = 8)]
    p: u32,
    /// Output folder: rtl/, sim/, tmds.bin, frame.png (and expected.png when they differ).
    #[arg(long)]
    out: PathBuf,
    /// Write the RTL only; no simulation.
    #[arg(long)]
    rtl_only: bool,
    /// Press F1 (btn[1]) in simulation once drawing is done, and record after the redraw.
    #[arg(long)]
    redraw: bool,
    /// Seed of the registers' random power-up values in simulation.
    #[arg(long, default_value_t = 1)]
    seed: u64,
}

const DEFAULT_TRIANGLES: &str = include_str!("../../docs/triangles.txt");

fn usage(e: impl std::fmt::Display) -> ExitCode {
    eprintln!("error: {e}");
    ExitCode::from(2)
}

fn main() -> ExitCode {
    let args = Args::parse();
    let Board::Ulx3s85f = args.board;
    let text = match &args.triangles {
        None => DEFAULT_TRIANGLES.to_string(),
        Some(f) => match std::fs::read_to_string(f) {
            Ok(t) => t,
            Err(e) => return usage(format!("--triangles {}: {e}", f.display())),
        },
    };
    let what = args.triangles.as_ref().map_or("docs/triangles.txt".into(), |f| f.display().to_string());
    let tris = match golden::setup::parse_triangles(&text) {
        Ok(t) => t,
        Err(e) => return usage(format!("{what}: {e}")),
    };
    let cfg = match config(args.p) {
        Ok(c) => c,
        Err(e) => return usage(format!("--p {}: {e}", args.p)),
    };
    let tris = fixed(&cfg, &tris);
    let files = match rtl_files(&cfg, &tris) {
        Ok(f) => f,
        Err(e) => return usage(format!("{what}: {e}")),
    };
    match run(&args, &cfg, &tris, &files) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(1),
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(1)
        }
    }
}

fn run(
    args: &Args,
    cfg: &golden::Config,
    tris: &[golden::frontend::FixedTriangle],
    files: &[hdl_gen::GeneratedFile],
) -> anyhow::Result<bool> {
    let rtl = args.out.join("rtl");
    hdl_gen::output::write_all(&rtl, files).with_context(|| format!("--out {}", args.out.display()))?;
    println!("wrote       {} ({} files, {} triangles in ROM)", rtl.display(), files.len(), tris.len());
    if args.rtl_only {
        return Ok(true);
    }
    let work = args.out.join("sim");
    let t = std::time::Instant::now();
    let exe = sim::build(&rtl, &work)?;
    println!("verilated   {:.1} s", t.elapsed().as_secs_f64());
    let t = std::time::Instant::now();
    let (rec, log) = sim::simulate(&exe, &rtl, &work, args.seed, args.redraw)?;
    print!("{log}");
    println!("simulated   {:.1} s", t.elapsed().as_secs_f64());
    let text = std::fs::read_to_string(&rec).with_context(|| format!("reading {}", rec.display()))?;
    let clocks = frame::parse_recording(&text)?;
    let start = frame::frame_start(&clocks)?;
    let one = &clocks[start..start + frame::CLOCKS];
    let tmds = args.out.join("tmds.bin");
    hdl_gen::output::write_one(&tmds, &frame::tmds_bin(one))?;
    println!("wrote       {}", tmds.display());
    let got = frame::decode_frame(one)?;
    let png_path = args.out.join("frame.png");
    hdl_gen::output::write_one(&png_path, &png(&got))?;
    println!("wrote       {}", png_path.display());
    let want = expected(cfg, tris)?;
    match differences(&want, &got) {
        (0, _) => {
            println!("frame:      equal to golden's picture pixel for pixel ({}x{})", frame::WIDTH, frame::HEIGHT);
            Ok(true)
        }
        (n, first) => {
            let exp_path = args.out.join("expected.png");
            hdl_gen::output::write_one(&exp_path, &png(&want))?;
            let (x, y, e, g) = first.expect("a difference");
            println!(
                "MISMATCH    {n} pixels differ from golden's picture; first ({x}, {y}): expected {e}, got {g} (golden: {})",
                exp_path.display()
            );
            Ok(false)
        }
    }
}
