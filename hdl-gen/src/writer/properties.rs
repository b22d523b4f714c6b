//! The block writer's formal properties (scripts/prove): every write against a reference writer.

use crate::formal::{assert, covers, past_flags, reset_and_stability, when, CUT_TAG, LEMMA_DEFINE};
use crate::verilog::{comment, lit, reg, set, wire, zext, Item, Stmt};
use golden::Align;

/// Properties of `fb_writer_p<P>` (SPEC §7) against a reference writer kept beside it.
///
/// The reference places each accepted segment's pixels by their screen x, without the
/// rotation the writer uses: lane j of a segment at x goes to block `x div P + (r + j) div P`,
/// lane `(r + j) mod P` (r = x mod P), so lanes r.. of the rotated mask are the head block and
/// the rest the tail, written with the next segment's head or, after the span's last segment,
/// on its own. Asserted: every write the writer issues is the reference's (valid, address and
/// enables, and the pixels under the enables; what a disabled lane carries is free), `in_ready`
/// holds only for the tail's own write, reset, stability, no write without an enable, and a
/// pixel count: the pixels accepted and not yet taken by memory are exactly those in the write
/// register and the pending tail, so none is lost or written twice.
///
/// The reference follows one block lane, `f_lane`, that the solver picks freely (`$anyconst`),
/// so everything lane-wise holds for every lane: which input lane lands there (`f_lane - r`
/// mod P, in the head block when `f_lane >= r`), its enable, its pixel, the pending tail's bit
/// and the count of pixels owed on it. Nothing in the properties is P lanes wide but the
/// writer's own registers: a whole-mask reference (enables shifted by r, counts of ones over P
/// lanes) made the solver prove that a rotation keeps a mask's ones, which took minutes at
/// P = 16 and did not finish at P = 64. What needs every lane is recovered from the lane-wise
/// statements and one whole-word one, "no write without an enable": a write is offered exactly
/// when the reference's has an enabled lane, and the tail's own write (`flush`) is owed exactly
/// when a span's last segment left a pixel in its tail.
///
/// The pixel path of the span-aligned writer, its rotation (`rot_pix`, a 16P-bit shift by 8r)
/// against the reference's lane select, is a lemma ([`LEMMA_DEFINE`]): for every input, offset
/// and lane, lane `f_lane` of `rot_pix` is input lane `f_lane - r`. Proven on its own and then
/// assumed with `rot_pix` cut, it keeps the induction from re-proving it in each step, which grew
/// ~30-fold per doubling of P past 32 (P = 128: 379 s; P = 256 unfinished after 30 min).
///
/// The environment is held to what the shader's own proof guarantees (assume-guarantee):
/// the segments of a span follow each other at x + P on one scanline.
pub fn writer_properties(w: &golden::writer::Writer) -> Item {
    let cfg = &w.cfg;
    let (p, l, yw) = (cfg.p, cfg.log2p(), w.y_bits());
    let aw = w.addr_bits();
    let glued = cfg.align == Align::Span && p > 1;
    // 2-inductive (stability looks one clock back); each further step of the base case and the
    // induction costs most of the proof (P = 64 span: 11 s at depth 2, 45 s at 4).
    let mut b = vec![comment(format!("{CUT_TAG}depth 2"))];
    b.extend(past_flags());
    b.extend(reset_and_stability("write", ("mem_valid", "mem_ready"), &["mem_addr", "mem_data", "mem_we"]));
    b.push(comment("No write without an enable."));
    b.push(Item::Comb(vec![when("f_past && mem_valid", vec![assert(format!("mem_we != {}", lit(p, 0)))])]));

    b.push(comment("The reference: each pixel placed by its screen x."));
    b.push(wire("f_free", 1, "!mem_valid || mem_ready"));
    b.push(wire("f_take", 1, "in_valid && in_ready"));
    let blk = block_of(w, "in_x");
    b.push(wire("f_addr", aw, format!("{} * {} + {blk}", zext("in_y", yw, aw), lit(aw, w.blocks_per_row() as u64))));
    b.push(comment("Everything lane-wise is checked on one lane of the block, f_lane, that the solver picks"));
    b.push(comment("freely, so it holds for every lane; following one lane keeps the reference free of"));
    b.push(comment("shifters and counts over all lanes."));
    let (lane, at) = match p > 1 {
        true => {
            b.push(wire("f_lane", l, "$anyconst"));
            ("f_lane", "{f_lane, 3'b000}")
        }
        false => ("0", "0"),
    };
    // The write register as the reference has it: a write attempted (f_wr; it is offered when an
    // enable is set), its address, f_lane's enable and f_lane's pixel.
    for (n, wd) in [("f_wr", 1), ("f_ma", aw), ("f_ml", 1), ("f_md", 8)] {
        b.push(reg(n, wd));
    }
    let mut link = vec![];
    if glued {
        link.extend(glued_reference(w, lane, at, &mut b));
    } else {
        b.push(wire("f_in", 1, format!("in_mask[{lane}]")));
        b.push(comment("One write per segment: its block, its lanes as they come."));
        b.push(Item::Always(vec![Stmt::If(
            "rst".into(),
            vec![set("f_wr", "1'b0"), set("f_ml", "1'b0")],
            vec![when(
                "f_free",
                vec![
                    set("f_wr", "in_valid"),
                    set("f_ma", "f_addr"),
                    set("f_ml", "in_valid && f_in"),
                    set("f_md", format!("in_pix[{at} +: 8]")),
                ],
            )],
        )]));
        b.push(comment("Valid never waits for ready, and nothing makes the writer refuse a segment but a full register."));
        b.push(Item::Comb(vec![when("f_past", vec![assert("in_ready == f_free")])]));
    }
    b.push(comment("Every write is the reference's: offered when f_lane is enabled in it, only when one was"));
    b.push(comment("attempted (with \"no write without an enable\" and every lane: exactly when the reference's"));
    b.push(comment("write enables some lane); its address, f_lane's enable and, under it, f_lane's pixel."));
    b.push(Item::Comb(vec![when(
        "f_past",
        vec![
            when("f_ml", vec![assert("mem_valid")]),
            when(
                "mem_valid",
                vec![
                    assert("f_wr"),
                    assert("mem_addr == f_ma"),
                    assert(format!("mem_we[{lane}] == f_ml")),
                    when(format!("mem_we[{lane}]"), vec![assert(format!("mem_data[{at} +: 8] == f_md"))]),
                ],
            ),
        ],
    )]));
    b.push(comment("Pixels owed on lane f_lane of the block: accepted, not yet taken by memory. They are"));
    b.push(comment("exactly the write register's and the pending tail's, so no pixel is lost, invented or"));
    b.push(comment("written twice on any lane."));
    b.push(reg("f_owed", 2));
    let held = if glued { "(f_pl ? 2'd1 : 2'd0)" } else { "2'd0" };
    b.push(Item::Always(vec![Stmt::If(
        "rst".into(),
        vec![set("f_owed", "2'd0")],
        vec![set("f_owed", format!("f_owed + (f_take && f_in ? 2'd1 : 2'd0) - (mem_valid && mem_ready && mem_we[{lane}] ? 2'd1 : 2'd0)"))],
    )]));
    link.push(assert(format!("f_owed == (mem_valid && mem_we[{lane}] ? 2'd1 : 2'd0) + {held}")));
    b.push(comment("Linking invariants: the writer's registers are the reference's."));
    b.push(Item::Comb(vec![when("f_past", link)]));
    let mut reach = vec![("Block written: a write taken.", "mem_valid && mem_ready")];
    if glued {
        reach.push(("Tail written: its own write, after a span.", "flush && mem_valid && mem_ready"));
    }
    b.extend(covers(8, &reach));
    Item::Formal(b)
}

