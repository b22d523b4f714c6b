//! The set-up's restoring dividers: `--fe-div-bits` quotient bits a clock, each bit one
//! compare-and-subtract step chained in the same clock, sharing one down-counter.

use crate::verilog::{lit, reg, set, wire, Item, Stmt};

/// One restoring divider: registers `<n>_p` (partial remainder), `<n>_d` (shifted divisor),
/// `<n>_q`; it takes quotient bits while the shared counter is below `qb`.
pub(super) struct Div {
    pub name: &'static str,
    pub pw: u32,
    pub qb: u32,
}

pub(super) fn div_regs(d: &Div) -> Vec<Item> {
    vec![reg(&format!("{}_p", d.name), d.pw), reg(&format!("{}_d", d.name), d.pw), reg(&format!("{}_q", d.name), d.qb)]
}

/// Statements that load a divider: dividend and divisor, both `pw` bits wide already.
pub(super) fn div_load(d: &Div, dividend: &str, divisor_shifted: &str) -> Vec<Stmt> {
    vec![set(format!("{}_p", d.name), dividend), set(format!("{}_d", d.name), divisor_shifted), set(format!("{}_q", d.name), lit(d.qb, 0))]
}

/// `bits` restoring steps in one clock, chained: step j takes quotient bit `cnt - j`, if
/// that bit exists and is one of this divider's `qb`.
pub(super) fn div_chain(d: &Div, cnt: &str, cnt_w: u32, bits: u32) -> Vec<Item> {
    let n = d.name;
    let mut items = Vec::new();
    for j in 0..bits {
        let (p, dd, q) = if j == 0 {
            (format!("{n}_p"), format!("{n}_d"), format!("{n}_q"))
        } else {
            (format!("{n}_p{j}"), format!("{n}_d{j}"), format!("{n}_q{j}"))
        };
        let on = if j == 0 {
            format!("{cnt} < {}", lit(cnt_w, d.qb as u64))
        } else {
            format!("{cnt} >= {} && {cnt} - {} < {}", lit(cnt_w, j as u64), lit(cnt_w, j as u64), lit(cnt_w, d.qb as u64))
        };
        items.push(wire(&format!("{n}_on{j}"), 1, on));
        items.push(wire(&format!("{n}_ge{j}"), 1, format!("{p} >= {dd}")));
        let k = j + 1;
        let shifted = if d.qb == 1 { format!("{n}_ge{j}") } else { format!("{{{q}[{}:0], {n}_ge{j}}}", d.qb - 2) };
        items.push(wire(&format!("{n}_p{k}"), d.pw, format!("({n}_on{j} && {n}_ge{j}) ? {p} - {dd} : {p}")));
        items.push(wire(&format!("{n}_d{k}"), d.pw, format!("{n}_on{j} ? {dd} >> 1 : {dd}")));
        items.push(wire(&format!("{n}_q{k}"), d.qb, format!("{n}_on{j} ? {shifted} : {q}")));
    }
    items
}

pub(super) fn div_iter(d: &Div, bits: u32) -> Vec<Stmt> {
    let n = d.name;
    vec![
        set(format!("{n}_p"), format!("{n}_p{bits}")),
        set(format!("{n}_d"), format!("{n}_d{bits}")),
        set(format!("{n}_q"), format!("{n}_q{bits}")),
    ]
}
