//! The formal properties each streaming module carries under `` `ifdef FORMAL ``: SPEC §3's
//! stream contract as assertions, and the invariants that make it provable by k-induction.
//!
//! The contract is checked at the ports against a *shadow* of the accepted spans, kept in the
//! property block: the spans whose segments have not all appeared yet (at most two: the one
//! at the output and the one loaded behind it). Every segment that appears is compared with
//! the one SPEC §3 says comes next (x, mask, last), so a segment lost, repeated, invented or
//! out of order fails, and a third span accepted while two are owed means one was dropped.
//!
//! Port properties alone are not inductive: a solver can start from a state in which the
//! shader's registers disagree with the shadow and stall forever. The generator knows its
//! stage structure, so it also states how the current-span registers relate to the shadow
//! (the linking invariants); with them every property is 1- or 2-inductive. They are
//! assertions too, so a wrong invariant fails rather than proves something false.
//!
//! The environment is held to one rule only: reset in the first clock. Sources need not keep
//! `in_valid` or the span steady (SPEC asks them to), so the proof covers any input sequence.
//! Pixel values are left to co-simulation and to the BFPI proof (`bfpi_reference`): each
//! lane is the accumulator plus a proven multiple of dI.

use crate::verilog::{assign, comment, lit, net, reg, set, sext, wire, zext, Item, Module, Port, Stmt};
use golden::{Align, Config};

/// A comment `scripts/prove` reads: the Yosys command, if any, that cuts what the solver cannot
/// manage out of this module's proof. The generator knows which blocks those are; the script
/// applies only what the module asks for.
pub const CUT_TAG: &str = "scripts/prove: ";

/// The define under which a module's lemmas are asserted: `scripts/prove` first proves them on
/// their own (`read_verilog -D`, every assumption removed, step 0: a lemma is a combinational
/// fact about the module's inputs, free there), then proves the module with them assumed and
/// what they describe cut. A fact the induction would otherwise rediscover in every step (the
/// writer's 256-lane rotation: over 30 min at P = 256) is proven once, in ~2 min.
pub const LEMMA_DEFINE: &str = "FORMAL_LEMMAS";

/// The output stream of the shader and the specular unit (SPEC §3).
const OUT: (&str, &str) = ("out_valid", "out_ready");

fn assert(c: impl Into<String>) -> Stmt {
    Stmt::Assert(c.into())
}
fn when(cond: impl Into<String>, then: Vec<Stmt>) -> Stmt {
    Stmt::If(cond.into(), then, vec![])
}

/// `f_past` (one clock since the solver's start) and `f_past2` (two), and the reset rule.
fn past_flags() -> Vec<Item> {
    vec![
        comment("Clocks since the start: $past is meaningful once f_past is set."),
        Item::RegInit { name: "f_past".into(), width: 1, value: "1'b0".into() },
        Item::RegInit { name: "f_past2".into(), width: 1, value: "1'b0".into() },
        Item::Always(vec![set("f_past", "1'b1"), set("f_past2", "f_past")]),
        comment("The one rule the environment keeps: reset in the first clock."),
        Item::Comb(vec![when("!f_past", vec![Stmt::Assume("rst".into())])]),
    ]
}

/// Reset (nothing out the clock after `rst`) and stability (an output offered on `valid` and
/// not taken by `ready` stays valid with every `held` port unchanged): the stream contract's
/// first two rules.
fn reset_and_stability(what: &str, (valid, ready): (&str, &str), held: &[&str]) -> Vec<Item> {
    let mut hold = vec![assert(valid)];
    hold.extend(held.iter().map(|q| assert(format!("{q} == $past({q})"))));
    vec![
        comment(format!("Reset: no {what} out of reset.")),
        Item::Always(vec![when("f_past && $past(rst)", vec![assert(format!("!{valid}"))])]),
        comment(format!("Stability: a {what} offered and not taken stays, unchanged.")),
        Item::Always(vec![when(format!("f_past && !$past(rst) && $past({valid} && !{ready})"), hold)]),
    ]
}

/// `name`: SPEC §3's mask of the segment `off` pixels into a span of `tot` = lead + m pixels,
/// lane i inside when `lead <= off + i < tot` (widths: `rw` for off and tot, `lw` for lead).
fn spec_mask(name: &str, (off, lead, tot): (&str, &str, &str), p: u32, (rw, lw): (u32, u32)) -> Vec<Item> {
    vec![
        net(name, p),
        Item::ForGenerate {
            var: "fk".into(),
            count: p,
            label: "f_lane".into(),
            body: vec![
                Item::Localparam { name: "FK".into(), width: rw + 1, value: "fk".into() },
                assign(
                    format!("{name}[fk]"),
                    format!("({{1'b0, {off}}} + FK >= {}) && ({{1'b0, {off}}} + FK < {{1'b0, {tot}}})", zext(lead, lw, rw + 1)),
                ),
            ],
        },
    ]
}

