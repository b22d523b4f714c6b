//! The set-up as a program: [`FrontEnd::setup`]'s arithmetic, one operation a line, with the
//! widths the RTL's registers have (`Widths`, and CALC's own in `hdl-gen/src/frontend/calc.rs`).

use super::{DivForm, EdgeOut, Kind, Op, Outputs, Plan, Program, StepOut, V};
use crate::frontend::{FrontEnd, Widths};
use crate::setup::SUBPIXEL;

/// Bits of a signed constant.
fn sbits(c: i128) -> u32 {
    let m = if c < 0 { !c } else { c };
    129 - m.leading_zeros()
}

struct B {
    ops: Vec<Op>,
}

impl B {
    /// An operation, or the same operation already in the program (same kind, operands, width
    /// and signedness; its first name stays): the set-up's formulas repeat a few (edge 2's
    /// direction is `dx1`, `dy1`; its rows' compares are `ymin`'s and `ymax`'s; its `128 - xa`
    /// is the plane's `xo`), and each repeat would be one more register and its logic.
    fn op(&mut self, name: impl Into<String>, kind: Kind, w: u32, signed: bool) -> V {
        if let Some(k) = self.ops.iter().position(|o| o.kind == kind && o.w == w && o.signed == signed) {
            return V(k as u32);
        }
        self.ops.push(Op { kind, w, signed, name: name.into() });
        V(self.ops.len() as u32 - 1)
    }
    fn w(&self, v: V) -> u32 {
        self.ops[v.0 as usize].w
    }
    fn c(&mut self, c: i128) -> V {
        self.op(format!("{c}"), Kind::Const(c), sbits(c), true)
    }
    fn sub(&mut self, n: &str, a: V, b: V, w: u32) -> V {
        self.op(n, Kind::Sub(a, b), w, true)
    }
    fn add(&mut self, n: &str, a: V, b: V, w: u32) -> V {
        self.op(n, Kind::Add(a, b), w, true)
    }
    fn lt(&mut self, a: V, b: V) -> V {
        self.op("lt", Kind::Lt(a, b), 1, false)
    }
    fn lt_c(&mut self, a: V, c: i128) -> V {
        let c = self.c(c);
        self.lt(a, c)
    }
    fn gt_c(&mut self, a: V, c: i128) -> V {
        let c = self.c(c);
        self.lt(c, a)
    }
    fn eq0(&mut self, a: V) -> V {
        let z = self.c(0);
        self.op("eq", Kind::Eq(a, z), 1, false)
    }
    fn and(&mut self, a: V, b: V) -> V {
        self.op("and", Kind::And(a, b), 1, false)
    }
    fn or(&mut self, a: V, b: V) -> V {
        self.op("or", Kind::Or(a, b), 1, false)
    }
    fn not(&mut self, a: V) -> V {
        self.op("not", Kind::Not(a), 1, false)
    }
    fn sel(&mut self, n: &str, c: V, a: V, b: V, w: u32, signed: bool) -> V {
        self.op(n, Kind::Sel(c, a, b), w, signed)
    }
    /// `c ? -a : a`.
    fn neg_if(&mut self, n: &str, c: V, a: V, w: u32, signed: bool) -> V {
        let z = self.c(0);
        let m = self.sub(&format!("-{n}"), z, a, w);
        self.sel(n, c, m, a, w, signed)
    }
    fn min(&mut self, n: &str, a: V, b: V, less: bool) -> V {
        let w = self.w(a).max(self.w(b));
        let c = if less { self.lt(a, b) } else { self.lt(b, a) };
        self.sel(n, c, a, b, w, true)
    }
    fn max_c(&mut self, n: &str, a: V, c: i128) -> V {
        let k = self.c(c);
        self.min(n, a, k, false)
    }
    fn min_c(&mut self, n: &str, a: V, c: i128) -> V {
        let k = self.c(c);
        self.min(n, a, k, true)
    }
    fn add_c(&mut self, n: &str, a: V, c: i128, w: u32) -> V {
        let k = self.c(c);
        self.add(n, a, k, w)
    }
    fn shl(&mut self, n: &str, a: V, s: u32, w: u32, signed: bool) -> V {
        self.op(n, Kind::Shl(a, s), w, signed)
    }
    fn mul(&mut self, n: &str, a: V, b: V, w: u32, signed: bool) -> V {
        self.op(n, Kind::Mul(a, b), w, signed)
    }
    /// A restoring division: the quotient and the remainder (`rw` bits).
    fn div(&mut self, n: &str, num: V, d: V, qb: u32, pw: u32, rw: u32) -> (V, V) {
        let q = self.op(n, Kind::Div { n: num, d, qb, pw }, qb, false);
        let r = self.op(format!("{n}.rem"), Kind::Rem(q), rw, false);
        (q, r)
    }
}

