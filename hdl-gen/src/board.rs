//! The generated half of the ULX3S board top (issue 30): `board_draw`, the drawing clock's side
//! (the triangle ROM, the frame buffer's clear, `tri_fb_p<P>` fed from the ROM), and the pin-level
//! top `segshade_ulx3s` that wires it to the hand-written video side and vendor cells
//! (`board/rtl/*.v`). What depends on P, the screen or the front-end's port widths is generated
//! here; what does not (video timing, TMDS, the serializer, the RAM lanes) is plain Verilog.

pub mod uart;
mod uart_draw;

pub use uart_draw::draw_module as draw_module_uart;

use crate::verilog::{assign, comment, lit, net, reg, set, wire, Item, Module, Param, Port, Stmt};
use crate::Names;
use golden::frontend::{FixedTriangle, FrontEnd};
use golden::writer::Writer;

/// The drawing clock: board_cells' PLL, 625 MHz / 16 (its `DRAW_DIV`).
pub const DRAW_HZ: f64 = 625e6 / 16.0;

/// Where the board's triangles come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// Baked into a ROM at generate time, drawn at power-up and on F1.
    Rom,
    /// Streamed over the FT231X's serial line at `div` drawing clocks a bit ([`uart`]).
    Uart { div: u32 },
}

/// Entries of the UART source's triangle queue: 2^10 words of the ROM's width (10 DP16KD at
/// the defaults), so a burst of 1024 triangles is taken whatever their size.
pub const QUEUE_BITS: u32 = 10;

/// Triangles the ROM holds at most: 4096 words of 3 x (x, y, I) bits, 180 at the defaults, so
/// at most 40 of the LFE5U-85F's 208 DP16KD blocks (as 512 x 36; the teapot's took 36), beside
/// the 320x240 frame buffer's 40: room for the teapot's 2176 front faces (docs/teapot-board.txt).
pub const MAX_TRIANGLES: usize = 4096;
/// The ROM image `board_draw` loads by `$readmemh` (a file beside the Verilog).
pub const ROM_HEX: &str = "board_tris.hex";
/// The generated modules' names.
pub const DRAW: &str = "board_draw";
pub const TOP: &str = "segshade_ulx3s";
/// Clocks without a block write, after the last triangle went in, before `done`: longer than
/// any set-up's or walk's gap between two writes (the dividers take tens of clocks).
const QUIET_BITS: u32 = 10;

/// Why no board is generated for a triangle list.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum BoardError {
    #[error("{count} triangles do not fit the board's triangle ROM (at most {limit})")]
    TooMany { count: usize, limit: usize },
    #[error("triangle {triangle}: a vertex does not fit the front-end's ports")]
    Ports { triangle: usize },
}

/// One ROM word: `{x0, y0, i0, x1, y1, i1, x2, y2, i2}`, x0 in the high bits, each field in its
/// port's width (two's complement for the coordinates).
fn word_fields(fe: &FrontEnd) -> [(usize, u32); 9] {
    let w = fe.widths();
    let iw = fe.cfg.iw();
    [(0, w.cx), (1, w.cy), (2, iw), (0, w.cx), (1, w.cy), (2, iw), (0, w.cx), (1, w.cy), (2, iw)]
}

fn word_bits(fe: &FrontEnd) -> u32 {
    word_fields(fe).iter().map(|f| f.1).sum()
}

/// ROM depth: a power of two above the last index, so the read address one past the last
/// triangle (where the sequencer rests) still names a word.
fn rom_depth(n: usize) -> usize {
    n.max(1).next_power_of_two().max(2)
}

