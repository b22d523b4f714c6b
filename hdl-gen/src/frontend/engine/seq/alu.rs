//! The sequential engine's ALU: add, subtract and the signed compare on one adder, equal,
//! and, or, not, select, the leading-zero count, one left shifter and the right shifts by
//! their constants, its result `ar`, which the write bus reads at golden's write clock
//! (`issue + READ + SeqPlan::alu_lat`, less its own `bus_lat`).
//!
//! - **One clock** ([`ALU_LAT`], the HX8K's until issue 27's stop 34, no plan's since): the
//!   operand select, the whole adder and the result multiplexer in one path, as first written.
//! - **Split** ([`ALU_LAT_SPLIT`], both iCE40 plans): on the UP5K that one path was the engine's
//!   clock, 15.1 MHz (its 67-bit carry chain alone about 26 ns, docs/fpga.md), and on this
//!   slow fabric (about 4 ns a LUT level with its routing) a 40 MHz clock leaves about five
//!   levels a clock. Clock 1 registers the operands (a select's choice among them) and the
//!   function; clock 2 adds the low half (its carry registered) and both sums of the high
//!   half (carry in 0 and 1, a carry select), tests the operands for zero, shifts by the
//!   amount's low bits and counts each group's leading zeros; clock 3 picks the high half by
//!   the low half's carry, forms the compare from the signs, shifts by the amount's high bits,
//!   finds the first group that is not zero and registers the wide result; `ar` chooses among
//!   the results' kinds, in the write bus's source select (a register and a clock of its own
//!   until issue 27's stop 35).

use super::cx::{Cx, FN_ADD, FN_AND, FN_EQ, FN_LT, FN_LZC, FN_NOT, FN_OR, FN_PASS, FN_SEL, FN_SHL, FN_SHLV, FN_SHR, FN_SUB};
use crate::frontend::engine::units::bits_for;
use crate::verilog::{comment, reg, set, wire, Item, Stmt};
use golden::frontend::engine::sequential::{Exec, ALU_LAT, ALU_LAT_SPLIT};
use golden::frontend::engine::Kind;

/// The ALU of the plan's latency.
pub(super) fn alu(cx: &Cx, b: &mut Vec<Item>) {
    let w = cx.w;
    b.push(comment("Operands: a flag from the flag file, else the port of the operand's position (A, B, A)."));
    // The split ALU reads the first and the third from the ports and the flags themselves
    // (`ax0`); units loading on the read clock read the first.
    let two = cx.s.plan.alu_lat == ALU_LAT_SPLIT;
    let xs: &[usize] = if !two {
        &[0, 1, 2]
    } else if cx.s.plan.load_lag == 0 {
        &[0, 1]
    } else {
        &[1]
    };
    for &j in xs {
        let port = ["da", "db", "da"][j];
        b.push(wire(&format!("x{j}"), w, format!("u_fl{j} ? {{{{{}{{1'b0}}}}, fl[u_fa{j}]}} : {port}", w - 1)));
    }
    match cx.s.plan.alu_lat {
        ALU_LAT => one_clock(cx, b),
        ALU_LAT_SPLIT => split(cx, b),
        l => panic!("an ALU of {l} clocks (the RTL has {ALU_LAT} and {ALU_LAT_SPLIT})"),
    }
    b.push(Item::Blank);
}

