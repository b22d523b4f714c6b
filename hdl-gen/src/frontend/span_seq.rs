//! The sequential span path (`--fe-span sequential`, the iCE40 targets): golden's
//! [`golden::frontend::span_seq`] unit, one shift-add accumulator for a covered row's three
//! products, a few multiplier bits a clock. The walker (and its row stages) wait while it is
//! busy: `adv`, their one stall, is the unit's readiness instead of the output register's.

use super::hw::Hw;
use super::properties::{SpanStage, SpanUnit};
use super::stager::Stager;
use super::walker;
use crate::verilog::{comment, lit, reg, set, wire, zext, Item, Stmt};
use crate::widths::bits_for;
use golden::frontend::span_seq::{AccLoad, Multiplicand, Multiplier, SpanSeq};
use golden::frontend::Widths;

pub(super) mod walk_ram;

/// The unit of a front-end whose span form is sequential.
pub(super) fn unit(hw: &Hw) -> Option<SpanSeq> {
    hw.fe.span_seq()
}

/// The unit as the properties' one span stage: busy while it holds a row.
pub(super) fn stage(hw: &Hw) -> SpanStage {
    // Where the walk memory holds dI, the walked triangle's there (`walk_ram::formal_di`).
    let di = if hw.row_stage() { "sq_di" } else { walker_di(hw) };
    SpanStage { valid: "sq_busy".into(), y: "sq_y".into(), x: "sq_x".into(), len: "sq_len".into(), di: di.into() }
}

/// Where the walker's triangle's `dI` is: its register, or the walk memory's word
/// (`walk_ram::formal_di`'s `f_wdi`, for the proofs).
pub(super) fn walker_di(hw: &Hw) -> &'static str {
    if walk_ram::di_value(hw).is_some() {
        "f_wdi"
    } else {
        "w_di"
    }
}

/// The unit's shape for the properties: its clocks, the clocks left from its phase and count
/// (each phase's steps, then a load clock and the steps of each phase after it), and whether the
/// walker takes a triangle only when empty (the unit reads its registers, `walker::emit`).
pub(super) fn shape(hw: &Hw) -> Option<SpanUnit> {
    let q = unit(hw)?;
    let (n, cnt_w) = (SpanSeq::PHASES.len(), count_bits(&q));
    let (phase_w, sw) = (phase_bits(), bits_for(q.row_clocks()));
    let after = |k: usize| -> u32 { SpanSeq::PHASES[k + 1..].iter().map(|p| 1 + q.steps(p)).sum() };
    let left = (0..n - 1)
        .rev()
        .fold(lit(sw, after(n - 1) as u64), |acc, k| format!("sq_ph == {} ? {} : {acc}", lit(phase_w, k as u64), lit(sw, after(k) as u64)));
    let steps = (0..n - 1).rev().fold(lit(cnt_w, q.steps(&SpanSeq::PHASES[n - 1]) as u64), |acc, k| {
        format!("sq_ph == {} ? {} : {acc}", lit(phase_w, k as u64), lit(cnt_w, q.steps(&SpanSeq::PHASES[k]) as u64))
    });
    Some(SpanUnit {
        row_clocks: q.row_clocks(),
        left: format!("{} + ({left})", zext("sq_cnt", cnt_w, sw)),
        bounds: vec![format!("sq_ph <= {}", lit(phase_w, n as u64 - 1)), format!("sq_cnt <= ({steps})")],
        take_when_empty: !hw.row_stage(),
    })
}

/// Width of the unit's step count: the most steps a phase takes.
fn count_bits(q: &SpanSeq) -> u32 {
    bits_for(SpanSeq::PHASES.iter().map(|p| q.steps(p)).max().expect("phases"))
}

/// Width of the unit's phase register: it holds each phase's index.
fn phase_bits() -> u32 {
    bits_for(SpanSeq::PHASES.len() as u32 - 1)
}

/// The unit's control registers and `adv` (declared before the walker reads it): the walker
/// moves when the unit is idle, or in the clock it writes its result to a free output. Then the
/// walk's constants in block RAM, where the form has them ([`walk_ram`]).
pub(super) fn handshake(hw: &Hw, body: &mut Vec<Item>) {
    let q = unit(hw).expect("the sequential span path");
    let phase_w = phase_bits();
    body.push(comment("The sequential span path's control: busy from a covered row's accept to its result's write."));
    body.extend([reg("sq_busy", 1), reg("sq_ph", phase_w), reg("sq_cnt", count_bits(&q))]);
    let last = lit(phase_w, SpanSeq::PHASES.len() as u64 - 1);
    body.push(wire("sq_done", 1, format!("sq_busy && sq_ph == {last} && sq_cnt == {}", lit(count_bits(&q), 0))));
    body.push(wire("sq_fin", 1, "sq_done && (!out_valid || out_ready)"));
    body.push(wire("adv", 1, "!sq_busy || sq_fin"));
    if hw.walk_ram() {
        walk_ram::emit(hw, body);
    }
}

