//! `tri_fe_engine` (issue 27): the shared set-up engine, written from golden's schedule of the
//! set-up program (`golden::frontend::engine`), so the schedule golden evaluates is the one
//! the RTL runs. A triangle enters every II clocks; each operation of the program runs at its
//! scheduled clock: logic as a one-clock register (wiring as a wire), products on the plan's
//! multipliers, divisions on its restoring dividers, every operand read from the register copy
//! it is in at that clock. Behind it, `tri_fe_queue` holds the results for the walker.
//!
//! - [`sequencer`]: phase and epoch rings, the entry, a valid bit per period.
//! - [`values`]: the values' registers, their copies, wiring and logic.
//! - [`units`]: the units' operand multiplexers and the units.
//! - [`queue`]: the set-up result queue.
//!
//! One enable, `en`, freezes the whole engine (every register of it) while a result is due and
//! the queue is full: simple, and its fan-out (every engine register's clock enable) is the
//! path to watch for timing.

mod queue;
mod seq;
mod sequencer;
mod units;
mod values;

use super::hw::Hw;
use crate::verilog::{comment, reg, set, Item, Module, Port, Stmt};
use crate::Names;
use golden::frontend::engine::schedule::{Class, Schedule};
use golden::frontend::engine::{DivForm, Kind, MulUnit, V};
use golden::frontend::Widths;
use sequencer::Seq;
use values::Values;

use queue::module as queue_module;

/// Whether this front-end's set-up is the shared engine.
pub(super) fn on(hw: &Hw) -> bool {
    hw.engine_form()
}

/// One field of the set-up result the walker reads: its name, the program's value and its
/// width in the queue.
pub(super) struct Field {
    pub name: String,
    pub v: V,
    pub w: u32,
}

/// The set-up result's fields, in the queue entry's order (the first least significant).
pub(super) fn fields(hw: &Hw, s: &Schedule) -> Vec<Field> {
    let Widths { yw, aw, k, rw, gw, dw_edge, .. } = hw.fe.widths();
    let o = &s.prog.out;
    let f = |name: &str, v: V, w: u32| Field { name: name.into(), v, w };
    let mut v = vec![
        f("first", o.first, yw),
        f("last", o.last, yw),
        f("di", o.di, hw.fe.cfg.dw()),
        f("an", o.an, aw),
        f("rn", o.rn, rw),
        f("tn", o.tn, k),
        f("dyn", o.dyn_, k),
        f("gxn", o.gxn, k),
    ];
    for (j, e) in o.edges.iter().enumerate() {
        for (n, x, w) in [
            ("act", e.active, 1),
            ("right", e.right, 1),
            ("rs", e.rs, yw),
            ("re", e.re, yw),
            ("d", e.d, dw_edge),
            ("g", e.g, gw),
            ("rem", e.rem, dw_edge),
            ("qs", e.qs, gw),
            ("rs256", e.rs256, dw_edge),
        ] {
            v.push(f(&format!("e{j}_{n}"), x, w));
        }
    }
    v
}

/// The queue entry's width.
pub(super) fn entry_bits(hw: &Hw, s: &Schedule) -> u32 {
    fields(hw, s).iter().map(|f| f.w).sum()
}

/// The set-up result queue module of this configuration.
pub(super) fn result_queue(hw: &Hw, names: &Names) -> Module {
    let s = hw.engine().expect("the engine form");
    queue_module(names, entry_bits(hw, &s), super::QUEUE_DEPTH)
}

fn plan_text(s: &Schedule) -> String {
    let p = &s.plan;
    let mul = match p.mul {
        MulUnit::Tile { bits } => format!("{} multiplier tiles of {} x {} signed ({bits}-bit chunks)", p.mults, bits + 1, bits + 1),
        MulUnit::ShiftAdd { bits } => format!("{} shift-add multipliers of {bits} bit(s) a clock", p.mults),
    };
    let form = match p.div_form {
        DivForm::ShiftRemainder => "remainder shifted past the divisor",
        DivForm::ShiftDivisor => "divisor shifted",
    };
    format!(
        "{mul}, {} restoring dividers of {} quotient bit(s) a clock ({form}), {}, division by 2A {}",
        p.dividers,
        p.div_bits,
        match p.shifters {
            0 => "each shift by a value its own logic".to_string(),
            k => format!("{k} shared barrel shifter(s)"),
        },
        if p.reciprocal { "by the reciprocal Rn" } else { "by restoring division" }
    )
}

