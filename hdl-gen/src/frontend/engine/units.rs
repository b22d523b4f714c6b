//! The shared units: per unit an operand multiplexer per port, selected by phase and epoch
//! (AND-OR: the binding puts one operation on a unit at a time, golden's `verify_binding`; a
//! multiplier's selects and operand loads registered a clock ahead), then the units themselves
//! as `generate` loops over identical lanes.
//!
//! - **Tile** (`MulUnit::Tile`): one pass multiplies a chunk of each operand (the top chunk of
//!   a signed operand signed, the others unsigned: `bits + 1`-bit signed lanes), registered;
//!   the product, registered; the accumulator adds it, cleared on a product's first pass and
//!   shifted one chunk up when the pair's weight drops (the passes run heaviest first: Horner),
//!   modulo its width. Golden's `MUL_PIPE` = 2: the value
//!   is ready two clocks after the last pass.
//! - **Shift-add** (`MulUnit::ShiftAdd`): a pass multiplies the wider operand by `bits` bits of
//!   the narrower one, shifted to their weight, registered; the accumulator adds it. Ready one
//!   clock after the last pass.
//! - **Divider** (restoring, the textbook form: the remainder shifted past a fixed divisor): a
//!   load clock takes the divisor, the dividend's top bits as the first remainder and its low
//!   quotient-width bits, left-aligned, in the quotient register; then `bits` compare-subtract
//!   steps a clock, each shifting a quotient bit in. Ready after its last step. A chained
//!   division (golden's `Schedule::div_stages`) runs on two dividers in series: the second
//!   loads the first's next step and its divisor, so its value has one source, not one a parity.

use super::sequencer::Seq;
use super::values::{Src, Values};
use crate::frontend::mul18;
use crate::verilog::{comment, reg, set, sreg, wire, Item, Stmt};
pub(super) use crate::widths::bits_for;
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

/// Units grouped by their widths, each group one generate loop: a unit's datapath is as wide as
/// the widest operation bound to it, not as the widest of all (a divider that only ever runs
/// the edges' 15-bit steps does not carry the reciprocal's 44-bit divisor).
struct Groups {
    /// Per unit with operations: its group and its lane in the group.
    of: Vec<Option<(usize, u32)>>,
    /// Per group: its widths and its units.
    keys: Vec<Vec<u32>>,
    members: Vec<Vec<u32>>,
}

impl Groups {
    fn new(keys_of: &[Option<Vec<u32>>]) -> Groups {
        let mut g = Groups { of: vec![None; keys_of.len()], keys: Vec::new(), members: Vec::new() };
        for (u, k) in keys_of.iter().enumerate() {
            let Some(k) = k else { continue };
            let gi = match g.keys.iter().position(|x| x == k) {
                Some(i) => i,
                None => {
                    g.keys.push(k.clone());
                    g.members.push(Vec::new());
                    g.keys.len() - 1
                }
            };
            g.of[u] = Some((gi, g.members[gi].len() as u32));
            g.members[gi].push(u as u32);
        }
        g
    }
}

/// Lane `li` of `lw` bits of a group's bus, bits `lo .. lo + w`.
fn lane_bits(bus: &str, li: u32, lw: u32, w: u32) -> String {
    if lw == 1 {
        format!("{bus}[{li}]")
    } else {
        format!("{bus}[{}:{}]", li * lw + w - 1, li * lw)
    }
}

/// A product's operands (for shift-add the wide one first) and its passes: chunk of a, chunk
/// of b, weight index, whether each chunk is its operand's top one.
type Passes = (golden::frontend::engine::V, golden::frontend::engine::V, Vec<(u32, u32, u32, bool, bool)>);

