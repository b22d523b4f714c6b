//! The BFPI (increment-forming block) as an adder graph planned once and used twice: the
//! golden model evaluates it bit-exactly here and `hdl-gen` prints it as Verilog.
//!
//! Every multiple `c*dI`, `c = 1..=p`, is an odd fundamental shifted left. Each odd
//! fundamental `3..p-1` costs exactly one adder `(a << s) ± (b << t)` of earlier values, so the
//! graph has `p/2 - 1` adders — the lower bound of multiple-constant multiplication for the set
//! {1..p}. Fundamentals are built level by level (breadth first): a value enters at the first
//! level where two earlier values make it, so every value sits at its minimal depth and the
//! graph depth is the minimum possible: 1 for p <= 8, 2 for 16..=128, 3 for 256.

use serde::{Deserialize, Serialize};

/// Add or subtract.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Op {
    Add,
    Sub,
}

/// One adder: `value = (a << a_shift) op (b << b_shift)`, where `a` and `b` are the input
/// (1) or earlier adders' values, always odd.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Adder {
    pub value: u32,
    pub a: u32,
    pub a_shift: u32,
    pub op: Op,
    pub b: u32,
    pub b_shift: u32,
    /// Adders on the longest path from the input, this one included.
    pub depth: u32,
}

impl Adder {
    /// The adder as an expression over named operands, e.g. `(m3 << 2) - m1`.
    pub fn describe(&self, name: impl Fn(u32) -> String) -> String {
        let term = |v: u32, s: u32| if s == 0 { name(v) } else { format!("({} << {s})", name(v)) };
        let op = match self.op {
            Op::Add => "+",
            Op::Sub => "-",
        };
        format!("{} {op} {}", term(self.a, self.a_shift), term(self.b, self.b_shift))
    }
}

/// The adder graph for the multiples `1..=p`.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct BfpiPlan {
    pub p: u32,
    /// In evaluation order: every operand is 1 or an earlier adder.
    pub adders: Vec<Adder>,
}

impl BfpiPlan {
    /// Plans the graph for `p`, a power of two in 1..=256.
    pub fn new(p: u32) -> BfpiPlan {
        crate::format::check_p(p).expect("BfpiPlan::new needs a valid p");
        let shift_max = p.trailing_zeros() + 1;
        // depth[v] for every odd v already built; 1 is the input.
        let mut depth = vec![None; p.max(2) as usize];
        depth[1] = Some(0u32);
        let mut adders = Vec::new();
        let mut level = 0;
        while (3..p).step_by(2).any(|c| depth[c as usize].is_none()) {
            level += 1;
            let built: Vec<u32> = (1..p).step_by(2).filter(|&v| depth[v as usize].is_some()).collect();
            let mut new = Vec::new();
            for c in (3..p).step_by(2).filter(|&c| depth[c as usize].is_none()) {
                if let Some(adder) = best_adder(c, &built, &depth, shift_max, level) {
                    new.push(adder);
                }
            }
            assert!(!new.is_empty(), "planner made no progress at level {level} for p = {p}");
            for a in &new {
                depth[a.value as usize] = Some(a.depth);
            }
            adders.extend(new);
        }
        BfpiPlan { p, adders }
    }

    pub fn adder_count(&self) -> usize {
        self.adders.len()
    }

    pub fn depth(&self) -> u32 {
        self.adders.iter().map(|a| a.depth).max().unwrap_or(0)
    }

    /// The multiple `c` (1..=p) as an odd fundamental and a left shift: `c = odd << shift`.
    pub fn multiple(c: u32) -> (u32, u32) {
        (c >> c.trailing_zeros(), c.trailing_zeros())
    }

    /// Bit-exact evaluation of the graph as the hardware does it: every node is a signed
    /// `width`-bit wire, so sums wrap modulo 2^width (harmless: every *output* fits).
    /// Returns lane `i` = `(i+1)*di` for `i = 0..p`.
    pub fn evaluate(&self, di: i64, width: u32) -> Vec<i64> {
        let mut lanes = vec![0; self.p as usize];
        self.evaluate_into(di, width, &mut vec![0; self.p as usize + 1], &mut lanes);
        lanes
    }