/// `tri_fe_engine`: the pipelined engine, or the sequential one where the form has it.
pub(super) fn module(hw: &Hw, names: &Names) -> Module {
    if let Some(q) = hw.sequential() {
        return seq::module(hw, &q, &names.fe_engine).module;
    }
    let s = hw.engine().expect("the engine form");
    assert_eq!(s.plan.div_form, DivForm::ShiftRemainder, "the RTL's dividers shift the remainder");
    s.verify().unwrap_or_else(|e| panic!("golden's schedule: {e}"));
    let epochs = s.verify_binding().unwrap_or_else(|e| panic!("golden's binding: {e}"));
    let wd = hw.fe.widths();
    let iw = hw.fe.cfg.iw();
    let seq = Seq { ii: s.ii, epochs };
    let v = Values::new(&s);
    let fields = fields(hw, &s);
    let res_w: u32 = fields.iter().map(|f| f.w).sum();
    let regs: u32 = (0..s.slots.len()).filter(|&o| v.root[o] == Some(o)).map(|o| v.copies[o] * v.op(o).w).sum();
    let mut header = vec![
        format!("{} — the shared set-up engine of {} (issue 27; docs/design.md).", names.fe_engine, names.frontend),
        "Generated by segshade hdl-gen from golden's schedule (golden::frontend::engine); do not edit.".into(),
        String::new(),
        format!("Plan {}: {}.", hw.fe.setup.name(), plan_text(&s)),
        format!(
            "II = {} clocks a triangle (sustained), latency {} clocks from the entry to the result; the binding repeats every {epochs} triangle(s).",
            s.ii, s.latency
        ),
        format!(
            "{} operations: {} products ({} tile passes), {} divisions; {} value register bits with their copies; a result of {res_w} bits.",
            s.prog.ops.len(),
            s.slots.iter().filter(|x| x.class == Class::Mul).count(),
            s.cost.mul_passes,
            s.slots.iter().filter(|x| x.class == Class::Div).count(),
            regs
        ),
        String::new(),
        "Structure: the sequencer (phase ring ph, epoch ring ep, valid bits vld, the vertex registers); every value of the".into(),
        "program as v<op>_<name>_<copy> (a register, or a wire for wiring), copy k the triangle k periods older, shifted".into(),
        "when the next triangle's value is written; each logic operation's result t<op>; per unit the operand multiplexers".into(),
        "(mu_* for the multipliers, du_* for the dividers, sh<k>_a/_n for the shifters), selected by phase and epoch; the units as generate loops".into(),
        "(g_mul, g_div); the result at the latency (res). en low freezes every register of the engine.".into(),
        String::new(),
        "The units' operations (clock from the entry, unit, operation, clocks busy), golden's listing:".into(),
    ];
    header.extend(s.listing().lines().map(|l| format!("  {l}")));
    let ports = ports(hw, res_w);
    let mut body = Vec::new();
    sequencer::emit(&seq, &wd, iw, s.latency, &mut body);
    // Values: many copies and wiring nets are read only in part or by some readers.
    body.push(comment("verilator lint_off UNUSEDSIGNAL"));
    body.push(comment("Values: each root's register copies."));
    let roots: Vec<usize> = (0..s.slots.len()).filter(|&o| v.root[o] == Some(o)).collect();
    for &o in &roots {
        for k in 0..v.copies[o] {
            body.push(reg(&format!("{}_{k}", v.name(o)), v.op(o).w));
        }
    }
    body.push(comment("Wiring: a value rewired from its operand, per copy."));
    for o in 0..s.slots.len() {
        if v.root[o].is_some_and(|r| r != o) {
            for k in 0..v.copies_of(o) {
                body.push(crate::verilog::wire(&format!("{}_{k}", v.name(o)), v.op(o).w, v.wiring(o, k)));
            }
        }
    }
    body.push(comment("Logic: each operation's result from its operands' copies at its clock."));
    let mut loads: Vec<Vec<Stmt>> = vec![Vec::new(); s.ii as usize];
    for &o in &roots {
        let op = v.op(o);
        if s.slots[o].class == Class::Logic {
            let (e, w) = v.logic(o);
            let t = format!("t{o}");
            body.push(crate::verilog::wire(&t, w, e));
            let val = if w == op.w { t } else { format!("{t}[{}:0]", op.w - 1) };
            loads[(s.slots[o].start % s.ii) as usize].extend(shift(&v, o, val));
        }
        if let Kind::In(k) = op.kind {
            let src = ["vx0", "vx1", "vx2", "vy0", "vy1", "vy2", "vi0", "vi1", "vi2"][k as usize];
            loads[(s.ii - 1) as usize].extend(shift(&v, o, src.to_string()));
        }
    }
    body.push(comment("verilator lint_on UNUSEDSIGNAL"));
    body.push(Item::Blank);
    let mut caps = units::multipliers(&v, &seq, &mut body);
    caps.extend(units::dividers(&v, &seq, &mut body));
    caps.extend(units::shifters(&v, &seq, &mut body));
    for c in caps {
        let w = v.op(c.op).w;
        // The register loads at its phase; the epoch only picks the unit.
        let items: Vec<(String, String)> = c.from.iter().map(|(es, f)| (seq.when_any(c.t, es), f.clone())).collect();
        let val = if items.len() == 1 { items[0].1.clone() } else { and_or(&items, w) };
        loads[(c.t % s.ii) as usize].extend(shift(&v, c.op, val));
    }
    body.push(comment("Every value register's load at its phase (the copies shift with it)."));
    let phases: Vec<Stmt> =
        loads.into_iter().enumerate().filter(|(_, l)| !l.is_empty()).map(|(p, l)| Stmt::If(seq.phase(p as u32), l, vec![])).collect();
    body.push(Item::Always(vec![Stmt::If("en".into(), phases, vec![])]));
    body.push(Item::Blank);
    body.push(comment(format!("The result, at clock {} of its triangle.", s.latency)));
    let at = |x: V, w: u32| v.at(x, s.latency).ext(w);
    body.push(Item::Assign("res_guard".into(), at(s.prog.out.guard_ok, 1)));
    body.push(Item::Assign("res_cull".into(), at(s.prog.out.cull, 1)));
    let parts: Vec<String> = fields.iter().rev().map(|f| at(f.v, f.w)).collect();
    body.push(Item::Assign("res".into(), format!("{{{}}}", parts.join(", "))));
    Module { name: names.fe_engine.clone(), header, params: vec![], ports, body }
}