/// The functions but the adder's, on operands `x` (x0, x1, x2 by prefix) under function
/// `f` and immediate `imm`, into `alu` (a parallel case: Yosys builds one multiplexer per bit,
/// not a chain). `adder`: the adder's logic and its arms, where the adder is in the same clock.
fn functions(cx: &Cx, x: &str, f: &str, imm: &str, adder: (Vec<Item>, &[(Vec<u64>, String)]), out: &str, b: &mut Vec<Item>) {
    let (w, sw, ops) = (cx.w, cx.sw, &cx.s.prog.ops);
    let (x0, x1, x2) = (format!("{x}0"), format!("{x}1"), format!("{x}2"));
    // Leading zeros of x0's low n bits (the program's counts: one width at the named screens),
    // halving: the top half zero or not, a bit of the count each, below it ones so that zero
    // counts n. Log depth, where a bit-serial chain would set the clock.
    let mut lzn: Vec<u32> = ops.iter().filter_map(|o| if let Kind::Lzc(_, n) = o.kind { Some(n) } else { None }).collect();
    lzn.sort();
    lzn.dedup();
    b.push(reg("lz", sw));
    // The last stage reads only the top bit of its pair.
    b.push(comment("verilator lint_off UNUSEDSIGNAL"));
    let mut sel = Vec::new();
    for &n in &lzn {
        let p = (n + 1).next_power_of_two();
        let lb = p.trailing_zeros();
        let mut st = vec![Stmt::Blocking(format!("lz{n}_v{lb}"), format!("{{{x0}[{}:0], {{{}{{1'b1}}}}}}", n - 1, p - n))];
        b.push(reg(&format!("lz{n}_v{lb}"), p));
        b.push(reg(&format!("lz{n}"), lb));
        for k in (0..lb).rev() {
            let h = 1u32 << k;
            let (v, nv) = (format!("lz{n}_v{}", k + 1), format!("lz{n}_v{k}"));
            if k > 0 {
                b.push(reg(&nv, h));
            }
            st.push(Stmt::Blocking(format!("lz{n}[{k}]"), format!("{v}[{}:{h}] == {h}'d0", 2 * h - 1)));
            if k > 0 {
                st.push(Stmt::Blocking(nv, format!("lz{n}[{k}] ? {v}[{}:0] : {v}[{}:{h}]", h - 1, 2 * h - 1)));
            }
        }
        b.push(Item::Comb(st));
        b.push(comment("verilator lint_on UNUSEDSIGNAL"));
        sel.push((n, format!("{{{{{}{{1'b0}}}}, lz{n}}}", sw - lb)));
    }
    let mut e = format!("{sw}'d0");
    for (n, v) in sel.iter().rev() {
        e = format!("({imm} == {sw}'d{n}) ? {v} : {e}");
    }
    b.push(Item::Comb(vec![Stmt::Blocking("lz".into(), e)]));
    let one = |e: &str| format!("{{{{{}{{1'b0}}}}, {e}}}", w - 1);
    let (items, adder) = adder;
    b.extend(items);
    // One left shifter for shifts by a constant and by the value on x1 (all out at W or more:
    // its bits above the amount's ORed, not a compare of the whole word, whose carry chain was
    // the split ALU's path on the UP5K).
    b.push(wire("shl_by", 1, format!("{f} == 4'd{FN_SHLV}")));
    b.push(wire("shl_amt", sw, format!("shl_by ? {x1}[{}:0] : {imm}", sw - 1)));
    b.push(wire("shl_out", 1, format!("shl_by && (|{x1}[{}:{sw}] || {x1}[{}:0] >= {sw}'d{w})", w - 1, sw - 1)));
    b.push(wire("shl", w, format!("shl_out ? {w}'d0 : {x0} << shl_amt")));
    // Right shifts are by constants, and few (one at the named screens): a multiplexer over them.
    let mut shrs: Vec<u32> = ops.iter().filter_map(|o| if let Kind::Shr(_, n) = o.kind { Some(n) } else { None }).collect();
    shrs.sort();
    shrs.dedup();
    b.push(reg("shr", w));
    let arms = shrs.iter().map(|n| (format!("{sw}'d{n}"), vec![Stmt::Blocking("shr".into(), format!("$signed({x0}) >>> {n}"))])).collect();
    b.push(Item::Comb(vec![Stmt::Case { sel: imm.into(), arms, default: vec![Stmt::Blocking("shr".into(), x0.clone())] }]));
    let mut alu = adder.to_vec();
    alu.extend([
        (vec![FN_EQ], one(&format!("{x0} == {x1}"))),
        (vec![FN_AND], one(&format!("|{x0} && |{x1}"))),
        (vec![FN_OR], one(&format!("|{x0} || |{x1}"))),
        (vec![FN_NOT], one(&format!("~|{x0}"))),
        (vec![FN_SEL], format!("|{x0} ? {x1} : {x2}")),
        (vec![FN_LZC], format!("{{{{{}{{1'b0}}}}, lz}}", w - sw)),
        (vec![FN_SHL, FN_SHLV], "shl".to_string()),
        (vec![FN_SHR], "shr".to_string()),
    ]);
    b.push(reg(out, w));
    let arms = alu
        .iter()
        .map(|(fs, v)| (fs.iter().map(|f| format!("4'd{f}")).collect::<Vec<_>>().join(", "), vec![Stmt::Blocking(out.into(), v.clone())]))
        .collect();
    b.push(Item::Comb(vec![Stmt::Case { sel: f.into(), arms, default: vec![Stmt::Blocking(out.into(), x0)] }]));
}