/// What every division by `2A` shares: `2An`, `s` and `Rn`.
struct ByA {
    an2: V,
    s: V,
    rn: V,
    reciprocal: bool,
}

impl ByA {
    /// `divmod(N, 2An)` of a normalised dividend `N < 2^K`: a restoring division, or by the
    /// reciprocal. The reciprocal form takes only `N`'s top `K - AW = IW + 2` bits:
    /// `q~ = ((N >> AW) Rn) >> (IW + 2)` is the quotient or up to two below it (each
    /// truncation loses less than one: `N < 2^K`, `2An >= 2^AW`), so one product by `2An`
    /// modulo 2^(AW+3) and two compares correct it. Against the walker's form (all of `N`,
    /// one compare) the first product is 2 x 2 tile passes instead of 4 x 2.
    fn divmod(&self, b: &mut B, wd: &Widths, n: &str, num: V, qb: u32) -> (V, V) {
        if !self.reciprocal {
            return b.div(n, num, self.an2, qb, qb + wd.aw + 1, wd.aw + 1);
        }
        let top = wd.k - wd.aw;
        let nh = b.op(format!("{n}.nh"), Kind::Shr(num, wd.aw), top, false);
        let p1 = b.mul(&format!("{n}.nr"), nh, self.rn, top + wd.rw, false);
        let qt = b.op(format!("{n}.qt"), Kind::Shr(p1, top), wd.rw, false);
        let p2 = b.mul(&format!("{n}.qa"), qt, self.an2, wd.aw + 3, false);
        let rt = b.op(format!("{n}.rt"), Kind::Sub(num, p2), wd.aw + 3, false);
        let an4 = b.shl(&format!("{n}.4An"), self.an2, 1, wd.aw + 2, false);
        let lo1 = b.lt(rt, self.an2);
        let lo2 = b.lt(rt, an4);
        let (c1, c2) = (b.not(lo1), b.not(lo2));
        let c = b.op(format!("{n}.c"), Kind::Add(c1, c2), 2, false);
        let q = b.op(n, Kind::Add(qt, c), qb, false);
        let r1 = b.op(format!("{n}.r1"), Kind::Sub(rt, self.an2), wd.aw + 1, false);
        let r2 = b.op(format!("{n}.r2"), Kind::Sub(rt, an4), wd.aw + 1, false);
        let r = b.sel(&format!("{n}.r12"), c2, r2, r1, wd.aw + 1, false);
        let r = b.sel(&format!("{n}.rem"), c1, r, rt, wd.aw + 1, false);
        (q, r)
    }
}

