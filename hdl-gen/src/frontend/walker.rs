//! The edge walker: one row per clock, one DDA step per active edge (in each `tri_fe_edge`),
//! the span's ends compared side by side; it loads the next triangle in the clock its current
//! one finishes.

use super::divider::Div;
use super::edge;
use super::hw::{slit, Hw};
use crate::verilog::{assign, comment, lit, net, reg, set, sext, swire, wire, Item, Stmt};
use crate::Names;
use golden::frontend::{DiMode, Widths};

/// The per-scanline dI's divider (the comparison option `--fe-di scanline`), and its counter's
/// width: IW quotient bits.
pub(super) fn scanline_divider(hw: &Hw) -> (Div, u32) {
    let (xw, iw) = (hw.fe.cfg.xbits, hw.fe.cfg.iw());
    (Div { name: "u_sdv", pw: xw + iw + 2, qb: iw }, 32 - (iw - 1).leading_zeros())
}

pub(super) fn emit(hw: &Hw, names: &Names, body: &mut Vec<Item>) {
    let fe = &hw.fe;
    let Widths { yw: row_w, aw: area_w, k: sum_w, rw: recip_w, .. } = fe.widths();
    let (xw, dw) = (fe.cfg.xbits, fe.cfg.dw());
    let w = fe.screen.width as i64;
    body.push(comment("Walker: the triangle being walked, one row per clock (each edge's DDA in g_edge[k].u_edge)."));
    body.push(reg("w_valid", 1));
    body.push(reg("w_row", row_w));
    body.push(reg("w_last", row_w));
    for (n, ww) in [("w_di", dw), ("w_an", area_w), ("w_rn", recip_w), ("w_tn", sum_w), ("w_gxn", sum_w), ("w_dyn", sum_w)] {
        body.push(reg(n, ww));
    }
    if fe.di == DiMode::Scanline {
        let (_, sd_cnt_w) = scanline_divider(hw);
        body.push(comment("Per-scanline dI (the comparison option): a restoring divider, busy for each span of m >= 2."));
        body.extend([reg("sd_busy", 1), reg("sd_cnt", sd_cnt_w), reg("sd_neg", 1)]);
        body.push(wire("adv", 1, "(!out_valid || out_ready) && !sd_busy"));
    } else {
        body.push(wire("adv", 1, "!out_valid || out_ready"));
    }
    body.push(wire("w_end", 1, "w_row == w_last"));
    let inc = super::incremental::on(hw);
    let engine = hw.engine_form();
    if engine {
        body.push(assign("take", "q_ne && adv && (!w_valid || w_end)"));
    } else if !inc {
        body.push(assign("take", "st == HOLD && adv && (!w_valid || w_end)"));
    }
    let end_w = edge::end_width(hw);
    body.push(swire("lo0", end_w, slit(end_w, 0)));
    body.push(swire("hi0", end_w, slit(end_w, w - 1)));
    body.push(comment("The edges: loaded with the set-up result, stepped a row; each one's bound on the row."));
    body.push(wire("w_load", 1, "!rst && take"));
    // The incremental I0's walker also waits for its start engine (`ie_wait`, declared below).
    let step_when = "!rst && !take && adv && w_valid && !w_end";
    if inc {
        body.push(net("w_step", 1));
    } else {
        body.push(wire("w_step", 1, step_when));
    }
    body.push(net("e_lg", 3 * end_w));
    body.push(net("e_ha", 3 * end_w));
    let state = edge::state_outputs(hw);
    for (port, w, ..) in &state {
        body.push(net(&format!("e_{port}"), 3 * w));
    }
    body.push(edge::instances(hw, names, &edge::input_buses(hw)));
    // The incremental I0 reads each edge's state by its own names, lane k of the edges' buses.
    for (port, w, signed, _, name) in &state {
        for k in 0..3 {
            let lane = if *w == 1 { format!("e_{port}[{k}]") } else { format!("e_{port}[{}:{}]", (k + 1) * w - 1, k * w) };
            let alias = format!("{name}{k}");
            body.push(if *signed { swire(&alias, *w, lane) } else { wire(&alias, *w, lane) });
        }
    }
    for k in 0..3 {
        body.push(swire(&format!("lg{k}"), end_w, format!("e_lg[{}:{}]", (k + 1) * end_w - 1, k * end_w)));
        body.push(swire(&format!("ha{k}"), end_w, format!("e_ha[{}:{}]", (k + 1) * end_w - 1, k * end_w)));
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
        body.push(assign("w_step", format!("{step_when} && !ie_wait")));
    } else {
        body.push(wire("emit", 1, format!("w_valid && !room[{end_w}]")));
    }
    body.push(wire("lo_u", xw, format!("lo3[{}:0]", xw - 1)));
    let mut load = vec![set("w_valid", "1'b1"), set("w_row", "s_first"), set("w_last", "s_last")];
    load.extend([
        set("w_di", "r_di"),
        set("w_an", "s_an"),
        set("w_rn", if engine { "r_rn" } else { "drn_q" }),
        set("w_tn", "s_tn"),
        set("w_gxn", "s_gxn"),
        set("w_dyn", "s_dyn"),
    ]);
    let step = vec![set("w_row", format!("w_row + {}", lit(row_w, 1))), set("w_tn", "w_tn + w_dyn")];
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
