//! The sequential engine's datapath beside the ALU: the HX8K's shift-add multiplier, the
//! restoring divider and the write bus.

use super::cx::{div_widths, operands, Cx, SRC_DIVQ, SRC_DIVR, SRC_IN, SRC_MUL, SRC_MUL1};
use crate::frontend::engine::units::bits_for;
use crate::verilog::{comment, reg, set, wire, Item, Stmt};
use golden::frontend::engine::MulUnit;

/// The shift-add multiplier.
pub(super) fn shift_add(cx: &Cx, b: &mut Vec<Item>) {
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
pub(super) fn divider(cx: &Cx, b: &mut Vec<Item>) {
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
    // Read only at a load, whose quotient width is one of them: the widest is the default.
    let (&last, rest) = qbs.split_last().expect("a division");
    let mut top = vec![Stmt::Blocking("dr0".into(), high(last)), Stmt::Blocking("dl0".into(), low(last))];
    for &q in rest.iter().rev() {
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

/// The write bus: its source, wrapped to the value's width and sign.
pub(super) fn write_bus(cx: &Cx, widths: &[u32], b: &mut Vec<Item>) {
    let (wd, iw, w) = (cx.hw.fe.widths(), cx.hw.fe.cfg.iw(), cx.w);
    b.push(comment("The write bus: the source the microword names, wrapped to the value's width and sign."));
    let ins = ["in_x0", "in_x1", "in_x2", "in_y0", "in_y1", "in_y2", "in_i0", "in_i1", "in_i2"];
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
    // write (registered; the input it names picked then from the port, which holds the
    // triangle until its last read: `sequencer`), the source's value registered a clock before
    // the write, and at the write wrapped to its width and sign (from the microword the clock
    // before): no path through both multiplexers.
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
        // Read only where the source is an input: the last input is the default.
        let arms = ins
            .iter()
            .enumerate()
            .take(ins.len() - 1)
            .map(|(k, n)| (format!("4'd{}", SRC_IN + k as u64), vec![Stmt::Blocking("inp".into(), ext(n, kind(k), wi))]));
        let last = ins.len() - 1;
        b.push(Item::Comb(vec![Stmt::Case {
            sel: "u_src".into(),
            arms: arms.collect(),
            default: vec![Stmt::Blocking("inp".into(), ext(ins[last], kind(last), wi))],
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
    let arm = |x: u32| {
        let m = if x >= w { format!("{{{w}{{1'b1}}}}") } else { format!("{{{{{}{{1'b0}}}}, {{{x}{{1'b1}}}}}}", w - x) };
        vec![Stmt::Blocking("wmask".into(), m), Stmt::Blocking("wsign".into(), format!("{val}[{}]", x - 1))]
    };
    // Every write names one of the widths: the widest is the default.
    let (&last, rest) = widths.split_last().expect("a width");
    let arms: Vec<(String, Vec<Stmt>)> = rest.iter().enumerate().map(|(k, &x)| (format!("{wb}'d{k}"), arm(x))).collect();
    b.push(Item::Comb(vec![Stmt::Case { sel: wc.into(), arms, default: arm(last) }]));
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