impl Program {
    /// `FrontEnd::setup` (and with `plan.i0_steps`, `FrontEnd::i0_steps`) as a program.
    pub fn setup(fe: &FrontEnd, plan: &Plan) -> Program {
        let wd = fe.widths();
        let Widths { cx, cy, aw, k: kw, .. } = wd;
        let iw = fe.cfg.iw();
        let (w, h) = (fe.screen.width as i128, fe.screen.height as i128);
        let sp = SUBPIXEL as i128;
        let mut b = B { ops: Vec::new() };
        let x = [0, 1, 2].map(|k| b.op(format!("x{k}"), Kind::In(k as u8), cx, true));
        let y = [0, 1, 2].map(|k| b.op(format!("y{k}"), Kind::In(3 + k as u8), cy, true));
        let i = [0, 1, 2].map(|k| b.op(format!("i{k}"), Kind::In(6 + k as u8), iw, false));
        // The guard band.
        let mut guard_ok = b.c(1);
        for k in 0..3 {
            for (v, lim) in [(x[k], w * sp), (y[k], h * sp)] {
                let below = b.lt_c(v, -lim);
                let inside = b.lt_c(v, 2 * lim);
                let ok = b.not(below);
                let ok = b.and(ok, inside);
                guard_ok = b.and(guard_ok, ok);
            }
        }
        // The area and its sign, from unoriented differences.
        let dx1 = b.sub("dx1", x[1], x[0], cx + 1);
        let dx2 = b.sub("dx2", x[2], x[0], cx + 1);
        let dy1 = b.sub("dy1", y[1], y[0], cy + 1);
        let dy2 = b.sub("dy2", y[2], y[0], cy + 1);
        let ma1 = b.mul("m_a1", dx1, dy2, cx + cy + 2, true);
        let ma2 = b.mul("m_a2", dy1, dx2, cx + cy + 2, true);
        let area = b.sub("area", ma1, ma2, aw + 1);
        let neg = b.lt_c(area, 0);
        let aabs = b.neg_if("aabs", neg, area, aw, false);
        let azero = b.eq0(area);
        // The edges, oriented; the top-left rule; the bottom edge's kill.
        let mut dirs = Vec::new();
        let mut kill = b.c(0);
        for k in 0..3 {
            let (ea, eb) = ((k + 1) % 3, (k + 2) % 3);
            let rdx = b.sub(&format!("rdx{k}"), x[eb], x[ea], cx + 1);
            let rdy = b.sub(&format!("rdy{k}"), y[eb], y[ea], cy + 1);
            let dx = b.neg_if(&format!("dx{k}"), neg, rdx, cx + 1, true);
            let dy = b.neg_if(&format!("dy{k}"), neg, rdy, cy + 1, true);
            let up = b.lt_c(dy, 0);
            let dyz = b.eq0(dy);
            let xp = b.gt_c(dx, 0);
            let flat = b.and(dyz, xp);
            let tl = b.or(up, flat);
            let ntl = b.not(tl);
            let bottom = b.and(dyz, ntl);
            kill = b.or(kill, bottom);
            dirs.push(Dir { ea, dx, dy, up, dyz, ntl });
        }
        // The rows and columns of the bounding box; cull.
        let (rt, rb) = vrows(&mut b, &wd, &y);
        let (first, last, cull) = rows(&mut b, fe, &x, &y, &rt, azero, kill);
        // Per edge: its rows, its DDA's step and first bound. The engine's dividers take g by
        // |dy| (`edge`); today's (`DivForm::ShiftDivisor`, the parallel form's, which the LUT
        // estimate's calibration counts) by D.
        let short_g = plan.div_form == DivForm::ShiftRemainder;
        let edges: Vec<EdgeOut> = dirs
            .iter()
            .enumerate()
            .map(|(k, dir)| edge(&mut b, &wd, k, dir, &x, &y, (&rt, &rb), (first, last), (short_g, plan.edge_t)))
            .collect();
        // The plane: the normal from unoriented products, oriented.
        let d1 = b.sub("d1", i[1], i[0], iw + 1);
        let d2 = b.sub("d2", i[2], i[0], iw + 1);
        let (nx_w, ny_w) = (iw + cy + 3, iw + cx + 3);
        let mx1 = b.mul("m_x1", d1, dy2, iw + cy + 2, true);
        let mx2 = b.mul("m_x2", d2, dy1, iw + cy + 2, true);
        let my1 = b.mul("m_y1", d2, dx1, iw + cx + 2, true);
        let my2 = b.mul("m_y2", d1, dx2, iw + cx + 2, true);
        let nxu = b.sub("nxu", mx1, mx2, nx_w);
        let nyu = b.sub("nyu", my1, my2, ny_w);
        let nx = b.neg_if("nx", neg, nxu, nx_w, true);
        let ny = b.neg_if("ny", neg, nyu, ny_w, true);
        // Normalisation and the reciprocal Rn = floor(2^K / 2An).
        let s = b.op("s", Kind::Lzc(aabs, aw), wd.sw, false);
        let an = b.op("an", Kind::ShlBy(aabs, s), aw, false);
        let an2 = b.shl("an2", an, 1, aw + 1, false);
        let two_k = b.c(1i128 << kw);
        let (rn, _) = b.div("rn", two_k, an2, wd.rw, aw + wd.rw + 1, aw + 1);
        let by_a = ByA { an2, s, rn, reciprocal: plan.reciprocal };
        // dI = round(256 Nx / A) = floor((512 |Nx| + A) / 2A), saturated.
        let nxneg = b.lt_c(nx, 0);
        let mag = b.neg_if("mag", nxneg, nx, nx_w, false);
        let m9 = b.shl("mag9", mag, 9, nx_w + 9, false);
        let x2 = b.add("x2", m9, aabs, (nx_w + 9).max(aw + 1) + 1);
        let lim = b.shl("A<<IW+1", aabs, iw + 1, aw + iw + 1, false);
        let under = b.lt(x2, lim);
        let sat = b.not(under);
        let nrm = b.op("x2n", Kind::ShlBy(x2, s), kw, false);
        let (q, _) = by_a.divmod(&mut b, &wd, "di", nrm, iw);
        let qn = b.neg_if("di_q", nxneg, q, iw + 1, true);
        let lo = b.c(-(1i128 << iw));
        let hi = b.c((1i128 << iw) - 1);
        let sv = b.sel("di_sat", nxneg, lo, hi, iw + 1, true);
        let di = b.sel("di", sat, sv, qn, iw + 1, true);
        // The first row's sum S(0, first) = I_0 A + Nx (128 - x0) + Ny (256 first + 128 - y0),
        // modulo 2^K, normalised; the steps per row and column.
        let c128 = b.c(128);
        let xo = b.sub("xo", c128, x[0], cx + 2);
        let t = b.shl("first8", first, 8, cy + 1, true);
        let t = b.add_c("first8c", t, 128, cy + 2);
        let yo = b.sub("yo", t, y[0], cy + 2);
        let ms1 = b.mul("m_s1", i[0], aabs, iw + aw, false);
        let ms2 = b.mul("m_s2", nx, xo, kw, false);
        let ms3 = b.mul("m_s3", ny, yo, kw, false);
        let t = b.op("s12", Kind::Add(ms1, ms2), kw, false);
        let sum = b.op("s0", Kind::Add(t, ms3), kw, false);
        let tn = b.op("tn", Kind::ShlBy(sum, s), kw, false);
        let t = b.shl("ny8", ny, 8, ny_w + 8, true);
        let dyn_ = b.op("dyn", Kind::ShlBy(t, s), kw, false);
        let t = b.shl("nx8", nx, 8, nx_w + 8, true);
        let gxn = b.op("gxn", Kind::ShlBy(t, s), kw, false);
        let sums = plan.run_sums.then(|| running_sums(&mut b, &wd, &edges, nx, s));
        let steps = plan.i0_steps.then(|| i0_steps(&mut b, &wd, iw, &by_a, aabs, nx, ny, &edges));
        let out = Outputs {
            guard_ok,
            cull,
            first,
            last,
            edges: [edges[0], edges[1], edges[2]],
            di,
            an,
            s,
            rn,
            tn,
            dyn_,
            gxn,
            i0a: ms1,
            nx,
            ny,
            a: aabs,
            steps,
            sums,
        };
        Program { ops: b.ops, out }
    }
}