/// The engine's ports, whichever form (the pipelined engine and the sequential one share them
/// and their contract).
pub(super) fn ports(hw: &Hw, res_w: u32) -> Vec<Port> {
    let wd = hw.fe.widths();
    let iw = hw.fe.cfg.iw();
    let mut p = vec![
        Port::input("clk", 1, "", "rising edge"),
        Port::input("rst", 1, "", "synchronous, active high: drops the triangles in flight"),
        Port::input("en", 1, "", "low: the whole engine holds (the queue cannot take the result due)"),
        Port::input("in_valid", 1, "", "triangle valid"),
        Port::output("in_ready", 1, "", "triangle accepted when in_valid && in_ready"),
    ];
    for k in 0..3 {
        p.push(Port::input(&format!("in_x{k}"), wd.cx, "", &format!("vertex {k} x")).signed());
        p.push(Port::input(&format!("in_y{k}"), wd.cy, "", &format!("vertex {k} y")).signed());
        p.push(Port::input(&format!("in_i{k}"), iw, "", &format!("vertex {k} intensity")));
    }
    p.push(Port::output("res_v", 1, "", "a triangle's result is due this clock"));
    p.push(Port::output("res_guard", 1, "", "its vertices are inside the guard band"));
    p.push(Port::output("res_cull", 1, "", "it covers no pixel"));
    p.push(Port::output("res", res_w, "", "its set-up result, the walker's fields (tri_frontend unpacks them)"));
    p
}

/// Loading value `o`'s copy 0 with `val`, its older copies shifting one on.
fn shift(v: &Values, o: usize, val: String) -> Vec<Stmt> {
    let n = v.name(o);
    let mut st: Vec<Stmt> = (1..v.copies[o]).rev().map(|k| set(format!("{n}_{k}"), format!("{n}_{}", k - 1))).collect();
    st.push(set(format!("{n}_0"), val));
    st
}