/// The ROM image: one hex word a line, the triangles in file order, zero-padded to the depth.
pub fn rom_image(fe: &FrontEnd, tris: &[FixedTriangle]) -> Result<String, BoardError> {
    if tris.len() > MAX_TRIANGLES {
        return Err(BoardError::TooMany { count: tris.len(), limit: MAX_TRIANGLES });
    }
    if let Some(k) = tris.iter().position(|t| !fe.fits_ports(t)) {
        return Err(BoardError::Ports { triangle: k + 1 });
    }
    let bits = word_bits(fe);
    let digits = bits.div_ceil(4) as usize;
    let mut out = String::new();
    for k in 0..rom_depth(tris.len()) {
        // Up to 3 x (22 + 19 + 20) bits at the widest defaults: u128 is not enough at wide XW,
        // so the word is built as bits, most significant first.
        let mut word: Vec<bool> = Vec::with_capacity(bits as usize);
        if let Some(t) = tris.get(k) {
            for (v, (field, width)) in word_fields(fe).iter().enumerate() {
                let value: u64 = match field {
                    0 => t.x[v / 3] as u64,
                    1 => t.y[v / 3] as u64,
                    _ => t.i[v / 3] as u64,
                };
                word.extend((0..*width).rev().map(|b| value >> b & 1 == 1));
            }
        } else {
            word.resize(bits as usize, false);
        }
        let pad = digits * 4 - word.len();
        let mut all = vec![false; pad];
        all.extend(word);
        for nibble in all.chunks(4) {
            let d = nibble.iter().fold(0u32, |a, &b| a << 1 | b as u32);
            out.push(char::from_digit(d, 16).expect("a nibble"));
        }
        out.push('\n');
    }
    Ok(out)
}

fn bits_for(n: u64) -> u32 {
    (64 - n.leading_zeros()).max(1)
}

/// `board_draw`: on the drawing clock, clears the frame buffer, then streams the ROM's
/// triangles into `tri_fb_p<P>` and its block writes into the frame buffer's write port.
pub fn draw_module(fe: &FrontEnd, w: &Writer, names: &Names, triangles: usize) -> Module {
    let p = fe.cfg.p;
    let aw = w.addr_bits();
    let bits = word_bits(fe);
    let depth = rom_depth(triangles);
    let raw = bits_for(depth as u64 - 1);
    let kw = bits_for(triangles as u64);
    let header = vec![
        format!("{DRAW} — the ULX3S board's drawing clock: clear the frame buffer, then draw the ROM's triangles."),
        "Generated by segshade hdl-gen (board); do not edit.".into(),
        String::new(),
        format!(
            "{triangles} triangles in a {depth} x {bits} ROM ({ROM_HEX}); {} on a {}x{} screen, {} blocks of {p} pixels.",
            names.fb_top,
            w.screen.width,
            w.screen.height,
            w.blocks()
        ),
        "After `locked` rises or the button is pressed: one clock per block writes zeros (all lanes), then".into(),
        "the triangles go in, in ROM order; `done` rises once the last is in and the chain has written".into(),
        format!("nothing for 2^{QUIET_BITS} clocks."),
    ];
    let mut ports = common_ports(w, "clear and draw again");
    ports.extend([
        Port::output("done", 1, "", "the picture is complete").reg(),
        Port::output("err_seen", 1, "", "a triangle was dropped (outside the guard band) since the last start").reg(),
    ]);
    let mut body = vec![
        Item::Localparam { name: "NTRI".into(), width: kw, value: lit(kw, triangles as u64) },
        Item::Localparam { name: "LAST_BLOCK".into(), width: aw, value: lit(aw, w.blocks() as u64 - 1) },
        Item::Memory { name: "rom".into(), width: bits, depth: depth as u32 },
        Item::ReadMemH { file: "INIT_FILE".into(), mem: "rom".into() },
        Item::Blank,
    ];
    body.extend(reset_items());
    body.extend([
        reg("clearing", 1),
        reg("drawing", 1),
        reg("caddr", aw),
        reg("k", kw),
        reg("ld", 1),
        reg("quiet", QUIET_BITS),
        reg("rom_q", bits),
    ]);
    body.extend(chain_nets(p, aw));
    body.extend([
        wire("in_valid", 1, "drawing && ld && (k != NTRI)"),
        wire("accept", 1, "in_valid && in_ready"),
        // k rests at NTRI after the last triangle; its low bits then name a padding word.
        wire("rd_addr", raw, if kw > raw { format!("k[{}:0]", raw - 1) } else { crate::verilog::zext("k", kw, raw) }),
        Item::Always(vec![
            set("rom_q", "rom[rd_addr]"),
            Stmt::If(
                "start".into(),
                vec![
                    set("clearing", "1'b1"),
                    set("drawing", "1'b0"),
                    set("caddr", lit(aw, 0)),
                    set("k", lit(kw, 0)),
                    set("ld", "1'b0"),
                    set("quiet", lit(QUIET_BITS, 0)),
                    set("done", "1'b0"),
                    set("err_seen", "1'b0"),
                ],
                vec![
                    clear_step(aw),
                    Stmt::If(
                        "drawing".into(),
                        vec![
                            // A read takes a clock: after a transfer, the next word is loaded first.
                            Stmt::If(
                                "accept".into(),
                                vec![set("k", format!("k + {}", lit(kw, 1))), set("ld", "1'b0")],
                                vec![set("ld", "1'b1")],
                            ),
                            Stmt::If(
                                "(k == NTRI) && !mem_valid".into(),
                                vec![Stmt::If(
                                    format!("quiet == {}", lit(QUIET_BITS, (1 << QUIET_BITS) - 1)),
                                    vec![set("done", "1'b1")],
                                    vec![set("quiet", format!("quiet + {}", lit(QUIET_BITS, 1)))],
                                )],
                                vec![set("quiet", lit(QUIET_BITS, 0))],
                            ),
                        ],
                        vec![],
                    ),
                    Stmt::If("tri_err".into(), vec![set("err_seen", "1'b1")], vec![]),
                ],
            ),
        ]),
        Item::Blank,
        comment("The chain is held in reset until the clear is over; the ROM word's fields, x0 in the high bits."),
    ]);
    body.extend(chain_and_port(fe, names, "rom_q", bits));
    Module {
        name: DRAW.into(),
        header,
        params: vec![Param { name: "INIT_FILE".into(), value: format!("\"{ROM_HEX}\""), doc: "$readmemh image of the triangles".into() }],
        ports,
        body,
    }
}