/// The multipliers: their lanes' multiplexers, a generate loop per width, and what each
/// product's value register captures.
/// `dsp`: the `tri_fe_mul18` module, when the tiles are its instances ([`crate::frontend::Hw::dsp_regs`]).
pub(super) fn multipliers(v: &Values, seq: &Seq, dsp: Option<&str>, body: &mut Vec<Item>) -> Vec<Capture> {
    let s = v.s;
    let plan = s.plan;
    let m = plan.mults as usize;
    let ops: Vec<usize> = (0..s.slots.len()).filter(|&o| s.slots[o].class == Class::Mul).collect();
    if ops.is_empty() {
        return Vec::new();
    }
    let w = |x: golden::frontend::engine::V| v.op(x.0 as usize).w;
    let sg = |x: golden::frontend::engine::V| v.op(x.0 as usize).signed;
    // Each product's passes: (pass index, chunk of a, chunk of b, weight index) and its operands
    // in order (for shift-add, the wide one first).
    let passes = |o: usize| -> Passes {
        let Kind::Mul(a, b) = v.op(o).kind else { unreachable!() };
        match plan.mul {
            MulUnit::Tile { bits } => {
                let (ca, cb) = (w(a).div_ceil(bits), w(b).div_ceil(bits));
                // Heaviest pair first (golden fixes the passes' clocks, not their order): the
                // accumulator then shifts one chunk up when the weight drops (Horner), instead
                // of a multiplexer placing each product at its weight.
                let mut p: Vec<_> = (0..ca)
                    .flat_map(|i| (0..cb).map(move |j| (i, j)))
                    .filter(|&(i, j)| (i + j) * bits < v.op(o).w)
                    .map(|(i, j)| (i, j, i + j, i + 1 == ca, j + 1 == cb))
                    .collect();
                p.sort_by_key(|x| std::cmp::Reverse(x.2));
                (a, b, p)
            }
            MulUnit::ShiftAdd { bits } => {
                let (wide, narrow) = if w(a) < w(b) { (b, a) } else { (a, b) };
                let p = w(narrow).div_ceil(bits);
                (wide, narrow, (0..p).map(|k| (0, k, k, false, k + 1 == p)).collect())
            }
        }
    };
    let mut keys: Vec<Option<Vec<u32>>> = vec![None; m];
    for &o in &ops {
        let (_, _, p) = passes(o);
        assert_eq!(p.len() as u32, s.slots[o].busy, "{}: golden's passes", v.op(o).name);
        // A tile's lane says only "shift down a weight"; a shift-add unit's, the pass's shift.
        let wmax = if matches!(plan.mul, MulUnit::Tile { .. }) { 1 } else { p.iter().map(|x| x.2).max().unwrap_or(0) };
        for (u, _) in seq.units_of(s, o) {
            let k = keys[u as usize].get_or_insert(vec![1, 0]);
            k[0] = k[0].max(v.op(o).w);
            k[1] = k[1].max(wmax);
        }
    }
    let groups = Groups::new(&keys);
    // Per unit, its lanes' sources: a, b, first, weight index, and a tile's operand registers'
    // loads (a, b).
    let mut src: Vec<[Vec<(String, String)>; 6]> = vec![Default::default(); m];
    let mut caps = Vec::new();
    for &o in &ops {
        let (a, b, p) = passes(o);
        let st = s.slots[o].start;
        let mut from = Vec::new();
        for (u, es) in seq.units_of(s, o) {
            let (gi, li) = groups.of[u as usize].expect("a unit with operations");
            let acc_w = groups.keys[gi][0];
            let u = u as usize;
            let mut held = [false; 2];
            for (k, &(i, j, x, top_a, top_b)) in p.iter().enumerate() {
                let t = st + k as u32;
                let c = seq.when_any(t, &es);
                // The operand ports' selects and the operand registers' loads are registered: set
                // the clock before (t - 1, a whole binding period on where t is 0).
                let cb = seq.when_any(t + s.ii * seq.epochs - 1, &es);
                let (va, vb) = match plan.mul {
                    MulUnit::Tile { bits } => (chunk(&v.at(a, t), i, bits, top_a, sg(a)), chunk(&v.at(b, t), j, bits, top_b, sg(b))),
                    MulUnit::ShiftAdd { bits } => (v.at(a, t).ext(acc_w), chunk(&v.at(b, t), j, bits, top_b, sg(b))),
                };
                // A tile's operand register holds a chunk the product's next pass takes again: no
                // multiplexer term for that pass (a product of 2 x 2 chunks takes 6, not 8).
                let tile = matches!(plan.mul, MulUnit::Tile { .. });
                for (port, x) in [(0, va), (1, vb)] {
                    let again = tile && k > 0 && src[u][port].last().is_some_and(|(_, y)| *y == x) && held[port];
                    if !again {
                        src[u][port].push((cb.clone(), x));
                        src[u][4 + port].push((cb.clone(), "1'b1".into()));
                    }
                    held[port] = true;
                }
                if k == 0 {
                    src[u][2].push((c.clone(), "1'b1".into()));
                }
                let drop = k > 0 && x < p[k - 1].2;
                match plan.mul {
                    MulUnit::Tile { .. } => src[u][3].push((c, if drop { "1" } else { "0" }.into())),
                    MulUnit::ShiftAdd { .. } => src[u][3].push((c, format!("{x}"))),
                }
            }
            from.push((es, lane_bits(&format!("m{gi}_acc"), li, acc_w, v.op(o).w)));
        }
        caps.push(Capture { op: o, t: s.slots[o].ready - 1, from });
    }
    body.push(comment(format!("Multipliers ({m}): each unit's ports, selected by phase and epoch; a generate loop per width.")));
    for (gi, (key, members)) in groups.keys.iter().zip(&groups.members).enumerate() {
        let (acc_w, sh_max) = (key[0], key[1]);
        let n = members.len() as u32;
        let sh_w = bits_for(sh_max);
        let (lane_a, lane_b) = match plan.mul {
            MulUnit::Tile { bits } => (bits + 1, bits + 1),
            MulUnit::ShiftAdd { bits } => (acc_w, bits + 1),
        };
        let bus = |x: &str| format!("m{gi}_{x}");
        body.push(comment(format!(
            "Group {gi}: units {} (g_mul{gi}[k]), accumulators of {acc_w} bits.",
            members.iter().map(|u| format!("mul{u}")).collect::<Vec<_>>().join(", ")
        )));
        let tile = matches!(plan.mul, MulUnit::Tile { .. });
        let ports: &[(&str, u32)] = if tile {
            &[("a", lane_a), ("b", lane_b), ("f", 1), ("sh", sh_w), ("la", 1), ("lb", 1)]
        } else {
            &[("a", lane_a), ("b", lane_b), ("f", 1), ("sh", sh_w)]
        };
        for &(x, lw) in ports {
            body.push(crate::verilog::bus(&bus(x), n * lw));
        }
        // Each product keeps the accumulator's low bits it needs.
        body.push(comment("verilator lint_off UNUSEDSIGNAL"));
        body.push(crate::verilog::bus(&bus("acc"), n * acc_w));
        body.push(comment("verilator lint_on UNUSEDSIGNAL"));
        for (li, &u) in members.iter().enumerate() {
            let (li, sr) = (li as u32, &src[u as usize]);
            operands(gi, li, sr, (lane_a, lane_b), body);
            let firsts: Vec<String> = sr[2].iter().map(|(c, _)| c.clone()).collect();
            body.push(Item::Assign(lane_bits(&bus("f"), li, 1, 1), or(&firsts)));
            let sh: Vec<(String, String)> =
                sr[3].iter().filter(|(_, x)| x != "0").map(|(c, x)| (c.clone(), format!("{sh_w}'d{x}"))).collect();
            let sh = match plan.mul {
                MulUnit::Tile { .. } => or(&sh.iter().map(|(c, _)| c.clone()).collect::<Vec<_>>()),
                MulUnit::ShiftAdd { .. } => and_or_zero(&sh, sh_w),
            };
            body.push(Item::Assign(lane_bits(&bus("sh"), li, sh_w, sh_w), sh));
            if tile {
                loads(gi, li, sr, body);
            }
        }
        let k = format!("m{gi}k");
        let lane = |x: &str, lw: u32| if lw == 1 { format!("{}[{k}]", bus(x)) } else { format!("{}[{k}*{lw} +: {lw}]", bus(x)) };
        let mut g = multiplier(plan.mul, dsp, acc_w, (lane_a, lane_b, sh_w), &lane);
        g.push(Item::Assign(lane("acc", acc_w), "accn".into()));
        body.push(Item::ForGenerate { var: k.clone(), count: n, label: format!("g_mul{gi}"), body: g });
    }
    body.push(Item::Blank);
    caps
}

