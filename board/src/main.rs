//! `board ulx3s-85f [--triangles FILE] [--p P] [--source rom|uart] --out DIR`: writes the board
//! top's RTL into DIR/rtl, simulates it with Verilator (for the UART source, the file sent over
//! the simulated serial line), and writes DIR/tmds.bin (one whole frame of symbols) and
//! DIR/frame.png (the frame they decode to), checked against golden pixel for pixel.
//! Exit 0: equal; 1: the frame differs or is not valid DVI; 2: bad input.
//!
//! `board send --port PATH [--baud N] FILE`: sends a triangle file to a board built with
//! `--source uart` (docs/board.md). It lives in this binary, not one of its own, because the
//! board's configuration, the wire format and the UART source's simulation are this crate's.

use anyhow::Context;
use clap::{Parser, Subcommand, ValueEnum};
use hdl_gen::board::{uart, Source, DRAW_HZ};
use segshade_board::{config, differences, expected, fixed, frame, png, rtl_files, send, sim, stream};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(about = "The segshade board top: RTL, simulation, and its DVI frame checked against golden; and the host's sender")]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Radiona ULX3S with the LFE5U-85F; DVI on its GPDI connector.
    #[command(name = "ulx3s-85f")]
    Ulx3s85f(Args),
    /// Send a triangle file to the board's UART source (a tty, or a file or pipe to check the bytes).
    Send(SendArgs),
    /// Write a Wavefront mesh as a triangle file for the board: lit, culled, back to front.
    Mesh(MeshArgs),
}