/// Properties of `segment_shader_p<P>` (names as `segment::module_with` declares them).
pub fn segment_properties(cfg: &Config, rw: u32) -> Item {
    let (p, xw, log2p) = (cfg.p, cfg.xbits, cfg.log2p());
    let screen = cfg.align == Align::Screen && p > 1;
    let lw = log2p.max(1);
    // Largest lead + m: the pixels-left counter's range.
    let max_tot = (1u64 << (xw + 1)) - 1 + if screen { p as u64 - 1 } else { 0 };
    let pr = lit(rw, p as u64);
    let mut b = past_flags();

    b.extend(reset_and_stability("segment", OUT, &["out_x", "out_pix", "out_mask", "out_last"]));

    b.push(comment("The shadow: spans accepted whose segments have not all appeared. Span h's next"));
    b.push(comment("segment starts f_h_off pixels after its first block's x (f_h_b); t waits behind it."));
    b.push(comment("A span is first lead (x0 mod P in screen alignment) masked lanes, then m pixels: tot = lead + m."));
    for s in ["h", "t"] {
        b.push(reg(&format!("f_{s}_v"), 1));
        b.push(reg(&format!("f_{s}_b"), xw));
        b.push(reg(&format!("f_{s}_lead"), lw));
        b.push(reg(&format!("f_{s}_tot"), rw));
    }
    b.push(reg("f_h_off", rw));
    let (in_b, in_lead) = if screen {
        let blk = if log2p == xw { lit(xw, 0) } else { format!("{{in_x[{}:{log2p}], {}}}", xw - 1, lit(log2p, 0)) };
        (blk, format!("in_x[{}:0]", log2p - 1))
    } else {
        ("in_x".to_string(), lit(lw, 0))
    };
    b.push(wire("f_in_b", xw, in_b));
    b.push(wire("f_in_lead", lw, in_lead));
    b.push(wire("f_in_tot", rw, format!("{} + {}", zext("in_len", xw + 1, rw), zext("f_in_lead", lw, rw))));
    b.push(comment("A new segment is on the output when it is valid and the register could load."));
    b.push(reg("f_free", 1));
    b.push(Item::Always(vec![set("f_free", "rst || !out_valid || out_ready")]));
    b.push(wire("f_fresh", 1, "f_past && out_valid && f_free"));
    b.push(wire("f_left", rw, "f_h_tot - f_h_off"));
    b.push(wire("f_exp_last", 1, format!("f_left <= {pr}")));
    b.push(wire("f_exp_x", xw, format!("f_h_b + f_h_off[{}:0]", xw - 1)));
    b.extend(spec_mask("f_exp_mask", ("f_h_off", "f_h_lead", "f_h_tot"), p, (rw, lw)));
    b.push(wire("f_push", 1, "in_valid && in_ready && in_len != 0"));
    b.push(wire("f_pop", 1, "f_fresh && f_exp_last"));
    b.push(comment("Each new segment is the one SPEC §3 says comes next; none comes unowed."));
    b.push(Item::Comb(vec![when(
        "f_fresh",
        vec![assert("f_h_v"), assert("out_x == f_exp_x"), assert("out_last == f_exp_last"), assert("out_mask == f_exp_mask")],
    )]));
    let take = |dst: &str, src: &str| -> Vec<Stmt> {
        ["b", "lead", "tot"].iter().map(|f| set(format!("f_{dst}_{f}"), format!("f_{src}_{f}"))).collect()
    };
    let mut pop = vec![set("f_h_v", "f_t_v || f_push"), set("f_h_off", lit(rw, 0)), set("f_t_v", "f_t_v && f_push")];
    pop.push(Stmt::If("f_t_v".into(), take("h", "t"), take("h", "in")));
    pop.extend(take("t", "in"));
    let mut push_h = vec![set("f_h_v", "1'b1"), set("f_h_off", lit(rw, 0))];
    push_h.extend(take("h", "in"));
    let mut push_t = vec![set("f_t_v", "1'b1")];
    push_t.extend(take("t", "in"));
    b.push(Item::Always(vec![Stmt::If(
        "rst".into(),
        vec![set("f_h_v", "1'b0"), set("f_t_v", "1'b0")],
        vec![
            when("f_fresh && !f_exp_last", vec![set("f_h_off", format!("f_h_off + {pr}"))]),
            Stmt::If("f_pop".into(), pop, vec![when("f_push", vec![Stmt::If("!f_h_v".into(), push_h, push_t)])]),
        ],
    )]));
    b.push(comment("Nothing lost: a span is accepted only when at most one is owed besides it."));
    b.push(Item::Comb(vec![when("f_past && f_push", vec![assert("!(f_h_v && f_t_v && !f_pop)")])]));

    b.push(comment("Throughput with out_ready high: no bubble inside a span, nor between spans when the"));
    b.push(comment("next non-empty span was offered by the time the last segment left the shader."));
    b.push(Item::Always(vec![
        when("f_past && !$past(rst) && $past(out_valid && out_ready && !out_last)", vec![assert("out_valid")]),
        when(
            "f_past2 && !$past(rst) && !$past(rst, 2) && $past(out_valid && out_ready && out_last) && $past(in_valid && in_len != 0, 2)",
            vec![assert("out_valid")],
        ),
    ]));

    b.push(comment("Valid never waits for ready: a segment owed to an empty output is offered the next"));
    b.push(comment("clock, whatever out_ready was (a sink may wait for valid before raising ready)."));
    b.push(Item::Always(vec![when("f_past && !$past(rst) && $past(f_h_v && !out_valid)", vec![assert("out_valid")])]));

    b.push(comment("Linking invariants: the current-span registers hold what the shadow owes next."));
    let lead_is = |v: &str| if screen { vec![assert(format!("cur_lead == {v}"))] } else { vec![] };
    let mut fresh_more = vec![
        assert("cur_valid"),
        assert("!f_t_v"),
        assert(format!("cur_x == f_exp_x + {}", lit(xw, p as u64 % (1u64 << xw)))),
        assert(format!("cur_rem == f_left - {pr}")),
    ];
    fresh_more.extend(lead_is(&lit(log2p.max(1), 0)));
    let mut next_t = vec![assert("cur_x == f_t_b"), assert("cur_rem == f_t_tot")];
    next_t.extend(lead_is("f_t_lead"));
    let mut held = vec![assert("cur_valid"), assert("!f_t_v"), assert("cur_x == f_exp_x"), assert("cur_rem == f_left")];
    held.extend(lead_is(&format!("(f_h_off == {} ? f_h_lead : {})", lit(rw, 0), lit(lw, 0))));
    let mut range =
        vec![assert(format!("f_h_tot != {}", lit(rw, 0))), assert("f_h_off < f_h_tot"), assert(format!("f_h_tot <= {}", lit(rw, max_tot)))];
    let mut trange = vec![assert(format!("f_t_tot != {}", lit(rw, 0))), assert(format!("f_t_tot <= {}", lit(rw, max_tot)))];
    if log2p > 0 {
        range.push(assert(format!("f_h_off[{}:0] == {}", log2p - 1, lit(log2p, 0))));
    }
    if screen {
        range.push(assert(format!("f_h_b[{}:0] == {}", log2p - 1, lit(log2p, 0))));
        trange.push(assert(format!("f_t_b[{}:0] == {}", log2p - 1, lit(log2p, 0))));
    } else {
        range.push(assert(format!("f_h_lead == {}", lit(lw, 0))));
        trange.push(assert(format!("f_t_lead == {}", lit(lw, 0))));
    }
    b.push(Item::Comb(vec![when(
        "f_past",
        vec![
            Stmt::If(
                "!f_h_v".into(),
                vec![assert("!cur_valid"), assert("!f_t_v"), assert("!f_fresh")],
                vec![Stmt::If(
                    "f_fresh && !f_exp_last".into(),
                    fresh_more,
                    vec![Stmt::If("f_fresh".into(), vec![assert("cur_valid == f_t_v"), when("f_t_v", next_t)], held)],
                )],
            ),
            when("f_h_v", range),
            when("f_t_v", trange),
            when("out_valid && !out_last", vec![assert("cur_valid")]),
        ],
    )]));
    Item::Formal(b)
}