/// Lane `li` of multiplier group `gi`: its operand ports from their sources `sr[0]`, `sr[1]`
/// (conditions of the clock before).
fn operands(gi: usize, li: u32, sr: &[Vec<(String, String)>; 6], (lane_a, lane_b): (u32, u32), body: &mut Vec<Item>) {
    for (port, x, lw) in [(0, "a", lane_a), (1, "b", lane_b)] {
        let terms = selected(&merged(&sr[port]), &format!("m{gi}_s{x}{li}"), body);
        body.push(Item::Assign(lane_bits(&format!("m{gi}_{x}"), li, lw, lw), and_or(&terms, lw)));
    }
}

/// Lane `li` of tile group `gi`: its operand registers' loads `sr[4]`, `sr[5]`, registered, so
/// an operand register's clock enable is a flip-flop, not the OR of its phases (the chain's
/// critical path on one 25F, seed 2 of stop 32).
fn loads(gi: usize, li: u32, sr: &[Vec<(String, String)>; 6], body: &mut Vec<Item>) {
    let mut loads = Vec::new();
    for (x, port) in [("la", 4), ("lb", 5)] {
        let r = format!("m{gi}_{x}{li}");
        body.push(reg(&r, 1));
        body.push(Item::Assign(lane_bits(&format!("m{gi}_{x}"), li, 1, 1), r.clone()));
        loads.push(set(r, or(&sr[port].iter().map(|(c, _)| c.clone()).collect::<Vec<_>>())));
    }
    body.push(Item::Always(loads));
}