/// The ALU in one clock: one adder for add, subtract and the signed compare (the
/// difference's sign, corrected where the operands' signs differ).
fn one_clock(cx: &Cx, b: &mut Vec<Item>) {
    let w = cx.w;
    let one = |e: &str| format!("{{{{{}{{1'b0}}}}, {e}}}", w - 1);
    b.push(comment("The ALU, its result registered (written the clock after)."));
    b.push(reg("ar", w));
    let items = vec![
        wire("sub", 1, format!("u_fn == 4'd{FN_SUB} || u_fn == 4'd{FN_LT}")),
        comment("verilator lint_off UNUSEDSIGNAL"),
        wire("as1", w + 1, format!("{{x0, 1'b1}} + {{x1 ^ {{{w}{{sub}}}}, sub}}")),
        comment("verilator lint_on UNUSEDSIGNAL"),
        wire("addsub", w, format!("as1[{w}:1]")),
        wire("lt", 1, format!("(x0[{0}] != x1[{0}]) ? x0[{0}] : addsub[{0}]", w - 1)),
    ];
    let adder = [(vec![FN_ADD, FN_SUB], "addsub".to_string()), (vec![FN_LT], one("lt"))];
    functions(cx, "x", "u_fn", "u_imm", (items, &adder), "alu", b);
    b.push(Item::Always(vec![Stmt::If("en".into(), vec![set("ar", "alu")], vec![])]));
}

