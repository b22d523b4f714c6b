//! The segment shader's formal properties (scripts/prove): SPEC §3's stream contract at its
//! ports, and the linking invariants that make it k-inductive, at level 0 and pipelined.
//!
//! The contract is checked against a *shadow* of the accepted spans: the spans whose segments
//! have not all appeared yet (at most two: the one at the output and the one loaded behind it).
//! Every segment that appears is compared with the one SPEC §3 says comes next (x, mask, last),
//! so a segment lost, repeated, invented or out of order fails, and a third span accepted while
//! two are owed means one was dropped. Sources need not keep `in_valid` or the span steady (SPEC
//! asks them to), so the proof covers any input sequence. Pixel values are left to
//! co-simulation and to the BFPI proof (`bfpi_reference`): each lane is the accumulator plus a
//! proven multiple of dI.

use crate::formal::{assert, covers, past_flags, reset_and_stability, spec_mask, when, CUT_TAG, OUT};
use crate::verilog::{comment, lit, reg, set, wire, zext, Item, Stmt};
use golden::{Align, Config};

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
    let lat = golden::segment::latency(cfg, golden::pipeline::Pipeline::default());
    b.extend(covers(
        lat + 4,
        &[
            ("Last segment taken: a span ends.", "out_valid && out_ready && out_last"),
            ("Earlier segment taken: a span of two or more.", "out_valid && out_ready && !out_last"),
        ],
    ));
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
    b.push(Item::Comb(vec![when("f_past", pipelined_links(cfg, rw, pipe))]));
    b.extend(covers(
        lat + 4,
        &[
            ("Last segment taken: a span ends.", "out_valid && out_ready && out_last"),
            ("Earlier segment taken: a span of two or more.", "out_valid && out_ready && !out_last"),
        ],
    ));
    Item::Formal(b)
}

/// A pipelined shader's linking invariants: the current, span and sum stages' registers are
/// the reference's, and a span's segments leave the current stage on consecutive moves.
fn pipelined_links(cfg: &Config, rw: u32, pipe: golden::pipeline::Pipeline) -> Vec<Stmt> {
    let (p, xw, log2p) = (cfg.p, cfg.xbits, cfg.log2p());
    let screen = cfg.align == Align::Screen && p > 1;
    let lw = log2p.max(1);
    let max_tot = (1u64 << (xw + 1)) - 1 + if screen { p as u64 - 1 } else { 0 };
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
    link
}