/// The running sums' start and step (`Plan::run_sums`) for the two left edges' slots
/// ([`crate::frontend::sums::left_slots`]): (Gxn >> 8) v = (Nx v) << s modulo 2^(K-10), the
/// product of Nx (narrower than Gxn >> 8: fewer tile passes) shifted on the shared
/// shifter. Two slots, not three edges: four products (12 tile passes) keep the 8 tiles'
/// static binding at II = 12, six (18) made it rotate over 6 triangles (docs/fpga.md).
fn running_sums(b: &mut B, wd: &Widths, edges: &[EdgeOut], nx: V, s: V) -> [(V, V); 2] {
    let sb = wd.sum_bits();
    let left: Vec<V> = edges
        .iter()
        .map(|e| {
            let l = b.not(e.right);
            b.and(e.active, l)
        })
        .collect();
    // Slot a is edge 0 if it is a left edge, else edge 1; slot b edge 2 if it is one, else
    // edge 1 (`crate::frontend::sums::left_slots`): each value a select of two.
    let slot = |b: &mut B, n: &str, (own, other): (usize, usize)| {
        let pick = |b: &mut B, what: &str, f: fn(&EdgeOut) -> V| {
            let w = b.w(f(&edges[own]));
            b.sel(&format!("{what}_{n}"), left[own], f(&edges[own]), f(&edges[other]), w, true)
        };
        let (g, qs) = (pick(b, "g", |e| e.g), pick(b, "qs", |e| e.qs));
        let sum = |b: &mut B, what: &str, v: V| {
            let p = b.mul(&format!("m_{what}{n}"), nx, v, sb, false);
            b.op(format!("{what}{n}"), Kind::ShlBy(p, s), sb, false)
        };
        (sum(b, "pg", g), sum(b, "pq", qs))
    };
    let [a, b_] = crate::frontend::sums::LEFT_SLOTS;
    [slot(b, "a", a), slot(b, "b", b_)]
}

