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
    let blk = if xw > l { zext(&format!("in_x[{}:{l}]", xw - 1), xw - l, aw) } else { lit(aw, 0) };
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
        b.extend([
            wire("f_r", l, format!("in_x[{}:0]", l - 1)),
            comment("Input lane j lands on block lane (r + j) mod P: f_lane gets input lane f_lane - r (mod P),"),
            comment("in the segment's head block when f_lane >= r, else in its tail (the next block)."),
            wire("f_src", l, "f_lane - f_r"),
            wire("f_in", 1, "in_mask[f_src]"),
            wire("f_head", 1, "f_lane >= f_r"),
            wire("f_pix", 8, "in_pix[{f_src, 3'b000} +: 8]"),
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
                    if xw > l { zext(&format!("f_px[{}:{l}]", xw - 1), xw - l, aw) } else { lit(aw, 0) },
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