/// The reference `bfpi_p<P>` is proven equal to (Yosys `equiv_*`, lane by lane, for all di):
/// `<bfpi>_ref`, each lane `(i+1) * di` written with `*`. A second module rather than an
/// assertion, because SAT on `x * constant` against a shift-and-add graph takes minutes at
/// P = 64 where structural equivalence takes seconds.
pub fn bfpi_reference(cfg: &Config, bfpi: &str) -> Module {
    let (p, dw, mw) = (cfg.p, cfg.dw(), cfg.mw());
    Module {
        name: format!("{bfpi}_ref"),
        header: vec![],
        params: vec![],
        ports: vec![
            Port::input("di", dw, "", "increment").signed(),
            Port::output("inc", p * mw, "", "lane i = (i+1)*di, by multiplication"),
        ],
        body: vec![Item::ForGenerate {
            var: "k".into(),
            count: p,
            label: "lane".into(),
            body: vec![
                Item::Localparam { name: "K".into(), width: mw, value: "k + 1".into() },
                assign(format!("inc[k*{mw} +: {mw}]"), format!("{} * K", sext("di", dw, mw))),
            ],
        }],
    }
}

/// Properties of `specular_unit`: its control against a reference model kept at the ports.
///
/// The reference issues an accepted span's `len` pixels one per free clock, the final one
/// marked last, and delays them through as many stages as the unit has (`stages`: valid and
/// last register names from the issue stage to the output), all moving when the output is
/// free. The unit's `out_valid` and `out_last` must equal the reference's, and `in_ready` must
/// be exactly "idle, or issuing its last pixel into a free pipe" (no span dropped, no bubble).
/// So every span yields exactly `len` pixels in order, `out_last` on the final one only, and
/// `len = 0` yields nothing. Pixel values pass through multipliers and ROMs the solver cannot
/// manage; `scripts/prove` cuts them (their outputs become free), so the proof holds for any
/// value they produce, and the values are left to co-simulation.
pub fn specular_properties(lw: u32, stages: &[(&str, &str)]) -> Item {
    let mut b = vec![
        comment(format!("{CUT_TAG}cutpoint t:$mul t:$mem_v2")),
        comment("(the multipliers and ROMs: their outputs become free, values are left to co-simulation)"),
    ];
    b.extend(past_flags());
    b.extend(reset_and_stability("pixel", OUT, &["out_spec", "out_last", "out_err"]));
    b.push(comment("The reference: the span being issued (f_len pixels, f_k issued) and the pipe."));
    b.push(reg("f_busy", 1));
    b.push(reg("f_len", lw));
    b.push(reg("f_k", lw));
    b.push(wire("f_adv", 1, "!out_valid || out_ready"));
    b.push(wire("f_last0", 1, format!("f_k + {} == f_len", lit(lw, 1))));
    let n = stages.len();
    for k in 1..=n {
        b.push(reg(&format!("f_v{k}"), 1));
        b.push(reg(&format!("f_l{k}"), 1));
    }
    let mut shift = vec![set("f_v1", "f_busy"), set("f_l1", "f_last0")];
    for k in 2..=n {
        shift.push(set(format!("f_v{k}"), format!("f_v{}", k - 1)));
        shift.push(set(format!("f_l{k}"), format!("f_l{}", k - 1)));
    }
    let mut reset: Vec<Stmt> = vec![set("f_busy", "1'b0")];
    reset.extend((1..=n).map(|k| set(format!("f_v{k}"), "1'b0")));
    b.push(Item::Always(vec![Stmt::If(
        "rst".into(),
        reset,
        vec![
            when("f_adv", shift),
            Stmt::If(
                "in_valid && in_ready".into(),
                vec![set("f_busy", format!("in_len != {}", lit(lw, 0))), set("f_len", "in_len"), set("f_k", lit(lw, 0))],
                vec![when(
                    "f_adv && f_busy",
                    vec![Stmt::If("f_last0".into(), vec![set("f_busy", "1'b0")], vec![set("f_k", format!("f_k + {}", lit(lw, 1)))])],
                )],
            ),
        ],
    )]));
    b.push(comment("Ports against the reference: accept exactly when idle or finishing into a free pipe;"));
    b.push(comment("the output's valid and last are the reference's."));
    let (vo, lo) = (format!("f_v{n}"), format!("f_l{n}"));
    b.push(Item::Comb(vec![when(
        "f_past",
        vec![
            assert("in_ready == (!f_busy || (f_adv && f_last0))"),
            assert(format!("out_valid == {vo}")),
            when("out_valid", vec![assert(format!("out_last == {lo}"))]),
        ],
    )]));
    b.push(comment("Linking invariants: the unit's stage registers are the reference's."));
    let mut link = vec![assert("busy == f_busy"), when("f_busy", vec![assert("f_k < f_len"), assert("cnt == f_len - f_k")])];
    for (k, (v, l)) in stages.iter().enumerate() {
        link.push(assert(format!("{v} == f_v{}", k + 1)));
        link.push(when(*v, vec![assert(format!("{l} == f_l{}", k + 1))]));
    }
    b.push(Item::Comb(vec![when("f_past", link)]));
    Item::Formal(b)
}

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
    let (p, l, xw, yw) = (cfg.p, cfg.log2p(), cfg.xbits, w.y_bits());
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
    // The block number of x, as an address term; on a screen narrower than 2^XW it is narrower
    // than the port (x < W).
    let blk_of = |x: &str| match w.block_bits() {
        0 => lit(aw, 0),
        bw => zext(&format!("{x}[{}:{l}]", l + bw - 1), bw, aw),
    };
    let blk = blk_of("in_x");
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
        link.extend([
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
                    blk_of("f_px"),
                    lit(aw, 1)
                ))],
            ),
        ]);
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
    Item::Formal(b)
}

