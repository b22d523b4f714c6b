//! `Gxn lo` without a product a row (issue 27, the engine form's span path on the ECP5-25F):
//! per left edge, a running sum of `Gxn g` stepped with the edge's DDA.
//!
//! The span path needs `Gxn lo` modulo 2^(K-2) for the span's left end `lo`, which is 0 (the
//! screen's clamp) or `-g` of the left edge the end comes from. So each left edge keeps `P =
//! (Gxn >> 8) g` modulo 2^[`Widths::sum_bits`] (`Gxn`'s low 8 bits are zero,
//! [`Widths::GXN_ZEROS`]); its DDA moves `g` by `Qs` or `Qs + 1` a row, so `P` moves by
//! `(Gxn >> 8) Qs` or that plus `Gxn >> 8`, adds only. Set-up forms each `P`'s start and step,
//! `(Gxn >> 8) g` and `(Gxn >> 8) Qs` ([`super::TriSetup::sums`]), once per triangle, and
//! `Gxn lo = -(P << 8)` of the source, or 0 at the clamp. Edges that tie on a row have equal
//! `g`, hence equal `P`: which of them is taken does not matter.
//!
//! A triangle has at most two left edges (`dy < 0`), so two *slots* hold the sums, not three
//! edges: slot a edge 0 if it is an active left edge, else edge 1; slot b edge 2 if it is one,
//! else edge 1 ([`LEFT_SLOTS`]). Four products a triangle instead of six keep the ECP5
//! plan's 8 tiles at II = 12 with every product on one tile (six rotated products over tiles
//! across 6 triangles, docs/fpga.md).
//!
//! [`FrontEnd::i0`]'s product stays the oracle: the tests compare the two on every span.

use super::{mask, EdgeWalk, FrontEnd, TriSetup, Widths};

/// Each left slot's edges `(own, other)`: the slot holds its own edge if that is a left edge,
/// else the other. Slot a is edge 0 or 1, slot b edge 2 or 1: a triangle has at most two left
/// edges, so every active left edge is in a slot (edge 1 in a when edge 0 is not left, else in
/// b, as edge 2 then is not), and each slot is a select of two.
pub const LEFT_SLOTS: [(usize, usize); 2] = [(0, 1), (2, 1)];

/// Each left slot's edge ([`LEFT_SLOTS`]).
pub fn left_slots(edges: &[EdgeWalk; 3]) -> [usize; 2] {
    LEFT_SLOTS.map(|(own, other)| if edges[own].active && !edges[own].right { own } else { other })
}

/// The right end's slots, on [`LEFT_SLOTS`]' pairs of edges: a triangle has at most two right
/// edges as well (`dy > 0`, and its edges' dy sum to 0), so the span's right end is the lesser
/// of two slots' bounds, each slot a select of two edges (the RTL's row stages hold both ends
/// so: one compare an end, not three).
pub fn right_slots(edges: &[EdgeWalk; 3]) -> [usize; 2] {
    slots(edges, true, LEFT_SLOTS)
}

/// The slots of the edges on one side (`right`) on the pairs `pairs`: each its own edge if that
/// is an active edge of the side, else the other.
pub(crate) fn slots(edges: &[EdgeWalk; 3], right: bool, pairs: [(usize, usize); 2]) -> [usize; 2] {
    pairs.map(|(own, other)| if edges[own].active && edges[own].right == right { own } else { other })
}

/// A fault planted in the running sums: the tests' negative controls.
#[cfg_attr(not(test), allow(dead_code))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum SumFault {
    None,
    /// The sum steps by `Gxn Qs` only, its DDA's carry ignored.
    NoCarry,
    /// The span's left end always takes slot 0's sum.
    OneSlot,
    /// The screen's clamp (`lo` = 0 with a left edge beyond it) takes slot 0's sum, not 0.
    NoClamp,
}

/// The two slots' sums on the walked row.
pub(crate) struct Sums {
    p: [u128; 2],
    step: [u128; 2],
    g8: u128,
    m: u128,
    fault: SumFault,
}

impl Sums {
    /// The sums at the triangle's first row, if its set-up has them.
    pub(crate) fn new(fe: &FrontEnd, st: &TriSetup, fault: SumFault) -> Option<Sums> {
        let s = st.sums?;
        Some(Sums { p: s.map(|x| x.0), step: s.map(|x| x.1), g8: st.gxn >> Widths::GXN_ZEROS, m: mask(fe.widths().sum_bits()), fault })
    }

    /// `Gxn lo` modulo 2^(K-2) for row `r`'s left end `lo`: minus the sum of the slot whose edge
    /// gives it, or 0 at the clamp.
    pub(crate) fn gx(&self, edges: &[EdgeWalk; 3], r: u32, lo: i64) -> u128 {
        let slots = left_slots(edges);
        let src = (0..3).find(|&k| {
            let e = &edges[k];
            lo > 0 && e.active && !e.right && (e.rs..=e.re).contains(&r) && -e.g == lo
        });
        let sum = match (src, self.fault) {
            (Some(_), SumFault::OneSlot) => self.p[0],
            (Some(k), _) => self.p[(k != slots[0]) as usize],
            (None, SumFault::NoClamp) => self.p[0],
            (None, _) => 0,
        };
        (sum.wrapping_neg() & self.m) << Widths::GXN_ZEROS
    }

    /// After row `r`: each slot steps with its edge's DDA (`edges` before the step, `carry` its
    /// carries): `Gxn Qs`, or `Gxn (Qs + 1)` on a carry.
    pub(crate) fn step(&mut self, edges: &[EdgeWalk; 3], r: u32, carry: [bool; 3]) {
        for (j, &k) in left_slots(edges).iter().enumerate() {
            let e = &edges[k];
            if e.active && r >= e.rs {
                let c = carry[k] && self.fault != SumFault::NoCarry;
                self.p[j] = (self.p[j] + self.step[j] + if c { self.g8 } else { 0 }) & self.m;
            }
        }
    }
}

impl FrontEnd {
    /// The left slots' running sums' start and step, `(Gxn >> 8) g` and `(Gxn >> 8) Qs` of
    /// each slot's edge modulo 2^[`Widths::sum_bits`] ([`TriSetup::sums`]), as the engine's
    /// products form them; 0 where the slot's edge is not an active left edge.
    pub fn running_sums(&self, st: &TriSetup) -> [(u128, u128); 2] {
        let g8 = st.gxn >> Widths::GXN_ZEROS;
        let m = mask(self.widths().sum_bits());
        let times = |v: i64| g8.wrapping_mul(v as i128 as u128) & m;
        left_slots(&st.edges).map(|k| {
            let e = &st.edges[k];
            if e.active && !e.right {
                (times(e.g), times(e.qs))
            } else {
                (0, 0)
            }
        })
    }
}