    /// `evaluate` without allocating: `nodes` has room for p + 1 values, `lanes` for p.
    pub fn evaluate_into(&self, di: i64, width: u32, nodes: &mut [i64], lanes: &mut [i64]) {
        let wrap = |v: i64| (v << (64 - width)) >> (64 - width);
        nodes[1] = wrap(di);
        for a in &self.adders {
            let x = nodes[a.a as usize].wrapping_shl(a.a_shift);
            let y = nodes[a.b as usize].wrapping_shl(a.b_shift);
            nodes[a.value as usize] = wrap(match a.op {
                Op::Add => x.wrapping_add(y),
                Op::Sub => x.wrapping_sub(y),
            });
        }
        for (lane, c) in lanes.iter_mut().zip(1..=self.p) {
            let (odd, s) = Self::multiple(c);
            *lane = wrap(nodes[odd as usize].wrapping_shl(s));
        }
    }
}

/// The adder that makes odd `c` from built odd values of depth < `level`, if any. Candidates
/// are `(a << s) + b`, `(a << s) - b` and `b - (a << s)`: with both operands odd, one shift
/// must be 0 for the result to be odd. Ties are broken toward shallow operands, small shifts
/// and additions, so the printed graph reads naturally (3 = (1 << 1) + 1, 7 = (1 << 3) - 1).
fn best_adder(c: u32, built: &[u32], depth: &[Option<u32>], shift_max: u32, level: u32) -> Option<Adder> {
    let mut best: Option<(u32, u32, u32, Adder)> = None;
    let c = c as i64;
    for &a in built {
        for &b in built {
            let da = depth[a as usize].unwrap();
            let db = depth[b as usize].unwrap();
            if da.max(db) + 1 != level {
                continue;
            }
            for s in 1..=shift_max {
                let sa = (a as i64) << s;
                let candidates =
                    [(sa + b as i64, Op::Add, a, s, b, 0), (sa - b as i64, Op::Sub, a, s, b, 0), (b as i64 - sa, Op::Sub, b, 0, a, s)];
                for (v, op, x, xs, y, ys) in candidates {
                    if v != c {
                        continue;
                    }
                    let adder = Adder { value: c as u32, a: x, a_shift: xs, op, b: y, b_shift: ys, depth: level };
                    let key = (da + db, s, (op == Op::Sub) as u32);
                    if best.as_ref().is_none_or(|(k0, k1, k2, _)| key < (*k0, *k1, *k2)) {
                        best = Some((key.0, key.1, key.2, adder));
                    }
                }
            }
        }
    }
    best.map(|b| b.3)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn all_p() -> impl Iterator<Item = u32> {
        (0..=8).map(|k| 1u32 << k)
    }

    #[test]
    fn reaches_the_adder_lower_bound_and_minimal_depth_for_every_p() {
        for p in all_p() {
            let plan = BfpiPlan::new(p);
            let expected_depth = match p {
                1 | 2 => 0,
                4 | 8 => 1,
                16..=128 => 2,
                _ => 3,
            };
            assert_eq!(plan.adder_count() as u32, (p / 2).saturating_sub(1), "adders for p = {p}");
            assert_eq!(plan.depth(), expected_depth, "depth for p = {p}");
        }
    }

    #[test]
    fn every_adder_uses_only_earlier_values() {
        for p in all_p() {
            let plan = BfpiPlan::new(p);
            let mut have = vec![1u32];
            for a in &plan.adders {
                assert!(have.contains(&a.a) && have.contains(&a.b), "{a:?} for p = {p}");
                let v = match a.op {
                    Op::Add => ((a.a as i64) << a.a_shift) + ((a.b as i64) << a.b_shift),
                    Op::Sub => ((a.a as i64) << a.a_shift) - ((a.b as i64) << a.b_shift),
                };
                assert_eq!(v, a.value as i64);
                have.push(a.value);
            }
        }
    }

    #[test]
    fn evaluates_every_multiple_exactly() {
        for p in all_p() {
            let plan = BfpiPlan::new(p);
            let width = 21 + p.trailing_zeros();
            for di in [0i64, 1, -1, 2, -2, 12345, -54321, (1 << 20) - 1, -(1 << 20), 0x5_5555, -0xA_AAAA] {
                let lanes = plan.evaluate(di, width);
                for (i, v) in lanes.iter().enumerate() {
                    assert_eq!(*v, (i as i64 + 1) * di, "p = {p}, di = {di}, lane {i}");
                }
            }
        }
    }

    #[test]
    fn seed_example_for_p16() {
        let plan = BfpiPlan::new(16);
        let by_value = |v: u32| plan.adders.iter().find(|a| a.value == v).unwrap();
        for v in [3, 5, 7, 9, 15] {
            assert_eq!(by_value(v).depth, 1);
        }
        assert_eq!(by_value(11).depth, 2);
        assert_eq!(by_value(13).depth, 2);
        assert_eq!(by_value(7).describe(|v| format!("m{v}")), "(m1 << 3) - m1");
    }
}