/// One multiplier unit's datapath (the body of its group's generate loop): `lane` names its
/// slice of the group's buses.
fn multiplier(
    mul: MulUnit,
    dsp: Option<&str>,
    acc_w: u32,
    (lane_a, lane_b, sh_w): (u32, u32, u32),
    lane: &dyn Fn(&str, u32) -> String,
) -> Vec<Item> {
    let mut g = Vec::new();
    match mul {
        MulUnit::Tile { bits } => {
            let pw = 2 * bits + 2;
            if dsp.is_none() {
                g.extend([sreg("ra", bits + 1), sreg("rb", bits + 1)]);
            }
            g.extend([reg("f1", 1), reg("s1", 1)]);
            // The operand and product registers are the tile's own with `tri_fe_mul18`.
            let pr = if dsp.is_some() { Item::Wire { name: "pr".into(), width: pw, signed: true, value: None } } else { sreg("pr", pw) };
            if acc_w < pw {
                // The accumulator keeps the product's low bits only.
                g.push(comment("verilator lint_off UNUSEDSIGNAL"));
                g.push(pr);
                g.push(comment("verilator lint_on UNUSEDSIGNAL"));
            } else {
                g.push(pr);
            }
            if let Some(module) = dsp {
                assert_eq!((lane_a, lane_b, pw), (mul18::BITS, mul18::BITS, mul18::P_BITS), "tri_fe_mul18 takes 18-bit lanes");
                let (la, lb, a, b) = (lane("la", 1), lane("lb", 1), lane("a", lane_a), lane("b", lane_b));
                let conns = mul18::MulConns { a: &a, b: &b, cea: &la, ceb: &lb, cep: "1'b1", p: "pr", signed: (true, true) };
                g.push(mul18::instance(module, "u_tile", &conns));
            }
            g.extend([reg("acc", acc_w)]);
            let pe = if acc_w > pw { crate::verilog::sext("pr", pw, acc_w) } else { format!("pr[{}:0]", acc_w - 1) };
            g.push(wire("pe", acc_w, pe));
            // The sum so far, cleared for a product's first pass and shifted a chunk up when the
            // weight drops, both as it is written the clock before (the pass's flags are known a
            // clock ahead: f1, s1), so a cleared register or its zero low bits are the
            // flip-flops' synchronous reset, not a multiplexer before the adder.
            let up = if acc_w > bits { format!("{{accn[{}:0], {bits}'d0}}", acc_w - bits - 1) } else { format!("{acc_w}'d0") };
            g.push(wire("accn", acc_w, "acc + pe"));
            g.push(wire("held", acc_w, format!("f1 ? {acc_w}'d0 : s1 ? {up} : accn")));
            let mut moves = Vec::new();
            if dsp.is_none() {
                moves.push(Stmt::If(lane("la", 1), vec![set("ra", lane("a", lane_a))], vec![]));
                moves.push(Stmt::If(lane("lb", 1), vec![set("rb", lane("b", lane_b))], vec![]));
            }
            moves.extend([set("f1", lane("f", 1)), set("s1", lane("sh", sh_w))]);
            if dsp.is_none() {
                moves.push(set("pr", "ra * rb"));
            }
            moves.push(set("acc", "held"));
            g.push(Item::Always(moves));
        }
        MulUnit::ShiftAdd { bits } => {
            g.extend([reg("pp", acc_w), reg("f2", 1), reg("acc", acc_w)]);
            g.push(wire("wa", acc_w, lane("a", lane_a)));
            g.push(crate::verilog::swire("cb", bits + 1, lane("b", lane_b)));
            let prod = if bits == 1 { format!("cb[1] ? -wa : (cb[0] ? wa : {acc_w}'d0)") } else { "$signed(wa) * cb".to_string() };
            g.push(wire("pw", acc_w, prod));
            g.push(wire("accn", acc_w, format!("(f2 ? {acc_w}'d0 : acc) + pp")));
            let shift = if bits == 1 { lane("sh", sh_w) } else { format!("({} * {bits})", lane("sh", sh_w)) };
            g.push(Item::Always(vec![set("pp", format!("pw << {shift}")), set("f2", lane("f", 1)), set("acc", "accn")]));
        }
    }
    g
}