/// The ALU over three clocks (module doc): each clock's logic a few LUT levels on the UP5K.
fn split(cx: &Cx, b: &mut Vec<Item>) {
    let (w, sw) = (cx.w, cx.sw);
    // The low half as wide as the high one or one bit wider: the two carry chains even.
    let h = w.div_ceil(2);
    let hw = w - h;
    let one = |e: &str| format!("{{{{{}{{1'b0}}}}, {e}}}", w - 1);
    b.push(comment("The ALU over three clocks. 1: the operands and the function registered (ax*, af, ai; the select's choice"));
    b.push(comment("into ax0, ax1 zero for a pass or a select). 2: the low half's sum with its carry and both sums of the high"));
    b.push(comment("half (carry in 0 and 1); the zero tests; the shift by the amount's low bits; the leading zeros of each group"));
    b.push(comment(
        "of bits; the right shift (b*). 3: the high half chosen by the carry and the compare; the shift by the amount's high bits; the",
    ));
    b.push(comment("count; the wide result in one register (c*). Then ar, the result, in the write bus's source select."));
    b.extend([reg("ax0", w), reg("ax1", w), reg("af", 4), reg("ai", sw)]);
    b.push(wire("sub", 1, format!("af == 4'd{FN_SUB} || af == 4'd{FN_LT}")));
    b.push(wire("ay1", w, format!("ax1 ^ {{{w}{{sub}}}}")));
    // The carry in rides as a low bit: 1 + sub carries sub into bit 0.
    b.push(comment("verilator lint_off UNUSEDSIGNAL"));
    b.push(wire("alo", h + 2, format!("{{1'b0, ax0[{0}:0], 1'b1}} + {{1'b0, ay1[{0}:0], sub}}", h - 1)));
    b.push(wire("ahi1", hw + 1, format!("{{ax0[{0}:{h}], 1'b1}} + {{ay1[{0}:{h}], 1'b1}}", w - 1)));
    b.push(comment("verilator lint_on UNUSEDSIGNAL"));
    b.push(wire("ahi0", hw, format!("ax0[{0}:{h}] + ay1[{0}:{h}]", w - 1)));
    // The one-bit results (equal, and, or, not) from the operands' zero tests. The select's
    // condition: where the program's are all one-bit values (its compares, as golden builds
    // them), their low bit, not a whole word's OR ahead of every bit's choice (the path at
    // 31.3 MHz).
    let ops = &cx.s.prog.ops;
    let bit = ops.iter().zip(&cx.s.slots).all(|(o, sl)| match o.kind {
        Kind::Sel(c, ..) if sl.exec == Exec::Alu => ops[c.0 as usize].w == 1,
        _ => true,
    });
    // The and, or and not of values whose bit 0 is their truth (one-bit values, as golden's
    // are, and constants such as 1), and equality with a constant 0 (golden's only): each from
    // a bit or one zero test, not a word's ORs and compare (about 70 LUTs on the UP5K).
    let alu = |o: usize| cx.s.slots[o].exec == Exec::Alu;
    let truth = |v: golden::frontend::engine::V| {
        let a = &ops[v.0 as usize];
        a.w == 1 || matches!(a.kind, Kind::Const(c) if (c != 0) == (c & 1 != 0))
    };
    let low = ops.iter().enumerate().all(|(o, op)| match op.kind {
        Kind::And(..) | Kind::Or(..) | Kind::Not(_) if alu(o) => op.kind.args().into_iter().all(truth),
        _ => true,
    });
    let eq0 = ops.iter().enumerate().all(|(o, op)| match op.kind {
        Kind::Eq(_, z) if alu(o) => matches!(ops[z.0 as usize].kind, Kind::Const(0)),
        _ => true,
    });
    let (t0, t1) = if low { ("ax0[0]", "ax1[0]") } else { ("|ax0", "|ax1") };
    b.push(wire("nz0", 1, t0));
    b.push(wire("nz1", 1, t1));
    // The select chooses on clock 1, into the first operand's register, and a pass or a select
    // zeroes the second's, so their value comes through the adder (`ax0 + 0`): no third operand
    // register and no move multiplexer beside the sum (a word of logic cells each on the UP5K,
    // which is short of cells). Each register's bits above the flag's are a port or zero (a
    // flip-flop's synchronous reset), not a choice among the operands. The divider (and the
    // HX8K's shift-add unit) loads from `ax0` and `ax1` only on its own read clocks, whose
    // function is no ALU's (0).
    let (sel, pass) = (format!("u_fn == 4'd{FN_SEL}"), format!("u_fn == 4'd{FN_PASS}"));
    b.push(wire("sc", 1, format!("u_fl0 ? fl[u_fa0] : {}", if bit { "da[0]" } else { "|da" })));
    b.push(wire("a_b", 1, format!("{sel} && sc")));
    b.push(wire("a_fl", 1, format!("({sel}) ? (sc ? u_fl1 : u_fl2) : u_fl0")));
    b.push(wire("a_fv", 1, format!("({sel}) ? (sc ? fl[u_fa1] : fl[u_fa2]) : fl[u_fa0]")));
    b.push(wire("b_z", 1, format!("{sel} || {pass}")));
    let eq = if eq0 { "~|ax0" } else { "(ax0 == ax1)" };
    let flag = format!("(af == 4'd{FN_EQ}) ? {eq} : (af == 4'd{FN_AND}) ? (nz0 && nz1) : (af == 4'd{FN_OR}) ? (nz0 || nz1) : !nz0");
    // Right shifts are by constants, and few (one at the named screens): a multiplexer over them.
    let mut shrs: Vec<u32> = ops.iter().filter_map(|o| if let Kind::Shr(_, n) = o.kind { Some(n) } else { None }).collect();
    shrs.sort();
    shrs.dedup();
    b.push(reg("shr", w));
    // Read only for a right shift: its last constant is the default.
    let by = |n: u32| vec![Stmt::Blocking("shr".into(), format!("$signed(ax0) >>> {n}"))];
    let (arms, default) = match shrs.split_last() {
        Some((&last, rest)) => (rest.iter().map(|&n| (format!("{sw}'d{n}"), by(n))).collect(), by(last)),
        None => (Vec::new(), vec![Stmt::Blocking("shr".into(), "ax0".into())]),
    };
    b.push(Item::Comb(vec![Stmt::Case { sel: "ai".into(), arms, default }]));

    // The result's kind, for clock 4's multiplexer.
    let kind = format!(
        "(af == 4'd{FN_ADD} || sub || af == 4'd{FN_PASS} || af == 4'd{FN_SEL}) ? {{af == 4'd{FN_LT}, 2'd0}} : (af == 4'd{FN_EQ} || af == 4'd{FN_AND} || af == 4'd{FN_OR} || af == 4'd{FN_NOT}) ? 3'd1 : (af == 4'd{FN_LZC}) ? 3'd2 : (af == 4'd{FN_SHL} || af == 4'd{FN_SHLV}) ? 3'd3 : 3'd5"
    );
    b.extend([reg("blo", h), reg("bc", 1), reg("bhi0", hw), reg("bhi1", hw), reg("bs0", 1), reg("bs1", 1)]);
    b.extend([reg("bfl", 1), reg("bmv", w), reg("bk", 3), reg("ck", 3), reg("cfl", 1)]);
    b.extend([reg("cv", w), reg("clt", 1)]);
    b.push(wire("addsub", w, "{bc ? bhi1 : bhi0, blo}"));
    let mut regs = vec![
        set("ax0", format!("a_fl ? {{{{{}{{1'b0}}}}, a_fv}} : (a_b ? db : da)", w - 1)),
        set("ax1", format!("b_z ? {w}'d0 : x1")),
        set("af", "u_fn"),
        set("ai", "u_imm"),
        set("blo", format!("alo[{}:1]", h)),
        set("bc", format!("alo[{}]", h + 1)),
        set("bhi0", "ahi0"),
        set("bhi1", format!("ahi1[{hw}:1]")),
        set("bs0", format!("ax0[{}]", w - 1)),
        set("bs1", format!("ax1[{}]", w - 1)),
        set("bfl", flag),
        set("bmv", "shr"),
        set("bk", kind),
        set("clt", format!("(bs0 != bs1) ? bs0 : addsub[{}]", w - 1)),
        set("cfl", "bfl"),
        set("ck", "bk"),
    ];
    // The wide results (the sum, the shift, the moves) share clock 3's register: a word of
    // flip-flops each was a word of logic cells on the UP5K; `ar` picks among it and the
    // one-bit and count results, in the write bus's source select.
    let (sh, lz) = (split_shift(cx, &mut regs, b), split_lzc(cx, &mut regs, b));
    regs.push(set("cv", format!("(bk == 3'd0) ? addsub : (bk == 3'd3) ? {sh} : bmv")));
    let ar =
        format!("(ck == 3'd4) ? {} : (ck == 3'd1) ? {} : (ck == 3'd2) ? {} : cv", one("clt"), one("cfl"), crate::verilog::zext(&lz, sw, w));
    b.push(Item::Always(vec![Stmt::If("en".into(), regs, vec![])]));
    b.push(wire("ar", w, ar));
}