/// The span's `sq_x` and `sq_len` from the held ends `sq_mg`, `sq_hi3` (`end_w` bits).
fn span_of_ends(end_w: u32, xw: u32) -> Vec<Item> {
    vec![
        comment("The span's x = -mg and length hi3 + mg + 1, from the held ends."),
        comment("verilator lint_off UNUSEDSIGNAL"),
        wire("sq_lo", end_w, "-sq_mg"),
        wire("sq_lw", end_w, "sq_hi3 + sq_mg + 1"),
        comment("verilator lint_on UNUSEDSIGNAL"),
        wire("sq_x", xw, format!("sq_lo[{}:0]", xw - 1)),
        wire("sq_len", xw + 1, format!("sq_lw[{xw}:0]")),
    ]
}

/// The output register: the unit's result, `dI` from `di`.
fn output_register(di: String, body: &mut Vec<Item>) {
    body.push(comment("The output register: the unit's result, written when it is done and the output is free."));
    let write = vec![set("out_y", "sq_y"), set("out_x", "sq_x"), set("out_len", "sq_len"), set("out_i0", "sq_i0"), set("out_di", di)];
    body.push(Item::Always(vec![Stmt::If(
        "rst".into(),
        vec![set("out_valid", "1'b0")],
        vec![Stmt::If(
            "!out_valid || out_ready".into(),
            vec![set("out_valid", "sq_done"), Stmt::If("sq_done".into(), write, vec![])],
            vec![],
        )],
    )]));
}