/// `and_or` over sources of which the zero ones were left out (the lane is zero on the others).
fn and_or_zero(items: &[(String, String)], w: u32) -> String {
    match items {
        [] => format!("{w}'d0"),
        [(c, x)] if w == 1 => format!("({c} && {x})"),
        [(c, x)] => format!("({{{w}{{{c}}}}} & {x})"),
        _ => and_or(items, w),
    }
}

/// The dividers: their lanes, a generate loop per width, and what each quotient's and
/// remainder's register captures.
pub(super) fn dividers(v: &Values, seq: &Seq, body: &mut Vec<Item>) -> Vec<Capture> {
    let s = v.s;
    let r = s.plan.div_bits;
    let d = s.plan.dividers as usize;
    let ops: Vec<usize> = (0..s.slots.len()).filter(|&o| s.slots[o].class == Class::Div).collect();
    if ops.is_empty() {
        return Vec::new();
    }
    let rem_of = |o: usize| (0..s.prog.ops.len()).find(|&k| matches!(s.prog.ops[k].kind, Kind::Rem(x) if x.0 as usize == o));
    let qpad = |qb: u32| qb.div_ceil(r) * r;
    // The units a division runs on: both of a chained one's (golden's `div_stages`), every
    // triangle; else by epoch.
    let units = |o: usize| match s.div_stages(o) {
        Some(st) => st.iter().map(|x| (x.0, (0..seq.epochs).collect())).collect(),
        None => seq.units_of(s, o),
    };
    let mut keys: Vec<Option<Vec<u32>>> = vec![None; d];
    for &o in &ops {
        let Kind::Div { d: dv, qb, .. } = v.op(o).kind else { unreachable!() };
        for (u, _) in units(o) {
            let k = keys[u as usize].get_or_insert(vec![1, 1]);
            k[0] = k[0].max(v.op(dv.0 as usize).w);
            k[1] = k[1].max(qpad(qb));
        }
    }
    let groups = Groups::new(&keys);
    let mut src: Vec<[Vec<(String, String)>; 4]> = vec![Default::default(); d];
    let mut caps = Vec::new();
    for &o in &ops {
        let Kind::Div { n, d: dv, qb, .. } = v.op(o).kind else { unreachable!() };
        let qp = qpad(qb);
        assert_eq!(1 + qp / r, s.slots[o].busy, "{}: golden's divider clocks", v.op(o).name);
        let st = s.slots[o].start;
        let (nn, dd) = (v.at(n, st), v.at(dv, st));
        let t = st + s.slots[o].busy - 1;
        let (mut fq, mut fr) = (Vec::new(), Vec::new());
        if let Some([(u0, _, _), (u1, at, _)]) = s.div_stages(o) {
            // In series: the second divider loads the first's next step (its remainder and
            // quotient bits) and divisor; the value is the second's last step.
            let ((g0, l0), (g1, l1)) = (groups.of[u0 as usize].expect("a unit"), groups.of[u1 as usize].expect("a unit"));
            assert_eq!(groups.keys[g0], groups.keys[g1], "{}: a chained division's dividers are as wide", v.op(o).name);
            let (wd, qm) = (groups.keys[g0][0], groups.keys[g0][1]);
            let lo = if qm > qp { format!("{{{}, {}'d0}}", nn.bits(0, qp), qm - qp) } else { nn.bits(0, qp) };
            let (c0, c1) = (seq.phase(st % s.ii), seq.phase(at % s.ii));
            src[u0 as usize][0].push((c0.clone(), "1'b1".into()));
            src[u0 as usize][1].push((c0.clone(), dd.ext(wd)));
            src[u0 as usize][2].push((c0.clone(), nn.bits(qp, wd)));
            src[u0 as usize][3].push((c0, lo));
            src[u1 as usize][0].push((c1.clone(), "1'b1".into()));
            src[u1 as usize][1].push((c1.clone(), lane_bits(&format!("d{g0}_dv"), l0, wd, wd)));
            src[u1 as usize][2].push((c1.clone(), lane_bits(&format!("d{g0}_r"), l0, wd, wd)));
            src[u1 as usize][3].push((c1, lane_bits(&format!("d{g0}_q"), l0, qm, qm)));
            let all: Vec<u32> = (0..seq.epochs).collect();
            caps.push(Capture { op: o, t, from: vec![(all.clone(), lane_bits(&format!("d{g1}_q"), l1, qm, qb))] });
            if let Some(ro) = rem_of(o) {
                caps.push(Capture { op: ro, t, from: vec![(all, lane_bits(&format!("d{g1}_r"), l1, wd, v.op(ro).w))] });
            }
            continue;
        }
        for (u, es) in seq.units_of(s, o) {
            let (gi, li) = groups.of[u as usize].expect("a unit with operations");
            let (wd, qm) = (groups.keys[gi][0], groups.keys[gi][1]);
            let lo = if qm > qp { format!("{{{}, {}'d0}}", nn.bits(0, qp), qm - qp) } else { nn.bits(0, qp) };
            let u = u as usize;
            let c = seq.when_any(st, &es);
            src[u][0].push((c.clone(), "1'b1".into()));
            src[u][1].push((c.clone(), dd.ext(wd)));
            src[u][2].push((c.clone(), nn.bits(qp, wd)));
            src[u][3].push((c, lo));
            fq.push((es.clone(), lane_bits(&format!("d{gi}_q"), li, qm, qb)));
            if let Some(ro) = rem_of(o) {
                fr.push((es.clone(), lane_bits(&format!("d{gi}_r"), li, wd, v.op(ro).w)));
            }
        }
        caps.push(Capture { op: o, t, from: fq });
        if let Some(ro) = rem_of(o) {
            caps.push(Capture { op: ro, t, from: fr });
        }
    }
    body.push(comment(format!(
        "Dividers ({d}, {r} quotient bit(s) a clock): each unit's load, selected by phase and epoch; a generate loop per width."
    )));
    for (gi, (key, members)) in groups.keys.iter().zip(&groups.members).enumerate() {
        let (wd, qm) = (key[0], key[1]);
        let n = members.len() as u32;
        let bus = |x: &str| format!("d{gi}_{x}");
        body.push(comment(format!(
            "Group {gi}: units {} (g_div{gi}[k]), divisors of {wd} bits, {qm} quotient bits.",
            members.iter().map(|u| format!("div{u}")).collect::<Vec<_>>().join(", ")
        )));
        for (x, lw) in [("ld", 1), ("d", wd), ("n", wd), ("lo", qm)] {
            body.push(crate::verilog::bus(&bus(x), n * lw));
        }
        // Each division keeps the quotient and remainder bits it needs.
        body.push(comment("verilator lint_off UNUSEDSIGNAL"));
        body.push(crate::verilog::bus(&bus("q"), n * qm));
        body.push(crate::verilog::bus(&bus("r"), n * wd));
        body.push(crate::verilog::bus(&bus("dv"), n * wd));
        body.push(comment("verilator lint_on UNUSEDSIGNAL"));
        for (li, &u) in members.iter().enumerate() {
            let (li, sr) = (li as u32, &src[u as usize]);
            let lds: Vec<String> = sr[0].iter().map(|(c, _)| c.clone()).collect();
            body.push(Item::Assign(lane_bits(&bus("ld"), li, 1, 1), or(&lds)));
            body.push(Item::Assign(lane_bits(&bus("d"), li, wd, wd), and_or(&sr[1], wd)));
            body.push(Item::Assign(lane_bits(&bus("n"), li, wd, wd), and_or(&sr[2], wd)));
            body.push(Item::Assign(lane_bits(&bus("lo"), li, qm, qm), and_or(&sr[3], qm)));
        }
        let k = format!("d{gi}k");
        let lane = |x: &str, lw: u32| if lw == 1 { format!("{}[{k}]", bus(x)) } else { format!("{}[{k}*{lw} +: {lw}]", bus(x)) };
        let mut g = vec![reg("dv", wd), reg("rm", wd), reg("lo", qm)];
        let (mut rm, mut lo) = ("rm".to_string(), "lo".to_string());
        for step in 0..r {
            let (t, ge, df) = (format!("t{step}"), format!("ge{step}"), format!("df{step}"));
            let top = if qm == 1 { lo.clone() } else { format!("{lo}[{}]", qm - 1) };
            g.push(wire(&t, wd + 1, format!("{{{rm}, {top}}}")));
            // The compare is the subtract's borrow: one carry chain a step, not a compare's
            // beside the subtract's (373 LUT4 and 150 CCU2C of the ECP5 plan's engine).
            // Its bit wd is the remainder's, which the borrow below it decides is unused.
            g.push(comment("verilator lint_off UNUSEDSIGNAL"));
            g.push(wire(&df, wd + 2, format!("{{1'b0, {t}}} - {{2'b0, dv}}")));
            g.push(comment("verilator lint_on UNUSEDSIGNAL"));
            g.push(wire(&ge, 1, format!("!{df}[{}]", wd + 1)));
            let (rn, ln) = (format!("rm{}", step + 1), format!("lo{}", step + 1));
            g.push(wire(&rn, wd, format!("{ge} ? {df}[{}:0] : {t}[{}:0]", wd - 1, wd - 1)));
            g.push(wire(&ln, qm, if qm == 1 { ge.clone() } else { format!("{{{lo}[{}:0], {ge}}}", qm - 2) }));
            (rm, lo) = (rn, ln);
        }
        g.push(Item::Assign(lane("q", qm), lo.clone()));
        g.push(Item::Assign(lane("r", wd), rm.clone()));
        g.push(Item::Assign(lane("dv", wd), "dv".into()));
        g.push(Item::Always(vec![Stmt::If(
            lane("ld", 1),
            vec![set("dv", lane("d", wd)), set("rm", lane("n", wd)), set("lo", lane("lo", qm))],
            vec![set("rm", rm), set("lo", lo)],
        )]));
        body.push(Item::ForGenerate { var: k, count: n, label: format!("g_div{gi}"), body: g });
    }
    body.push(Item::Blank);
    caps
}

