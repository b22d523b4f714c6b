//! The edge walker: one row per clock, one DDA step per active edge, the span's ends compared
//! side by side; it loads the next triangle in the clock its current one finishes.

use super::divider::{div_regs, Div};
use super::hw::{slit, Hw};
use crate::verilog::{assign, comment, lit, reg, set, sext, sreg, swire, wire, zext, Item, Stmt};
use golden::frontend::{DiMode, Widths};

/// The per-scanline dI's divider (the comparison option `--fe-di scanline`), and its counter's
/// width: IW quotient bits.
pub(super) fn scanline_divider(hw: &Hw) -> (Div, u32) {
    let (xw, iw) = (hw.fe.cfg.xbits, hw.fe.cfg.iw());
    (Div { name: "sdv", pw: xw + iw + 2, qb: iw }, 32 - (iw - 1).leading_zeros())
}

pub(super) fn emit(hw: &Hw, body: &mut Vec<Item>) {
    let fe = &hw.fe;
    let Widths { yw: row_w, aw: area_w, gw: bound_w, dw_edge: ediv_w, k: sum_w, rw: recip_w, .. } = fe.widths();
    let (xw, dw) = (fe.cfg.xbits, fe.cfg.dw());
    let w = fe.screen.width as i64;
    body.push(comment("Walker: the triangle being walked, one row per clock."));
    body.push(reg("w_valid", 1));
    body.push(reg("w_row", row_w));
    body.push(reg("w_last", row_w));
    for k in 0..3 {
        for (n, ww) in [("act", 1), ("right", 1), ("rs", row_w), ("re", row_w), ("d", ediv_w), ("rem", ediv_w), ("rs256_", ediv_w)] {
            body.push(reg(&format!("w_{n}{k}"), ww));
        }
        body.push(sreg(&format!("w_g{k}"), bound_w));
        body.push(sreg(&format!("w_qs{k}"), bound_w));
    }
    for (n, ww) in [("w_di", dw), ("w_an", area_w), ("w_rn", recip_w), ("w_tn", sum_w), ("w_gxn", sum_w), ("w_dyn", sum_w)] {
        body.push(reg(n, ww));
    }
    if fe.di == DiMode::Scanline {
        let (sdv, sd_cnt_w) = scanline_divider(hw);
        body.push(comment("Per-scanline dI (the comparison option): a restoring divider, busy for each span of m >= 2."));
        body.extend([reg("sd_busy", 1), reg("sd_cnt", sd_cnt_w), reg("sd_neg", 1)]);
        body.extend(div_regs(&sdv));
        body.push(wire("adv", 1, "(!out_valid || out_ready) && !sd_busy"));
    } else {
        body.push(wire("adv", 1, "!out_valid || out_ready"));
    }
    body.push(wire("w_end", 1, "w_row == w_last"));
    let inc = super::incremental::on(hw);
    if !inc {
        body.push(assign("take", "st == HOLD && adv && (!w_valid || w_end)"));
    }
    let end_w = bound_w + 1;
    body.push(swire("lo0", end_w, slit(end_w, 0)));
    body.push(swire("hi0", end_w, slit(end_w, w - 1)));
    for k in 0..3 {
        body.push(wire(&format!("in{k}"), 1, format!("w_act{k} && w_row >= w_rs{k} && w_row <= w_re{k}")));
        body.push(swire(&format!("gg{k}"), end_w, sext(&format!("w_g{k}"), bound_w, end_w)));
        // This edge's bound on its side of the row, or the screen's where it bounds none here;
        // a left edge's bound is -g, kept as g (its smallest is the span's left end).
        body.push(swire(&format!("lg{k}"), end_w, format!("(in{k} && !w_right{k} && gg{k} < lo0) ? gg{k} : lo0")));
        body.push(swire(&format!("ha{k}"), end_w, format!("(in{k} && w_right{k} && gg{k} < hi0) ? gg{k} : hi0")));
    }
    // Side by side rather than in a chain, and no negation before the pixel test or the length:
    // this is the walker's row clock, the staged front-end's limit at 2 and 1 quotient bits.
    body.push(comment("The span's ends, the edges compared side by side: x = lo3 = -mg (the smallest left-edge g),"));
    body.push(comment("hi3 the smallest right bound; the row has a pixel when hi3 + mg >= 0."));
    for (end, side) in [("mg", "lg"), ("hi3", "ha")] {
        let c = |i: u32, j: u32| format!("{side}{i} <= {side}{j}");
        body.push(swire(end, end_w, format!("({} && {}) ? {side}0 : ({}) ? {side}1 : {side}2", c(0, 1), c(0, 2), c(1, 2))));
    }
    body.push(comment("verilator lint_off UNUSEDSIGNAL"));
    body.push(swire("lo3", end_w, "-mg"));
    body.push(swire("room", end_w + 1, format!("{} + {}", sext("hi3", end_w, end_w + 1), sext("mg", end_w, end_w + 1))));
    body.push(wire("len_w", end_w, "hi3 + mg + 1"));
    body.push(comment("verilator lint_on UNUSEDSIGNAL"));
    if inc {
        body.push(wire("px", 1, format!("w_valid && !room[{end_w}]")));
        super::incremental::select(hw, body);
        body.push(wire("emit", 1, "px && !ie_wait"));
    } else {
        body.push(wire("emit", 1, format!("w_valid && !room[{end_w}]")));
    }
    body.push(wire("lo_u", xw, format!("lo3[{}:0]", xw - 1)));
    for k in 0..3 {
        body.push(wire(
            &format!("rsum{k}"),
            ediv_w + 1,
            format!("{} + {}", zext(&format!("w_rem{k}"), ediv_w, ediv_w + 1), zext(&format!("w_rs256_{k}"), ediv_w, ediv_w + 1)),
        ));
        body.push(wire(&format!("cy{k}"), 1, format!("rsum{k} >= {}", zext(&format!("w_d{k}"), ediv_w, ediv_w + 1))));
        body.push(comment("verilator lint_off UNUSEDSIGNAL"));
        body.push(wire(
            &format!("rnext{k}"),
            ediv_w + 1,
            format!("cy{k} ? rsum{k} - {} : rsum{k}", zext(&format!("w_d{k}"), ediv_w, ediv_w + 1)),
        ));
        body.push(comment("verilator lint_on UNUSEDSIGNAL"));
    }
    let mut load = vec![set("w_valid", "1'b1"), set("w_row", "s_first"), set("w_last", "s_last")];
    for k in 0..3 {
        for (n, v) in [
            ("act", format!("s_act{k}")),
            ("right", format!("s_right{k}")),
            ("rs", format!("s_rs{k}")),
            ("re", format!("s_re{k}")),
            ("d", format!("s_d{k}")),
        ] {
            load.push(set(format!("w_{n}{k}"), v));
        }
        load.push(set(format!("w_g{k}"), format!("r_g{k}")));
        load.push(set(format!("w_rem{k}"), format!("r_rem{k}")));
        load.push(set(format!("w_qs{k}"), format!("r_qs{k}")));
        load.push(set(format!("w_rs256_{k}"), format!("r_rs256_{k}")));
    }
    load.extend([
        set("w_di", "r_di"),
        set("w_an", "s_an"),
        set("w_rn", "drn_q"),
        set("w_tn", "s_tn"),
        set("w_gxn", "s_gxn"),
        set("w_dyn", "s_dyn"),
    ]);
    let mut step = vec![set("w_row", format!("w_row + {}", lit(row_w, 1))), set("w_tn", "w_tn + w_dyn")];
    for k in 0..3 {
        step.push(Stmt::If(
            format!("w_act{k} && w_row >= w_rs{k}"),
            vec![
                set(format!("w_rem{k}"), format!("rnext{k}[{}:0]", ediv_w - 1)),
                set(format!("w_g{k}"), format!("w_g{k} + w_qs{k} + {}", zext(&format!("cy{k}"), 1, bound_w))),
            ],
            vec![],
        ));
    }
    body.push(Item::Always(vec![Stmt::If(
        "rst".into(),
        vec![set("w_valid", "1'b0")],
        vec![Stmt::If(
            "take".into(),
            load,
            vec![Stmt::If(
                if inc { "adv && w_valid && !ie_wait" } else { "adv && w_valid" }.into(),
                vec![Stmt::If("w_end".into(), vec![set("w_valid", "1'b0")], step)],
                vec![],
            )],
        )],
    )]));
    body.push(Item::Blank);
    if inc {
        super::incremental::engine(hw, body);
    }
}
