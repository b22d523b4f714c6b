//! The shared units: per unit an operand multiplexer per port, selected by phase and epoch
//! (AND-OR: the binding puts one operation on a unit at a time, golden's `verify_binding`),
//! then the units themselves as `generate` loops over identical lanes.
//!
//! - **Tile** (`MulUnit::Tile`): one pass multiplies a chunk of each operand (the top chunk of
//!   a signed operand signed, the others unsigned: `bits + 1`-bit signed lanes), registered;
//!   the product, registered; the accumulator adds it at the pair's weight (`2^(bits (i + j))`,
//!   modulo its width), cleared on a product's first pass. Golden's `MUL_PIPE` = 2: the value
//!   is ready two clocks after the last pass.
//! - **Shift-add** (`MulUnit::ShiftAdd`): a pass multiplies the wider operand by `bits` bits of
//!   the narrower one, shifted to their weight, registered; the accumulator adds it. Ready one
//!   clock after the last pass.
//! - **Divider** (restoring, the textbook form: the remainder shifted past a fixed divisor): a
//!   load clock takes the divisor, the dividend's top bits as the first remainder and its low
//!   quotient-width bits, left-aligned, in the quotient register; then `bits` compare-subtract
//!   steps a clock, each shifting a quotient bit in. Ready after its last step.

use super::sequencer::Seq;
use super::values::{Src, Values};
use crate::verilog::{comment, reg, set, sreg, wire, Item, Stmt};
use golden::frontend::engine::schedule::Class;
use golden::frontend::engine::{Kind, MulUnit};

/// `(condition, value)` pairs as one AND-OR multiplexer of `w` bits; a lone source needs none
/// (its unit's value is a don't-care on its other clocks).
fn and_or(items: &[(String, String)], w: u32) -> String {
    match items {
        [] => format!("{w}'d0"),
        [(_, v)] => v.clone(),
        _ => items
            .iter()
            .map(|(c, v)| if w == 1 { format!("({c} && {v})") } else { format!("({{{w}{{{c}}}}} & {v})") })
            .collect::<Vec<_>>()
            .join(" | "),
    }
}

fn or(conds: &[String]) -> String {
    if conds.is_empty() {
        "1'b0".into()
    } else {
        conds.join(" || ")
    }
}

fn bits_for(max: u32) -> u32 {
    (32 - max.leading_zeros()).max(1)
}

/// A unit output a value register captures: (register load clock, epoch) -> Verilog.
pub(super) struct Capture {
    pub op: usize,
    /// Schedule clock of the load (the value is ready the clock after).
    pub t: u32,
    /// The unit outputs' expressions, each with the epochs it serves.
    pub from: Vec<(Vec<u32>, String)>,
}

/// A chunk of `bits` of value `v` starting at chunk `i`, as a `bits + 1`-bit signed lane.
fn chunk(v: &Src, i: u32, bits: u32, top: bool, signed: bool) -> String {
    if top && signed {
        v.bits(bits * i, bits + 1)
    } else {
        format!("{{1'b0, {}}}", v.bits(bits * i, bits))
    }
}