/// Power-up and F1: `start` is high for 16 clocks after the PLL locks and for one clock on the
/// button's rising edge (two flops against metastability).
fn reset_items() -> Vec<Item> {
    vec![
        comment("Reset: 16 clocks after lock, and the button's rising edge (two flops against metastability)."),
        reg("por", 5),
        reg("btn_s", 3),
        wire("start", 1, "!por[4] || (btn_s[1] && !btn_s[2])"),
        Item::Always(vec![
            Stmt::If("!locked".into(), vec![set("por", "5'd0")], vec![Stmt::If("!por[4]".into(), vec![set("por", "por + 5'd1")], vec![])]),
            set("btn_s", "{btn_s[1:0], redraw}"),
        ]),
        Item::Blank,
    ]
}

/// Both sources' clock, reset, button and frame-buffer write port; `button` says what F1 does.
fn common_ports(w: &Writer, button: &str) -> Vec<Port> {
    let (p, aw) = (w.cfg.p, w.addr_bits());
    vec![
        Port::input("clk", 1, "", "drawing clock, rising edge"),
        Port::input("locked", 1, "", "the PLL's lock: low holds everything in reset"),
        Port::input("redraw", 1, "", &format!("button, asynchronous, active high: {button}")),
        Port::output("fb_we", p, "bit per lane", "frame buffer write enable of lane i").vector(),
        Port::output("fb_addr", aw, "unsigned integer", &format!("block y * {} + x div {p}", w.blocks_per_row())),
        Port::output("fb_data", 8 * p, &format!("{p} lanes of UQ8.0"), "lane i = pixel x mod P = i"),
    ]
}

/// The chain's outputs.
fn chain_nets(p: u32, aw: u32) -> Vec<Item> {
    vec![
        net("in_ready", 1),
        net("tri_err", 1),
        net("mem_valid", 1),
        net("mem_addr", aw),
        net("mem_data", 8 * p),
        Item::Bus { name: "mem_we".into(), width: p },
    ]
}

/// One block of the clear a clock; drawing starts after the last.
fn clear_step(aw: u32) -> Stmt {
    Stmt::If(
        "clearing".into(),
        vec![
            set("caddr", format!("caddr + {}", lit(aw, 1))),
            Stmt::If("caddr == LAST_BLOCK".into(), vec![set("clearing", "1'b0"), set("drawing", "1'b1")], vec![]),
        ],
        vec![],
    )
}