/// The incremental `I0`'s steps (`FrontEnd::i0_steps`): `divmod(X, 2A)` of `X = 512 Ny` and,
/// per edge, `512 Ny - 512 Nx (Qs + c)`, when `|X| < 2A << IW`, as a quotient modulo 2^IW and a
/// normalised remainder: `N = (X << s) + (2An << IW)` divided by `2An`.
#[allow(clippy::too_many_arguments)]
fn i0_steps(b: &mut B, wd: &Widths, iw: u32, by_a: &ByA, aabs: V, nx: V, ny: V, edges: &[EdgeOut]) -> (StepOut, [[StepOut; 2]; 3]) {
    let kw = wd.k;
    let lim = b.shl("2A<<IW", aabs, iw + 1, wd.aw + iw + 1, false);
    let bias = b.shl("2An<<IW", by_a.an2, iw, kw, false);
    let step = |b: &mut B, n: &str, x: V| {
        let sw = b.w(x).max(b.w(lim)) + 1;
        let above = b.lt(x, lim);
        let sum = b.add(&format!("{n}+lim"), x, lim, sw);
        let pos = b.gt_c(sum, 0);
        let ok = b.and(above, pos);
        let xs = b.op(format!("{n}<<s"), Kind::ShlBy(x, by_a.s), kw, false);
        let num = b.op(format!("{n}.N"), Kind::Add(xs, bias), kw, false);
        let (q, rn) = by_a.divmod(b, wd, n, num, iw + 1);
        let q = b.op(format!("{n}.q"), Kind::Wire(q), iw, false);
        StepOut { ok, q, rn }
    };
    let nyw = b.w(ny);
    let y9 = b.shl("ny9", ny, 9, nyw + 9, true);
    let col0 = step(b, "step_c0", y9);
    let nxw = b.w(nx);
    let x9 = b.shl("nx9", nx, 9, nxw + 9, true);
    let mut edge = Vec::new();
    for (k, e) in edges.iter().enumerate() {
        let pw = nxw + wd.gw;
        let p = b.mul(&format!("m_q{k}"), nx, e.qs, pw, true);
        let t = b.sub(&format!("ny-p{k}"), ny, p, pw + 1);
        let x0 = b.shl(&format!("X0_{k}"), t, 9, pw + 10, true);
        let x1 = b.sub(&format!("X1_{k}"), x0, x9, pw + 11);
        edge.push([step(b, &format!("step_e{k}c0"), x0), step(b, &format!("step_e{k}c1"), x1)]);
    }
    (col0, [edge[0], edge[1], edge[2]])
}