/// The multipliers: their lanes' multiplexers, the generate loop, and what each product's
/// value register captures.
pub(super) fn multipliers(v: &Values, seq: &Seq, body: &mut Vec<Item>) -> Vec<Capture> {
    let s = v.s;
    let plan = s.plan;
    let m = plan.mults;
    let ops: Vec<usize> = (0..s.slots.len()).filter(|&o| s.slots[o].class == Class::Mul).collect();
    if ops.is_empty() {
        return Vec::new();
    }
    let acc_w = ops.iter().map(|&o| v.op(o).w).max().unwrap_or(1);
    let w = |x: golden::frontend::engine::V| v.op(x.0 as usize).w;
    let sg = |x: golden::frontend::engine::V| v.op(x.0 as usize).signed;
    // Per unit, its lanes' sources: a, b, first, weight (shift).
    let mut src: Vec<[Vec<(String, String)>; 4]> = vec![Default::default(); m as usize];
    let mut caps = Vec::new();
    let (lane_a, lane_b, sh_max);
    match plan.mul {
        MulUnit::Tile { bits } => {
            let mut wmax = 0;
            for &o in &ops {
                let Kind::Mul(a, b) = v.op(o).kind else { unreachable!() };
                let (ca, cb) = (w(a).div_ceil(bits), w(b).div_ceil(bits));
                let pairs: Vec<(u32, u32)> =
                    (0..ca).flat_map(|i| (0..cb).map(move |j| (i, j))).filter(|&(i, j)| (i + j) * bits < v.op(o).w).collect();
                assert_eq!(pairs.len() as u32, s.slots[o].busy, "{}: golden's passes", v.op(o).name);
                let st = s.slots[o].start;
                let mut from = Vec::new();
                for (u, es) in seq.units_of(s, o) {
                    let u = u as usize;
                    for (k, &(i, j)) in pairs.iter().enumerate() {
                        let t = st + k as u32;
                        let c = seq.when_any(t, &es);
                        src[u][0].push((c.clone(), chunk(&v.at(a, t), i, bits, i + 1 == ca, sg(a))));
                        src[u][1].push((c.clone(), chunk(&v.at(b, t), j, bits, j + 1 == cb, sg(b))));
                        if k == 0 {
                            src[u][2].push((c.clone(), "1'b1".into()));
                        }
                        src[u][3].push((c, format!("{}", i + j)));
                        wmax = wmax.max(i + j);
                    }
                    from.push((es, format!("mu_acc[{}:{}]", u as u32 * acc_w + v.op(o).w - 1, u as u32 * acc_w)));
                }
                caps.push(Capture { op: o, t: s.slots[o].ready - 1, from });
            }
            (lane_a, lane_b, sh_max) = (bits + 1, bits + 1, wmax);
        }
        MulUnit::ShiftAdd { bits } => {
            let mut wmax = 0;
            for &o in &ops {
                let Kind::Mul(a, b) = v.op(o).kind else { unreachable!() };
                let (wide, narrow) = if w(a) < w(b) { (b, a) } else { (a, b) };
                let p = w(narrow).div_ceil(bits);
                assert_eq!(p, s.slots[o].busy, "{}: golden's passes", v.op(o).name);
                let st = s.slots[o].start;
                let mut from = Vec::new();
                for (u, es) in seq.units_of(s, o) {
                    let u = u as usize;
                    for k in 0..p {
                        let t = st + k;
                        let c = seq.when_any(t, &es);
                        src[u][0].push((c.clone(), v.at(wide, t).ext(acc_w)));
                        src[u][1].push((c.clone(), chunk(&v.at(narrow, t), k, bits, k + 1 == p, sg(narrow))));
                        if k == 0 {
                            src[u][2].push((c.clone(), "1'b1".into()));
                        }
                        src[u][3].push((c, format!("{}", k * bits)));
                        wmax = wmax.max(k * bits);
                    }
                    from.push((es, format!("mu_acc[{}:{}]", u as u32 * acc_w + v.op(o).w - 1, u as u32 * acc_w)));
                }
                caps.push(Capture { op: o, t: s.slots[o].ready - 1, from });
            }
            (lane_a, lane_b, sh_max) = (acc_w, bits + 1, wmax);
        }
    }
    let sh_w = bits_for(sh_max);
    body.push(comment(format!("Multipliers ({m}): each unit's ports, selected by phase and epoch.")));
    for (n, lw) in [("mu_a", lane_a), ("mu_b", lane_b), ("mu_f", 1), ("mu_sh", sh_w)] {
        body.push(crate::verilog::bus(n, m * lw));
    }
    // Each product keeps the accumulator's low bits it needs.
    body.push(comment("verilator lint_off UNUSEDSIGNAL"));
    body.push(crate::verilog::bus("mu_acc", m * acc_w));
    body.push(comment("verilator lint_on UNUSEDSIGNAL"));
    for (u, sr) in src.iter().enumerate() {
        let u = u as u32;
        body.push(Item::Assign(format!("mu_a[{}:{}]", (u + 1) * lane_a - 1, u * lane_a), and_or(&sr[0], lane_a)));
        body.push(Item::Assign(format!("mu_b[{}:{}]", (u + 1) * lane_b - 1, u * lane_b), and_or(&sr[1], lane_b)));
        let firsts: Vec<String> = sr[2].iter().map(|(c, _)| c.clone()).collect();
        body.push(Item::Assign(format!("mu_f[{u}]"), or(&firsts)));
        let sh: Vec<(String, String)> = sr[3].iter().map(|(c, x)| (c.clone(), format!("{sh_w}'d{x}"))).collect();
        body.push(Item::Assign(format!("mu_sh[{}:{}]", (u + 1) * sh_w - 1, u * sh_w), and_or(&sh, sh_w)));
    }
    let lane = |n: &str, lw: u32| if lw == 1 { format!("{n}[mk]") } else { format!("{n}[mk*{lw} +: {lw}]") };
    let mut g = Vec::new();
    match plan.mul {
        MulUnit::Tile { bits } => {
            let pw = 2 * bits + 2;
            g.extend([sreg("ra", bits + 1), sreg("rb", bits + 1), reg("f1", 1), reg("s1", sh_w)]);
            g.extend([sreg("pr", pw), reg("f2", 1), reg("s2", sh_w), reg("acc", acc_w)]);
            let pe = if acc_w > pw { crate::verilog::sext("pr", pw, acc_w) } else { format!("pr[{}:0]", acc_w - 1) };
            g.push(wire("pe", acc_w, pe));
            // The pair's weight 2^(bits (i + j)): a multiplexer over the few weights the unit
            // uses, not a barrel shifter over every shift its lane could encode.
            let mut ps = format!("{acc_w}'d0");
            for x in (0..=sh_max).rev() {
                let sh = x * bits;
                let v = if sh == 0 {
                    "pe".to_string()
                } else if sh >= acc_w {
                    format!("{acc_w}'d0")
                } else {
                    format!("{{pe[{}:0], {sh}'d0}}", acc_w - sh - 1)
                };
                ps = if x == sh_max { v } else { format!("(s2 == {sh_w}'d{x}) ? {v} : {ps}") };
            }
            g.push(wire("ps", acc_w, ps));
            g.push(wire("accn", acc_w, format!("(f2 ? {acc_w}'d0 : acc) + ps")));
            g.push(Item::Always(vec![Stmt::If(
                "en".into(),
                vec![
                    set("ra", lane("mu_a", lane_a)),
                    set("rb", lane("mu_b", lane_b)),
                    set("f1", lane("mu_f", 1)),
                    set("s1", lane("mu_sh", sh_w)),
                    set("pr", "ra * rb"),
                    set("f2", "f1"),
                    set("s2", "s1"),
                    set("acc", "accn"),
                ],
                vec![],
            )]));
        }
        MulUnit::ShiftAdd { bits } => {
            g.extend([reg("pp", acc_w), reg("f2", 1), reg("acc", acc_w)]);
            g.push(wire("wa", acc_w, lane("mu_a", lane_a)));
            g.push(swire_c("cb", bits + 1, lane("mu_b", lane_b)));
            let prod = if bits == 1 { format!("cb[1] ? -wa : (cb[0] ? wa : {acc_w}'d0)") } else { "$signed(wa) * cb".to_string() };
            g.push(wire("pw", acc_w, prod));
            g.push(wire("accn", acc_w, format!("(f2 ? {acc_w}'d0 : acc) + pp")));
            g.push(Item::Always(vec![Stmt::If(
                "en".into(),
                vec![set("pp", format!("pw << {}", lane("mu_sh", sh_w))), set("f2", lane("mu_f", 1)), set("acc", "accn")],
                vec![],
            )]));
        }
    }
    g.push(Item::Assign(format!("mu_acc[mk*{acc_w} +: {acc_w}]"), "accn".into()));
    body.push(Item::ForGenerate { var: "mk".into(), count: m, label: "g_mul".into(), body: g });
    body.push(Item::Blank);
    caps
}

