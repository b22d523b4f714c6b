//! The sequential set-up engine (issue 27, the iCE40 plans): golden's microprogram
//! ([`golden::frontend::engine::sequential::SeqSchedule`]) printed as a machine: a microcode
//! ROM of one word a clock, a register file of two block-RAM copies (a read port each, one
//! write port), a flag file, one ALU, the plan's multipliers (the HX8K's shift-add unit, the
//! UP5K's SB_MAC16 tiles: [`tile`]) and restoring divider, and the result fields captured as
//! their values are written. Its ports and its contract are
//! `tri_fe_engine`'s: a triangle (or a bubble) enters every `clocks` clocks, its result is due
//! `clocks` clocks later, `en` low freezes every register.
//!
//! `--fe-setup ice40-hx8k|ice40-up5k` (and their `--target`s) take it in place of the pipelined
//! engine; co-simulated in `verilator-harness/tests/frontend.rs` (`sequential_engine_*`, slow
//! tier). docs/design.md, *A sequential engine for the iCE40 HX8K*.

mod alu;
mod cx;
mod datapath;
mod tile;

use super::result::{fields, ports, Field};
use super::units::bits_for;
use crate::frontend::hw::Hw;
use crate::verilog::{comment, reg, set, wire, Item, Module, Param, Port, Stmt};
use cx::{
    Cx, FN_ADD, FN_AND, FN_EQ, FN_LT, FN_LZC, FN_NOT, FN_OR, FN_PASS, FN_SEL, FN_SHL, FN_SHLV, FN_SHR, FN_SUB, SRC_ALU, SRC_DIVQ, SRC_DIVR,
    SRC_IN, SRC_MUL, SRC_MUL1,
};
use datapath::{divider, shift_add, write_bus};
use golden::frontend::engine::schedule::Class;
use golden::frontend::engine::sequential::{Exec, Loc, SeqSchedule, READ};
use golden::frontend::engine::{Kind, MulUnit, V};

