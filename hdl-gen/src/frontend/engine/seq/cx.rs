//! What the sequential engine's parts share: the microword's function and source codes, the
//! block's widths ([`Cx`]) and where the units load their operands.

use crate::frontend::hw::Hw;
use golden::frontend::engine::sequential::{Exec, SeqSchedule};
use golden::frontend::engine::Kind;

/// The ALU's functions (the microword's `fn` field). 0 is a clock that issues no ALU
/// operation (a unit's load, or none): the split ALU zeroes its second operand for a pass and a
/// select (their value then comes through the adder), never on a unit's load, which reads it.
pub(super) const FN_PASS: u64 = 13;
pub(super) const FN_ADD: u64 = 1;
pub(super) const FN_SUB: u64 = 2;
pub(super) const FN_LT: u64 = 3;
pub(super) const FN_EQ: u64 = 4;
pub(super) const FN_AND: u64 = 5;
pub(super) const FN_OR: u64 = 6;
pub(super) const FN_NOT: u64 = 7;
pub(super) const FN_SEL: u64 = 8;
pub(super) const FN_LZC: u64 = 9;
pub(super) const FN_SHL: u64 = 10;
pub(super) const FN_SHR: u64 = 11;
pub(super) const FN_SHLV: u64 = 12;

/// The write bus's sources (the microword's `src` field); an input `k` is `SRC_IN + k`.
pub(super) const SRC_ALU: u64 = 0;
pub(super) const SRC_MUL: u64 = 1;
pub(super) const SRC_DIVQ: u64 = 2;
pub(super) const SRC_DIVR: u64 = 3;
pub(super) const SRC_IN: u64 = 4;
/// The second multiplier's product (the UP5K's two tiles; after the nine inputs).
pub(super) const SRC_MUL1: u64 = 13;

/// What every part of the block reads: golden's microprogram and the block's widths (the
/// register file's word, a shift amount, `pc`, an address) and clocks a triangle.
pub(super) struct Cx<'a> {
    pub(super) hw: &'a Hw,
    pub(super) s: &'a SeqSchedule,
    pub(super) w: u32,
    pub(super) sw: u32,
    pub(super) cw: u32,
    pub(super) aw: u32,
    pub(super) c: u32,
}

/// Where the units load their operands: the read ports' operands, or the split ALU's
/// registers of them a clock later (`SeqPlan::load_lag`).
pub(super) fn operands(cx: &Cx) -> (&'static str, &'static str) {
    match cx.s.plan.load_lag {
        0 => ("x0", "x1"),
        1 => {
            assert_eq!(
                cx.s.plan.alu_lat,
                golden::frontend::engine::sequential::ALU_LAT_SPLIT,
                "the operands' registers are the split ALU's"
            );
            ("ax0", "ax1")
        }
        l => panic!("units loading {l} clocks after their operands (the RTL has 0 and 1)"),
    }
}

/// The divider's widths: the widest divisor, the widest quotient and the quotient widths.
pub(super) fn div_widths(s: &SeqSchedule) -> (u32, u32, Vec<u32>) {
    let ops = &s.prog.ops;
    let divs: Vec<(u32, u32)> = (0..ops.len())
        .filter(|&o| s.slots[o].exec != Exec::Dead)
        .filter_map(|o| if let Kind::Div { d, qb, .. } = ops[o].kind { Some((ops[d.0 as usize].w, qb)) } else { None })
        .collect();
    let mut qbs: Vec<u32> = divs.iter().map(|d| d.1).collect();
    qbs.sort();
    qbs.dedup();
    (divs.iter().map(|d| d.0).max().expect("a division"), *qbs.last().expect("a division"), qbs)
}