/// The block number of x, as an address term; on a screen narrower than 2^XW it is narrower
/// than the port (x < W).
fn block_of(w: &golden::writer::Writer, x: &str) -> String {
    let (l, aw) = (w.cfg.log2p(), w.addr_bits());
    match w.block_bits() {
        0 => lit(aw, 0),
        bw => zext(&format!("{x}[{}:{l}]", l + bw - 1), bw, aw),
    }
}

/// The span-aligned writer's reference: the rotation (a lemma), the pending tail, the
/// shader's guarantee about a span's next segment, the write register's clock, and the links
/// for the tail's own write (returned).
fn glued_reference(w: &golden::writer::Writer, lane: &str, at: &str, b: &mut Vec<Item>) -> Vec<Stmt> {
    let cfg = &w.cfg;
    let (p, l, xw, yw) = (cfg.p, cfg.log2p(), cfg.xbits, w.y_bits());
    let aw = w.addr_bits();
    let rotation = format!("rot_pix[{at} +: 8] == f_pix");
    b.extend([
        wire("f_r", l, format!("in_x[{}:0]", l - 1)),
        comment("Input lane j lands on block lane (r + j) mod P: f_lane gets input lane f_lane - r (mod P),"),
        comment("in the segment's head block when f_lane >= r, else in its tail (the next block)."),
        wire("f_src", l, "f_lane - f_r"),
        wire("f_in", 1, "in_mask[f_src]"),
        wire("f_head", 1, "f_lane >= f_r"),
        wire("f_pix", 8, "in_pix[{f_src, 3'b000} +: 8]"),
        comment("The rotation on lane f_lane, a lemma: asserted in a proof of its own, which sees the"),
        comment("rotation for every input, lane and offset, and assumed here, where the rotation is cut (the"),
        comment("solver would otherwise redo that proof inside the induction: minutes at P = 128)."),
        comment(format!("{CUT_TAG}cutpoint w:rot_pix")),
        Item::IfDef {
            name: LEMMA_DEFINE.into(),
            then: vec![Item::Comb(vec![assert(rotation.clone())])],
            els: vec![Item::Comb(vec![Stmt::Assume(rotation)])],
        },
        comment("The pending tail: f_pl, f_lane's pixel f_pp is in it and not yet written; block f_pa; the"),
        comment("segment that left it (f_px, f_py) and whether its span goes on (f_cont)."),
        reg("f_cont", 1),
        reg("f_pl", 1),
        reg("f_pa", aw),
        reg("f_pp", 8),
        reg("f_px", xw),
        reg("f_py", yw),
    ]);
    b.push(comment("What the shader guarantees: a span's next segment is P pixels on, on its scanline."));
    b.push(Item::Comb(vec![when(
        "f_past && f_take && f_cont",
        vec![Stmt::Assume(format!("in_x == f_px + {} && in_y == f_py", lit(xw, p as u64)))],
    )]));
    // The tail's own write follows the writer's `flush`, which the links below pin to the
    // reference's: set exactly when a span's last segment left a pixel in its tail.
    b.push(Item::Always(vec![Stmt::If(
        "rst".into(),
        vec![set("f_wr", "1'b0"), set("f_ml", "1'b0"), set("f_cont", "1'b0"), set("f_pl", "1'b0")],
        vec![when(
            "f_free",
            vec![Stmt::If(
                "flush".into(),
                vec![set("f_wr", "1'b1"), set("f_ma", "f_pa"), set("f_ml", "f_pl"), set("f_md", "f_pp"), set("f_pl", "1'b0")],
                vec![Stmt::If(
                    "in_valid".into(),
                    vec![
                        set("f_wr", "1'b1"),
                        set("f_ma", "f_addr"),
                        set("f_ml", "(f_in && f_head) || (f_cont && f_pl)"),
                        set("f_md", "f_in && f_head ? f_pix : f_pp"),
                        set("f_pl", "f_in && !f_head"),
                        set("f_pa", format!("f_addr + {}", lit(aw, 1))),
                        set("f_pp", "f_pix"),
                        set("f_px", "in_x"),
                        set("f_py", "in_y"),
                        set("f_cont", "!in_last"),
                    ],
                    vec![set("f_wr", "1'b0"), set("f_ml", "1'b0")],
                )],
            )],
        )],
    )]));
    b.push(comment("The writer takes a segment exactly when its write register is free and no tail owes its"));
    b.push(comment("own write (flush: the reference's, by the links below)."));
    b.push(Item::Comb(vec![when("f_past", vec![assert("in_ready == (f_free && !flush)")])]));
    vec![
        assert("cont == f_cont"),
        Stmt::Comment("flush is the reference's: only after a span's last segment, only for a tail with a pixel".into()),
        Stmt::Comment("(on some lane, so on f_lane for some choice), and whenever f_lane's pixel is owed there.".into()),
        when("flush", vec![assert("!f_cont"), assert(format!("pend_we != {}", lit(p, 0)))]),
        when("f_pl && !f_cont", vec![assert("flush")]),
        when("f_cont || flush", vec![assert("pend_addr == f_pa"), assert(format!("pend_we[{lane}] == f_pl"))]),
        when("f_pl", vec![assert(format!("pend_pix[{at} +: 8] == f_pp"))]),
        // The reference's own: a pending tail lies below the span's lane offset, in the block after
        // the last segment's.
        when("f_pl", vec![assert(format!("{lane} < f_px[{}:0]", l - 1))]),
        when(
            "f_cont || flush",
            vec![assert(format!(
                "f_pa == {} * {} + {} + {}",
                zext("f_py", yw, aw),
                lit(aw, w.blocks_per_row() as u64),
                block_of(w, "f_px"),
                lit(aw, 1)
            ))],
        ),
    ]
}
