//! What the two `board_draw` forms share (the ROM source's in `board.rs`, the UART source's in
//! `uart_draw.rs`): the triangle word's fields, reset, the common ports, the chain and the frame
//! buffer's write port. A leaf, so neither form imports the other's file.

use crate::verilog::{assign, comment, lit, net, reg, set, wire, Item, Port, Stmt};
use crate::Names;
use golden::frontend::FrontEnd;
use golden::writer::Writer;

pub const DRAW: &str = "board_draw";
/// Entries of the UART source's triangle queue: 2^10 words of the ROM's width (10 DP16KD at
/// the defaults), so a burst of 1024 triangles is taken whatever their size.
pub const QUEUE_BITS: u32 = 10;

/// Clocks without a block write, after the last triangle went in, before `done`: longer than
/// any set-up's or walk's gap between two writes (the dividers take tens of clocks).
pub(super) const QUIET_BITS: u32 = 10;

/// One ROM word: `{x0, y0, i0, x1, y1, i1, x2, y2, i2}`, x0 in the high bits, each field in its
/// port's width (two's complement for the coordinates).
pub(super) fn word_fields(fe: &FrontEnd) -> [(usize, u32); 9] {
    let w = fe.widths();
    let iw = fe.cfg.iw();
    [(0, w.cx), (1, w.cy), (2, iw), (0, w.cx), (1, w.cy), (2, iw), (0, w.cx), (1, w.cy), (2, iw)]
}

pub(super) fn word_bits(fe: &FrontEnd) -> u32 {
    word_fields(fe).iter().map(|f| f.1).sum()
}

/// Power-up and F1: `start` is high for 16 clocks after the PLL locks and for one clock on the
/// button's rising edge (two flops against metastability).
pub(super) fn reset_items() -> Vec<Item> {
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
pub(super) fn common_ports(w: &Writer, button: &str) -> Vec<Port> {
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
pub(super) fn chain_nets(p: u32, aw: u32) -> Vec<Item> {
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
pub(super) fn clear_step(aw: u32) -> Stmt {
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
pub(super) fn chain_and_port(fe: &FrontEnd, names: &Names, word: &str, bits: u32) -> Vec<Item> {
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
