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
mod tile;

use super::result::{fields, ports, Field};
use super::units::bits_for;
use crate::frontend::hw::Hw;
use crate::verilog::{comment, reg, set, sreg, wire, Item, Module, Param, Port, Stmt};
use golden::frontend::engine::schedule::Class;
use golden::frontend::engine::sequential::{Exec, Loc, SeqSchedule, READ};
use golden::frontend::engine::{Kind, MulUnit, V};

/// The ALU's functions (the microword's `fn` field).
const FN_PASS: u64 = 0;
const FN_ADD: u64 = 1;
const FN_SUB: u64 = 2;
const FN_LT: u64 = 3;
const FN_EQ: u64 = 4;
const FN_AND: u64 = 5;
const FN_OR: u64 = 6;
const FN_NOT: u64 = 7;
const FN_SEL: u64 = 8;
const FN_LZC: u64 = 9;
const FN_SHL: u64 = 10;
const FN_SHR: u64 = 11;
const FN_SHLV: u64 = 12;

/// The write bus's sources (the microword's `src` field); an input `k` is `SRC_IN + k`.
const SRC_ALU: u64 = 0;
const SRC_MUL: u64 = 1;
const SRC_DIVQ: u64 = 2;
const SRC_DIVR: u64 = 3;
const SRC_IN: u64 = 4;
/// The second multiplier's product (the UP5K's two tiles; after the nine inputs).
const SRC_MUL1: u64 = 13;

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
            ("pb0", 1),
            ("pb1", 1),
            ("pb2", 1),
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

