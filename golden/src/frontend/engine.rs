//! The shared set-up engine (issue 27, `docs/design.md`): [`FrontEnd::setup`] written once more as
//! a dataflow program of operations with their widths, which golden both evaluates and
//! schedules onto a few shared units, so the plan of the engine cannot drift from the set-up.
//!
//! - **The program** ([`Program::setup`], `engine/build.rs`): differences, compares and selects
//!   (dedicated logic, as CALC's stages are today), products with their operand widths
//!   (`Mul`), restoring divisions with dividend, divisor and quotient widths (`Div`), in the
//!   set-up's own formulas: the orientation from the area's sign, each edge's DDA, `dI`, the
//!   reciprocal `Rn`, the first row's sum, and with [`Plan::i0_steps`] the incremental `I0`'s
//!   per-source steps ([`FrontEnd::i0_steps`]). Every value is wrapped to its declared width
//!   as a register of that width would, so a width too narrow shows as a wrong result.
//! - **Division by reciprocal** ([`Plan::reciprocal`]): every division by `2A` (dI and the
//!   steps) is formed as the walker forms `I0`: the dividend normalised by `s` (below 2^K),
//!   a product by `Rn`, one product by `2An` and compares to correct it. `Rn` itself
//!   stays a restoring division, and so do the edges' (each has its own divisor). Only the
//!   dividend's top `IW + 2` bits enter the product, so the estimate is up to two below and two
//!   compares correct it (`engine/build.rs`, `ByA::divmod`).
//! - **The schedule** (`engine/schedule.rs`): a modulo schedule of the program on `M`
//!   multipliers and `D` dividers of `R` quotient bits a clock; the set-up's *latency* and
//!   *initiation interval* (clocks between two triangles entering the engine, the sustained
//!   rate), which unit runs which operation in which clock, how many copies of each register
//!   the overlap needs, and an estimate of the engine's LUT4s.
//! - **The sequenced evaluation** ([`schedule::Schedule::run`]): triangles stream through the schedule
//!   clock by clock; an operation reads each operand from the register copy it would hold at
//!   that clock, so a schedule that reads a value before it is written, or overwrites it
//!   before its last reader, gives a wrong set-up, which the tests compare with
//!   [`FrontEnd::setup`] and [`FrontEnd::i0_steps`].

mod build;
mod placement;
pub mod schedule;
pub mod sequential;
#[cfg(test)]
mod tests;

use super::incremental::{Step, Steps};
use super::{EdgeWalk, FrontEnd, Outcome, Plane, TriSetup};
use serde::{Deserialize, Serialize};

/// What a multiplier unit is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MulUnit {
    /// One hard multiplier of `bits` x `bits` (ECP5 MULT18X18D: 18; iCE40 SB_MAC16: 16), or, as
    /// the RTL infers it, of `bits + 1`-bit signed operands (17 and 15: [`Plan::TILE18_RTL`]). A
    /// wider product is cut into `bits`-wide chunks of each operand and takes one pass a chunk
    /// pair, accumulated at the pair's weight; passes wholly above the bits the product keeps
    /// are skipped. The sign is handled per chunk (ECP5's SIGNEDA/B are inputs) or as
    /// magnitude and sign.
    Tile { bits: u32 },
    /// No hard multiplier (iCE40 HX): shift and add, `bits` bits of the narrower operand a
    /// clock, one adder as wide as the product it keeps.
    ShiftAdd { bits: u32 },
}

/// How a restoring divider is built (the same quotients; the cost differs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum DivForm {
    /// Today's (`hdl-gen/src/frontend/divider.rs`): the divisor shifted right across a partial
    /// remainder of quotient plus divisor bits; the subtractor is that wide.
    ShiftDivisor,
    /// The textbook form: the partial remainder shifted left past a fixed divisor, the dividend's
    /// bits shifted in; the subtractor is one bit wider than the divisor.
    #[default]
    ShiftRemainder,
}

