//! segshade on a board (issue 30): the Radiona ULX3S (LFE5U-85F) top's RTL, its Verilator
//! simulation, and the check of its DVI output against golden, frame for frame.
//!
//! The RTL is `tri_fb_p<P>` (screen alignment, 320 x 240) and the board's generated modules
//! (`hdl_gen::board`), plus the hand-written video side and vendor cells in `board/rtl/`. The
//! simulation swaps only the vendor cells (`board/sim/board_cells_sim.v`), records the GPDI pins
//! after drawing ends, and [`frame`] cuts, checks and decodes one whole frame.

pub mod frame;
pub mod mesh;
pub mod send;
pub mod sim;
pub mod stream;
pub mod tmds;

use golden::frontend::{FixedTriangle, FrontEnd, FrontEndError};
use golden::setup::{Screen, Triangle};
use golden::writer::{Memory, Writer, WriterError};
use golden::{Align, Config};
use hdl_gen::board::{BoardError, Source};
use hdl_gen::GeneratedFile;

/// The frame buffer's screen: 640 x 480 with every pixel doubled.
pub const SCREEN: Screen = Screen { width: frame::WIDTH as u32, height: frame::HEIGHT as u32 };

/// The chain's register stages (`generate --pipeline 1`) and the front-end's quotient bits a
/// clock (`--fe-div-bits 2`): the fastest front-end measured on the ECP5-85F (47.5 MHz alone,
/// docs/fpga.md), where level 0 is 17 MHz. Both leave every value as golden computes it.
pub const PIPELINE: u32 = 1;
pub const FE_DIV_BITS: u32 = 2;

/// The hand-written RTL, written beside the generated files.
pub const HAND_WRITTEN: [(&str, &str); 4] = [
    ("board_fb.v", include_str!("../rtl/board_fb.v")),
    ("board_video.v", include_str!("../rtl/board_video.v")),
    ("tmds_encoder.v", include_str!("../rtl/tmds_encoder.v")),
    ("board_cells.v", include_str!("../rtl/board_cells.v")),
];
/// The simulation's files: the vendor cells' behavioural twin and the bench.
pub const SIM_FILES: [(&str, &str); 2] =
    [("board_cells_sim.v", include_str!("../sim/board_cells_sim.v")), ("board_tb.v", include_str!("../sim/board_tb.v"))];
/// The vendor cells' file, which the simulation leaves out.
pub const VENDOR_FILE: &str = "board_cells.v";

