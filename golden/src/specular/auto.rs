//! `--brdf-k auto`: the k-set with the least ROM that keeps the approximation error inside
//! every epicentre within a target.
//!
//! Two facts make an exact search cheap. The error of k for a given n is unimodal in k
//! (zero at k = n, growing away from it; a test checks all n and k), so on a least-error
//! decoder n only ever competes between its two neighbours in the ascending k-set; and
//! what a table costs depends on the smallest n it serves, which its lower neighbour
//! decides. Both are properties of adjacent pairs, so a dynamic program over chains
//! `k1 < k2 < ... < kT` (T <= 5, k <= 64) scores every set exactly: 64 x 64 pair terms,
//! each O(gap) to evaluate. (One exception: whether n = 2 stays on k = 1 depends on k = 1's
//! upper neighbour; that edge carries the difference.) The cost of a table is the analytic size the plan builder starts
//! from; the chosen set is then built and verified like any other.

use super::contract::{K_MAX, NK_DEPTH, N_MAX};
use super::decoder::{BrdfK, Decoder};
use super::plan::{analytic_len, PlanError, SpecularPlan, WORD_BITS_RANGE};
use super::reference::{approx_error, epicentre_arg};
use crate::rom::addr_bits;

/// The search considers sets of at most this many tables.
pub const MAX_AUTO_TABLES: usize = 5;

const K: usize = K_MAX as usize;
/// Best chains of the dynamic program: `cells[c][b]` for chains of c+1 tables ending at k = b.
type Cells<T> = Vec<Vec<Option<(T, Vec<u32>)>>>;
/// Width of M the search charges the n-table with (the builder settles the real one; it
/// barely depends on the set).
const NOMINAL_M_BITS: u32 = 16;

/// Errors for all n and k, and the pair terms of the dynamic program.
struct Tables {
    /// `err[n][k]`, n in 0..=1000 (row 0 unused), k in 0..=64 (column 0 unused).
    err: Vec<[f64; K + 1]>,
}

impl Tables {
    fn new() -> Tables {
        let err = (0..=N_MAX)
            .map(|n| {
                let mut row = [0.0; K + 1];
                if n > 0 {
                    for (k, e) in row.iter_mut().enumerate().skip(1) {
                        *e = approx_error(n, k as u32);
                    }
                }
                row
            })
            .collect();
        Tables { err }
    }

    /// Least-error owner of n between neighbours a < b (a tie goes to a, like the decoder).
    fn owner(&self, n: u32, a: usize, b: usize) -> usize {
        if self.err[n as usize][b] < self.err[n as usize][a] {
            b
        } else {
            a
        }
    }

    /// Worst error among the n strictly between a and b, and the largest epicentre argument
    /// among those of them that b serves (together with b itself).
    fn gap(&self, a: usize, b: usize) -> (f64, f64) {
        let mut worst: f64 = 0.0;
        let mut x_b = epicentre_arg(b as u32, b as u32);
        for n in a as u32 + 1..b as u32 {
            let o = self.owner(n, a, b);
            worst = worst.max(self.err[n as usize][o]);
            if o == b {
                x_b = x_b.max(epicentre_arg(n, b as u32));
            }
        }
        (worst, x_b)
    }

    /// The n from 1 up to b, all on b.
    fn head(&self, b: usize) -> (f64, f64) {
        (1..=b as u32).fold((0.0f64, 0.0f64), |(e, x), n| (e.max(self.err[n as usize][b]), x.max(epicentre_arg(n, b as u32))))
    }

    /// Worst error of the n above a, all on a (they never raise a's epicentre argument,
    /// which falls with n from n = 2 on).
    fn tail(&self, a: usize) -> f64 {
        (a as u32 + 1..=N_MAX).map(|n| self.err[n as usize][a]).fold(0.0, f64::max)
    }
}

/// Smallest achievable worst-case approximation error with at most `max_tables` tables,
/// and a set achieving it.
pub fn best_reachable(max_tables: usize) -> (f64, Vec<u32>) {
    let tb = Tables::new();
    // best[c][b]: (minimax error, chain) over chains of c+1 tables ending at b.
    let mut best: Cells<f64> = vec![vec![None; K + 1]; max_tables];
    for (b, cell) in best[0].iter_mut().enumerate().skip(1) {
        *cell = Some((tb.head(b).0, vec![b as u32]));
    }
    for c in 1..max_tables {
        for b in 2..=K {
            let mut cand: Option<(f64, Vec<u32>)> = None;
            for (a, prev) in best[c - 1].iter().enumerate().take(b).skip(1) {
                if let Some((e, chain)) = prev {
                    let e = e.max(tb.gap(a, b).0);
                    if cand.as_ref().is_none_or(|(ce, _)| e < *ce) {
                        let mut ch = chain.clone();
                        ch.push(b as u32);
                        cand = Some((e, ch));
                    }
                }
            }
            best[c][b] = cand;
        }
    }
    let mut out = (f64::INFINITY, Vec::new());
    for row in &best {
        for (b, v) in row.iter().enumerate() {
            if let Some((e, chain)) = v {
                let e = e.max(tb.tail(b));
                if e < out.0 {
                    out = (e, chain.clone());
                }
            }
        }
    }
    out
}