/// Each vertex's first row at or below it and last row above it (centres at +128 sub-pixels):
/// the edges' rows and the first row are least or greatest of these.
fn vrows(b: &mut B, wd: &Widths, y: &[V; 3]) -> ([V; 3], [V; 3]) {
    let (cy, rw_s) = (wd.cy, wd.cy - 7);
    let row = |b: &mut B, n: &str, v: V, c: i128| {
        let t = b.add_c(&format!("{n}_c"), v, c, cy + 1);
        b.op(n, Kind::Shr(t, 8), rw_s, true)
    };
    let rt = [0, 1, 2].map(|k| row(b, &format!("rt{k}"), y[k], 127));
    let rb = [0, 1, 2].map(|k| row(b, &format!("rb{k}"), y[k], -128));
    (rt, rb)
}

/// The rows and columns of the bounding box (centres at +128 sub-pixels), and cull.
fn rows(b: &mut B, fe: &FrontEnd, x: &[V; 3], y: &[V; 3], rt: &[V; 3], azero: V, kill: V) -> (V, V, V) {
    let Widths { cx, cy, .. } = fe.widths();
    let (w, h) = (fe.screen.width as i128, fe.screen.height as i128);
    // The first row and the columns as the least or greatest of the vertices' own (a floor of a
    // shift is monotone): selects of row and column numbers, not of sub-pixel coordinates.
    let t = b.min("first_raw", rt[0], rt[1], true);
    let t = b.min("first_raw", t, rt[2], true);
    let first = b.max_c("first", t, 0);
    let ymax = b.min("ymax", y[0], y[1], false);
    let ymax = b.min("ymax", ymax, y[2], false);
    let rw_s = cy - 7;
    let t = b.add_c("ymax_c", ymax, -128, cy + 1);
    let t = b.sub("ymax_k", t, kill, cy + 1);
    let t = b.op("last_raw", Kind::Shr(t, 8), rw_s, true);
    let last = b.min_c("last", t, h - 1);
    let col = |b: &mut B, n: &str, v: V, c: i128| {
        let t = b.add_c(&format!("{n}_c"), v, c, cx + 1);
        b.op(n, Kind::Shr(t, 8), cx - 7, true)
    };
    let cf = [0, 1, 2].map(|k| col(b, &format!("cf{k}"), x[k], 127));
    let cl = [0, 1, 2].map(|k| col(b, &format!("cl{k}"), x[k], -128));
    let cfirst = b.min("cfirst", cf[0], cf[1], true);
    let cfirst = b.min("cfirst", cfirst, cf[2], true);
    let clast = b.min("clast", cl[0], cl[1], false);
    let clast = b.min("clast", clast, cl[2], false);
    let mut cull = azero;
    for c in [b.lt(last, first), b.lt(clast, cfirst), b.gt_c(cfirst, w - 1), b.lt_c(clast, 0)] {
        cull = b.or(cull, c);
    }
    (first, last, cull)
}

/// An edge oriented: its first vertex `a`, direction, going up, horizontal, not top-left.
#[derive(Clone, Copy)]
struct Dir {
    ea: usize,
    dx: V,
    dy: V,
    up: V,
    dyz: V,
    ntl: V,
}