/// The unit and the output register, after the walker: returns the span path's (empty) stages.
pub(super) fn emit(hw: &Hw, body: &mut Vec<Item>) -> Stager {
    let q = unit(hw).expect("the sequential span path");
    let fe = &hw.fe;
    let Widths { yw: row_w, aw: area_w, k: sum_w, rw: recip_w, .. } = fe.widths();
    let (xw, iw, dw) = (fe.cfg.xbits, fe.cfg.iw(), fe.cfg.dw());
    let (w, mp_w, cnt_w, b) = (q.acc_bits(), q.mp_bits(), count_bits(&q), q.bits);
    let s2_w = hw.s2n_bits();
    let zeros = Widths::GXN_ZEROS;
    let gx_w = s2_w - 1 - zeros;
    let t = fe.widths().i0_shift();
    let est = q.estimate_bits();
    let row = |n: &str| walker::row(hw, n);
    body.push(Item::Blank);
    body.push(comment(format!(
        "Sequential span path (golden::frontend::span_seq): a covered row's products on one accumulator, {b} multiplier bits a step;"
    )));
    body.push(comment("phases: 2Tn + An; + ((Gxn >> 8) << 9) lo = S2n; H Rn (q~ its top bits); ~L + An (q~ + 1); + An. Each a load"));
    body.push(comment(format!("clock (the accept for the first), then its steps: {} clocks a covered row.", q.row_clocks())));
    // The sums are read modulo 2^(K-2) (`Hw::s2n_bits`), Gxn without its zero bits.
    body.push(comment("verilator lint_off UNUSEDSIGNAL"));
    body.push(wire("unused_sums_top", 4, format!("{{w_tn[{0}:{1}], w_gxn[{0}:{1}]}}", sum_w - 1, sum_w - 2)));
    body.push(wire("unused_gxn_low", zeros, format!("{}[{}:0]", row("w_gxn"), zeros - 1)));
    body.push(comment("verilator lint_on UNUSEDSIGNAL"));
    // The triangle's values: without row stages the walker's own registers, which hold while
    // the unit is busy (`adv` is low, and the walker takes the next triangle only once it is
    // idle, `walker::emit`); behind row stages, which hold the rows after it, copies.
    let copies = hw.row_stage();
    let tri = |n: &str| -> String {
        match (copies, n) {
            (true, _) => format!("sq_{n}"),
            (false, "gxn") => format!("w_gxn[{}:{zeros}]", s2_w - 2),
            (false, _) => format!("w_{n}"),
        }
    };
    // Behind the lean edges the row's ends are held as the walker picks them and x and the length
    // formed from the registers: their adds after the picks were the HX8K's clock (docs/fpga.md).
    let ends = super::edge::ends_side_by_side(hw);
    let end_w = super::edge::end_width(hw);
    let mut held = vec![("sq_y", row_w)];
    held.extend(if ends { [("sq_mg", end_w), ("sq_hi3", end_w)] } else { [("sq_x", xw), ("sq_len", xw + 1)] });
    if copies {
        held.extend([("sq_di", dw), ("sq_gxn", gx_w), ("sq_an", area_w), ("sq_rn", recip_w)]);
    }
    held.extend([("sq_l", area_w + 2), ("sq_qt", iw), ("sq_ge2", 1), ("sq_acc", w), ("sq_mc", w), ("sq_mp", mp_w)]);
    body.extend(held.iter().map(|(n, ww)| reg(n, *ww)));
    if ends {
        body.extend(span_of_ends(end_w, xw));
    }
    // One step: the accumulator plus the multiplicand times the multiplier's low B bits, as B
    // shifted adds (an iCE40 LUT4 and carry a bit each).
    let terms: Vec<String> = (0..b)
        .map(|k| {
            let shifted = if k == 0 { "sq_mc".to_string() } else { format!("(sq_mc << {k})") };
            format!("({{{w}{{sq_mp[{k}]}}}} & {shifted})")
        })
        .collect();
    body.push(wire("sq_sum", w, format!("sq_acc + {}", terms.join(" + "))));
    body.push(wire("sq_qt_now", iw, format!("sq_acc[{}:{}]", est - 1, est - iw)));
    body.push(wire("sq_i0", iw, format!("sq_acc[{0}] ? sq_qt + {1} : sq_ge2 ? sq_qt + {2} : sq_qt", area_w + 1, lit(iw, 2), lit(iw, 1))));
    let acc_load = |a: AccLoad| -> Option<String> {
        match a {
            AccLoad::Tn2 => Some(format!("{{{}[{}:0], 1'b0}}", row("w_tn"), s2_w - 2)),
            AccLoad::Keep => None,
            AccLoad::Zero => Some(lit(w, 0)),
            AccLoad::NotL => Some(zext("~sq_l", area_w + 2, w)),
        }
    };
    let mc_load = |m: Multiplicand, accept: bool| match m {
        Multiplicand::An if accept => zext(&row("w_an"), area_w, w),
        Multiplicand::An => zext(&tri("an"), area_w, w),
        Multiplicand::Gx => format!("{{{}, {}}}", tri("gxn"), lit(zeros + 1, 0)),
        Multiplicand::H => zext(&format!("sq_acc[{}:{t}]", w - 1), w - t, w),
    };
    let mp_load = |m: Multiplier| match m {
        Multiplier::One => lit(mp_w, 1),
        Multiplier::Lo => zext("sq_x", xw, mp_w),
        Multiplier::Rn => zext(&tri("rn"), recip_w, mp_w),
        Multiplier::Qt1 => zext(&format!("{} + {}", zext("sq_qt_now", iw, iw + 1), lit(iw + 1, 1)), iw + 1, mp_w),
    };
    let load = |k: usize, accept: bool| -> Vec<Stmt> {
        let p = SpanSeq::PHASES[k];
        let mut v = vec![set("sq_ph", lit(phase_bits(), k as u64))];
        v.push(set("sq_cnt", lit(cnt_w, q.steps(&p) as u64)));
        v.extend(acc_load(p.acc).map(|a| set("sq_acc", a)));
        v.push(set("sq_mc", mc_load(p.mc, accept)));
        v.push(set("sq_mp", mp_load(p.mp)));
        // What the load reads of the accumulator before it is loaded (golden's `i0_with`).
        match k {
            2 => v.push(set("sq_l", format!("sq_acc[{}:1]", area_w + 2))),
            3 => v.push(set("sq_qt", "sq_qt_now")),
            4 => v.push(set("sq_ge2", format!("sq_acc[{}]", area_w + 1))),
            _ => {}
        }
        v
    };
    // Whenever the walker moves the unit loads its row (busy only when the row has a pixel): its
    // ~300 registers' enable is then `adv` alone, where with the walker's pixel test in it that
    // test's fan-out was the HX8K's critical path at level 0 (docs/fpga.md).
    let mut on_accept = vec![set("sq_busy", "emit")];
    on_accept.extend(load(0, true));
    on_accept.push(set("sq_y", row("w_row")));
    if ends {
        on_accept.extend([set("sq_mg", "mg"), set("sq_hi3", "hi3")]);
    } else {
        on_accept.extend([set("sq_x", "lo_u"), set("sq_len", format!("len_w[{xw}:0]"))]);
    }
    if copies {
        on_accept.extend([
            set("sq_di", row("w_di")),
            set("sq_gxn", format!("{}[{}:{zeros}]", row("w_gxn"), s2_w - 2)),
            set("sq_an", row("w_an")),
            set("sq_rn", row("w_rn")),
        ]);
    }
    let step = vec![
        set("sq_acc", "sq_sum"),
        set("sq_mc", format!("sq_mc << {b}")),
        set("sq_mp", format!("sq_mp >> {b}")),
        set("sq_cnt", format!("sq_cnt - {}", lit(cnt_w, 1))),
    ];
    let phase_w = phase_bits();
    // The next phase's load, by the current phase (none after the last: its result waits).
    let mut next: Vec<Stmt> = Vec::new();
    for k in (1..SpanSeq::PHASES.len()).rev() {
        next = vec![Stmt::If(format!("sq_ph == {}", lit(phase_w, k as u64 - 1)), load(k, false), next)];
    }
    let busy = vec![Stmt::If(format!("sq_cnt != {}", lit(cnt_w, 0)), step, next)];
    body.push(Item::Always(vec![Stmt::If(
        "rst".into(),
        vec![set("sq_busy", "1'b0")],
        vec![Stmt::If("adv".into(), on_accept, vec![Stmt::If("sq_busy".into(), busy, vec![])])],
    )]));
    // Where the walk memory holds dI, its read register's, `An`'s word when the unit is done.
    output_register(walk_ram::di_value(hw).map_or_else(|| tri("di"), str::to_string), body);
    if hw.walk_ram() {
        walk_ram::emit_ports(hw, body);
    }
    Stager::new("p", Vec::new())
}