#[derive(Debug, thiserror::Error)]
pub enum RtlError {
    #[error("the configuration: {0}")]
    Config(#[from] golden::ConfigError),
    #[error("the 320x240 screen: {0}")]
    Screen(#[from] golden::setup::ScreenError),
    #[error("the front-end: {0}")]
    FrontEnd(#[from] FrontEndError),
    #[error("the writer: {0}")]
    Writer(#[from] WriterError),
    #[error(transparent)]
    Board(#[from] BoardError),
}

/// The configuration of the board's chain at `p`: screen alignment (a segment is a block).
pub fn config(p: u32) -> Result<Config, RtlError> {
    let d = Config::default();
    let cfg = Config::new(p, d.frac, d.xbits, Align::Screen)?;
    SCREEN.check_for(&cfg)?;
    Ok(cfg)
}

/// The triangles as they stand on the front-end's ports (golden's conversion).
pub fn fixed(cfg: &Config, tris: &[Triangle]) -> Vec<FixedTriangle> {
    tris.iter().map(|t| FixedTriangle::from_triangle(t, cfg.frac)).collect()
}

/// Every file of the board's RTL folder: the chain's modules, the board's, and for the ROM
/// source the ROM image of `tris` (the UART source takes its triangles from the serial line).
pub fn rtl_files(cfg: &Config, tris: &[FixedTriangle], source: Source) -> Result<Vec<GeneratedFile>, RtlError> {
    let opts = hdl_gen::Options {
        cfg: *cfg,
        screen: Some(SCREEN),
        pipeline: golden::pipeline::Pipeline::at(PIPELINE),
        fe_div_bits: Some(FE_DIV_BITS),
        ..Default::default()
    };
    let names = hdl_gen::Names::new("", cfg);
    let hw = opts.frontend()?;
    let w = opts.writer()?;
    let chain: Vec<String> =
        [&names.bfpi, &names.segment, &names.frontend, &names.fe_edge, &names.fe_div, &names.top, &names.writer, &names.fb_top]
            .iter()
            .map(|n| format!("{n}.v"))
            .collect();
    let mut files: Vec<GeneratedFile> = hdl_gen::generate(&opts).into_iter().filter(|f| chain.contains(&f.name)).collect();
    let modules = match source {
        Source::Rom => {
            let rom = hdl_gen::board::rom_image(&hw.fe, tris)?;
            files.push(GeneratedFile { name: hdl_gen::board::ROM_HEX.into(), contents: rom });
            vec![hdl_gen::board::draw_module(&hw.fe, &w, &names, tris.len())]
        }
        Source::Uart { div } => {
            use hdl_gen::board::uart;
            vec![hdl_gen::board::draw_module_uart(&hw.fe, &w, &names, div), uart::rx_module(div), uart::tx_module(div, uart::STATUS_LEN)]
        }
    };
    for m in modules.into_iter().chain([hdl_gen::board::top_module(&w, source)]) {
        files.push(GeneratedFile { name: format!("{}.v", m.name), contents: m.render() });
    }
    files.extend(HAND_WRITTEN.iter().map(|(n, c)| GeneratedFile { name: n.to_string(), contents: c.to_string() }));
    Ok(files)
}

/// Golden's picture of the triangles, drawn in order into the cleared block memory: what
/// `render --triangles FILE --frontend rtl --writer rtl` checks its memory against.
pub fn expected(cfg: &Config, tris: &[FixedTriangle]) -> Result<Vec<u8>, RtlError> {
    let fe = FrontEnd::new(*cfg, SCREEN)?;
    let w = Writer::new(*cfg, SCREEN)?;
    let mut mem = Memory::new(w);
    for t in tris {
        fe.spans(t, |y, span| {
            for bw in w.writes(y, &span) {
                mem.apply(&bw).expect("golden's writes stay in memory");
            }
        });
    }
    Ok(mem.frame().pixels().to_vec())
}

/// The differing pixels of two frames: their count and the first `(x, y, expected, got)`.
pub fn differences(expected: &[u8], got: &[u8]) -> (usize, Option<(usize, usize, u8, u8)>) {
    let mut first = None;
    let mut n = 0;
    for (k, (&e, &g)) in expected.iter().zip(got).enumerate() {
        if e != g {
            n += 1;
            first.get_or_insert((k % frame::WIDTH, k / frame::WIDTH, e, g));
        }
    }
    (n, first)
}

/// A grey PNG of a frame-buffer picture.
pub fn png(pixels: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, SCREEN.width, SCREEN.height);
    encoder.set_color(png::ColorType::Grayscale);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().expect("in-memory PNG header");
    writer.write_image_data(pixels).expect("in-memory PNG encoding");
    writer.finish().expect("in-memory PNG end");
    out
}

/// Drawing clocks of the last drawing in a ROM run's bench output: from the end of the clear
/// (`drawing from`) to `done`, less the 2^10 quiet clocks `done` waits for.
pub fn drawing_clocks(log: &str) -> Option<u64> {
    let at = |prefix: &str| log.lines().filter_map(|l| l.strip_prefix(prefix)?.strip_suffix(" ps")?.parse::<u64>().ok()).next_back();
    let (from, done) = (at("board_tb: drawing from ")?, at("board_tb: drawing done at ")?);
    let period_ps = (1e12 / hdl_gen::board::DRAW_HZ).round() as u64;
    (done.checked_sub(from)? / period_ps).checked_sub(1 << 10)
}