/// Edge k's rows, its DDA's step `Qs` and first bound `g`, both divisions biased by
/// B = 2^(GW-1) divisors so the dividends are non-negative (q = value + B).
#[allow(clippy::too_many_arguments)]
fn edge(
    b: &mut B,
    wd: &Widths,
    k: usize,
    dir: &Dir,
    x: &[V; 3],
    y: &[V; 3],
    (rt, rb): (&[V; 3], &[V; 3]),
    (first, last): (V, V),
    (short_g, edge_t): (bool, bool),
) -> EdgeOut {
    let Widths { cx, cy, gw, .. } = *wd;
    let Dir { ea, dx, dy, up, dyz, ntl } = *dir;
    let bias = 1i128 << (gw - 1);
    let eb = (k + 2) % 3;
    // The edge's rows from its vertices' own row numbers (`vrows`), as `rows` takes the first.
    let t = b.min(&format!("rs_raw{k}"), rt[ea], rt[eb], true);
    let rs = b.min(&format!("rs{k}"), t, first, false);
    let t = b.min(&format!("re_raw{k}"), rb[ea], rb[eb], false);
    let re = b.min(&format!("re{k}"), t, last, true);
    let empty = b.lt(re, rs);
    let nz = b.not(dyz);
    let ne = b.not(empty);
    let active = b.and(nz, ne);
    let right = b.gt_c(dy, 0);
    let ady = b.neg_if(&format!("ady{k}"), up, dy, cy, false);
    let d = b.shl(&format!("d{k}"), ady, 8, wd.dw_edge, false);
    let sh = b.shl(&format!("adyB{k}"), ady, gw - 1, gw + cy, false);
    let sn = b.add(&format!("sn{k}"), dx, sh, (cx + 2).max(gw + cy + 1));
    let (qsb, srem) = b.div(&format!("qs{k}"), sn, ady, gw, gw + cy, cy);
    let qs = b.add_c(&format!("qs{k}-B"), qsb, -bias, gw);
    let rs256 = b.shl(&format!("rs256_{k}"), srem, 8, wd.dw_edge, false);
    // n = dx (256 rs + 128 - ya) - dy (128 - xa) - t + B D.
    let t = b.shl(&format!("rs8_{k}"), rs, 8, cy + 1, true);
    let t = b.add_c(&format!("rs8c{k}"), t, 128, cy + 2);
    let ry = b.sub(&format!("ry{k}"), t, y[ea], cy + 2);
    let c128 = b.c(128);
    let rx = b.sub(&format!("rx{k}"), c128, x[ea], cx + 2);
    let me = b.mul(&format!("m_e{k}"), dx, ry, cx + cy + 3, true);
    let mf = b.mul(&format!("m_f{k}"), dy, rx, cx + cy + 3, true);
    let e = b.sub(&format!("e{k}"), me, mf, cx + cy + 4);
    let e = b.sub(&format!("et{k}"), e, ntl, cx + cy + 5);
    let bd = b.shl(&format!("BD{k}"), d, gw - 1, wd.dw_edge + gw, false);
    let n = b.add(&format!("n{k}"), e, bd, cx + cy + 5);
    let (gb, rem, rh) = if short_g {
        // D = 256 |dy| has eight zero bits: floor(n / D) = floor((n >> 8) / |dy|), and the
        // remainder is that division's, shifted back, with n's low byte. So the divider is as
        // wide as |dy| (CY bits, as Qs's), not as D (CY + 8): Qs's and g's dividers are one width.
        let nh = b.op(format!("n{k}>>8"), Kind::Shr(n, 8), cx + cy - 3, false);
        let zero = b.c(0);
        let nl = b.op(format!("n{k}lo"), Kind::Add(n, zero), 8, false);
        let (gb, rh) = b.div(&format!("g{k}"), nh, ady, gw, gw + cy, cy);
        let rh8 = b.shl(&format!("rem8_{k}"), rh, 8, wd.dw_edge, false);
        (gb, b.op(format!("rem{k}"), Kind::Add(rh8, nl), wd.dw_edge, false), Some(rh))
    } else {
        let (gb, rem) = b.div(&format!("g{k}"), n, d, gw, gw + wd.dw_edge, wd.dw_edge);
        (gb, rem, None)
    };
    let g = b.add_c(&format!("g{k}-B"), gb, -bias, gw);
    // thr = (D - rs256) >> 8 = |dy| - (Qs's remainder) in 1..=|dy| on a stepped edge; rem's bits
    // above the eight: g's remainder before its shift back.
    let dda = edge_t.then(|| {
        let thr = b.op(format!("thr{k}"), Kind::Sub(ady, srem), cy, false);
        let rh = rh.unwrap_or_else(|| b.op(format!("rem{k}>>8"), Kind::Shr(rem, 8), cy, false));
        (thr, b.sub(&format!("t{k}"), rh, thr, cy + 1))
    });
    EdgeOut { dyz, right, active, rs, re, g, rem, d, qs, rs256, dda }
}