fn swire_c(name: &str, w: u32, v: String) -> Item {
    crate::verilog::swire(name, w, v)
}

/// The dividers: their lanes, the generate loop, and what each quotient's and remainder's
/// register captures.
pub(super) fn dividers(v: &Values, seq: &Seq, body: &mut Vec<Item>) -> Vec<Capture> {
    let s = v.s;
    let r = s.plan.div_bits;
    let d = s.plan.dividers;
    let ops: Vec<usize> = (0..s.slots.len()).filter(|&o| s.slots[o].class == Class::Div).collect();
    if ops.is_empty() {
        return Vec::new();
    }
    let rem_of = |o: usize| (0..s.prog.ops.len()).find(|&k| matches!(s.prog.ops[k].kind, Kind::Rem(x) if x.0 as usize == o));
    let qpad = |qb: u32| qb.div_ceil(r) * r;
    let wd = ops.iter().map(|&o| if let Kind::Div { d, .. } = v.op(o).kind { v.op(d.0 as usize).w } else { 0 }).max().unwrap_or(1);
    let qm = ops.iter().map(|&o| if let Kind::Div { qb, .. } = v.op(o).kind { qpad(qb) } else { 0 }).max().unwrap_or(1);
    let mut src: Vec<[Vec<(String, String)>; 4]> = vec![Default::default(); d as usize];
    let mut caps = Vec::new();
    for &o in &ops {
        let Kind::Div { n, d: dv, qb, .. } = v.op(o).kind else { unreachable!() };
        let qp = qpad(qb);
        assert_eq!(1 + qp / r, s.slots[o].busy, "{}: golden's divider clocks", v.op(o).name);
        let st = s.slots[o].start;
        let (nn, dd) = (v.at(n, st), v.at(dv, st));
        let lo = if qm > qp { format!("{{{}, {}'d0}}", nn.bits(0, qp), qm - qp) } else { nn.bits(0, qp) };
        let t = st + s.slots[o].busy - 1;
        let (mut fq, mut fr) = (Vec::new(), Vec::new());
        for (u, es) in seq.units_of(s, o) {
            let u = u as usize;
            let c = seq.when_any(st, &es);
            src[u][0].push((c.clone(), "1'b1".into()));
            src[u][1].push((c.clone(), dd.ext(wd)));
            src[u][2].push((c.clone(), nn.bits(qp, wd)));
            src[u][3].push((c, lo.clone()));
            let u = u as u32;
            fq.push((es.clone(), format!("du_q[{}:{}]", u * qm + qb - 1, u * qm)));
            if let Some(ro) = rem_of(o) {
                fr.push((es.clone(), format!("du_r[{}:{}]", u * wd + v.op(ro).w - 1, u * wd)));
            }
        }
        caps.push(Capture { op: o, t, from: fq });
        if let Some(ro) = rem_of(o) {
            caps.push(Capture { op: ro, t, from: fr });
        }
    }
    body.push(comment(format!("Dividers ({d}, {r} quotient bit(s) a clock): each unit's load, selected by phase and epoch.")));
    for (n, lw) in [("du_ld", 1), ("du_d", wd), ("du_n", wd), ("du_lo", qm)] {
        body.push(crate::verilog::bus(n, d * lw));
    }
    // Each division keeps the quotient and remainder bits it needs.
    body.push(comment("verilator lint_off UNUSEDSIGNAL"));
    body.push(crate::verilog::bus("du_q", d * qm));
    body.push(crate::verilog::bus("du_r", d * wd));
    body.push(comment("verilator lint_on UNUSEDSIGNAL"));
    for (u, sr) in src.iter().enumerate() {
        let u = u as u32;
        let lds: Vec<String> = sr[0].iter().map(|(c, _)| c.clone()).collect();
        body.push(Item::Assign(format!("du_ld[{u}]"), or(&lds)));
        body.push(Item::Assign(format!("du_d[{}:{}]", (u + 1) * wd - 1, u * wd), and_or(&sr[1], wd)));
        body.push(Item::Assign(format!("du_n[{}:{}]", (u + 1) * wd - 1, u * wd), and_or(&sr[2], wd)));
        body.push(Item::Assign(format!("du_lo[{}:{}]", (u + 1) * qm - 1, u * qm), and_or(&sr[3], qm)));
    }
    let lane = |n: &str, lw: u32| if lw == 1 { format!("{n}[dk]") } else { format!("{n}[dk*{lw} +: {lw}]") };
    let mut g = vec![reg("dv", wd), reg("rm", wd), reg("lo", qm)];
    let (mut rm, mut lo) = ("rm".to_string(), "lo".to_string());
    for step in 0..r {
        let (t, ge) = (format!("t{step}"), format!("ge{step}"));
        let top = if qm == 1 { lo.clone() } else { format!("{lo}[{}]", qm - 1) };
        g.push(wire(&t, wd + 1, format!("{{{rm}, {top}}}")));
        g.push(wire(&ge, 1, format!("{t} >= {{1'b0, dv}}")));
        let (rn, ln) = (format!("rm{}", step + 1), format!("lo{}", step + 1));
        g.push(wire(&rn, wd, format!("{ge} ? {t}[{}:0] - dv : {t}[{}:0]", wd - 1, wd - 1)));
        g.push(wire(&ln, qm, if qm == 1 { ge.clone() } else { format!("{{{lo}[{}:0], {ge}}}", qm - 2) }));
        (rm, lo) = (rn, ln);
    }
    g.push(Item::Assign(lane("du_q", qm), lo.clone()));
    g.push(Item::Assign(lane("du_r", wd), rm.clone()));
    g.push(Item::Always(vec![Stmt::If(
        "en".into(),
        vec![Stmt::If(
            lane("du_ld", 1),
            vec![set("dv", lane("du_d", wd)), set("rm", lane("du_n", wd)), set("lo", lane("du_lo", qm))],
            vec![set("rm", rm), set("lo", lo)],
        )],
        vec![],
    )]));
    body.push(Item::ForGenerate { var: "dk".into(), count: d, label: "g_div".into(), body: g });
    body.push(Item::Blank);
    caps
}
