//! The specular unit's formal properties (scripts/prove): its control against a reference.

use crate::formal::{assert, covers, past_flags, reset_and_stability, when, CUT_TAG, OUT};
use crate::verilog::{comment, lit, reg, set, wire, Item, Stmt};

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
    b.extend(covers(stages.len() as u32 + 4, &[("Last pixel taken: a span ends.", "out_valid && out_ready && out_last")]));
    Item::Formal(b)
}