#[derive(clap::Args)]
struct MeshArgs {
    /// The mesh (e.g. meshes/teapot.obj).
    #[arg(long, value_name = "FILE.obj")]
    obj: PathBuf,
    /// The triangle file to write.
    #[arg(long)]
    out: PathBuf,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum SourceArg {
    /// The triangle file in block RAM, drawn at power-up and on F1.
    Rom,
    /// Triangles streamed over the USB serial port (FT231X), drawn as they come.
    Uart,
}

#[derive(clap::Args)]
struct Args {
    /// A triangle file (`render --triangles` format): the ROM's, or the one the simulation sends
    /// over the serial line; default docs/teapot-board.txt.
    #[arg(long)]
    triangles: Option<PathBuf>,
    /// Pixels per block write of tri_fb_p<P>.
    #[arg(long, default_value_t = 8)]
    p: u32,
    /// Where the triangles come from.
    #[arg(long, value_enum, default_value_t = SourceArg::Rom)]
    source: SourceArg,
    /// The UART source's rate (the FT231X takes at most 3000000).
    #[arg(long, default_value_t = uart::DEFAULT_BAUD)]
    baud: u32,
    /// Output folder: rtl/, sim/, tmds.bin, frame.png (and expected.png when they differ).
    #[arg(long)]
    out: PathBuf,
    /// Write the RTL only; no simulation.
    #[arg(long)]
    rtl_only: bool,
    /// ROM source: press F1 (btn[1]) in simulation once drawing is done, and record after the redraw.
    #[arg(long)]
    redraw: bool,
    /// Seed of the registers' random power-up values in simulation.
    #[arg(long, default_value_t = 1)]
    seed: u64,
}

#[derive(clap::Args)]
struct SendArgs {
    /// The serial port (e.g. /dev/ttyUSB0), or a file or pipe to write the bytes to.
    #[arg(long)]
    port: PathBuf,
    /// The rate the board was built for (`--baud` of ulx3s-85f).
    #[arg(long, default_value_t = uart::DEFAULT_BAUD)]
    baud: u32,
    /// Then ask the board for its status record and print its counts (a tty only).
    #[arg(long)]
    status: bool,
    /// A triangle file (`render --triangles` format).
    file: PathBuf,
}

const DEFAULT_TRIANGLES: &str = include_str!("../../docs/teapot-board.txt");
const DEFAULT_NAME: &str = "docs/teapot-board.txt";

fn usage(e: impl std::fmt::Display) -> ExitCode {
    eprintln!("error: {e}");
    ExitCode::from(2)
}

fn main() -> ExitCode {
    match Cli::parse().cmd {
        Cmd::Ulx3s85f(args) => board(&args),
        Cmd::Send(args) => send_file(&args),
        Cmd::Mesh(args) => mesh_file(&args),
    }
}

/// Refuses an output file `out` that cannot be written or is `input` (by any name): checked
/// before the work, so a bad path is a usage error and never destroys the input.
fn check_out(flag: &str, out: &std::path::Path, input: &std::path::Path) -> Result<(), ExitCode> {
    hdl_gen::output::check_writable(out)
        .and_then(|()| hdl_gen::output::check_not_input(out, &[input]))
        .map_err(|e| usage(format!("{flag}: {e}")))
}

fn mesh_file(args: &MeshArgs) -> ExitCode {
    let name = args.obj.display().to_string();
    if let Err(code) = check_out("--out", &args.out, &args.obj) {
        return code;
    }
    let text = match hdl_gen::input::read_text(&args.obj) {
        Ok(t) => t,
        Err(e) => return usage(format!("--obj {e}")),
    };
    let (out, faces, front) = match segshade_board::mesh::painter_triangles(&text, &name, frame::WIDTH as f64, frame::HEIGHT as f64) {
        Ok(r) => r,
        Err(e) => return usage(format!("--obj {name}: {e}")),
    };
    if let Err(e) = hdl_gen::output::write_one(&args.out, out.as_bytes()) {
        eprintln!("error: --out {}: {e}", args.out.display());
        return ExitCode::from(1);
    }
    println!("wrote       {} ({front} of {faces} triangles facing the viewer, back to front)", args.out.display());
    ExitCode::SUCCESS
}

fn send_file(args: &SendArgs) -> ExitCode {
    let what = args.file.display().to_string();
    // A port that is a folder, a file in no folder, or the file itself (by any name) is bad
    // input. A device or pipe (/dev/stdout) is opened as it is, not checked as a file to replace.
    let device = std::fs::metadata(&args.port).is_ok_and(|m| !m.is_file() && !m.is_dir());
    if device {
        if let Err(e) = hdl_gen::output::check_not_input(&args.port, &[&args.file]) {
            return usage(format!("--port: {e}"));
        }
    } else if let Err(code) = check_out("--port", &args.port, &args.file) {
        return code;
    }
    let sent = (|| {
        uart::divider(args.baud, DRAW_HZ)?;
        let text = hdl_gen::input::read_text(&args.file).map_err(|e| send::SendError::Input(e.to_string()))?;
        let bytes = send::packets(&text, &what)?;
        let status = send::send(&args.port, args.baud, &bytes, args.status)?;
        Ok::<_, send::SendError>((bytes.len(), status))
    })();
    match sent {
        Ok((n, status)) => {
            println!("sent        {n} bytes ({} packets) to {} at {} baud", n / uart::LEN, args.port.display(), args.baud);
            match (args.status, status) {
                (false, _) => ExitCode::SUCCESS,
                (true, Some(s)) => {
                    println!(
                        "board:      {} packets taken, {} bad windows, {} framing errors, {} triangles dropped on receipt, {} outside the guard band",
                        s.packets, s.bad, s.framing, s.dropped, s.guard
                    );
                    ExitCode::SUCCESS
                }
                (true, None) => {
                    eprintln!("error: --status: no status record from the board within 2 s");
                    ExitCode::from(1)
                }
            }
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(if e.is_usage() { 2 } else { 1 })
        }
    }
}

fn board(args: &Args) -> ExitCode {
    if args.out.exists() && !args.out.is_dir() {
        return usage(format!("--out {}: not a folder (the board writes rtl/, sim/ and its frame into it)", args.out.display()));
    }
    let text = match &args.triangles {
        None => DEFAULT_TRIANGLES.to_string(),
        Some(f) => {
            // The files the run replaces in --out: none may be the triangle file.
            for name in ["tmds.bin", "frame.png", "expected.png"] {
                if let Err(e) = hdl_gen::output::check_not_input(&args.out.join(name), &[f]) {
                    return usage(format!("--out: {e}"));
                }
            }
            match hdl_gen::input::read_text(f) {
                Ok(t) => t,
                Err(e) => return usage(format!("--triangles {e}")),
            }
        }
    };
    let what = args.triangles.as_ref().map_or(DEFAULT_NAME.into(), |f| f.display().to_string());
    let tris = match golden::setup::parse_triangles(&text) {
        Ok(t) => t,
        Err(e) => return usage(format!("{what}: {e}")),
    };
    let cfg = match config(args.p) {
        Ok(c) => c,
        Err(e) => return usage(format!("--p {}: {e}", args.p)),
    };
    let source = match args.source {
        SourceArg::Rom => Source::Rom,
        SourceArg::Uart => match uart::divider(args.baud, DRAW_HZ) {
            Ok(div) => Source::Uart { div },
            Err(e) => return usage(format!("--baud {e}")),
        },
    };
    let tris = fixed(&cfg, &tris);
    let files = match rtl_files(&cfg, &tris, source) {
        Ok(f) => f,
        Err(e) => return usage(format!("{what}: {e}")),
    };
    let packets = match source {
        Source::Rom => None,
        Source::Uart { .. } => match send::packets(&text, &what) {
            Ok(b) => Some(b),
            Err(e) => return usage(e),
        },
    };
    match run(args, &cfg, &tris, &files, packets.as_deref()) {
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
    packets: Option<&[u8]>,
) -> anyhow::Result<bool> {
    let rtl = args.out.join("rtl");
    hdl_gen::output::write_all(&rtl, files).with_context(|| format!("--out {}", args.out.display()))?;
    match packets {
        None => println!("wrote       {} ({} files, {} triangles in ROM)", rtl.display(), files.len(), tris.len()),
        Some(_) => println!("wrote       {} ({} files, UART source at {} baud)", rtl.display(), files.len(), args.baud),
    }
    if args.rtl_only {
        return Ok(true);
    }
    let work = args.out.join("sim");
    let t = std::time::Instant::now();
    let exe = sim::build(&rtl, &work)?;
    println!("verilated   {:.1} s", t.elapsed().as_secs_f64());
    let t = std::time::Instant::now();
    let (rec, log) = match packets {
        None => sim::simulate(&exe, &rtl, &work, args.seed, args.redraw)?,
        Some(bytes) => {
            let stimulus = work.join("stream.txt");
            std::fs::write(&stimulus, stream::stimulus(&stream::bytes(bytes)))
                .with_context(|| format!("writing {}", stimulus.display()))?;
            // Each packet's 320 bits, and the drawing and the frame after them.
            let line_ms = (bytes.len() as f64 * 10.0 / args.baud as f64 * 1e3).ceil() as u32;
            let s = sim::Stream { stimulus, baud: args.baud, writes: false, timeout_ms: line_ms + 100 };
            let r = sim::simulate_stream(&exe, &rtl, &work, args.seed, &s)?;
            (r.recording.expect("a recording"), r.log)
        }
    };
    print!("{log}");
    println!("simulated   {:.1} s", t.elapsed().as_secs_f64());
    if let (None, Some(clocks)) = (packets, segshade_board::drawing_clocks(&log)) {
        let secs = clocks as f64 / DRAW_HZ;
        println!(
            "drawing:    {} triangles in {clocks} clocks at {:.2} MHz: {:.0} triangles/s",
            tris.len(),
            DRAW_HZ / 1e6,
            tris.len() as f64 / secs
        );
    }
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