/// The left shift in two clocks: by the amount's low three bits on clock 2, by its high bits
/// on clock 3 (all out at W or more: the amount's bits above its width ORed, not a compare of
/// the whole word). Where every amount is below W (the constants, and each variable amount's
/// unsigned width: golden's are leading-zero counts), the amount is only as wide as the
/// largest and nothing shifts out. Returns clock 3's shifted value, which [`split`] registers.
fn split_shift(cx: &Cx, regs: &mut Vec<Stmt>, b: &mut Vec<Item>) -> String {
    let (w, sw, ops) = (cx.w, cx.sw, &cx.s.prog.ops);
    let mut most = Some(0u64);
    for (_, op) in ops.iter().enumerate().filter(|&(o, _)| cx.s.slots[o].exec == Exec::Alu) {
        let n = match op.kind {
            Kind::Shl(_, n) => Some(n as u64),
            Kind::ShlBy(_, a) => {
                let a = &ops[a.0 as usize];
                (!a.signed && a.w < 32).then(|| (1u64 << a.w) - 1)
            }
            _ => continue,
        };
        most = most.zip(n).map(|(m, n)| m.max(n));
    }
    let bound = most.filter(|&m| m < w as u64).map(|m| bits_for(m.max(1)));
    let aw = bound.unwrap_or(sw);
    let lo = aw.min(3);
    b.push(wire("shl_by", 1, format!("af == 4'd{FN_SHLV}")));
    let ai = if aw < sw { format!("ai[{}:0]", aw - 1) } else { "ai".into() };
    b.push(wire("shl_amt", aw, format!("shl_by ? ax1[{}:0] : {ai}", aw - 1)));
    if cx.s.plan.shift_on_macs {
        return shift_on_macs(cx, aw, bound.is_none(), regs, b);
    }
    b.push(reg("bsh", w));
    regs.push(set("bsh", format!("ax0 << shl_amt[{}:0]", lo - 1)));
    let out = shifts_out(cx, bound.is_none(), w, regs, b);
    if aw > lo {
        b.push(reg("bamt", aw - lo));
        regs.push(set("bamt", format!("shl_amt[{}:{lo}]", aw - 1)));
        b.push(wire("csh", w, format!("{out}bsh << {{bamt, {lo}'d0}}")));
    } else {
        b.push(wire("csh", w, format!("{out}bsh")));
    }
    "csh".into()
}