/// The shared set-up engine's parameters: the generator and the manifest print them with the
/// schedule's clocks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Plan {
    /// Multiplier units `M`.
    pub mults: u32,
    pub mul: MulUnit,
    /// Restoring dividers `D`.
    pub dividers: u32,
    /// Quotient bits a divider takes a clock: radix `2^R`.
    pub div_bits: u32,
    pub div_form: DivForm,
    /// Divisions by `2A` by the reciprocal `Rn` (a product and one correction).
    pub reciprocal: bool,
    /// The incremental `I0`'s per-source steps are part of the set-up.
    pub i0_steps: bool,
    /// The span path's `Gxn lo` from per-edge running sums, not a product a row: the set-up
    /// forms each edge's `(Gxn >> 8) g` and `(Gxn >> 8) Qs` ([`super::TriSetup::sums`]) as
    /// `(Nx g) << s` and `(Nx Qs) << s` modulo 2^(K-10), six products and six shifts more.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub run_sums: bool,
    /// Each edge's DDA start in the form the walker's edges hold behind the row stages
    /// ([`EdgeOut::dda`]): `thr = (D - rs256) / 256` and `t = rem / 256 - thr`, two subtracts
    /// on the engine's carry chains where each edge's load formed `rem + rs256 - D` carry-save
    /// and `D - rs256` (docs/fpga.md).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub edge_t: bool,
    /// A division busier than II runs on its pair of dividers in series, not alternating
    /// between them by the triangle's parity: the first divider takes the load and the first
    /// half of the steps, the second the rest from the first's partial remainder
    /// ([`super::engine::schedule::Schedule::div_stages`]). Both then serve every triangle, so
    /// no value register chooses its quotient or remainder between two dividers by epoch
    /// (those selects were about 980 of the ECP5 plan's engine LUT4, docs/fpga.md); the
    /// clocks are the same.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub div_chain: bool,
    /// Shared barrel shifters for the normalising shifts by a value (`ShlBy`: `2A`, and the
    /// plane's terms by `s`); 0: each shift its own logic, as CALC's. Five 64-bit shifts by a
    /// 6-bit amount were about 1,560 of the ECP5 plan's engine LUT4 (docs/fpga.md).
    pub shifters: u32,
}

impl Plan {
    /// ECP5 MULT18X18D tiles, 18-bit chunks (the sign per chunk, as the tile's SIGNEDA/B
    /// inputs can take it): the estimates' grid.
    pub const TILE18: MulUnit = MulUnit::Tile { bits: 18 };
    /// The same tiles as the RTL infers them: 17-bit chunks, each an 18-bit signed operand of
    /// fixed signedness (a lower chunk zero-extended, the top one sign-extended), so synthesis
    /// maps a pass onto one MULT18X18D. At 640x480 the set-up's products take as many passes
    /// as with 18-bit chunks (75), and the schedule the same II and latency.
    pub const TILE18_RTL: MulUnit = MulUnit::Tile { bits: 17 };

    /// docs/design.md's recommendation for the ECP5-25F: 12 clocks a triangle on 8 MULT18X18D
    /// and fourteen 1-bit dividers, the incremental steps left to the walker's start evaluator.
    /// 8 tiles, not 12: 8 are the fewest the scheduler keeps at 12 clocks (7 give 13), so the
    /// front-end with the span path's 9 per-row tiles has 17 MULT18X18D, within the
    /// LFE5U-25F's 28. 14 dividers, not the 12 that 120 divider clocks need at II = 12: each
    /// edge's `Qs` and `g` (16 clocks) and `Rn` (24) then alternate over a pair of dividers of
    /// their own, where 12 rotated `Qs` and `g` over three dividers each: the dividers' operand
    /// multiplexers go, and `Qs`'s dividers are 19 bits wide, not 27 (tri_frontend 6,092 ->
    /// 5,252 LUT4, docs/fpga.md). Each pair runs its division in series ([`Plan::div_chain`]),
    /// not by the triangle's parity.
    pub const ECP5_25F: Plan = Plan {
        mults: 8,
        mul: Plan::TILE18_RTL,
        dividers: 14,
        div_bits: 1,
        div_form: DivForm::ShiftRemainder,
        reciprocal: true,
        i0_steps: false,
        run_sums: true,
        edge_t: true,
        div_chain: true,
        shifters: 1,
    };
    /// For the iCE40 UP5K: 2 of its SB_MAC16 and one 1-bit divider, the smallest engine. 15-bit
    /// chunks, 16-bit signed operands (as [`Plan::TILE18_RTL`]): 120 clocks a triangle either way.
    pub const ICE40_UP5K: Plan = Plan {
        mults: 2,
        mul: MulUnit::Tile { bits: 15 },
        dividers: 1,
        div_bits: 1,
        div_form: DivForm::ShiftRemainder,
        reciprocal: true,
        i0_steps: false,
        run_sums: false,
        edge_t: false,
        div_chain: false,
        shifters: 1,
    };
    /// For the iCE40 HX8K, which has no multiplier: one shift-add unit and one divider, a bit a clock.
    pub const ICE40_HX8K: Plan = Plan {
        mults: 1,
        mul: MulUnit::ShiftAdd { bits: 1 },
        dividers: 1,
        div_bits: 1,
        div_form: DivForm::ShiftRemainder,
        reciprocal: false,
        i0_steps: false,
        run_sums: false,
        edge_t: false,
        div_chain: false,
        shifters: 1,
    };
}