/// The plan with the least ROM (BRDF plus n-table bits) whose approximation error inside
/// every epicentre is at most `max_err`, over sets of at most [`MAX_AUTO_TABLES`] tables.
pub fn auto_plan(max_err: f64) -> Result<SpecularPlan, PlanError> {
    if max_err.is_nan() || max_err <= 0.0 {
        return Err(PlanError::AutoTarget(max_err));
    }
    let tb = Tables::new();
    let e_ok = |e: f64| e <= max_err;
    // Pair terms are the same for every word width: compute them once.
    let gaps: Vec<Vec<Option<f64>>> = (0..=K)
        .map(|a| {
            (0..=K)
                .map(|b| {
                    if a == 0 || b <= a {
                        return None;
                    }
                    let (e, x) = tb.gap(a, b);
                    e_ok(e).then_some(x)
                })
                .collect()
        })
        .collect();
    let heads: Vec<Option<f64>> = (0..=K).map(|b| (b > 0).then(|| tb.head(b)).filter(|h| e_ok(h.0)).map(|h| h.1)).collect();
    let tails: Vec<bool> = (0..=K).map(|a| a > 0 && e_ok(tb.tail(a))).collect();

    // Table 1's own cost depends on whether n = 2 stays on it, which its upper neighbour
    // decides: charge the difference on that edge (or at the tail for the set {1, ...}).
    let x1 = epicentre_arg(1, 1);
    let x12 = x1.max(epicentre_arg(2, 1));
    let mut winner: Option<(u64, u32, Vec<u32>)> = None;
    for w in WORD_BITS_RANGE {
        let len = |k: usize, x: f64| analytic_len(k as u32, x, w, 0.0).map(u64::from);
        let one_extra = match (len(1, x12), len(1, x1)) {
            (Some(a), Some(b)) => Some(a.saturating_sub(b)),
            _ => None,
        };
        // dp[c][b]: (entries, chain) of the cheapest feasible chain of c+1 tables ending at b.
        let mut dp: Cells<u64> = vec![vec![None; K + 1]; MAX_AUTO_TABLES];
        for (b, cell) in dp[0].iter_mut().enumerate().skip(1) {
            *cell = heads[b].and_then(|x| len(b, x)).map(|l| (l, vec![b as u32]));
        }
        for c in 1..MAX_AUTO_TABLES {
            for b in 2..=K {
                let mut cand: Option<(u64, Vec<u32>)> = None;
                for a in 1..b {
                    let (Some((entries, chain)), Some(xb)) = (&dp[c - 1][a], gaps[a][b]) else { continue };
                    let extra = if a == 1 && tb.owner(2, 1, b) == 1 { one_extra } else { Some(0) };
                    let (Some(lb), Some(extra)) = (len(b, xb), extra) else { continue };
                    let total = entries + lb + extra;
                    if cand.as_ref().is_none_or(|c| total < c.0) {
                        let mut ch = chain.clone();
                        ch.push(b as u32);
                        cand = Some((total, ch));
                    }
                }
                dp[c][b] = cand;
            }
        }
        for (c, row) in dp.iter().enumerate() {
            let nk_bits = NK_DEPTH as u64 * (addr_bits(c + 1) + NOMINAL_M_BITS) as u64;
            for (b, v) in row.iter().enumerate() {
                let (Some((entries, chain)), true) = (v, tails[b]) else { continue };
                let extra = if chain.len() == 1 && b == 1 { one_extra } else { Some(0) };
                let Some(extra) = extra else { continue };
                let bits = (entries + extra) * w as u64 + nk_bits;
                if winner.as_ref().is_none_or(|win| bits < win.0) {
                    winner = Some((bits, w, chain.clone()));
                }
            }
        }
    }
    let Some((_, w, ks)) = winner else {
        let (best, best_ks) = best_reachable(MAX_AUTO_TABLES);
        return Err(PlanError::Unreachable { max_tables: MAX_AUTO_TABLES, max_err, best, best_ks });
    };
    let decoder = Decoder::least_error(&ks)?;
    // The search sized with one W; let the builder settle W on the verified sizes.
    SpecularPlan::build(decoder, None).or_else(|_| SpecularPlan::build(Decoder::least_error(&ks)?, Some(w)))
}

// Here, not beside the other constructors in `plan`, so that `plan` never imports the search
// built on it.
impl SpecularPlan {
    /// `--brdf-k`: a listed k-set ([`SpecularPlan::from_k_set`]) or the search ([`auto_plan`]).
    pub fn from_brdf_k(b: &BrdfK) -> Result<SpecularPlan, PlanError> {
        match b {
            BrdfK::List(ks) => SpecularPlan::from_k_set(ks),
            BrdfK::Auto { max_err } => auto_plan(*max_err),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn specular_auto_best_reachable() {
        let (e4, k4) = best_reachable(4);
        assert_eq!(k4, [1, 2, 3, 9], "the patent's own 1% set (fig. 8)");
        assert!(e4 < 0.01);
        let (e5, k5) = best_reachable(5);
        assert!(e5 < e4 && k5.len() == 5, "{e5} {k5:?}");
        let err = auto_plan(e5 * 0.99).unwrap_err();
        assert_eq!(err, PlanError::Unreachable { max_tables: MAX_AUTO_TABLES, max_err: e5 * 0.99, best: e5, best_ks: k5 });
        assert!(err.to_string().contains("the best reachable is"), "{err}");
        assert_eq!(auto_plan(0.0), Err(PlanError::AutoTarget(0.0)));
    }

    #[test]
    fn specular_auto_meets_its_target_with_less_rom() {
        let patent = SpecularPlan::patent();
        for target in [0.0109, 0.006, 0.02] {
            let p = auto_plan(target).unwrap();
            let (e, n) = p.decoder.max_error();
            assert!(e <= target, "target {target}: {e} at n = {n}");
            p.verify().unwrap();
            if target >= 0.0109 {
                assert!(p.rom_bits() <= patent.rom_bits());
            }
        }
    }
}