/// The same left shift with its low four bits on 16 x 16 multipliers (`SeqPlan::shift_on_macs`):
/// on clock 2 each 16 bits of `ax0` times `2^k` into the multiplier's output register (Yosys
/// maps each to an SB_MAC16 under `synth_ice40 -dsp`); the products do not overlap, so an OR
/// joins them, and on clock 3 a choice among 16-bit steps. Only the widest shift's bits are
/// formed: every value is wrapped to its width as it is written, so the bits above it are
/// never read.
fn shift_on_macs(cx: &Cx, aw: u32, out: bool, regs: &mut Vec<Stmt>, b: &mut Vec<Item>) -> String {
    let (w, ops) = (cx.w, &cx.s.prog.ops);
    let shw = ops
        .iter()
        .zip(&cx.s.slots)
        .filter(|(op, sl)| sl.exec == Exec::Alu && matches!(op.kind, Kind::Shl(..) | Kind::ShlBy(..)))
        .map(|(op, _)| op.w)
        .max()
        .unwrap_or(1)
        .min(w);
    let n = shw.div_ceil(MAC_BITS);
    let lo = aw.min(4);
    b.push(comment(format!(
        "The left shift's low {lo} bits as products by 2^k on {n} SB_MAC16 (each 16 bits of ax0, their output registers"
    )));
    b.push(comment(format!(
        "clock 2's), joined by an OR (they do not overlap); its high bits in 16-bit steps; {shw} bits, the widest shift's."
    )));
    b.push(wire("shl_p", MAC_BITS, format!("{MAC_BITS}'d1 << shl_amt[{}:0]", lo - 1)));
    let (xw, pw) = (n * MAC_BITS, 2 * MAC_BITS);
    let x = if xw > shw { format!("{{{}'d0, ax0[{}:0]}}", xw - shw, shw - 1) } else { format!("ax0[{}:0]", shw - 1) };
    b.push(wire("shl_x", xw, x));
    b.push(reg("bfp", n * pw));
    b.push(Item::Integer("shl_k".into()));
    regs.push(Stmt::For {
        var: "shl_k".into(),
        count: n.to_string(),
        body: vec![set(
            format!("bfp[{pw}*shl_k +: {pw}]"),
            format!("{{{MAC_BITS}'d0, shl_x[{MAC_BITS}*shl_k +: {MAC_BITS}]}} * {{{MAC_BITS}'d0, shl_p}}"),
        )],
    });
    // The products' sum: the OR of each at its 16 bits' place (16 bits above the last).
    let fw = xw + MAC_BITS;
    b.push(reg("shl_f", fw));
    b.push(Item::Integer("shl_j".into()));
    b.push(Item::Comb(vec![
        Stmt::Blocking("shl_f".into(), format!("{fw}'d0")),
        Stmt::For {
            var: "shl_j".into(),
            count: n.to_string(),
            body: vec![Stmt::Blocking(
                "shl_f".into(),
                format!("shl_f | ({{{}'d0, bfp[{pw}*shl_j +: {pw}]}} << ({MAC_BITS}*shl_j))", fw - pw),
            )],
        },
    ]));
    let mut sh = format!("shl_f[{}:0]", shw - 1);
    if aw > lo {
        b.push(reg("bamt", aw - lo));
        regs.push(set("bamt", format!("shl_amt[{}:{lo}]", aw - 1)));
        sh = format!("({sh} << {{bamt, {lo}'d0}})");
    }
    let out = shifts_out(cx, out, shw, regs, b);
    b.push(wire("csh_v", shw, format!("{out}{sh}")));
    b.push(wire("csh", w, crate::verilog::zext("csh_v", shw, w)));
    "csh".into()
}