/// The microword's fields, least significant first: name and width.
struct Layout {
    fields: Vec<(&'static str, u32)>,
}

impl Layout {
    /// `tiles`: the tile multipliers' fields ([`tile::fields`]) in place of the shift-add unit's.
    fn new(aw: u32, fb: u32, sw: u32, cb: u32, wb: u32, tiles: Option<Vec<(&'static str, u32)>>) -> Layout {
        let mut fields = vec![
            ("ra", aw),
            ("rb", aw),
            ("fn", 4),
            ("fl0", 1),
            ("fl1", 1),
            ("fl2", 1),
            ("fa0", fb),
            ("fa1", fb),
            ("fa2", fb),
            ("imm", sw),
            ("mld", 1),
            ("mn", sw),
            ("mbs", 1),
            ("dld", 1),
            ("dqb", sw),
            ("we", 1),
            ("wa", aw),
            ("fwe", 1),
            ("fwa", fb),
            ("src", 4),
            ("wc", wb),
            ("wsg", 1),
            ("cap", cb),
        ];
        if let Some(t) = tiles {
            let at = fields.iter().position(|f| f.0 == "mld").expect("the multiplier's fields");
            fields.splice(at..at + 3, t);
        }
        Layout { fields }
    }
    fn width(&self) -> u32 {
        self.fields.iter().map(|f| f.1).sum()
    }
    fn at(&self, name: &str) -> (u32, u32) {
        let mut lo = 0;
        for &(n, w) in &self.fields {
            if n == name {
                return (lo, w);
            }
            lo += w;
        }
        panic!("no field {name}")
    }
}

/// One microword under construction: each field set at most once.
#[derive(Clone, Default)]
struct Word(std::collections::BTreeMap<&'static str, u64>);

impl Word {
    fn set(&mut self, k: &'static str, v: u64, clock: u32) {
        if let Some(old) = self.0.insert(k, v) {
            assert_eq!(old, v, "microword field {k} set twice at clock {clock}");
        }
    }
    fn hex(&self, l: &Layout) -> String {
        let mut v: u128 = 0;
        for (k, x) in &self.0 {
            let (lo, w) = l.at(k);
            assert!(*x < 1u64 << w.min(63), "field {k} = {x} wider than {w}");
            v |= (*x as u128) << lo;
        }
        let digits = l.width().div_ceil(4) as usize;
        format!("{v:0digits$x}")
    }
}

/// The block: golden's microprogram and constants are its tables (case statements read into a
/// register, which synthesis maps to block RAM), so the block needs no image file.
pub struct SeqEngine {
    pub module: Module,
}

/// The microprogram as [`microprogram`] lays it out.
struct Micro {
    l: Layout,
    micro: Vec<String>,
    groups: Vec<V>,
    widths: Vec<u32>,
}

/// `name`: the sequential engine of `hw` (an iCE40 form), with `s` golden's microprogram.
pub fn module(hw: &Hw, s: &SeqSchedule, name: &str) -> SeqEngine {
    s.verify().unwrap_or_else(|e| panic!("golden's microprogram: {e}"));
    assert!(
        matches!(s.plan.units.mul, MulUnit::ShiftAdd { bits: 1 } | MulUnit::Tile { .. }),
        "the RTL's multiplier is shift-add a bit a clock, or tiles"
    );
    assert_eq!(s.plan.units.div_bits, 1, "the RTL's divider takes a bit a clock");
    let pipe = hw.engine().expect("an engine form");
    let fields: Vec<Field> = fields(hw, &pipe);
    assert_eq!(pipe.prog.out, s.prog.out, "one program");
    let w = s.cost.ram_width;
    let (words, flags) = s.words();
    let c = s.clocks;
    let cx = Cx { hw, s, w, sw: bits_for(w), cw: bits_for(c - 1), aw: bits_for(words - 1), c };
    let Micro { l, micro, groups, widths } = microprogram(&cx, &fields);
    let nconst = s.preload.len() as u32;
    assert!(s.preload.iter().enumerate().all(|(k, p)| p.0 == k as u32), "the constants at the first addresses");
    assert!(nconst < c, "the constants are written within the first period");
    let mask = if w >= 128 { u128::MAX } else { (1u128 << w) - 1 };
    let consts: Vec<String> = s.preload.iter().map(|&(_, v)| format!("{w}'h{:x}", (v as u128) & mask)).collect();

    let res_w: u32 = fields.iter().map(|f| f.w).sum();
    let mut ports = ports(hw, res_w);
    ports.push(Port::output("res_we", fields.len() as u32, "", "per field of res: write it into the queue's tail this clock"));
    ports.push(Port::output("res_wr", 1, "", "a field of res is due this clock (whether or not en)"));
    let walk_ram = hw.walk_ram().then(|| crate::frontend::span_seq::walk_ram::bus_width(hw));
    if let Some(bw) = walk_ram {
        assert!(bw <= w, "the walk's constants are narrower than the word");
        ports.push(Port::output("res_bus", bw, "", "the write bus: the walk's constants in block RAM are written from it at res_we"));
    }
    let params: Vec<Param> = Vec::new();
    let header = vec![
        format!("{name} — the sequential set-up engine (issue 27; docs/design.md): golden's microprogram on one ALU."),
        "Generated by segshade hdl-gen from golden::frontend::engine::sequential; do not edit.".into(),
        String::new(),
        format!(
            "{c} clocks a triangle; register file {words} x {w} bits (two copies, a read port each), {flags} flags, microword {} bits.",
            l.width()
        ),
        "Microword fields (least significant first): ".to_string()
            + &l.fields.iter().map(|(n, w)| format!("{n}:{w}")).collect::<Vec<_>>().join(" "),
    ];

    let mut b: Vec<Item> = Vec::new();
    sequencer(&cx, &mut b);
    memories(&cx, &l, &micro, &consts, &mut b);
    alu::alu(&cx, &mut b);
    match tile::Tiles::new(s) {
        Some(t) => t.units(w, ("da", "db"), &mut b),
        None => shift_add(&cx, &mut b),
    }
    divider(&cx, &mut b);
    write_bus(&cx, &widths, &mut b);
    results(&cx, &fields, &groups, &mut b);
    if let Some(bw) = walk_ram {
        b.push(Item::Assign("res_bus".into(), format!("bus[{}:0]", bw - 1)));
    }
    SeqEngine { module: Module { name: name.into(), header, params, ports, body: b } }
}

/// The microprogram's words (one a clock), their layout, the capture groups (each output value
/// written once, every field of it loading then) and the widths values are written at.
fn microprogram(cx: &Cx, fields: &[Field]) -> Micro {
    let (s, w, sw, aw, c) = (cx.s, cx.w, cx.sw, cx.aw, cx.c);
    let ops = &s.prog.ops;
    let (_, flags) = s.words();
    let fb = bits_for(flags.max(1) - 1);
    // Capture groups: each output value written once, every field of it loads then.
    let out = &s.prog.out;
    let mut groups: Vec<V> = Vec::new();
    for v in fields.iter().map(|f| f.v).chain([out.guard_ok, out.cull]) {
        if !groups.contains(&v) && !matches!(ops[v.0 as usize].kind, Kind::Const(_)) {
            groups.push(v);
        }
    }
    let cb = bits_for(groups.len() as u32);
    // The widths values are written at: few, so the write's wrap reads a table, not a shifter.
    let mut widths: Vec<u32> = (0..ops.len()).filter(|&o| !matches!(s.slots[o].exec, Exec::Dead | Exec::Const)).map(|o| ops[o].w).collect();
    widths.sort();
    widths.dedup();
    let tiles = tile::Tiles::new(s);
    let l = Layout::new(aw, fb, sw, cb, bits_for(widths.len() as u32 - 1), tiles.as_ref().map(tile::Tiles::fields));
    let mut mw = vec![Word::default(); c as usize + 2];
    let addr = |v: V| match s.slots[v.0 as usize].loc {
        Loc::Ram(a) => a,
        l => panic!("{} is not in the register file: {l:?}", ops[v.0 as usize].name),
    };
    for (o, op) in ops.iter().enumerate() {
        let sl = s.slots[o];
        let t = sl.issue;
        // Operands: a flag from the flag file, else the port of its position (the first and
        // the third on port A, the second on B), so the ALU's operand registers need no choice
        // of port (the choice between two ports was a LUT level on all 66 bits of each).
        let mut args = op.kind.args();
        if let (Kind::Mul(a, b), None) = (op.kind, &tiles) {
            // The shift-add unit steps through its second operand: the narrower.
            if ops[a.0 as usize].w < ops[b.0 as usize].w {
                args = vec![b, a];
            }
        }
        let exec = sl.exec;
        if matches!(exec, Exec::Alu | Exec::Unit(..)) {
            for (j, a) in args.iter().enumerate() {
                let (fl, fa) = (["fl0", "fl1", "fl2"][j], ["fa0", "fa1", "fa2"][j]);
                match s.slots[a.0 as usize].loc {
                    Loc::Flag(k) => {
                        mw[t as usize + 1].set(fl, 1, t + 1);
                        mw[t as usize + 1].set(fa, k as u64, t + 1);
                    }
                    _ => {
                        let port = ["ra", "rb", "ra"][j];
                        assert!(!mw[t as usize].0.contains_key(port), "{}: its first and third operands both wide", op.name);
                        mw[t as usize].set(port, addr(*a) as u64, t);
                    }
                }
            }
            // A unit loads its operands load_lag clocks after they are on the read ports.
            let e = t + READ + if matches!(exec, Exec::Unit(..)) { s.plan.load_lag } else { 0 };
            let x = &mut mw[e as usize];
            match (exec, op.kind) {
                (Exec::Unit(Class::Mul, u), _) if tiles.is_some() => {
                    // The tiles hold their operands from the ports themselves (`tile`).
                    assert!(args.iter().all(|a| !matches!(s.slots[a.0 as usize].loc, Loc::Flag(_))), "{}: a flag on a tile", op.name);
                    for (t, k, v) in tiles.as_ref().expect("tiles").passes(o, u) {
                        mw[t as usize].set(k, v, t);
                    }
                }
                (Exec::Unit(Class::Mul, _), _) => {
                    let nb = ops[args[1].0 as usize].w;
                    x.set("mld", 1, e);
                    x.set("mn", nb as u64, e);
                    x.set("mbs", ops[args[1].0 as usize].signed as u64, e);
                }
                (Exec::Unit(Class::Div, _), Kind::Div { qb, .. }) => {
                    x.set("dld", 1, e);
                    x.set("dqb", qb as u64, e);
                }
                (Exec::Alu, k) => {
                    let (f, imm) = match k {
                        Kind::Wire(_) => (FN_PASS, 0),
                        Kind::Add(..) => (FN_ADD, 0),
                        Kind::Sub(..) => (FN_SUB, 0),
                        Kind::Lt(..) => (FN_LT, 0),
                        Kind::Eq(..) => (FN_EQ, 0),
                        Kind::And(..) => (FN_AND, 0),
                        Kind::Or(..) => (FN_OR, 0),
                        Kind::Not(_) => (FN_NOT, 0),
                        Kind::Sel(..) => (FN_SEL, 0),
                        Kind::Lzc(_, n) => (FN_LZC, n),
                        Kind::Shl(_, n) => (FN_SHL, n),
                        Kind::Shr(_, n) => (FN_SHR, n),
                        Kind::ShlBy(..) => (FN_SHLV, 0),
                        k => panic!("{k:?} on the ALU"),
                    };
                    assert!(imm <= w, "shift or count {imm} beyond the word");
                    x.set("fn", f, e);
                    x.set("imm", imm as u64, e);
                    let lat = s.plan.alu_lat + s.plan.bus_lat;
                    assert_eq!(sl.write, t + READ + lat, "the ALU's result is written alu_lat + bus_lat clocks after its operands");
                }
                other => panic!("{other:?} issued"),
            }
        }
        if matches!(exec, Exec::Dead | Exec::Const) {
            continue;
        }
        let src = match (exec, op.kind) {
            (Exec::Alu, _) => SRC_ALU,
            (Exec::Unit(Class::Mul, 1), _) => SRC_MUL1,
            (Exec::Unit(Class::Mul, _), _) => SRC_MUL,
            (Exec::Unit(Class::Div, _), _) => SRC_DIVQ,
            (Exec::Rem, _) => SRC_DIVR,
            (Exec::Input, Kind::In(k)) => SRC_IN + k as u64,
            other => panic!("{other:?} writes"),
        };
        let wt = sl.write;
        // A registered bus selects its source two clocks before the write ([`write_bus`]).
        let (st, wrap) = (wt - 2 * s.plan.bus_lat, wt - s.plan.bus_lat);
        mw[st as usize].set("src", src, st);
        mw[wrap as usize].set("wc", widths.iter().position(|&k| k == op.w).unwrap() as u64, wrap);
        mw[wrap as usize].set("wsg", op.signed as u64, wrap);
        let x = &mut mw[wt as usize];
        match sl.loc {
            Loc::Ram(a) => {
                x.set("we", 1, wt);
                x.set("wa", a as u64, wt);
            }
            Loc::Flag(a) => {
                x.set("fwe", 1, wt);
                x.set("fwa", a as u64, wt);
            }
            Loc::None => panic!("{} written nowhere", op.name),
        }
        if let Some(g) = groups.iter().position(|&v| v.0 as usize == o) {
            x.set("cap", g as u64 + 1, wt);
        }
    }
    assert!(mw[c as usize..].iter().all(|x| x.0.is_empty()), "the microprogram ends within its clocks");
    // No operand is read at the address written in the same clock: the register file's block
    // RAM then needs no collision logic (`no_rw_check`, [`memories`]; about 130 logic cells).
    for (t, x) in mw.iter().enumerate() {
        if let Some(wa) = x.0.get("wa") {
            assert!(["ra", "rb"].iter().all(|p| x.0.get(p) != Some(wa)), "clock {t} reads the register it writes");
        }
    }
    let mwn = l.width();
    assert!(mwn <= 128, "a microword of {mwn} bits");
    let micro: Vec<String> = mw[..c as usize].iter().map(|x| format!("{mwn}'h{}", x.hex(&l))).collect();
    Micro { l, micro, groups, widths }
}

/// The sequencer: `pc`, the valid bits, boot. The engine keeps no copy of a triangle: the
/// stream contract (SPEC §3) holds a triangle offered on `in_valid` and its inputs unchanged
/// until it is taken, so a triangle on the port at a period's last clock enters the next period,
/// whose microprogram reads its inputs from the ports themselves, and is taken (`in_ready`) at
/// the clock of their last read ([`SeqSchedule::inputs_read_by`], early in the period). A
/// vertex register was 183 flip-flops alone at 640x480, on devices short of cells.
fn sequencer(cx: &Cx, b: &mut Vec<Item>) {
    let (cw, c) = (cx.cw, cx.c);
    let held = cx.s.inputs_read_by();
    b.push(comment("Sequencer: the clock of the triangle (pc), a valid bit per period in flight, boot (the first period"));
    b.push(comment(format!("after reset). The entered triangle stays on the ports until it is taken at clock {held}, its inputs' last")));
    b.push(comment("read; one gone from the port by then (against the stream contract) is dropped, a bubble, so no result"));
    b.push(comment("leaves for a triangle not taken."));
    b.push(reg("pc", cw));
    b.push(reg("vld", 2));
    b.push(reg("boot", 1));
    let last = format!("pc == {cw}'d{}", c - 1);
    b.push(wire("pc_n", cw, format!("({last}) ? {cw}'d0 : pc + {cw}'d1")));
    b.push(wire("at_read", 1, format!("pc == {cw}'d{held} && vld[0]")));
    b.push(Item::Assign("in_ready".into(), "en && at_read".into()));
    b.push(Item::Assign("res_v".into(), format!("pc == {cw}'d0 && vld[1]")));
    b.push(Item::Always(vec![Stmt::If(
        "rst".into(),
        vec![set("vld", "2'd0"), set("pc", format!("{cw}'d0")), set("boot", "1'b1")],
        vec![Stmt::If(
            "en".into(),
            vec![
                set("pc", "pc_n"),
                Stmt::If(
                    last,
                    vec![set("vld", "{vld[0], in_valid}"), set("boot", "1'b0")],
                    vec![Stmt::If("at_read && !in_valid".into(), vec![set("vld[0]", "1'b0")], vec![])],
                ),
            ],
            vec![],
        )],
    )]));
    b.push(Item::Blank);
}

/// The microprogram's and the constants' tables, the microword's fields, the register file (never
/// read where it is written that clock: [`microprogram`]) and the flag file.
fn memories(cx: &Cx, l: &Layout, micro: &[String], consts: &[String], b: &mut Vec<Item>) {
    let (w, cw, aw) = (cx.w, cx.cw, cx.aw);
    let (words, flags) = cx.s.words();
    let nconst = consts.len();
    let mwn = l.width();
    b.push(comment("The microprogram: word t is clock t's (reset reads word 0); beside it the constants, written into the"));
    b.push(comment("register file in the first period after reset (boot), which is always a bubble's."));
    b.push(wire("mpc", cw, format!("rst ? {cw}'d0 : pc_n")));
    b.push(reg("mw", mwn));
    b.push(reg("cq", w));
    let arms = |vals: &[String], lhs: &str| -> Vec<(String, Vec<Stmt>)> {
        vals.iter().enumerate().map(|(k, v)| (format!("{cw}'d{k}"), vec![set(lhs, v.clone())])).collect()
    };
    b.push(Item::Always(vec![Stmt::If(
        "rst || en".into(),
        vec![
            Stmt::Case { sel: "mpc".into(), arms: arms(micro, "mw"), default: vec![set("mw", format!("{mwn}'d0"))] },
            Stmt::Case { sel: "mpc".into(), arms: arms(consts, "cq"), default: vec![set("cq", format!("{w}'d0"))] },
        ],
        vec![],
    )]));
    for &(n, fw) in &l.fields {
        let (lo, _) = l.at(n);
        b.push(wire(&format!("u_{n}"), fw, if fw == 1 { format!("mw[{lo}]") } else { format!("mw[{}:{lo}]", lo + fw - 1) }));
    }
    b.push(Item::Blank);
    b.push(comment("The register file: two copies written together, a registered read port each; the flag file."));
    b.push(Item::Memory { name: "rfa".into(), width: w, depth: words, no_rw_check: true });
    b.push(Item::Memory { name: "rfb".into(), width: w, depth: words, no_rw_check: true });
    b.push(reg("da", w));
    b.push(reg("db", w));
    b.push(reg("fl", flags.max(1)));
    b.push(crate::verilog::net("bus", w));
    b.push(Item::Always(vec![Stmt::If(
        "en".into(),
        vec![
            set("da", "rfa[u_ra]"),
            set("db", "rfb[u_rb]"),
            Stmt::If(
                "boot".into(),
                vec![Stmt::If(
                    format!("pc < {cw}'d{nconst}"),
                    vec![set(format!("rfa[pc[{}:0]]", aw - 1), "cq"), set(format!("rfb[pc[{}:0]]", aw - 1), "cq")],
                    vec![],
                )],
                vec![Stmt::If("u_we".into(), vec![set("rfa[u_wa]", "bus"), set("rfb[u_wa]", "bus")], vec![])],
            ),
            Stmt::If("u_fwe".into(), vec![set("fl[u_fwa]", "bus[0]")], vec![]),
        ],
        vec![],
    )]));
    b.push(Item::Blank);
}

/// The result: each field written into the queue's tail entry as its value is written
/// (`res_we`, a bit a field, for a valid period's triangle and not while frozen; `res_wr`: a
/// field is due this clock), so the engine keeps no copy of it; the guard-band check and the
/// cull, which the front-end reads as the result is pushed, loaded here.
fn results(cx: &Cx, fields: &[Field], groups: &[V], b: &mut Vec<Item>) {
    let (ops, out, s) = (&cx.s.prog.ops, &cx.s.prog.out, cx.s);
    let cb = bits_for(groups.len() as u32);
    b.push(comment("The result: each field written into the queue's tail as its value is written (res_we), the guard-band"));
    b.push(comment("check and the cull loaded here. The tail becomes an entry at res_v, the next period's clock 0, which"));
    b.push(comment("writes no field (cap_ok: gated by the clock, not only by the microprogram, so that the proof's induction,"));
    b.push(comment("whose microword register is free, sees it too)."));
    b.push(wire("cap_ok", 1, format!("en && vld[0] && pc != {}'d0", cx.cw)));
    let cap = |v: V| format!("u_cap == {cb}'d{}", groups.iter().position(|&x| x == v).unwrap() + 1);
    // The fields' groups come first in `groups` (then the checks'): res_wr is a range of them.
    let nf = groups.iter().take_while(|v| fields.iter().any(|f| f.v == **v)).count();
    assert!(nf > 0 && groups[nf..].iter().all(|v| fields.iter().all(|f| f.v != *v)), "the fields' groups first");
    for &v in &groups[..nf] {
        assert!(s.slots[v.0 as usize].write > 0, "{}: a field written at clock 0, the push's", ops[v.0 as usize].name);
    }
    let first = fields.iter().find(|f| !matches!(ops[f.v.0 as usize].kind, Kind::Const(_))).expect("a computed field").v;
    let mut parts = Vec::new();
    let mut we = Vec::new();
    for f in fields {
        match ops[f.v.0 as usize].kind {
            // A constant rides with the first computed field's write.
            Kind::Const(k) => {
                parts.push(format!("{}'d{}", f.w, k >> f.lo));
                we.push(format!("cap_ok && {}", cap(first)));
            }
            _ => {
                // A field's bits from `lo` up (the edges' D, rem, rs256 behind the row stages).
                parts.push(if f.w == 1 { format!("bus[{}]", f.lo) } else { format!("bus[{}:{}]", f.lo + f.w - 1, f.lo) });
                we.push(format!("cap_ok && {}", cap(f.v)));
            }
        }
    }
    let mut loads = Vec::new();
    for (v, n) in [(out.guard_ok, "c_guard"), (out.cull, "c_cull")] {
        b.push(reg(n, 1));
        loads.push(Stmt::If(cap(v), vec![set(n, "bus[0]")], vec![]));
    }
    b.push(Item::Always(vec![Stmt::If("en".into(), loads, vec![])]));
    parts.reverse();
    we.reverse();
    b.push(Item::Assign("res".into(), format!("{{{}}}", parts.join(", "))));
    b.push(Item::Assign("res_we".into(), format!("{{{}}}", we.join(",\n    "))));
    b.push(Item::Assign("res_wr".into(), format!("vld[0] && u_cap != {cb}'d0 && u_cap <= {cb}'d{nf}")));
    b.push(Item::Assign("res_guard".into(), "c_guard".into()));
    b.push(Item::Assign("res_cull".into(), "c_cull".into()));
}