/// Properties of a pipelined `segment_shader_p<P>` (`--pipeline` 1 or 2): its control against
/// a reference written from SPEC §3 at the ports, the way the specular unit's proof works.
///
/// The reference holds, stage by stage, what the shader must: the span waiting in front
/// (level 1 and up), the span being cut as (first block's x, offset, lead + m, lead), from which
/// the segment at the offset follows by SPEC §3 (x = block + offset, lane i inside when
/// lead <= offset + i < lead + m, last when at most P pixels are left), and that segment's
/// (x, mask, last) in the sum stage (level 2) and in the output register, every stage moving
/// when the output register is free. Asserted: `in_ready`, `out_valid` and every new output's
/// x, mask and last equal the reference's, so each accepted span yields exactly its SPEC
/// segments, in order, none lost and none invented, and `m = 0` yields nothing; reset,
/// stability, throughput (the next span offered `latency` clocks before a span's last segment
/// leaves follows with no bubble) and "valid never waits for ready"; and the linking
/// invariants (each stage's registers are the reference's) that make it k-inductive. Pixel
/// values are left to the BFPI's equivalence and co-simulation, as at level 0.
pub fn segment_pipelined_properties(cfg: &Config, rw: u32, pipe: golden::pipeline::Pipeline) -> Item {
    let (p, xw, log2p) = (cfg.p, cfg.xbits, cfg.log2p());
    let screen = cfg.align == Align::Screen && p > 1;
    let lw = log2p.max(1);
    let lat = golden::segment::latency(cfg, pipe);
    let max_tot = (1u64 << (xw + 1)) - 1 + if screen { p as u64 - 1 } else { 0 };
    let pr = lit(rw, p as u64);
    // The throughput property looks `lat` clocks back: induction needs a window past that.
    let mut b = vec![comment(format!("{CUT_TAG}depth {}", lat + 2))];
    b.extend(past_flags());
    // $past(x, k) needs k clocks of history: f_pastK is set once the solver has run K clocks.
    for k in 3..=lat {
        b.push(Item::RegInit { name: format!("f_past{k}"), width: 1, value: "1'b0".into() });
        b.push(Item::Always(vec![set(format!("f_past{k}"), if k == 3 { "f_past2".to_string() } else { format!("f_past{}", k - 1) })]));
    }
    let past_k = |k: u32| if k == 1 { "f_past".to_string() } else { format!("f_past{k}") };
    b.extend(reset_and_stability("segment", OUT, &["out_x", "out_pix", "out_mask", "out_last"]));

    b.push(comment("The reference, stage by stage: what SPEC §3 says each stage of the shader holds."));
    // The span's first block and lead (SPEC §3), from the x it starts at.
    let (blk, lead) = if screen {
        let blk = if log2p == xw { lit(xw, 0) } else { format!("{{f_src_x[{}:{log2p}], {}}}", xw - 1, lit(log2p, 0)) };
        (blk, format!("f_src_x[{}:0]", log2p - 1))
    } else {
        ("f_src_x".to_string(), lit(lw, 0))
    };
    b.extend([reg("f_cv", 1), reg("f_cb", xw), reg("f_coff", rw), reg("f_ctot", rw), reg("f_clead", lw)]);
    if pipe.span_stage() {
        b.extend([reg("f_sv", 1), reg("f_sx", xw), reg("f_slen", xw + 1)]);
    }
    if pipe.sum_stage() {
        b.extend([reg("f_1v", 1), reg("f_1x", xw), reg("f_1m", p), reg("f_1l", 1)]);
    }
    b.extend([reg("f_ov", 1), reg("f_ox", xw), reg("f_om", p), reg("f_ol", 1)]);
    b.push(wire("f_free", 1, "!f_ov || out_ready"));
    b.push(wire("f_clast", 1, format!("f_ctot - f_coff <= {pr}")));
    b.push(wire("f_fire", 1, "f_cv && f_free"));
    b.push(wire("f_take", 1, "!f_cv || (f_fire && f_clast)"));
    let (src_x, src_len) = if pipe.span_stage() { ("f_sx", "f_slen") } else { ("in_x", "in_len") };
    if pipe.span_stage() {
        b.push(wire("f_rdy", 1, "!f_sv || f_take"));
        b.push(wire("f_start", 1, "f_sv && f_take"));
    } else {
        b.push(wire("f_rdy", 1, "f_take"));
        b.push(wire("f_start", 1, "in_valid && f_rdy"));
    }
    b.push(wire("f_src_x", xw, src_x));
    b.push(wire("f_src_lead", lw, lead));
    b.push(wire("f_cx", xw, format!("f_cb + f_coff[{}:0]", xw - 1)));
    b.extend(spec_mask("f_cmask", ("f_coff", "f_clead", "f_ctot"), p, (rw, lw)));
    let start = vec![
        set("f_cv", if pipe.span_stage() { "1'b1".to_string() } else { format!("{src_len} != 0") }),
        set("f_cb", blk),
        set("f_coff", lit(rw, 0)),
        set("f_ctot", format!("{} + {}", zext(src_len, xw + 1, rw), zext("f_src_lead", lw, rw))),
        set("f_clead", "f_src_lead"),
    ];
    let mut resets = vec![set("f_cv", "1'b0"), set("f_ov", "1'b0")];
    let mut moves = vec![Stmt::If(
        "f_start".into(),
        start,
        vec![when("f_fire", vec![Stmt::If("f_clast".into(), vec![set("f_cv", "1'b0")], vec![set("f_coff", format!("f_coff + {pr}"))])])],
    )];
    if pipe.span_stage() {
        resets.push(set("f_sv", "1'b0"));
        moves.push(Stmt::If(
            "in_valid && f_rdy".into(),
            vec![set("f_sv", "in_len != 0"), set("f_sx", "in_x"), set("f_slen", "in_len")],
            vec![when("f_start", vec![set("f_sv", "1'b0")])],
        ));
    }
    let out_from = if pipe.sum_stage() {
        resets.push(set("f_1v", "1'b0"));
        moves.push(when("f_free", vec![set("f_1v", "f_cv"), set("f_1x", "f_cx"), set("f_1m", "f_cmask"), set("f_1l", "f_clast")]));
        ["f_1v", "f_1x", "f_1m", "f_1l"]
    } else {
        ["f_cv", "f_cx", "f_cmask", "f_clast"]
    };
    moves
        .push(when("f_free", vec![set("f_ov", out_from[0]), set("f_ox", out_from[1]), set("f_om", out_from[2]), set("f_ol", out_from[3])]));
    b.push(Item::Always(vec![Stmt::If("rst".into(), resets, moves)]));

    b.push(comment("The shader is the reference at its ports."));
    b.push(Item::Comb(vec![when(
        "f_past",
        vec![
            assert("in_ready == f_rdy"),
            assert("out_valid == f_ov"),
            when("f_ov", vec![assert("out_x == f_ox"), assert("out_mask == f_om"), assert("out_last == f_ol")]),
        ],
    )]));

    b.push(comment("Throughput with out_ready high: no bubble inside a span, nor between spans when the"));
    b.push(comment(format!("next non-empty span was offered {lat} clocks (the latency) before the last segment left,")));
    b.push(comment("out_ready high all the while."));
    let quiet: Vec<String> = (1..=lat).map(|k| format!("!$past(rst, {k})")).collect();
    // out_ready held high through the window: a stall freezes any gap already in the pipe.
    let held: Vec<String> = (1..=lat).map(|k| format!("$past(out_ready, {k})")).collect();
    b.push(Item::Always(vec![
        when("f_past && !$past(rst) && $past(out_valid && out_ready && !out_last)", vec![assert("out_valid")]),
        when(
            format!(
                "{} && {} && {} && $past(out_valid && out_last) && $past(in_valid && in_len != 0, {lat})",
                past_k(lat),
                quiet.join(" && "),
                held.join(" && ")
            ),
            vec![assert("out_valid")],
        ),
    ]));
    b.push(comment("Valid never waits for ready: with a span owed and the output empty for latency - 1"));
    b.push(comment("clocks, whatever out_ready was, a segment is offered."));
    let owed = if pipe.span_stage() { "(f_cv || f_sv)" } else { "f_cv" };
    let waited: Vec<String> = (1..lat).map(|k| format!("$past({owed} && !out_valid && !rst, {k})")).collect();
    b.push(Item::Always(vec![when(format!("{} && {}", past_k(lat - 1), waited.join(" && ")), vec![assert("out_valid")])]));

    b.push(comment("Linking invariants: every stage's registers are the reference's."));
    let mut cur = vec![
        assert("cur_x == f_cx"),
        assert("cur_rem == f_ctot - f_coff"),
        assert("cur_last == f_clast"),
        assert("f_coff < f_ctot"),
        assert(format!("f_ctot <= {}", lit(rw, max_tot))),
    ];
    if log2p > 0 {
        cur.push(assert(format!("f_coff[{}:0] == {}", log2p - 1, lit(log2p, 0))));
    }
    if screen {
        cur.push(assert(format!("cur_lead == (f_coff == {} ? f_clead : {})", lit(rw, 0), lit(lw, 0))));
        cur.push(assert(format!("f_cb[{}:0] == {}", log2p - 1, lit(log2p, 0))));
    } else {
        cur.push(assert(format!("f_clead == {}", lit(lw, 0))));
    }
    let mut link = vec![assert("cur_valid == f_cv"), when("f_cv", cur)];
    // A span's segments leave the current stage on consecutive moves: behind a segment that is
    // not its span's last, the next stage holds the following one.
    if pipe.sum_stage() {
        link.push(when("f_ov && !f_ol", vec![assert("f_1v")]));
        link.push(when("f_1v && !f_1l", vec![assert("f_cv")]));
    } else {
        link.push(when("f_ov && !f_ol", vec![assert("f_cv")]));
    }
    if pipe.span_stage() {
        link.push(assert("sp_valid == f_sv"));
        link.push(when("f_sv", vec![assert("sp_x == f_sx"), assert("sp_len == f_slen"), assert(format!("f_slen != {}", lit(xw + 1, 0)))]));
    }
    if pipe.sum_stage() {
        link.push(assert("s1_valid == f_1v"));
        link.push(when("f_1v", vec![assert("s1_x == f_1x"), assert("s1_mask == f_1m"), assert("s1_last == f_1l")]));
    }
    b.push(Item::Comb(vec![when("f_past", link)]));
    Item::Formal(b)
}

