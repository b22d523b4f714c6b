//! The walker's running sums of `Gxn g` (`Hw::run_sums`, golden's `frontend::sums`): two left
//! slots, each the sum of one left edge, stepped with that edge's DDA; the span's `Gxn lo` is
//! minus the sum of the slot its left end comes from, or 0 at the screen's clamp. No product a
//! row: the span path's `Gxn lo` tiles go.

use super::hw::Hw;
use crate::verilog::{comment, lit, reg, set, wire, Item, Stmt};
use golden::frontend::sums::LEFT_SLOTS;
use golden::frontend::Widths;

/// The slots: each has its edge (one-hot), its sum in two parts and its step.
const SLOTS: [&str; 2] = ["a", "b"];

/// Slot `slot`'s sum on the walked row: its two parts added.
pub(super) fn slot_sum(slot: &str) -> String {
    format!("(w_p{slot} + w_c{slot})")
}

fn onehot(k: usize) -> String {
    lit(3, 1 << k)
}

/// Whether the row stages hold the edges' bounds by slot (the running sums' form): a triangle
/// has at most two left edges and two right ones (its edges' dy sum to 0), so each end is the
/// least of two slots' bounds, each slot a select of two edges ([`LEFT_SLOTS`]: the running
/// sums' slots for the left end, the same pairs for the right), made as the walked row's bounds
/// are registered. One compare and a select of two a clock where the least of three, three
/// compares then a select of three, was the 25F's critical path (docs/fpga.md).
pub(super) fn slotted(hw: &Hw) -> bool {
    hw.run_sums() && hw.row_stage()
}

/// The walker's declarations, its load (from the queue head) and its step (on the walker's
/// next row, each slot as its edge steps).
pub(super) fn walker(hw: &Hw) -> (Vec<Item>, Vec<Stmt>, Vec<Stmt>) {
    let wd = hw.fe.widths();
    let sb = wd.sum_bits();
    let z = Widths::GXN_ZEROS;
    let mut decls = vec![
        comment("Running sums of Gxn g (Gxn >> 8 units, modulo 2^(K-10)) of the two left slots: slot a edge 0 if it is an active"),
        comment("left edge, else edge 1; slot b edge 2 if it is one, else edge 1 (w_sa, w_sb one-hot). A slot's sum is w_p + w_c:"),
        comment("w_p steps by Gxn qs as its edge steps, w_c by Gxn (w_g8) as its edge carries."),
        reg("w_g8", sb),
    ];
    let mut load = vec![set("w_g8", format!("s_gxn[{}:{z}]", z + sb - 1))];
    let mut step = Vec::new();
    let left = |k: usize| format!("(e_act[{k}] && !e_right[{k}])");
    for (slot, (own, other)) in SLOTS.iter().zip(LEFT_SLOTS) {
        let (s, p, q, c) = (format!("w_s{slot}"), format!("w_p{slot}"), format!("w_q{slot}"), format!("w_c{slot}"));
        decls.push(reg(&s, 3));
        decls.extend([&p, &q, &c].map(|n| reg(n, sb)));
        load.push(set(&s, format!("{} ? {} : {}", left(own), onehot(own), onehot(other))));
        load.push(set(&p, format!("s_pg{slot}")));
        load.push(set(&q, format!("s_pq{slot}")));
        load.push(set(&c, lit(sb, 0)));
        // The carry's Gxn in a sum of its own, not a select of the step before one add: its
        // enable is the carry, and the two sums meet in an add into the row stage (carry chains,
        // where the select was a LUT4 a bit).
        let carry = Stmt::If(format!("|(e_x_cy & {s})"), vec![set(&c, format!("{c} + w_g8"))], vec![]);
        step.push(Stmt::If(format!("|(e_x_on & {s})"), vec![set(&p, format!("{p} + {q}")), carry], vec![]));
    }
    if slotted(hw) {
        // The right end's slots, on the same pairs of edges: slot a holds its own edge if that
        // is an active right edge, else the other (the row stages' bounds, `walker::bound_registers`).
        decls.push(comment("The right end's slots: w_ra (w_rb) when edge 0 (2) is an active right edge, else edge 1."));
        for (r, (own, _)) in ["w_ra", "w_rb"].iter().zip(LEFT_SLOTS) {
            decls.push(reg(r, 1));
            load.push(set(*r, format!("e_act[{own}] && e_right[{own}]")));
        }
    }
    // The queue head's Gxn is read for its steps only, modulo 2^(K-2) and above its zero bits.
    decls.push(comment("verilator lint_off UNUSEDSIGNAL"));
    decls.push(wire("unused_s_gxn", 2 + z, format!("{{s_gxn[{}:{}], s_gxn[{}:0]}}", wd.k - 1, wd.k - 2, z - 1)));
    decls.push(comment("verilator lint_on UNUSEDSIGNAL"));
    (decls, load, step)
}

/// Whether the left end's source is slot a (`sa` one-hot: slot a's edge): the edge that wins the
/// left end's least-of-three (`side0..2`, the edges' bounds on the row) is slot a's. Edges that
/// tie have equal sums, so either slot is right for them.
pub(super) fn slot_a_wins(side: &str, sa: &str) -> String {
    let c = |i: u32, j: u32| format!("{side}{i} <= {side}{j}");
    let win = format!("(({} && {}) ? {} : ({}) ? {} : {})", c(0, 1), c(0, 2), onehot(0), c(1, 2), onehot(1), onehot(2));
    format!("|({win} & {sa})")
}

/// The span's `Gxn lo` source (`sb` bits, a sum to negate): slot a's sum when `a_wins`
/// ([`slot_a_wins`]), else slot b's; 0 when the end is the clamp (`mg`'s sign clear: every bound
/// is at most 0, `lo = -mg`).
pub(super) fn source(hw: &Hw, (pa, pb, a_wins): (&str, &str, &str), mg: &str) -> String {
    let end_w = super::edge::end_width(hw);
    format!("{mg}[{}] ? (({a_wins}) ? {pa} : {pb}) : {}", end_w - 1, lit(hw.fe.widths().sum_bits(), 0))
}