/// What every part of the block reads: golden's microprogram and the block's widths (the
/// register file's word, a shift amount, `pc`, an address) and clocks a triangle.
struct Cx<'a> {
    hw: &'a Hw,
    s: &'a SeqSchedule,
    w: u32,
    sw: u32,
    cw: u32,
    aw: u32,
    c: u32,
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
        Some(t) => t.units(w, operands(&cx), &mut b),
        None => shift_add(&cx, &mut b),
    }
    divider(&cx, &mut b);
    write_bus(&cx, &widths, &mut b);
    results(&cx, &fields, &groups, &mut b);
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
        // Operands: the wide ones on ports A then B, the flags from the flag file.
        let mut args = op.kind.args();
        if let (Kind::Mul(a, b), None) = (op.kind, &tiles) {
            // The shift-add unit steps through its second operand: the narrower.
            if ops[a.0 as usize].w < ops[b.0 as usize].w {
                args = vec![b, a];
            }
        }
        let exec = sl.exec;
        if matches!(exec, Exec::Alu | Exec::Unit(..)) {
            let mut port = 0;
            for (j, a) in args.iter().enumerate() {
                let (fl, pb, fa) = (["fl0", "fl1", "fl2"][j], ["pb0", "pb1", "pb2"][j], ["fa0", "fa1", "fa2"][j]);
                match s.slots[a.0 as usize].loc {
                    Loc::Flag(k) => {
                        mw[t as usize + 1].set(fl, 1, t + 1);
                        mw[t as usize + 1].set(fa, k as u64, t + 1);
                    }
                    _ => {
                        mw[t as usize].set(["ra", "rb"][port], addr(*a) as u64, t);
                        mw[t as usize + 1].set(pb, port as u64, t + 1);
                        port += 1;
                    }
                }
            }
            // A unit loads its operands load_lag clocks after they are on the read ports.
            let e = t + READ + if matches!(exec, Exec::Unit(..)) { s.plan.load_lag } else { 0 };
            let x = &mut mw[e as usize];
            match (exec, op.kind) {
                (Exec::Unit(Class::Mul, u), _) if tiles.is_some() => {
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
    let mwn = l.width();
    assert!(mwn <= 128, "a microword of {mwn} bits");
    let micro: Vec<String> = mw[..c as usize].iter().map(|x| format!("{mwn}'h{}", x.hex(&l))).collect();
    Micro { l, micro, groups, widths }
}

/// The sequencer: `pc`, the vertex register, the entered triangle's inputs, the valid bits, boot.
fn sequencer(cx: &Cx, b: &mut Vec<Item>) {
    let (wd, iw, cw, c) = (cx.hw.fe.widths(), cx.hw.fe.cfg.iw(), cx.cw, cx.c);
    b.push(comment("Sequencer: the clock of the triangle (pc), the vertex register (v*) and the entered triangle's inputs"));
    b.push(comment("(n*), a valid bit per period in flight, boot (the first period after reset)."));
    b.push(reg("pc", cw));
    b.push(reg("vld", 2));
    b.push(reg("v_full", 1));
    b.push(reg("boot", 1));
    for k in 0..3 {
        for (v, wv, sg) in [("x", wd.cx, true), ("y", wd.cy, true), ("i", iw, false)] {
            for p in ["v", "n"] {
                b.push(if sg { sreg(&format!("{p}{v}{k}"), wv) } else { reg(&format!("{p}{v}{k}"), wv) });
            }
        }
    }
    let last = format!("pc == {cw}'d{}", c - 1);
    b.push(wire("enter", 1, format!("en && {last}")));
    b.push(wire("pc_n", cw, format!("({last}) ? {cw}'d0 : pc + {cw}'d1")));
    b.push(Item::Assign("in_ready".into(), "!v_full || enter".into()));
    b.push(Item::Assign("res_v".into(), format!("pc == {cw}'d0 && vld[1]")));
    let mut take = vec![set("v_full", "1'b1")];
    let mut entry = vec![set("vld", "{vld[0], v_full}")];
    for k in 0..3 {
        for (v, p) in [("x", "in_x"), ("y", "in_y"), ("i", "in_i")] {
            take.push(set(format!("v{v}{k}"), format!("{p}{k}")));
            entry.push(set(format!("n{v}{k}"), format!("v{v}{k}")));
        }
    }
    b.push(Item::Always(vec![Stmt::If(
        "rst".into(),
        vec![set("v_full", "1'b0"), set("vld", "2'd0"), set("pc", format!("{cw}'d0")), set("boot", "1'b1")],
        vec![
            Stmt::If("in_valid && in_ready".into(), take, vec![Stmt::If("enter".into(), vec![set("v_full", "1'b0")], vec![])]),
            Stmt::If(
                "en".into(),
                vec![set("pc", "pc_n"), Stmt::If(last.clone(), [entry, vec![set("boot", "1'b0")]].concat(), vec![])],
                vec![],
            ),
        ],
    )]));
    b.push(Item::Blank);
}

/// The microprogram's and the constants' tables, the microword's fields, the register file and the flag file.
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
    b.push(Item::Memory { name: "rfa".into(), width: w, depth: words });
    b.push(Item::Memory { name: "rfb".into(), width: w, depth: words });
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

/// The shift-add multiplier.
fn shift_add(cx: &Cx, b: &mut Vec<Item>) {
    let (x0, x1) = operands(cx);
    let (w, sw) = (cx.w, cx.sw);
    b.push(comment(
        "The shift-add multiplier: the product modulo 2^W, a bit of the second operand a clock (its sign bit's weight negative).",
    ));
    for (n, wn) in [("ma", w), ("mb", w), ("macc", w), ("mcnt", sw), ("mbs_r", 1)] {
        b.push(reg(n, wn));
    }
    b.push(Item::Always(vec![Stmt::If(
        "en".into(),
        vec![Stmt::If(
            "u_mld".into(),
            vec![set("ma", x0), set("mb", x1), set("macc", format!("{w}'d0")), set("mcnt", "u_mn"), set("mbs_r", "u_mbs")],
            vec![Stmt::If(
                format!("mcnt != {sw}'d0"),
                vec![
                    set("macc", format!("mb[0] ? ((mcnt == {sw}'d1 && mbs_r) ? macc - ma : macc + ma) : macc")),
                    set("ma", "ma << 1"),
                    set("mb", "mb >> 1"),
                    set("mcnt", format!("mcnt - {sw}'d1")),
                ],
                vec![],
            )],
        )],
        vec![],
    )]));
    b.push(Item::Blank);
}

/// The restoring divider, as wide as the widest divisor (`wd`, as the pipelined engine's
/// shift-remainder dividers): the partial remainder stays below the divisor, so it fits `wd`
/// bits after each step, and the quotient's `qm` bits (the widest) share a register with the
/// dividend's low bits they replace. Where a quotient does not fit its bits the result is
/// golden's "unspecified", which the program never reads.
fn divider(cx: &Cx, b: &mut Vec<Item>) {
    let (sw, w) = (cx.sw, cx.w);
    let (x0, x1) = operands(cx);
    let (wd, qm, qbs) = div_widths(cx.s);
    b.push(comment(format!(
        "The restoring divider ({wd}-bit divisors, {qm} quotient bits): the remainder shifted past the divisor, the dividend's"
    )));
    b.push(comment(
        "low qb bits shifted in from dl as the quotient's bits enter it, a bit a clock; one subtractor, its borrow the compare.",
    ));
    for (n, wn) in [("dr", wd), ("dd", wd), ("dl", qm), ("dcnt", sw), ("dr0", wd), ("dl0", qm)] {
        b.push(reg(n, wn));
    }
    b.push(wire("dt", wd + 1, format!("{{dr, dl[{}]}}", qm - 1)));
    if cx.s.plan.alu_lat == golden::frontend::engine::sequential::ALU_LAT_SPLIT {
        // The split form's step (the UP5K: one borrow chain through the divisor was its path
        // at 29.9 MHz): a carry select, the low half's difference and both of the high
        // half's (borrow in 0 and 1), chosen by the low half's borrow. Their top bits are
        // zero wherever they are taken.
        let l = wd.div_ceil(2);
        let hb = wd + 1 - l;
        b.push(comment("verilator lint_off UNUSEDSIGNAL"));
        b.push(wire("dslo", l + 1, format!("{{1'b0, dt[{}:0]}} - {{1'b0, dd[{}:0]}}", l - 1, l - 1)));
        b.push(wire("dshi0", hb + 1, format!("{{1'b0, dt[{wd}:{l}]}} - {{2'b0, dd[{}:{l}]}}", wd - 1)));
        // The borrow in rides as a low bit: 0 - 1 borrows one.
        b.push(wire("dshi1", hb + 2, format!("{{1'b0, dt[{wd}:{l}], 1'b0}} - {{2'b0, dd[{}:{l}], 1'b1}}", wd - 1)));
        b.push(wire("dsub", wd + 1, format!("{{dslo[{l}] ? dshi1[{hb}:1] : dshi0[{}:0], dslo[{}:0]}}", hb - 1, l - 1)));
        b.push(comment("verilator lint_on UNUSEDSIGNAL"));
        b.push(wire("dge", 1, format!("!(dslo[{l}] ? dshi1[{}] : dshi0[{hb}])", hb + 1)));
    } else {
        // Its bit wd is zero wherever it is taken.
        b.push(comment("verilator lint_off UNUSEDSIGNAL"));
        b.push(wire("dsub", wd + 2, "{1'b0, dt} - {2'b0, dd}"));
        b.push(comment("verilator lint_on UNUSEDSIGNAL"));
        b.push(wire("dge", 1, format!("!dsub[{}]", wd + 1)));
    }
    // The quotient widths are few: a multiplexer over them, not a barrel shifter.
    let high = |q: u32| {
        if q + wd <= w {
            format!("{x0}[{}:{q}]", q + wd - 1)
        } else {
            crate::verilog::zext(&format!("{x0}[{}:{q}]", w - 1), w - q, wd)
        }
    };
    let low = |q: u32| if q < qm { format!("{{{x0}[{}:0], {}'d0}}", q - 1, qm - q) } else { format!("{x0}[{}:0]", q - 1) };
    let mut top = vec![Stmt::Blocking("dr0".into(), format!("{x0}[{}:0]", wd - 1)), Stmt::Blocking("dl0".into(), format!("{qm}'d0"))];
    for &q in qbs.iter().rev() {
        top = vec![Stmt::If(
            format!("u_dqb == {sw}'d{q}"),
            vec![Stmt::Blocking("dr0".into(), high(q)), Stmt::Blocking("dl0".into(), low(q))],
            top,
        )];
    }
    b.push(Item::Comb(top));
    b.push(Item::Always(vec![Stmt::If(
        "en".into(),
        vec![Stmt::If(
            "u_dld".into(),
            vec![set("dr", "dr0"), set("dl", "dl0"), set("dd", format!("{x1}[{}:0]", wd - 1)), set("dcnt", "u_dqb")],
            vec![Stmt::If(
                format!("dcnt != {sw}'d0"),
                vec![
                    set("dr", format!("dge ? dsub[{0}:0] : dt[{0}:0]", wd - 1)),
                    set("dl", if qm > 1 { format!("{{dl[{}:0], dge}}", qm - 2) } else { "dge".into() }),
                    set("dcnt", format!("dcnt - {sw}'d1")),
                ],
                vec![],
            )],
        )],
        vec![],
    )]));
    b.push(Item::Blank);
}

/// Where the units load their operands: the read ports' operands, or the split ALU's
/// registers of them a clock later (`SeqPlan::load_lag`).
fn operands(cx: &Cx) -> (&'static str, &'static str) {
    match cx.s.plan.load_lag {
        0 => ("x0", "x1"),
        1 => {
            assert_eq!(
                cx.s.plan.alu_lat,
                golden::frontend::engine::sequential::ALU_LAT_SPLIT,
                "the operands' registers are the split ALU's"
            );
            ("ax0", "ax1")
        }
        l => panic!("units loading {l} clocks after their operands (the RTL has 0 and 1)"),
    }
}

/// The divider's widths: the widest divisor, the widest quotient and the quotient widths.
fn div_widths(s: &SeqSchedule) -> (u32, u32, Vec<u32>) {
    let ops = &s.prog.ops;
    let divs: Vec<(u32, u32)> = (0..ops.len())
        .filter(|&o| s.slots[o].exec != Exec::Dead)
        .filter_map(|o| if let Kind::Div { d, qb, .. } = ops[o].kind { Some((ops[d.0 as usize].w, qb)) } else { None })
        .collect();
    let mut qbs: Vec<u32> = divs.iter().map(|d| d.1).collect();
    qbs.sort();
    qbs.dedup();
    (divs.iter().map(|d| d.0).max().expect("a division"), *qbs.last().expect("a division"), qbs)
}

/// The write bus: its source, wrapped to the value's width and sign.
fn write_bus(cx: &Cx, widths: &[u32], b: &mut Vec<Item>) {
    let (wd, iw, w) = (cx.hw.fe.widths(), cx.hw.fe.cfg.iw(), cx.w);
    b.push(comment("The write bus: the source the microword names, wrapped to the value's width and sign."));
    let ins = ["nx0", "nx1", "nx2", "ny0", "ny1", "ny2", "ni0", "ni1", "ni2"];
    let mut srcs: Vec<(u64, String)> = match cx.s.plan.units.mul {
        MulUnit::Tile { .. } => (0..cx.s.plan.units.mults).map(|u| ([SRC_MUL, SRC_MUL1][u as usize], format!("m{u}acc"))).collect(),
        MulUnit::ShiftAdd { .. } => vec![(SRC_MUL, "macc".into())],
    };
    let (dw, qm, _) = div_widths(cx.s);
    srcs.extend([(SRC_DIVQ, crate::verilog::zext("dl", qm, w)), (SRC_DIVR, crate::verilog::zext("dr", dw, w))]);
    let mut srcs: Vec<(String, String)> = srcs.into_iter().map(|(k, x)| (format!("4'd{k}"), x)).collect();
    let kind = |k: usize| {
        if k < 3 {
            (wd.cx, true)
        } else if k < 6 {
            (wd.cy, true)
        } else {
            (iw, false)
        }
    };
    let ext = |n: &str, (wv, sg): (u32, bool), to: u32| if sg { crate::verilog::sext(n, wv, to) } else { crate::verilog::zext(n, wv, to) };
    // Registered (`SeqPlan::bus_lat`): the source from the microword two clocks before the
    // write (registered; the input it names picked then, as the inputs hold for the period),
    // the source's value registered a clock before the write, and at the write wrapped to its
    // width and sign (from the microword the clock before): no path through both multiplexers.
    let reg_bus = match cx.s.plan.bus_lat {
        0 => false,
        1 => true,
        l => panic!("a write bus of {l} clocks (the RTL has 0 and 1)"),
    };
    let wb = bits_for(widths.len() as u32 - 1);
    let (src, wc, wsg, val) = if reg_bus {
        // The inputs in one register as wide as the widest, sign-extended (the unsigned ones
        // with a zero bit on top).
        let wi = (0..ins.len()).map(|k| kind(k).0 + !kind(k).1 as u32).max().expect("inputs");
        b.extend([reg("src_r", 4), reg("in_r", wi), reg("inp", wi), reg("wc_r", wb), reg("wsg_r", 1), reg("bus_r", w)]);
        let arms = ins
            .iter()
            .enumerate()
            .map(|(k, n)| (format!("4'd{}", SRC_IN + k as u64), vec![Stmt::Blocking("inp".into(), ext(n, kind(k), wi))]));
        b.push(Item::Comb(vec![Stmt::Case {
            sel: "u_src".into(),
            arms: arms.collect(),
            default: vec![Stmt::Blocking("inp".into(), format!("{wi}'d0"))],
        }]));
        let labels: Vec<String> = (0..ins.len()).map(|k| format!("4'd{}", SRC_IN + k as u64)).collect();
        srcs.push((labels.join(", "), crate::verilog::sext("in_r", wi, w)));
        ("src_r", "wc_r", "wsg_r", "bus_r")
    } else {
        srcs.extend(ins.iter().enumerate().map(|(k, n)| (format!("4'd{}", SRC_IN + k as u64), ext(n, kind(k), w))));
        ("u_src", "u_wc", "u_wsg", "raw")
    };
    b.push(reg("raw", w));
    let arms = srcs.into_iter().map(|(k, x)| (k, vec![Stmt::Blocking("raw".into(), x)])).collect();
    b.push(Item::Comb(vec![Stmt::Case { sel: src.into(), arms, default: vec![Stmt::Blocking("raw".into(), "ar".into())] }]));
    b.push(reg("wmask", w));
    b.push(reg("wsign", 1));
    let arms: Vec<(String, Vec<Stmt>)> = widths
        .iter()
        .enumerate()
        .map(|(k, &x)| {
            let m = if x >= w { format!("{{{w}{{1'b1}}}}") } else { format!("{{{{{}{{1'b0}}}}, {{{x}{{1'b1}}}}}}", w - x) };
            (format!("{wb}'d{k}"), vec![Stmt::Blocking("wmask".into(), m), Stmt::Blocking("wsign".into(), format!("{val}[{}]", x - 1))])
        })
        .collect();
    b.push(Item::Comb(vec![Stmt::Case {
        sel: wc.into(),
        arms,
        default: vec![Stmt::Blocking("wmask".into(), format!("{{{w}{{1'b1}}}}")), Stmt::Blocking("wsign".into(), "1'b0".into())],
    }]));
    let wrapped = format!("({val} & wmask) | (({wsg} && wsign) ? ~wmask : {{{w}{{1'b0}}}})");
    if reg_bus {
        b.push(Item::Always(vec![Stmt::If(
            "en".into(),
            vec![set("src_r", "u_src"), set("in_r", "inp"), set("bus_r", "raw"), set("wc_r", "u_wc"), set("wsg_r", "u_wsg")],
            vec![],
        )]));
    }
    b.push(Item::Assign("bus".into(), wrapped));
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
                parts.push(format!("{}'d{}", f.w, k));
                we.push(format!("cap_ok && {}", cap(first)));
            }
            _ => {
                parts.push(if f.w == 1 { "bus[0]".to_string() } else { format!("bus[{}:0]", f.w - 1) });
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