/// The chain fed from `word`, and the frame buffer's write port: the clear's zeros, then the
/// chain's block writes.
fn chain_and_port(fe: &FrontEnd, names: &Names, word: &str, bits: u32) -> Vec<Item> {
    let p = fe.cfg.p;
    vec![
        Item::Instance { module: names.fb_top.clone(), name: "u_chain".into(), params: vec![], conns: chain_conns(fe, word, bits) },
        Item::Blank,
        comment("The frame buffer's write port: the clear's zeros, then the chain's block writes."),
        assign("fb_we", format!("clearing ? {{{p}{{1'b1}}}} : ((drawing && mem_valid) ? mem_we : {})", lit(p, 0))),
        assign("fb_addr", "clearing ? caddr : mem_addr"),
        assign("fb_data", format!("clearing ? {} : mem_data", lit(8 * p, 0))),
    ]
}

/// `tri_fb_p<P>`'s connections: held in reset until the clear is over, its triangle from the
/// word's fields (x0 in the high bits), its block writes to the frame buffer's port.
fn chain_conns(fe: &FrontEnd, word: &str, bits: u32) -> Vec<(String, String)> {
    let mut conns: Vec<(String, String)> = vec![
        ("clk".into(), "clk".into()),
        ("rst".into(), "!drawing".into()),
        ("in_valid".into(), "in_valid".into()),
        ("in_ready".into(), "in_ready".into()),
    ];
    let mut hi = bits;
    for (v, (field, width)) in word_fields(fe).iter().enumerate() {
        let name = format!("in_{}{}", ["x", "y", "i"][*field], v / 3);
        conns.push((name, format!("{word}[{}:{}]", hi - 1, hi - width)));
        hi -= width;
    }
    for (port, sig) in [
        ("err", "tri_err"),
        ("mem_valid", "mem_valid"),
        ("mem_ready", "drawing"),
        ("mem_addr", "mem_addr"),
        ("mem_data", "mem_data"),
        ("mem_we", "mem_we"),
    ] {
        conns.push((port.into(), sig.into()));
    }
    conns
}