/// The shared barrel shifters (`Plan::shifters`): per unit the operand and the amount
/// selected by phase (AND-OR), registered, then the shift, which the value's register
/// captures a clock later (golden's `SHIFT_PIPE` = 2). A unit is as wide as its widest shift:
/// the shift moves bits only upwards, so an operand extended past its value's width gives the
/// same low bits.
pub(super) fn shifters(v: &Values, seq: &Seq, body: &mut Vec<Item>) -> Vec<Capture> {
    let s = v.s;
    let n = s.plan.shifters as usize;
    let ops: Vec<usize> = (0..s.slots.len()).filter(|&o| s.slots[o].class == Class::Shift).collect();
    if ops.is_empty() {
        return Vec::new();
    }
    let amount = |o: usize| match v.op(o).kind {
        Kind::ShlBy(a, k) => (a, k),
        _ => unreachable!("{} is not a shift", v.op(o).name),
    };
    let mut widths = vec![(0u32, 0u32); n];
    for &o in &ops {
        let (_, k) = amount(o);
        for (u, _) in seq.units_of(s, o) {
            let w = &mut widths[u as usize];
            *w = (w.0.max(v.op(o).w), w.1.max(v.op(k.0 as usize).w));
        }
    }
    let mut src: Vec<[Vec<(String, String)>; 2]> = vec![Default::default(); n];
    let mut caps = Vec::new();
    for &o in &ops {
        let (a, k) = amount(o);
        let t = s.slots[o].start;
        let mut from = Vec::new();
        for (u, es) in seq.units_of(s, o) {
            let (w, wk) = widths[u as usize];
            let c = seq.when_any(t, &es);
            src[u as usize][0].push((c.clone(), v.at(a, t).ext(w)));
            src[u as usize][1].push((c, v.at(k, t).ext(wk)));
            from.push((es, if v.op(o).w == w { format!("sh{u}_y") } else { format!("sh{u}_y[{}:0]", v.op(o).w - 1) }));
        }
        caps.push(Capture { op: o, t: s.slots[o].ready - 1, from });
    }
    body.push(comment(format!(
        "Shifters ({n}): each one's operand and amount selected by phase and registered, then shifted into the value's register."
    )));
    for (u, ((w, wk), sr)) in widths.iter().zip(&src).enumerate() {
        if sr[0].is_empty() {
            continue;
        }
        let (ra, rk) = (format!("sh{u}_a"), format!("sh{u}_n"));
        body.push(reg(&ra, *w));
        body.push(reg(&rk, *wk));
        body.push(Item::Always(vec![set(&ra, and_or(&merged(&sr[0]), *w)), set(&rk, and_or(&merged(&sr[1]), *wk))]));
        body.push(comment("verilator lint_off UNUSEDSIGNAL"));
        body.push(wire(&format!("sh{u}_y"), *w, format!("{ra} << {rk}")));
        body.push(comment("verilator lint_on UNUSEDSIGNAL"));
    }
    body.push(Item::Blank);
    caps
}