pub use super::SetupForm;

impl SetupForm {
    /// The engine's plan; `None` for the parallel set-up.
    pub fn plan(self) -> Option<Plan> {
        match self {
            SetupForm::Parallel => None,
            SetupForm::Ecp5_25f => Some(Plan::ECP5_25F),
            SetupForm::Ice40Up5k => Some(Plan::ICE40_UP5K),
            SetupForm::Ice40Hx8k => Some(Plan::ICE40_HX8K),
        }
    }
}

/// A value of the program: the result of the operation with this index.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct V(pub u32);

/// An operation. Shifts by constants, the remainder of a division and a plain copy are wiring;
/// the others are logic, one clock each, except products and divisions, which run on units.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Port value: x0, x1, x2, y0, y1, y2, i0, i1, i2.
    In(u8),
    Const(i128),
    /// The operand wrapped to this operation's width.
    Wire(V),
    Shl(V, u32),
    /// Arithmetic shift right: floor division by a power of two.
    Shr(V, u32),
    Add(V, V),
    Sub(V, V),
    /// `a << s` for a value `s`: a barrel shifter.
    ShlBy(V, V),
    /// 1 if `a < b`, else 0.
    Lt(V, V),
    Eq(V, V),
    And(V, V),
    Or(V, V),
    Not(V),
    /// `c ? a : b`.
    Sel(V, V, V),
    /// Leading zeros of a value in this many bits.
    Lzc(V, u32),
    /// A product, kept to this operation's width (its low bits).
    Mul(V, V),
    /// Restoring division: `floor(n / d)` when `d > 0`, `n >= 0` and the quotient fits `qb`
    /// bits; otherwise unspecified (here all ones), and the program reads it only where it fits.
    /// `pw` is the partial remainder's width, as today's dividers hold it.
    Div {
        n: V,
        d: V,
        qb: u32,
        pw: u32,
    },
    /// The remainder of a `Div`.
    Rem(V),
}

impl Kind {
    /// The values this operation reads (a `Rem` reads its division's second result).
    pub fn args(&self) -> Vec<V> {
        use Kind::*;
        match *self {
            In(_) | Const(_) => vec![],
            Wire(a) | Shl(a, _) | Shr(a, _) | Not(a) | Lzc(a, _) | Rem(a) => vec![a],
            Add(a, b) | Sub(a, b) | ShlBy(a, b) | Lt(a, b) | Eq(a, b) | And(a, b) | Or(a, b) | Mul(a, b) => vec![a, b],
            Sel(c, a, b) => vec![c, a, b],
            Div { n, d, .. } => vec![n, d],
        }
    }
}

/// One operation: what, its result's width and signedness, and a name for schedules.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Op {
    pub kind: Kind,
    pub w: u32,
    pub signed: bool,
    pub name: String,
}

/// One edge's results.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EdgeOut {
    pub dyz: V,
    pub right: V,
    pub active: V,
    pub rs: V,
    pub re: V,
    pub g: V,
    pub rem: V,
    pub d: V,
    pub qs: V,
    pub rs256: V,
    /// With [`Plan::edge_t`]: the DDA's start on the bits above D's eight zero bits, `(thr, t)`
    /// with `thr = (D - rs256) >> 8` (`|dy|` bits) and `t = (rem >> 8) - thr` (one more,
    /// signed). `rem >= D - rs256` exactly when `t >= 0`: the walker's carry is `t`'s sign.
    pub dda: Option<(V, V)>,
}

/// A step's results: whether it is in range, its quotient and normalised remainder.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StepOut {
    pub ok: V,
    pub q: V,
    pub rn: V,
}

/// The values the walker loads from the set-up result queue (and golden's self-check data).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Outputs {
    pub guard_ok: V,
    pub cull: V,
    pub first: V,
    pub last: V,
    pub edges: [EdgeOut; 3],
    pub di: V,
    pub an: V,
    pub s: V,
    pub rn: V,
    pub tn: V,
    pub dyn_: V,
    pub gxn: V,
    pub i0a: V,
    pub nx: V,
    pub ny: V,
    pub a: V,
    pub steps: Option<(StepOut, [[StepOut; 2]; 3])>,
    /// Per left slot `(Gxn >> 8) g` and `(Gxn >> 8) Qs` ([`Plan::run_sums`]).
    pub sums: Option<[(V, V); 2]>,
}

