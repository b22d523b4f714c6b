//! `I0` per scanline without a product per row (issue 27's plan, `docs/design.md`): the same
//! spans as [`FrontEnd::walk`], bit for bit, with `I0` kept per *source* of the span's left end
//! as a quotient and remainder over `2A` and stepped by adds.
//!
//! A span's left end `lo = max(0, -g_k)` over the left edges active on its row comes from one
//! source: column 0 (the screen's clamp) or a left edge `k`. From one row to the next a
//! source's numerator `N = 2 S(lo, r) + A` changes by a constant: `512 Ny` for column 0, and for
//! an edge `512 Ny - 512 Nx (Qs + c)`, where `c` is its DDA's carry that row. Set-up divides
//! those constants by `2A` once per triangle; each row adds the step's quotient (modulo 2^IW:
//! only the in-range values ever leave) and its remainder, with one carry.
//!
//! A source's state is *started* at the first row where it gives the left end of a span with
//! pixels, from today's reciprocal formula ([`FrontEnd::i0`]): that pixel is covered, so its
//! value is in range and the formula is exact there, where a value set-up could compute at a
//! source's first row may be the plane extrapolated far out of range (beside a sliver). A step
//! whose quotient lies outside `[-2^IW, 2^IW)` is not one set-up can divide with the same
//! reciprocal, so taking it leaves the source unstarted again: it restarts at its next use.
//! Everything the hardware would hold is modelled: normalised remainders (`<< s`, against
//! `2 An`) and quotients modulo 2^IW.

use super::{mask, FrontEnd, I0Form, SetupForm, TriSetup};
use crate::format::Span;

/// One source's step per row: quotient (modulo 2^IW) and normalised remainder of `X / 2A`, or
/// none when the quotient is outside the divider's range.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Step {
    pub q: u32,
    pub rn: u128,
}

/// Per triangle: column 0's step, and each edge's without and with its DDA's carry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Steps {
    pub col0: Option<Step>,
    pub edge: [[Option<Step>; 2]; 3],
}

/// A source's state: started or not, and `(q, rn)` of its left end on the current row.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct State {
    started: bool,
    q: u32,
    rn: u128,
}

/// What a walk cost the incremental form: rows walked, spans, and starts (reciprocal
/// evaluations), in total and the most in one triangle.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Cost {
    pub rows: u64,
    pub spans: u64,
    pub starts: u64,
    pub most_starts: u32,
}

/// Products the start engine's program forms before its last step, which writes the source
/// (the RTL's `tri_frontend`, `--fe-i0 incremental`; docs/design.md): at an edge `Gxn lo`,
/// `|Nx Qs|`, `S2n Rn`, `q~ 2An`, `Gxn |Qs|`, the step's `X0 Rn`, `q~ 2An`, `X1 Rn`, `q~ 2An`;
/// column 0 has one step and stops two products earlier.
pub const EDGE_PRODUCTS: u32 = 9;
pub const COL0_PRODUCTS: u32 = 7;

impl FrontEnd {
    /// Clocks each of the start engine's products takes: one on a K x RW multiplier, or RW (one
    /// bit of the narrower operand a clock) on a shift-add one, which the HX8K's form takes: the
    /// HX8K has no multiplier, and at its sequential set-up's few hundred clocks a triangle the
    /// starts' clocks are cheaper than a K x RW product in logic.
    pub fn start_product_clocks(&self) -> u32 {
        match self.setup {
            SetupForm::Ice40Hx8k => self.widths().rw,
            _ => 1,
        }
    }

    /// Clocks a start takes, `(at an edge, at column 0)`, from the clock it begins to the one
    /// that writes the source; `(0, 0)` in the reciprocal form, which has none. A walker's
    /// start holds the walker as long; a triangle's first row is started while it is held.
    pub fn start_clocks(&self) -> (u32, u32) {
        match self.i0 {
            I0Form::Reciprocal => (0, 0),
            I0Form::Incremental => {
                let m = self.start_product_clocks();
                (EDGE_PRODUCTS * m + 1, COL0_PRODUCTS * m + 1)
            }
        }
    }