/// A sized signed decimal constant (`-w'sdN` for a negative one).
fn slit(w: u32, v: i64) -> String {
    if v < 0 {
        format!("-{w}'sd{}", -v)
    } else {
        format!("{w}'sd{v}")
    }
}

/// What the front-end's proof needs from its generator: widths, screen, divider clocks.
pub struct FrontendShape {
    /// Row bits (`out_y`), vertex x and y bits.
    pub yw: u32,
    pub cx: u32,
    pub cy: u32,
    pub xw: u32,
    /// `dI`'s bits (`out_di`).
    pub dw: u32,
    /// Screen width and height, pixels.
    pub width: u64,
    pub height: u64,
    /// The dividers' counter width, quotient bits per clock, the reciprocal's quotient bits,
    /// and the clocks they run (`Hw::div_clocks`).
    pub cnt_w: u32,
    pub bits: u32,
    pub rw: u32,
    pub div_clocks: u32,
    /// The set-up dividers' registers (partial remainder, divisor, quotient of each): cut.
    pub div_regs: Vec<String>,
    /// CALC's stages after the vertex register (none at level 0), in order.
    pub calc_stages: Vec<CalcStage>,
    /// The names under which the last CALC stage holds the guard-band check and the cull.
    pub guard: String,
    pub cull: String,
    /// The span path's register stages between the walker and the output, in order.
    pub span_stages: Vec<SpanStage>,
}

/// A register stage of the front-end's span path: where it holds a span's valid, row, columns
/// and `dI`.
pub struct SpanStage {
    pub valid: String,
    pub y: String,
    pub x: String,
    pub len: String,
    pub di: String,
}

/// A CALC stage of the pipelined set-up: its valid register and where it holds what the
/// reference follows (the guard-band check; the vertical extent, or the rows made of it).
pub struct CalcStage {
    pub valid: String,
    pub guard: String,
    pub ymin: Option<String>,
    pub ymax: Option<String>,
    /// The first and last rows, signed (`ryw` bits) and clipped, and the cull decision.
    pub first_s: Option<String>,
    pub last_s: Option<String>,
    pub cull: Option<String>,
    /// Candidates for the last row held before the choice between them (each as `last_s`).
    pub last_alt: Vec<String>,
}