impl Outputs {
    /// Every value the queue takes.
    pub fn all(&self) -> Vec<V> {
        let mut v = vec![self.guard_ok, self.cull, self.first, self.last, self.di, self.an, self.s, self.rn];
        v.extend([self.tn, self.dyn_, self.gxn, self.i0a, self.nx, self.ny, self.a]);
        for e in &self.edges {
            v.extend([e.dyz, e.right, e.active, e.rs, e.re, e.g, e.rem, e.d, e.qs, e.rs256]);
            v.extend(e.dda.iter().flat_map(|&(thr, t)| [thr, t]));
        }
        if let Some((c0, edge)) = &self.steps {
            for s in std::iter::once(c0).chain(edge.iter().flatten()) {
                v.extend([s.ok, s.q, s.rn]);
            }
        }
        for (pg, pq) in self.sums.iter().flatten() {
            v.extend([*pg, *pq]);
        }
        v
    }
}

/// The set-up as a program: operations in an order where every operand comes first.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Program {
    pub ops: Vec<Op>,
    pub out: Outputs,
}

/// A value wrapped to `w` bits, as a register of that width holds it.
pub(crate) fn wrap(v: i128, w: u32, signed: bool) -> i128 {
    if w >= 127 {
        return v;
    }
    let m = v & ((1i128 << w) - 1);
    if signed && m >> (w - 1) != 0 {
        m - (1i128 << w)
    } else {
        m
    }
}

/// One operation's result (and a division's remainder) from its operands' values, in `args`
/// order; a `Rem`'s operand is the remainder itself.
pub(crate) fn compute(op: &Op, x: &[i128], inputs: &[i128; 9]) -> (i128, i128) {
    use Kind::*;
    let b = |c: bool| c as i128;
    let (v, r) = match op.kind {
        In(k) => (inputs[k as usize], 0),
        Const(c) => (c, 0),
        Wire(_) | Rem(_) => (x[0], 0),
        Shl(_, n) => (x[0] << n, 0),
        Shr(_, n) => (x[0] >> n, 0),
        Add(..) => (x[0] + x[1], 0),
        Sub(..) => (x[0] - x[1], 0),
        ShlBy(..) => (if x[1] >= 120 { 0 } else { x[0] << x[1] }, 0),
        Lt(..) => (b(x[0] < x[1]), 0),
        Eq(..) => (b(x[0] == x[1]), 0),
        And(..) => (b(x[0] != 0 && x[1] != 0), 0),
        Or(..) => (b(x[0] != 0 || x[1] != 0), 0),
        Not(_) => (b(x[0] == 0), 0),
        Sel(..) => (if x[0] != 0 { x[1] } else { x[2] }, 0),
        Lzc(_, w) => ((0..w).rev().take_while(|&i| x[0] >> i & 1 == 0).count() as i128, 0),
        Mul(..) => (x[0].wrapping_mul(x[1]), 0),
        Div { qb, .. } => {
            let (n, d) = (x[0], x[1]);
            let q = if d > 0 && n >= 0 { n / d } else { i128::MAX };
            if q < 1i128 << qb {
                (q, n - q * d)
            } else {
                ((1i128 << qb) - 1, n)
            }
        }
    };
    (wrap(v, op.w, op.signed), r)
}

impl Program {
    /// The inputs of a triangle, in `Kind::In`'s order.
    pub fn inputs(t: &super::FixedTriangle) -> [i128; 9] {
        let mut v = [0i128; 9];
        for k in 0..3 {
            (v[k], v[3 + k], v[6 + k]) = (t.x[k] as i128, t.y[k] as i128, t.i[k] as i128);
        }
        v
    }

    /// Evaluates the program in order, every operand ready: the reference for the schedule.
    pub fn eval(&self, t: &super::FixedTriangle) -> (Outcome, Option<TriSetup>, Option<Steps>) {
        let val = self.values(t);
        self.out.extract(t, |v| val[v.0 as usize])
    }

    /// Every operation's value, in order, each wrapped to its width.
    pub fn values(&self, t: &super::FixedTriangle) -> Vec<i128> {
        let inputs = Self::inputs(t);
        let mut val = vec![0i128; self.ops.len()];
        let mut rem = vec![0i128; self.ops.len()];
        for (o, op) in self.ops.iter().enumerate() {
            let x: Vec<i128> = match op.kind {
                Kind::Rem(d) => vec![rem[d.0 as usize]],
                k => k.args().iter().map(|a| val[a.0 as usize]).collect(),
            };
            (val[o], rem[o]) = compute(op, &x, &inputs);
        }
        val
    }
}