    /// Set-up's steps for a walked triangle: `divmod(X, 2A)` of each source's constant.
    pub fn i0_steps(&self, st: &TriSetup) -> Steps {
        let p = &st.plane;
        let a2 = 2 * p.a;
        let iw = self.cfg.iw();
        let step = |x: i128| {
            if x.unsigned_abs() >= (a2 as u128) << iw {
                return None;
            }
            let (q, r) = (x.div_euclid(a2), x.rem_euclid(a2));
            Some(Step { q: (q as u32) & mask(iw) as u32, rn: (r as u128) << st.s })
        };
        let edge = st.edges.map(|e| [0, 1].map(|c| step(512 * p.ny - 512 * p.nx * (e.qs + c) as i128)));
        Steps { col0: step(512 * p.ny), edge }
    }

    /// [`FrontEnd::walk`] with `I0` from the sources' states; the spans are the same (the
    /// per-scanline `dI` option's last-pixel value still comes from the reciprocal formula).
    /// Returns what it cost.
    pub fn walk_incremental(&self, st: &TriSetup, out: impl FnMut(u32, Span)) -> Cost {
        self.walk_with_steps(st, &self.i0_steps(st), out)
    }

    /// The walk with the given steps (the tests plant wrong ones here).
    pub(super) fn walk_with_steps(&self, st: &TriSetup, steps: &Steps, mut out: impl FnMut(u32, Span)) -> Cost {
        let wd = self.widths();
        let km = mask(wd.k);
        let iw = self.cfg.iw();
        let an2 = 2 * st.an;
        let mut edges = st.edges;
        let mut tn = st.tn;
        // 0: column 0; 1 + k: edge k.
        let mut src = [State::default(); 4];
        let mut cost = Cost::default();
        let mut starts = 0u32;
        for r in st.first..=st.last {
            // The left end and its source: the largest candidate, a started one among equals.
            let mut lo = (0i64, 0usize);
            let mut hi = self.screen.width as i64 - 1;
            for (k, e) in edges.iter().enumerate() {
                if e.active && (e.rs..=e.re).contains(&r) {
                    if e.right {
                        hi = hi.min(e.g);
                    } else if -e.g > lo.0 || (-e.g == lo.0 && src[1 + k].started && !src[lo.1].started) {
                        lo = (-e.g, 1 + k);
                    }
                }
            }
            cost.rows += 1;
            if lo.0 <= hi {
                let s = &mut src[lo.1];
                if !s.started {
                    // The start: today's reciprocal formula, exact on a covered pixel.
                    let q = self.i0(st, tn, lo.0 as u32);
                    let s2n = (2 * (tn + st.gxn * lo.0 as u128) + st.an) & km;
                    let rn = s2n.wrapping_sub(q as u128 * an2) & mask(wd.aw + 2);
                    *s = State { started: true, q, rn };
                    starts += 1;
                }
                let len = (hi - lo.0 + 1) as u32;
                let di = match self.di {
                    super::DiMode::Triangle => st.di,
                    super::DiMode::Scanline if len == 1 => 0,
                    super::DiMode::Scanline => {
                        let last = self.i0(st, tn, hi as u32);
                        self.di(last as i128 - s.q as i128, (len - 1) as u128)
                    }
                };
                cost.spans += 1;
                out(r, Span { x0: lo.0 as u32, len, i0: s.q, di });
            }
            // Every source steps to the next row; an edge's step follows its DDA's carry.
            let advance = |s: &mut State, step: Option<Step>| match step {
                Some(d) if s.started => {
                    let rn = s.rn + d.rn;
                    let carry = rn >= an2;
                    s.rn = if carry { rn - an2 } else { rn };
                    s.q = s.q.wrapping_add(d.q).wrapping_add(carry as u32) & mask(iw) as u32;
                }
                _ => s.started = false,
            };
            advance(&mut src[0], steps.col0);
            for (k, e) in edges.iter_mut().enumerate() {
                if e.active && r >= e.rs {
                    let carry = e.step_carry();
                    advance(&mut src[1 + k], steps.edge[k][carry as usize]);
                }
            }
            tn = (tn + st.dyn_) & km;
        }
        cost.starts = starts as u64;
        cost.most_starts = starts;
        cost
    }
}