/// A port's sources each with a select register (one-hot, set the clock before from the merged
/// conditions), so the port is an AND-OR of flip-flops and values, one term a source; a lone
/// source needs none.
fn selected(terms: &[(String, String)], sel: &str, body: &mut Vec<Item>) -> Vec<(String, String)> {
    if terms.len() < 2 {
        return terms.to_vec();
    }
    let k = terms.len() as u32;
    body.push(reg(sel, k));
    body.push(Item::Always(terms.iter().enumerate().map(|(j, (c, _))| set(format!("{sel}[{j}]"), c.clone())).collect()));
    terms.iter().enumerate().map(|(j, (_, x))| (format!("{sel}[{j}]"), x.clone())).collect()
}

/// AND-OR sources with the same value merged into one term (the amount is one value's copy
/// at most clocks).
fn merged(items: &[(String, String)]) -> Vec<(String, String)> {
    let mut out: Vec<(Vec<String>, String)> = Vec::new();
    for (c, x) in items {
        match out.iter_mut().find(|(_, y)| y == x) {
            Some((cs, _)) => cs.push(c.clone()),
            None => out.push((vec![c.clone()], x.clone())),
        }
    }
    out.into_iter().map(|(cs, x)| (if cs.len() == 1 { cs[0].clone() } else { format!("({})", cs.join(" || ")) }, x)).collect()
}
