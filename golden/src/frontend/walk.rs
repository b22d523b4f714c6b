//! The walker's model: one row a step, each edge's DDA, the span's ends, its `I0` from the
//! reciprocal (`Gxn lo` by a product, or from the running sums of [`super::sums`]).

use super::sums::{SumFault, Sums};
use super::{mask, DiMode, FrontEnd, TriSetup, Widths};
use crate::format::Span;

impl FrontEnd {
    /// Walks a set-up triangle: `out(y, span)` for every covered row, top to bottom.
    pub fn walk(&self, st: &TriSetup, mut out: impl FnMut(u32, Span)) {
        self.walk_with(st, SumFault::None, |y, s, _| out(y, s));
    }

    /// [`FrontEnd::walk`] with a fault planted in the running sums (the tests' negative
    /// controls), each span with the `Gxn lo` the sums gave it (`None` without them).
    pub(crate) fn walk_with(&self, st: &TriSetup, fault: SumFault, mut out: impl FnMut(u32, Span, Option<u128>)) {
        let wd = self.widths();
        let km = mask(wd.k);
        let mut edges = st.edges;
        let mut tn = st.tn;
        let mut sums = Sums::new(self, st, fault);
        for r in st.first..=st.last {
            let (mut lo, mut hi) = (0i64, self.screen.width as i64 - 1);
            for e in &edges {
                if e.active && (e.rs..=e.re).contains(&r) {
                    if e.right {
                        hi = hi.min(e.g);
                    } else {
                        lo = lo.max(-e.g);
                    }
                }
            }
            if lo <= hi {
                let gx = sums.as_ref().map(|s| s.gx(&edges, r, lo));
                if fault == SumFault::None {
                    debug_assert!(gx.is_none_or(|gx| gx == wd.gx_lo(st.gxn, lo as u32, Widths::GXN_ZEROS)), "Gxn lo, row {r}: {st:?}");
                }
                let i0 = match gx {
                    Some(gx) => self.i0_from(st, tn, gx),
                    None => match self.span_seq() {
                        Some(q) => q.i0(tn, st.gxn, st.an, st.rn, lo as u32),
                        None => self.i0(st, tn, lo as u32),
                    },
                };
                debug_assert!(
                    fault != SumFault::None || i0 as i128 == (2 * st.plane.s(lo, r as i64) + st.plane.a) / (2 * st.plane.a),
                    "I0 of row {r} at column {lo}, {st:?}"
                );
                let len = (hi - lo + 1) as u32;
                let di = match self.di {
                    DiMode::Triangle => st.di,
                    DiMode::Scanline if len == 1 => 0,
                    DiMode::Scanline => {
                        let last = self.i0(st, tn, hi as u32);
                        self.di(last as i128 - i0 as i128, (len - 1) as u128)
                    }
                };
                out(r, Span { x0: lo as u32, len, i0, di }, gx);
            }
            let before = edges;
            let mut carry = [false; 3];
            for (k, e) in edges.iter_mut().enumerate() {
                if e.active && r >= e.rs {
                    carry[k] = e.step_carry();
                }
            }
            if let Some(s) = &mut sums {
                s.step(&before, r, carry);
            }
            tn = (tn + st.dyn_) & km;
        }
    }
}