/// Properties of `tri_frontend` (SPEC §6; names as `frontend::module` declares them), with the
/// per-triangle `dI`: its control against a reference model of its stages kept at the ports.
///
/// The reference, written from SPEC §6: a triangle waits in the vertex register until the
/// set-up is free; the set-up drops it with one `err` pulse when a vertex lies outside the
/// guard band (decided by the reference itself from the ports, SPEC's `-W <= x < 2W`,
/// `-H <= y < 2H`), yields nothing for a culled one, and otherwise divides for `div_clocks`
/// clocks and holds the result until the walker is free (idle, or on its last row with the
/// output free: the next triangle's set-up overlaps the walk); the walker walks the rows from
/// first to last, one per free clock, and each row with covered pixels becomes a span that
/// moves through the I0 stages (two, or six when pipelined) to the output, every stage moving
/// when the output is free. With CALC in stages, a triangle moves through them as a queue
/// between the vertex register and the set-up.
/// Whether a row has covered pixels (the walker's `lo <= hi`), whether a triangle is culled
/// (its area and row range) and the rows' first and last are the design's data decisions the
/// reference takes as given; it checks them where SPEC constrains them: every walked row's
/// centre lies within the triangle's vertical extent and on the screen, and every span is on
/// the screen with at least one pixel (`out_x + out_len <= W`). Asserted: `in_ready`, `err`,
/// `out_valid` and `out_y` equal the reference's (no triangle dropped or invented, spans top
/// to bottom in order, a triangle's spans before the next one's, `err` exactly once per
/// triangle outside the band and never otherwise); the triangle count (accepted = flagged +
/// culled + walked + in flight) and the span count (every covered row's span offered once);
/// `dI` once per triangle (a span that is not its triangle's first carries the `dI` of the one
/// before it); the rate (a row every free clock, no bubble between triangles when the set-up is
/// done, a dropped triangle costs one clock); reset and stability; and the linking invariants. Every multiplier is cut (area, edge and plane products, I0's product and
/// correction) and so are the set-up dividers' registers (free every clock): their values never
/// decide the control beyond what the reference takes as given, and the values are
/// co-simulated bit-exactly against golden. The dividers' cut is for speed: a run from reset
/// through their restoring steps (66 bits wide at 640x480) is more than twice as slow.
pub fn frontend_properties(s: &FrontendShape) -> Item {
    let FrontendShape {
        yw,
        cx,
        cy,
        xw,
        dw,
        width,
        height,
        cnt_w,
        bits,
        rw,
        div_clocks,
        ref div_regs,
        ref calc_stages,
        ref guard,
        ref cull,
        ref span_stages,
    } = *s;
    // The span path's stages: the reference's f_<i>v, f_<i>y, f_<i>n for i = 1..=nsp.
    let nsp = span_stages.len();
    // CALC's stages: 0 is the vertex register, 1.. the pipelined set-up's (none at level 0).
    let last = calc_stages.len();
    let f_v = |j: usize| if j == 0 { "f_vf".to_string() } else { format!("f_c{j}v") };
    let f_g = |j: usize| if j == 0 { "f_vg".to_string() } else { format!("f_c{j}g") };
    let f_ymin = |j: usize| if j == 0 { "f_vymin".to_string() } else { format!("f_c{j}ymin") };
    let f_ymax = |j: usize| if j == 0 { "f_vymax".to_string() } else { format!("f_c{j}ymax") };
    let f_mv = |j: usize| if j == last { "f_calc".to_string() } else { format!("f_mv{j}") };
    // No `*` below: the proof cuts every multiplier, the properties' own too.
    assert!(bits.is_power_of_two(), "divider bits per clock: {bits}");
    // Reference counters: wide enough for the stages they count through, modulo 2^cw.
    let cw = 4;
    let nw = 32 - div_clocks.leading_zeros();
    let mut b = vec![
        comment(format!("{CUT_TAG}cutpoint t:$mul {}", div_regs.iter().map(|r| format!("w:{r}")).collect::<Vec<_>>().join(" "))),
        comment("(the multipliers: area, edges, plane, I0; and the set-up dividers' registers, free every clock:"),
        comment("only the coverage decision, taken as given, depends on them; values are left to co-simulation)"),
    ];
    b.extend(past_flags());
    b.extend(reset_and_stability("span", OUT, &["out_y", "out_x", "out_len", "out_i0", "out_di"]));
    b.push(comment("Reset: no error pulse out of reset either."));
    b.push(Item::Always(vec![when("f_past && $past(rst)", vec![assert("!err")])]));

    b.push(comment("The reference. The input stage: the triangle waiting for the set-up, whether its"));
    b.push(comment("vertices lie in SPEC §6's guard band (decided here from the ports), its vertical extent."));
    b.extend([reg("f_vf", 1), reg("f_vg", 1), Item::Reg { name: "f_vymin".into(), width: cy, signed: true }]);
    b.push(Item::Reg { name: "f_vymax".into(), width: cy, signed: true });
    let (gxl, gxh) = (-(width as i64) * 256, 2 * width as i64 * 256);
    let (gyl, gyh) = (-(height as i64) * 256, 2 * height as i64 * 256);
    let mut band = Vec::new();
    for k in 0..3 {
        b.push(Item::Wire { name: format!("f_ix{k}"), width: cx + 2, signed: true, value: Some(sext(&format!("in_x{k}"), cx, cx + 2)) });
        b.push(Item::Wire { name: format!("f_iy{k}"), width: cy + 2, signed: true, value: Some(sext(&format!("in_y{k}"), cy, cy + 2)) });
        band.push(format!(
            "f_ix{k} >= {} && f_ix{k} < {} && f_iy{k} >= {} && f_iy{k} < {}",
            slit(cx + 2, gxl),
            slit(cx + 2, gxh),
            slit(cy + 2, gyl),
            slit(cy + 2, gyh)
        ));
    }
    b.push(wire("f_band", 1, band.join(" && ")));
    let min3 = |op: &str| format!("((in_y0 {op} in_y1) ? ((in_y0 {op} in_y2) ? in_y0 : in_y2) : ((in_y1 {op} in_y2) ? in_y1 : in_y2))");
    b.push(Item::Wire { name: "f_iymin".into(), width: cy, signed: true, value: Some(min3("<")) });
    b.push(Item::Wire { name: "f_iymax".into(), width: cy, signed: true, value: Some(min3(">")) });

    for j in 1..=last {
        if j == 1 {
            b.push(comment("CALC's stages: each triangle's guard-band check and vertical extent, as the vertex register's."));
        }
        b.extend([reg(&f_v(j), 1), reg(&f_g(j), 1)]);
        b.push(Item::Reg { name: f_ymin(j), width: cy, signed: true });
        b.push(Item::Reg { name: f_ymax(j), width: cy, signed: true });
    }
    b.push(comment("The set-up: busy (dividing, f_sn + 1 clocks left, or holding its result: f_sh), its extent."));
    b.extend([reg("f_sb", 1), reg("f_sh", 1), reg("f_sn", nw)]);
    b.push(Item::Reg { name: "f_symin".into(), width: cy, signed: true });
    b.push(Item::Reg { name: "f_symax".into(), width: cy, signed: true });
    b.push(comment("The walker: the triangle being walked, its row and last row, its extent."));
    b.extend([reg("f_wv", 1), reg("f_wrow", yw), reg("f_wlast", yw)]);
    b.push(Item::Reg { name: "f_wymin".into(), width: cy, signed: true });
    b.push(Item::Reg { name: "f_wymax".into(), width: cy, signed: true });
    b.push(comment("The spans: the walker's row in the I0 stages and the output (valid, row)."));
    for i in 1..=nsp {
        b.extend([reg(&format!("f_{i}v"), 1), reg(&format!("f_{i}y"), yw)]);
    }
    b.extend([reg("f_ov", 1), reg("f_oy", yw)]);
    b.push(comment("Each span's tag: its triangle's first (the walker has emitted none of it yet: f_wnew)."));
    b.push(reg("f_wnew", 1));
    for i in 1..=nsp {
        b.push(reg(&format!("f_{i}n"), 1));
    }
    b.push(reg("f_on", 1));
    b.push(comment("The dI of the last span offered, and whether the output register could load (f_free):"));
    b.push(comment("a span on the output is new when it is valid and f_free."));
    b.extend([reg("f_pdi", dw), reg("f_free", 1)]);
    b.push(Item::Always(vec![set("f_free", "rst || !out_valid || out_ready"), when("out_valid", vec![set("f_pdi", "out_di")])]));
    b.push(comment("The error pulse owed, and counts: triangles accepted, flagged (at the port), culled,"));
    b.push(comment("walked; spans the walker produced (covered rows) and spans taken at the port."));
    b.extend([reg("f_errp", 1), reg("f_nacc", cw), reg("f_nerr", cw), reg("f_ncull", cw), reg("f_nwalk", cw)]);
    b.extend([reg("f_nrow", cw), reg("f_nout", cw)]);

    b.push(wire("f_adv", 1, "!out_valid || out_ready"));
    b.push(wire("f_wend", 1, "f_wrow == f_wlast"));
    b.push(wire("f_take", 1, "f_sb && f_sh && f_adv && (!f_wv || f_wend)"));
    b.push(wire("f_calc", 1, format!("{} && (!f_sb || f_take)", f_v(last))));
    for j in (0..last).rev() {
        b.push(wire(&f_mv(j), 1, format!("{} && (!{} || {})", f_v(j), f_v(j + 1), f_mv(j + 1))));
    }
    b.push(wire("f_rdy", 1, format!("!f_vf || {}", f_mv(0))));
    b.push(wire("f_acc", 1, "in_valid && f_rdy"));
    b.push(comment("The design's data decisions, taken as given: culled, and a walked row's covered pixels."));
    b.push(wire("f_cull", 1, cull.as_str()));
    b.push(wire("f_cover", 1, "lo3 <= hi3"));

    let one = |w: u32| lit(w, 1);
    let inc1 = |n: &str| set(n, format!("{n} + {}", one(cw)));
    let inc = |n: &str, c: &str| when(c, vec![inc1(n)]);
    let calc_go = vec![
        set("f_sb", "1'b1"),
        set("f_sh", "1'b0"),
        set("f_sn", lit(nw, (div_clocks - 1) as u64)),
        set("f_symin", f_ymin(last)),
        set("f_symax", f_ymax(last)),
    ];
    let setup = Stmt::If(
        "f_calc".into(),
        vec![Stmt::If(
            format!("!{}", f_g(last)),
            vec![set("f_errp", "1'b1"), set("f_sb", "1'b0")],
            vec![Stmt::If("f_cull".into(), vec![set("f_sb", "1'b0"), inc1("f_ncull")], calc_go)],
        )],
        vec![Stmt::If(
            "f_take".into(),
            vec![set("f_sb", "1'b0")],
            vec![when(
                "f_sb && !f_sh",
                vec![Stmt::If(
                    format!("f_sn == {}", lit(nw, 0)),
                    vec![set("f_sh", "1'b1")],
                    vec![set("f_sn", format!("f_sn - {}", one(nw)))],
                )],
            )],
        )],
    );
    let walker = Stmt::If(
        "f_take".into(),
        vec![
            set("f_wv", "1'b1"),
            set("f_wrow", "s_first"),
            set("f_wlast", "s_last"),
            set("f_wymin", "f_symin"),
            set("f_wymax", "f_symax"),
            set("f_wnew", "1'b1"),
            inc1("f_nwalk"),
        ],
        vec![
            when("f_adv && f_wv && f_cover", vec![set("f_wnew", "1'b0")]),
            when(
                "f_adv && f_wv",
                vec![Stmt::If("f_wend".into(), vec![set("f_wv", "1'b0")], vec![set("f_wrow", format!("f_wrow + {}", one(yw)))])],
            ),
        ],
    );
    let spans = when(
        "f_adv",
        vec![set("f_1v", "f_wv && f_cover"), set("f_1y", "f_wrow"), set("f_1n", "f_wnew")]
            .into_iter()
            .chain((2..=nsp).flat_map(|i| ["v", "y", "n"].map(|f| set(format!("f_{i}{f}"), format!("f_{}{f}", i - 1)))))
            .chain(["v", "y", "n"].map(|f| set(format!("f_o{f}"), format!("f_{nsp}{f}"))))
            .collect(),
    );
    let input = Stmt::If(
        "f_acc".into(),
        vec![set("f_vf", "1'b1"), set("f_vg", "f_band"), set("f_vymin", "f_iymin"), set("f_vymax", "f_iymax")],
        vec![when(f_mv(0), vec![set("f_vf", "1'b0")])],
    );
    let stages: Vec<Stmt> = (1..=last)
        .map(|j| {
            Stmt::If(
                f_mv(j - 1),
                vec![set(f_v(j), "1'b1"), set(f_g(j), f_g(j - 1)), set(f_ymin(j), f_ymin(j - 1)), set(f_ymax(j), f_ymax(j - 1))],
                vec![when(f_mv(j), vec![set(f_v(j), "1'b0")])],
            )
        })
        .collect();
    let zero = lit(cw, 0);
    b.push(Item::Always(vec![Stmt::If(
        "rst".into(),
        vec![set("f_vf", "1'b0")]
            .into_iter()
            .chain((1..=last).map(|j| set(f_v(j), "1'b0")))
            .chain([set("f_sb", "1'b0"), set("f_wv", "1'b0")])
            .chain((1..=nsp).map(|i| set(format!("f_{i}v"), "1'b0")))
            .chain([
                set("f_ov", "1'b0"),
                set("f_errp", "1'b0"),
                set("f_nacc", zero.clone()),
                set("f_nerr", zero.clone()),
                set("f_ncull", zero.clone()),
                set("f_nwalk", zero.clone()),
                set("f_nrow", zero.clone()),
                set("f_nout", zero.clone()),
            ])
            .collect(),
        vec![
            set("f_errp", "1'b0"),
            inc("f_nacc", "f_acc"),
            inc("f_nerr", "err"),
            inc("f_nrow", "f_adv && f_wv && f_cover"),
            inc("f_nout", "out_valid && out_ready"),
            input,
        ]
        .into_iter()
        .chain(stages)
        .chain([setup, walker, spans])
        .collect(),
    )]));

    b.push(comment("The front-end is the reference at its ports: it takes a triangle exactly when the"));
    b.push(comment("vertex register is free or handing its triangle to the set-up, pulses err once per"));
    b.push(comment("triangle outside the guard band and never otherwise, and offers exactly the reference's"));
    b.push(comment("spans, row by row: a triangle's rows top to bottom, then the next triangle's."));
    let wlim = lit(xw + 2, width);
    let on_screen = |v: &str, x: &str, len: &str| {
        when(
            v,
            vec![
                assert(format!("{len} != {}", lit(xw + 1, 0))),
                assert(format!("{} + {} <= {wlim}", zext(x, xw, xw + 2), zext(len, xw + 1, xw + 2))),
            ],
        )
    };
    let mut ports = vec![
        assert("in_ready == f_rdy"),
        assert("err == f_errp"),
        assert("out_valid == f_ov"),
        when("f_ov", vec![assert("out_y == f_oy")]),
    ];
    ports.push(on_screen("out_valid", "out_x", "out_len"));
    ports.push(Stmt::Comment("dI once per triangle: a new span that is not its triangle's first carries the dI of".into()));
    ports.push(Stmt::Comment("the span before it (the same triangle's).".into()));
    ports.push(when("out_valid && f_free && !f_on", vec![assert("out_di == f_pdi")]));
    b.push(Item::Comb(vec![when("f_past", ports)]));
    b.push(comment("Rate (SPEC §6), in the design's terms: the walker takes a row every clock the output is"));
    b.push(comment("free; a set-up result waiting when the walker is on its last row follows it with no"));
    b.push(comment("bubble (set-up overlapped with the walk); a dropped or culled triangle costs its CALC clock."));
    b.push(Item::Always(vec![when(
        "f_past && !$past(rst)",
        vec![
            when("$past(w_valid && adv && !w_end)", vec![assert("w_valid"), assert(format!("w_row == $past(w_row) + {}", one(yw)))]),
            when("$past(w_valid && adv && w_end && st == HOLD)", vec![assert("w_valid"), assert("w_row == $past(s_first)")]),
            // The triangle behind a dropped one moves up in the same clock: into the last CALC
            // stage, or (CALC in one clock) straight into it from the port.
            when(
                format!("$past(calc && (!{guard} || {cull}))"),
                vec![match last {
                    0 => assert("in_ready"),
                    1 => assert(format!("!$past(v_full) || {}", calc_stages[0].valid)),
                    _ => assert(format!("!$past({}) || {}", calc_stages[last - 2].valid, calc_stages[last - 1].valid)),
                }],
            ),
        ],
    )]));
    b.push(comment("Nothing lost or invented: every accepted triangle was flagged, culled or walked, or is"));
    b.push(comment("still waiting or in set-up (counts modulo 16)."));
    b.push(Item::Comb(vec![when(
        "f_past",
        vec![assert(
            format!("f_nacc == f_nerr + {} + f_ncull + f_nwalk + {} + {}", zext("err", 1, cw), zext("f_vf", 1, cw), zext("f_sb", 1, cw))
                + &(1..=last).map(|j| format!(" + {}", zext(&f_v(j), 1, cw))).collect::<String>(),
        )],
    )]));
    b.push(comment("Every span the walker produced is offered once: taken at the port, or still in a stage."));
    b.push(Item::Comb(vec![when(
        "f_past",
        vec![assert(format!(
            "f_nrow == f_nout{} + {}",
            (1..=nsp).map(|i| format!(" + {}", zext(&format!("f_{i}v"), 1, cw))).collect::<String>(),
            zext("f_ov", 1, cw)
        ))],
    )]));

    b.push(comment("Linking invariants: every stage's registers are the reference's; a row's centre"));
    b.push(comment("(256 r + 128 sub-pixels) lies within its triangle's vertical extent and on the screen."));
    let centre = |r: &str| format!("$signed({{2'b00, {r}, 8'd128}})");
    let within = |r: &str, lo: &str, hi: &str| vec![assert(format!("{} >= {lo}", centre(r))), assert(format!("{} <= {hi}", centre(r)))];
    let hmax = lit(yw, height - 1);
    let st_is = "(f_sb ? (f_sh ? HOLD : DIV) : IDLE)";
    let mut su = vec![assert(format!("{} <= f_symax", centre("s_last"))), assert(format!("{} >= f_symin", centre("s_first")))];
    su.extend([assert("s_first <= s_last"), assert(format!("s_last <= {hmax}"))]);
    let mut wk = vec![assert("w_row == f_wrow"), assert("w_last == f_wlast"), assert("f_wrow <= f_wlast")];
    wk.extend(within("f_wrow", "f_wymin", "f_wymax"));
    wk.extend([assert(format!("{} <= f_wymax", centre("f_wlast"))), assert(format!("f_wlast <= {hmax}"))]);
    let mut link = vec![
        assert("v_full == f_vf"),
        when("f_vf", vec![assert("guard_ok == f_vg"), assert("ymin == f_vymin"), assert("ymax == f_vymax")]),
    ];
    let ryc = |r: &str| format!("$signed({{{r}, 8'd128}})");
    for (j, c) in calc_stages.iter().enumerate().map(|(i, c)| (i + 1, c)) {
        let mut held = vec![assert(format!("{} == {}", c.guard, f_g(j)))];
        if let Some(r) = &c.ymin {
            held.push(assert(format!("{r} == {}", f_ymin(j))));
        }
        if let Some(r) = &c.ymax {
            held.push(assert(format!("{r} == {}", f_ymax(j))));
        }
        if let Some(r) = &c.first_s {
            held.push(assert(format!("!{r}[{}]", cy - 8)));
            held.push(assert(format!("{} >= {}", ryc(r), f_ymin(j))));
        }
        for r in c.last_s.iter().chain(&c.last_alt) {
            held.push(assert(format!("{r} <= {}", slit(cy - 7, height as i64 - 1))));
            held.push(assert(format!("{} <= {}", ryc(r), f_ymax(j))));
        }
        if let (Some(k), Some(a), Some(z)) = (&c.cull, &c.first_s, &c.last_s) {
            held.push(when(format!("!{k}"), vec![assert(format!("{a} <= {z}"))]));
        }
        link.push(assert(format!("{} == {}", c.valid, f_v(j))));
        link.push(when(f_v(j), held));
    }
    link.extend([
        assert(format!("st == {st_is}")),
        when(
            "f_sb && !f_sh",
            vec![assert(format!(
                "div_cnt == ({} << {}) + {}",
                zext("f_sn", nw, cnt_w.max(nw)),
                bits.trailing_zeros(),
                lit(cnt_w.max(nw), ((rw - 1) % bits) as u64)
            ))],
        ),
        when(format!("f_sn > {}", lit(nw, (div_clocks - 1) as u64)), vec![assert("!(f_sb && !f_sh)")]),
        when("f_sb", su),
        assert("w_valid == f_wv"),
        when("f_wv", wk),
    ]);
    for (i, sp) in span_stages.iter().enumerate().map(|(k, sp)| (k + 1, sp)) {
        link.push(assert(format!("{} == f_{i}v", sp.valid)));
        link.push(when(format!("f_{i}v"), vec![assert(format!("{} == f_{i}y", sp.y))]));
    }
    link.push(Stmt::Comment("A span that is not its triangle's first has the dI of the span ahead of it.".into()));
    link.push(when("f_ov && !f_free", vec![assert("out_di == f_pdi")]));
    // The dI ahead of stage i (i = nsp + 1: the output's): the nearest valid stage's, else the
    // output's or the last span offered.
    let ahead = |i: usize| {
        (i..=nsp).rev().fold("f_ov ? out_di : f_pdi".to_string(), |acc, k| format!("f_{k}v ? {} : {acc}", span_stages[k - 1].di))
    };
    for (i, sp) in span_stages.iter().enumerate().map(|(k, sp)| (k + 1, sp)).rev() {
        link.push(when(format!("f_{i}v && !f_{i}n"), vec![assert(format!("{} == ({})", sp.di, ahead(i + 1)))]));
    }
    link.push(when("f_wv && !f_wnew", vec![assert(format!("w_di == ({})", ahead(1)))]));
    for sp in span_stages {
        link.push(on_screen(&sp.valid, &sp.x, &sp.len));
    }
    b.push(Item::Comb(vec![when("f_past", link)]));
    Item::Formal(b)
}