fn and_or(items: &[(String, String)], w: u32) -> String {
    items
        .iter()
        .map(|(c, x)| if w == 1 { format!("({c} && {x})") } else { format!("({{{w}{{{c}}}}} & {x})") })
        .collect::<Vec<_>>()
        .join(" | ")
}

/// `tri_frontend`'s set-up in the engine form: the engine, its result queue, the head's fields
/// as the walker reads them (`s_*`, `r_di`, `r_rn`, the edges' buses), the freeze and `err`.
pub(super) fn setup(hw: &Hw, names: &Names, body: &mut Vec<Item>) {
    let s = hw.engine().expect("the engine form");
    let fields = fields(hw, &s);
    let res_w: u32 = fields.iter().map(|f| f.w).sum();
    let (ii, latency, _) = hw.engine_timing().expect("the engine form");
    body.push(comment(format!(
        "Set-up: the {} engine ({}, II = {ii} clocks a triangle, latency {latency}), then its result queue ({}, {} entries).",
        if hw.sequential().is_some() { "sequential" } else { "shared" },
        names.fe_engine,
        names.fe_queue,
        super::QUEUE_DEPTH
    )));
    body.push(comment(
        "A result due while the queue is full freezes the engine (en); a guard-band drop pulses err; a culled triangle is dropped.",
    ));
    for (n, w) in
        [("en", 1), ("res_v", 1), ("res_guard", 1), ("res_cull", 1), ("res", res_w), ("q_head", res_w), ("q_ne", 1), ("q_full", 1)]
    {
        body.push(crate::verilog::net(n, w));
    }
    body.push(crate::verilog::net("take", 1));
    body.push(crate::verilog::wire("q_push", 1, "res_v && res_guard && !res_cull"));
    body.push(Item::Assign("en".into(), "!(q_push && q_full)".into()));
    body.push(crate::verilog::wire("q_in", 1, "q_push && !q_full"));
    let mut conns: Vec<(String, String)> =
        ["clk", "rst", "en", "in_valid", "in_ready"].iter().map(|p| (p.to_string(), p.to_string())).collect();
    for k in 0..3 {
        for p in ["in_x", "in_y", "in_i"] {
            conns.push((format!("{p}{k}"), format!("{p}{k}")));
        }
    }
    conns.extend(["res_v", "res_guard", "res_cull", "res"].map(|p| (p.to_string(), p.to_string())));
    body.push(Item::Instance { module: names.fe_engine.clone(), name: "u_engine".into(), params: vec![], conns });
    let qc = [
        ("clk", "clk"),
        ("rst", "rst"),
        ("push", "q_in"),
        ("din", "res"),
        ("pop", "take"),
        ("dout", "q_head"),
        ("nonempty", "q_ne"),
        ("full", "q_full"),
    ];
    body.push(Item::Instance {
        module: names.fe_queue.clone(),
        name: "u_queue".into(),
        params: vec![("W".into(), res_w.to_string()), ("DEPTH".into(), super::QUEUE_DEPTH.to_string())],
        conns: qc.map(|(a, b)| (a.to_string(), b.to_string())).to_vec(),
    });
    body.push(Item::Always(vec![Stmt::If("rst".into(), vec![set("err", "1'b0")], vec![set("err", "res_v && !res_guard")])]));
    body.push(comment("The queue head's fields: the set-up result the walker loads."));
    let mut lo = 0;
    let mut lanes: std::collections::BTreeMap<String, Vec<String>> = Default::default();
    for f in &fields {
        let slice = if f.w == 1 { format!("q_head[{lo}]") } else { format!("q_head[{}:{lo}]", lo + f.w - 1) };
        lo += f.w;
        match f.name.split_once('_') {
            Some((e, port)) if e.starts_with('e') && e.len() == 2 => lanes.entry(port.to_string()).or_default().push(slice),
            _ => {
                let name = match f.name.as_str() {
                    "di" => "r_di".to_string(),
                    "rn" => "r_rn".to_string(),
                    n => format!("s_{n}"),
                };
                body.push(crate::verilog::wire(&name, f.w, slice));
            }
        }
    }
    for (port, bus, w) in super::edge::input_buses(hw).inputs {
        let l = &lanes[port];
        body.push(crate::verilog::wire(bus, 3 * w, format!("{{{}, {}, {}}}", l[2], l[1], l[0])));
    }
    body.push(Item::Blank);
}