/// Where a variable amount can reach W (`out`): the shift's zero, its test registered beside
/// the amount's low bits. Returns the prefix that zeroes a `width`-bit shift.
fn shifts_out(cx: &Cx, out: bool, width: u32, regs: &mut Vec<Stmt>, b: &mut Vec<Item>) -> String {
    if !out {
        return String::new();
    }
    let (w, sw) = (cx.w, cx.sw);
    b.push(wire("shl_out", 1, format!("shl_by && (|ax1[{}:{sw}] || ax1[{}:0] >= {sw}'d{w})", w - 1, sw - 1)));
    b.push(reg("bout", 1));
    regs.push(set("bout", "shl_out"));
    format!("bout ? {width}'d0 : ")
}

/// The SB_MAC16's operand width.
const MAC_BITS: u32 = 16;

/// The leading-zero count in two clocks: on clock 2 each group of 8 bits' zero test and
/// count, on clock 3 the first group that is not zero and its count. Returns clock 3's
/// register.
fn split_lzc(cx: &Cx, regs: &mut Vec<Stmt>, b: &mut Vec<Item>) -> String {
    let (sw, ops) = (cx.sw, &cx.s.prog.ops);
    let mut lzn: Vec<u32> = ops.iter().filter_map(|o| if let Kind::Lzc(_, n) = o.kind { Some(n) } else { None }).collect();
    lzn.sort();
    lzn.dedup();
    b.extend([reg("bi", sw), reg("clz", sw)]);
    regs.push(set("bi", "ai"));
    let mut e = format!("{sw}'d0");
    for &n in lzn.iter().rev() {
        // Leading zeros of x0's low n bits, padded below with ones so that zero counts n.
        let p = (n + 1).next_power_of_two();
        let g = p.min(8);
        assert!(g >= 2, "a count of {n} bits");
        let k = p / g;
        let gb = g.trailing_zeros();
        // Its lowest bit decides nothing: a group's count is its width less one there.
        b.push(comment("verilator lint_off UNUSEDSIGNAL"));
        b.push(wire(&format!("lz{n}_v"), p, format!("{{ax0[{}:0], {{{}{{1'b1}}}}}}", n - 1, p - n)));
        b.push(comment("verilator lint_on UNUSEDSIGNAL"));
        // The last group's zero test is never read: the padding's ones.
        if k > 1 {
            b.push(reg(&format!("lz{n}_z"), k - 1));
        }
        b.push(reg(&format!("lz{n}_c"), k * gb));
        for j in 0..k {
            // Group j from the top: its zero test and its own count (a priority chain of g bits).
            let top = p - 1 - j * g;
            let mut c = format!("{}'d{}", gb, g - 1);
            for bit in 1..g {
                c = format!("lz{n}_v[{}] ? {}'d{} : ({c})", top + 1 - g + bit, gb, g - 1 - bit);
            }
            if j + 1 < k {
                regs.push(set(format!("lz{n}_z[{j}]"), format!("~|lz{n}_v[{top}:{}]", top + 1 - g)));
            }
            let hi = (j + 1) * gb - 1;
            regs.push(set(format!("lz{n}_c[{hi}:{}]", j * gb), c));
        }
        // Clock 3: the first group not zero (the last one never is: the padding's ones).
        let mut cnt = String::new();
        for j in (0..k).rev() {
            // 8 j + the group's count: the group's index above its count's bits.
            let here = format!("{{{}'d{j}, lz{n}_c[{}:{}]}}", sw - gb, (j + 1) * gb - 1, j * gb);
            cnt = if j + 1 == k { here } else { format!("!lz{n}_z[{j}] ? ({here}) : ({cnt})") };
        }
        e = format!("(bi == {sw}'d{n}) ? ({cnt}) : ({e})");
    }
    regs.push(set("clz", e));
    "clz".into()
}
