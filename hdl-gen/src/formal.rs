//! The formal properties' shared part: SPEC §3's stream contract (reset, stability, the
//! segment mask), the reference's clock flags and the tags `scripts/prove` reads. Each block's
//! properties live beside its generator (`segment/properties.rs`, `specular/properties.rs`,
//! `writer/properties.rs`, `frontend/properties.rs`, `bfpi/properties.rs`), each under
//! `` `ifdef FORMAL ``.
//!
//! How every proof is built: the contract is checked at the ports against a reference model
//! kept in the property block (a *shadow* of what the block owes). Port properties alone are
//! not inductive: a solver can start from a state in which the block's registers disagree with
//! the reference and stall forever. The generator knows its stage structure, so it also states
//! how its registers relate to the reference (the linking invariants); with them every property
//! is 1- or 2-inductive. They are assertions too, so a wrong invariant fails rather than proves
//! something false. The environment is held to one rule only: reset in the first clock.

use crate::verilog::{assign, comment, net, set, zext, Item, Stmt};

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

/// The tag `scripts/prove` reads for how many clocks from reset its cover search may take.
pub const COVER_DEPTH_TAG: &str = "scripts/prove: cover depth ";

/// Covers: states every proof must show reachable from reset within `depth` clocks (the
/// block's latency and a margin), each `(heading, condition)` labelled by its heading. A proof
/// whose assumptions or reset made it vacuous holds every assertion and reaches no cover.
pub(crate) fn covers(depth: u32, what: &[(&str, &str)]) -> Vec<Item> {
    let mut v = vec![comment(format!("{COVER_DEPTH_TAG}{depth}"))];
    for (heading, cond) in what {
        v.push(comment(*heading));
        v.push(Item::Comb(vec![when("f_past && !rst", vec![Stmt::Cover(cond.to_string())])]));
    }
    v
}

/// The output stream of the shader and the specular unit (SPEC §3).
pub(crate) const OUT: (&str, &str) = ("out_valid", "out_ready");

pub(crate) fn assert(c: impl Into<String>) -> Stmt {
    Stmt::Assert(c.into())
}
pub(crate) fn when(cond: impl Into<String>, then: Vec<Stmt>) -> Stmt {
    Stmt::If(cond.into(), then, vec![])
}

/// `f_past` (one clock since the solver's start) and `f_past2` (two), and the reset rule.
pub(crate) fn past_flags() -> Vec<Item> {
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
pub(crate) fn reset_and_stability(what: &str, (valid, ready): (&str, &str), held: &[&str]) -> Vec<Item> {
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
pub(crate) fn spec_mask(name: &str, (off, lead, tot): (&str, &str, &str), p: u32, (rw, lw): (u32, u32)) -> Vec<Item> {
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

/// A sized signed decimal constant (`-w'sdN` for a negative one).
pub(crate) fn slit(w: u32, v: i64) -> String {
    if v < 0 {
        format!("-{w}'sd{}", -v)
    } else {
        format!("{w}'sd{v}")
    }
}