/// `segshade_ulx3s`: the board's pins (the names of the ULX3S LPF) and the four blocks.
pub fn top_module(w: &Writer, source: Source) -> Module {
    let p = w.cfg.p;
    let aw = w.addr_bits();
    let header = vec![
        format!(
            "{TOP} — segshade on the Radiona ULX3S: triangles from {}, drawn into a frame buffer, shown as DVI on GPDI.",
            match source {
                Source::Rom => "ROM",
                Source::Uart { .. } => "the USB serial port",
            }
        ),
        "Generated by segshade hdl-gen (board); do not edit.".into(),
        String::new(),
        format!(
            "Frame buffer {}x{} 8-bit grey, {} blocks of {p} pixels; 640x480 at 60 Hz, each pixel doubled.",
            w.screen.width,
            w.screen.height,
            w.blocks()
        ),
        "Clocks (board_cells): 25 MHz pixel, 125 MHz shift (DDR: 10 bits per pixel clock), the drawing clock.".into(),
        "The frame buffer crosses the clocks: a true dual-port RAM, written on the drawing clock, read on the pixel clock.".into(),
        match source {
            Source::Rom => "LEDs: 0 drawing done, 1 PLL locked, 2 a triangle was dropped. btn[1] (F1): clear and draw again.",
            Source::Uart { .. } => {
                "LEDs: 0 all received drawn, 1 PLL locked, 2 a triangle dropped, 3 a framing error, 4 a bad packet, 7:5 packets taken. btn[1] (F1): reset."
            }
        }
        .into(),
    ];
    let ports = vec![
        Port::input("clk_25mhz", 1, "", "the board's 25 MHz oscillator"),
        Port::input("btn", 7, "", "buttons; btn[1] redraws"),
        Port::output("led", 8, "", "status"),
        Port::output("gpdi_dp", 4, "", "TMDS: blue (syncs), green, red, clock; the LPF makes them differential"),
        Port::input("ftdi_txd", 1, "", "the FT231X's TXD: the host's serial line into the board"),
        Port::output("ftdi_rxd", 1, "", "the FT231X's RXD: the board's serial line to the host"),
    ];
    let mut draw_conns: Vec<(String, String)> = [
        ("clk", "clk_draw"),
        ("locked", "locked"),
        ("redraw", "btn[1]"),
        ("fb_we", "fb_we"),
        ("fb_addr", "fb_waddr"),
        ("fb_data", "fb_wdata"),
        ("done", "done"),
        ("err_seen", "err_seen"),
    ]
    .map(|(a, b)| (a.to_string(), b.to_string()))
    .into();
    let (unused, led, flags) = match source {
        Source::Rom => ("&{1'b1, btn[0], btn[6:2], ftdi_txd}", "{5'd0, err_seen, locked, done}", vec![]),
        Source::Uart { .. } => {
            draw_conns.extend(
                [("rx", "ftdi_txd"), ("tx", "ftdi_rxd"), ("ferr_seen", "ferr_seen"), ("bad_seen", "bad_seen"), ("pk", "pk")]
                    .map(|(a, b)| (a.to_string(), b.to_string())),
            );
            (
                "&{1'b1, btn[0], btn[6:2]}",
                "{pk, bad_seen, ferr_seen, err_seen, locked, done}",
                vec![net("ferr_seen", 1), net("bad_seen", 1), net("pk", 3)],
            )
        }
    };
    let mut body = vec![
        net("clk_pix", 1),
        net("clk_shift", 1),
        net("clk_draw", 1),
        net("locked", 1),
        net("ddr_d0", 4),
        net("ddr_d1", 4),
        Item::Bus { name: "fb_we".into(), width: p },
        net("fb_waddr", aw),
        net("fb_wdata", 8 * p),
        net("fb_raddr", aw),
        net("fb_rdata", 8 * p),
        net("done", 1),
        net("err_seen", 1),
        wire("unused_in", 1, unused),
    ];
    body.extend(flags);
    if source == Source::Rom {
        body.push(assign("ftdi_rxd", "1'b1"));
    }
    body.extend([
        Item::Instance {
            module: "board_cells".into(),
            name: "u_cells".into(),
            params: vec![],
            conns: [
                ("clk_in", "clk_25mhz"),
                ("clk_pix", "clk_pix"),
                ("clk_shift", "clk_shift"),
                ("clk_draw", "clk_draw"),
                ("locked", "locked"),
                ("ddr_d0", "ddr_d0"),
                ("ddr_d1", "ddr_d1"),
                ("ddr_q", "gpdi_dp"),
            ]
            .map(|(a, b)| (a.to_string(), b.to_string()))
            .into(),
        },
        Item::Instance { module: DRAW.into(), name: "u_draw".into(), params: vec![], conns: draw_conns },
        Item::Instance {
            module: "board_fb".into(),
            name: "u_fb".into(),
            params: vec![("P".into(), p.to_string()), ("AW".into(), aw.to_string()), ("BLOCKS".into(), w.blocks().to_string())],
            conns: [
                ("wclk", "clk_draw"),
                ("we", "fb_we"),
                ("waddr", "fb_waddr"),
                ("wdata", "fb_wdata"),
                ("rclk", "clk_pix"),
                ("raddr", "fb_raddr"),
                ("rdata", "fb_rdata"),
            ]
            .map(|(a, b)| (a.to_string(), b.to_string()))
            .into(),
        },
        Item::Instance {
            module: "board_video".into(),
            name: "u_video".into(),
            params: vec![("P".into(), p.to_string()), ("AW".into(), aw.to_string()), ("BPR".into(), w.blocks_per_row().to_string())],
            conns: [
                ("clk_pix", "clk_pix"),
                ("clk_shift", "clk_shift"),
                ("locked", "locked"),
                ("fb_addr", "fb_raddr"),
                ("fb_data", "fb_rdata"),
                ("ddr_d0", "ddr_d0"),
                ("ddr_d1", "ddr_d1"),
            ]
            .map(|(a, b)| (a.to_string(), b.to_string()))
            .into(),
        },
        assign("led", led),
    ]);
    Module { name: TOP.into(), header, params: vec![], ports, body }
}