impl Outputs {
    /// The set-up result from the queue's values, in [`FrontEnd::setup`]'s form: a field the
    /// walker never reads is left as `setup` leaves it (an inactive edge's rows, bound and
    /// remainder 0; a horizontal edge's divisor 1 and step 0). Edges' steps that the walker
    /// never takes (an edge active on fewer than two rows) are normalised by [`canonical`].
    pub fn extract(&self, t: &super::FixedTriangle, get: impl Fn(V) -> i128) -> (Outcome, Option<TriSetup>, Option<Steps>) {
        if get(self.guard_ok) == 0 {
            return (Outcome::Guard, None, None);
        }
        if get(self.cull) != 0 {
            return (Outcome::Culled, None, None);
        }
        let u = |v: V| get(v) as u128;
        let edges = self.edges.map(|e| {
            let (dyz, active) = (get(e.dyz) != 0, get(e.active) != 0);
            let on = |v: V| if active { get(v) as i64 } else { 0 };
            EdgeWalk {
                right: get(e.right) != 0,
                active,
                rs: on(e.rs) as u32,
                re: on(e.re) as u32,
                g: on(e.g),
                rem: on(e.rem),
                d: if dyz { 1 } else { get(e.d) as i64 },
                qs: if dyz { 0 } else { get(e.qs) as i64 },
                rs256: if dyz { 0 } else { get(e.rs256) as i64 },
            }
        });
        let plane = Plane { i0a: get(self.i0a), nx: get(self.nx), ny: get(self.ny), x0: t.x[0], y0: t.y[0], a: get(self.a) };
        let st = TriSetup {
            first: get(self.first) as u32,
            last: get(self.last) as u32,
            edges,
            di: get(self.di) as i32,
            an: u(self.an),
            s: get(self.s) as u32,
            rn: u(self.rn),
            tn: u(self.tn),
            dyn_: u(self.dyn_),
            gxn: u(self.gxn),
            // As the edge's own fields: a slot's sums are 0 where its edge is not an active left
            // edge (never a span's source), its step where the edge is never stepped (`canonical`).
            sums: self.sums.map(|s| {
                let src = super::sums::left_slots(&edges);
                std::array::from_fn(|j| {
                    let (pg, pq) = s[j];
                    let e = &edges[src[j]];
                    if e.active && !e.right {
                        (u(pg), u(pq))
                    } else {
                        (0, 0)
                    }
                })
            }),
            plane,
        };
        let steps = self.steps.map(|(c0, edge)| {
            let step = |s: StepOut| (get(s.ok) != 0).then(|| Step { q: get(s.q) as u32, rn: u(s.rn) });
            Steps { col0: step(c0), edge: edge.map(|e| e.map(step)) }
        });
        (Outcome::Walked, Some(canonical(st)), steps.map(|s| canonical_steps(&st, s)))
    }
}

/// Whether the walker ever takes edge `e`'s step: it is active on two rows or more.
fn stepped(e: &EdgeWalk) -> bool {
    e.active && e.re > e.rs
}

/// A set-up with the steps the walker never takes zeroed: `setup` divides them exactly, a
/// divider of the step's width does not need to (their quotient may not fit it).
pub fn canonical(mut st: TriSetup) -> TriSetup {
    let src = super::sums::left_slots(&st.edges);
    if let Some(s) = &mut st.sums {
        for j in 0..2 {
            if !stepped(&st.edges[src[j]]) {
                s[j].1 = 0;
            }
        }
    }
    for e in &mut st.edges {
        if !stepped(e) {
            (e.qs, e.rs256) = (0, 0);
        }
    }
    st
}

/// The incremental steps with those of edges the walker never steps removed.
pub fn canonical_steps(st: &TriSetup, mut s: Steps) -> Steps {
    for (k, e) in st.edges.iter().enumerate() {
        if !stepped(e) {
            s.edge[k] = [None, None];
        }
    }
    s
}

/// `FrontEnd::setup` and its steps in the canonical form the engine is compared in, with the
/// running sums when `plan` forms them ([`Plan::run_sums`]).
pub fn reference(fe: &FrontEnd, plan: &Plan, t: &super::FixedTriangle) -> (Outcome, Option<TriSetup>, Option<Steps>) {
    let (o, st) = fe.setup(t);
    match st {
        Some(st) => {
            let st = TriSetup { sums: plan.run_sums.then(|| fe.running_sums(&st)), ..st };
            let steps = fe.i0_steps(&st);
            (o, Some(canonical(st)), Some(canonical_steps(&st, steps)))
        }
        None => (o, None, None),
    }
}
