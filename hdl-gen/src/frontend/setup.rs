//! The set-up around CALC: the vertex registers, CALC's stages and their moves, the set-up
//! result (the edges' part is in each `tri_fe_edge`, with its two divisions; dI's and the
//! reciprocal's dividers are here) and the state machine that completes it (`IDLE`, `DIV`,
//! `HOLD`).

use super::calc::calc;
use super::divider::counter_width;
use super::divider::{Div, DivConns};
use super::edge;
use super::hw::Hw;
use super::stager::Stager;
use crate::verilog::{assign, comment, lit, net, reg, set, sreg, wire, zext, Item, Stmt};
use crate::Names;
use golden::frontend::Widths;

/// What the set-up hands on: CALC (its stage registers, for the properties), the dividers'
/// registers (hierarchical names after flattening, as a proof cuts them) and their counter's
/// width, and CALC's decisions on the last stage.
pub(super) struct Setup {
    pub st: Stager,
    pub div_regs: Vec<String>,
    pub cnt_w: u32,
    pub guard: String,
    pub cull: String,
}

/// CALC stage j's valid bit; stage 0 is the vertex registers.
pub(super) fn valid(j: usize) -> String {
    if j == 0 {
        "v_full".to_string()
    } else {
        format!("c{j}_v")
    }
}

/// Stage j's triangle moves on; the last stage's move is the dividers' load (`calc`).
fn mv(j: usize, last: usize) -> String {
    if j == last {
        "calc".to_string()
    } else {
        format!("c{j}_mv")
    }
}

/// The set-up, from the vertex registers to the set-up result the walker loads.
pub(super) fn emit(hw: &Hw, names: &Names, body: &mut Vec<Item>) -> Setup {
    let wd = hw.fe.widths();
    let cnt_w = counter_width(&wd);
    state(hw, cnt_w, body);
    let st = calc(hw);
    // What the last CALC stage hands on (the edges' values, the dividers' loads, the set-up's
    // result, the decision) is read before the stage registers are declared, so every register
    // carrying it is among them.
    let edges = edge_inputs(hw, &st);
    let (ddi, drn) = dividers(hw);
    let divs = divider_instances(hw, names, &st, &ddi, &drn, cnt_w);
    let load = calc_load(hw, &st, cnt_w);
    let (guard, cull) = (st.at("guard_ok"), st.at("cull"));
    let v_go = calc_stages(&st, body);
    body.push(comment("The set-up's load (CALC's last clock, the triangle kept) and its dividers' clocks."));
    body.push(wire("calc_go", 1, format!("!rst && calc && {guard} && !{cull}")));
    body.push(wire("div_run", 1, "!rst && !calc && st == DIV"));
    body.extend(edges);
    results_regs(hw, divs, body);
    control(hw, cnt_w, load, &v_go, &guard, &cull, body);
    results(hw, body);
    let mut div_regs = Vec::new();
    for d in edge::dividers(hw) {
        div_regs.extend(["p", "d", "q"].map(|r| format!("g_edge*.u_edge.{}.{r}", d.name)));
    }
    for d in [&ddi, &drn] {
        div_regs.extend(["p", "d", "q"].map(|r| format!("{}.{r}", d.name)));
    }
    Setup { st, div_regs, cnt_w, guard, cull }
}

fn state(hw: &Hw, cnt_w: u32, body: &mut Vec<Item>) {
    let Widths { cx: vx_w, cy: vy_w, .. } = hw.fe.widths();
    let iw = hw.fe.cfg.iw();
    body.extend([
        comment("Set-up: a triangle waits in the vertex registers (v_full) until the dividers are free: idle, or"),
        comment("handing their last result to the walker (take). In that clock CALC computes everything and loads"),
        comment("the dividers; DIV runs them; HOLD offers the result. The next triangle is latched meanwhile."),
    ]);
    body.push(Item::Localparam { name: "IDLE".into(), width: 2, value: "2'd0".into() });
    body.push(Item::Localparam { name: "DIV".into(), width: 2, value: "2'd2".into() });
    body.push(Item::Localparam { name: "HOLD".into(), width: 2, value: "2'd3".into() });
    body.push(reg("st", 2));
    body.push(reg("div_cnt", cnt_w));
    for k in 0..3 {
        body.push(sreg(&format!("vx{k}"), vx_w));
        body.push(sreg(&format!("vy{k}"), vy_w));
        body.push(reg(&format!("vi{k}"), iw));
    }
    body.push(reg("v_full", 1));
    body.push(net("take", 1));
}

/// dI's divider (ddi) and the reciprocal's (drn); the edges' are in `tri_fe_edge`.
fn dividers(hw: &Hw) -> (Div, Div) {
    let Widths { aw: area_w, rw: recip_w, .. } = hw.fe.widths();
    let iw = hw.fe.cfg.iw();
    (Div { name: "u_ddi", pw: iw + area_w + 1, qb: iw }, Div { name: "u_drn", pw: area_w + recip_w + 1, qb: recip_w })
}

/// CALC's per-edge values as buses of three lanes, edge k in lane k, for the edges' `generate`
/// loop.
fn edge_inputs(hw: &Hw, st: &Stager) -> Vec<Item> {
    let row_w = hw.fe.widths().yw;
    let mut items = vec![comment("CALC's values for the edges, edge k in lane k.")];
    for (port, bus, w) in edge::input_buses(hw).inputs {
        let lane = |k: usize| match port {
            "n" => format!("{}[{}:0]", st.at(&format!("n{k}")), w - 1),
            "sn" => format!("{}[{}:0]", st.at(&format!("sn{k}")), w - 1),
            "ady" => st.at(&format!("ady{k}")),
            "act" => st.at(&format!("act{k}")),
            "right" => format!("!{}", st.at(&format!("dyneg{k}"))),
            "rs" => st.at(&format!("rsu{k}")),
            "re" => format!("{}[{}:0]", st.at(&format!("re{k}")), row_w - 1),
            _ => unreachable!("an edge input {port} CALC does not compute"),
        };
        let lanes: Vec<String> = (0..3).rev().map(lane).collect();
        items.push(wire(bus, 3 * w, format!("{{{}}}", lanes.join(", "))));
    }
    items
}

/// dI's and the reciprocal's dividers, loaded in CALC's last clock.
fn divider_instances(hw: &Hw, names: &Names, st: &Stager, ddi: &Div, drn: &Div, cnt_w: u32) -> Vec<Item> {
    let Widths { aw: area_w, k: sum_w, rw: recip_w, .. } = hw.fe.widths();
    let iw = hw.fe.cfg.iw();
    let (x2, x2w) = (st.at("x2"), st.width("x2"));
    let x2_fit = if x2w >= ddi.pw { format!("{x2}[{}:0]", ddi.pw - 1) } else { zext(&x2, x2w, ddi.pw) };
    let ddi_dv = format!("{} << {}", zext(&st.at("aabs"), area_w, ddi.pw), iw);
    let drn_n = format!("{} << {}", lit(drn.pw, 1), sum_w);
    let drn_dv = format!("{} << {}", zext(&st.at("an"), area_w, drn.pw), recip_w);
    let mut items = vec![comment("Its dividers: dI's quotient (ddi) and the reciprocal Rn = 2^K / (2 An) (drn).")];
    for (d, dividend, divisor) in [(ddi, x2_fit.as_str(), ddi_dv.as_str()), (drn, drn_n.as_str(), drn_dv.as_str())] {
        let conns = DivConns { cnt: "div_cnt", load: "calc_go", run: "div_run", dividend, divisor };
        items.extend(d.instance(&names.fe_div, hw.div_bits, cnt_w, &conns, &["q"]));
    }
    items
}

/// CALC's last clock: start the dividers' counter and load the set-up result registers.
fn calc_load(hw: &Hw, st: &Stager, cnt_w: u32) -> Vec<Stmt> {
    let recip_w = hw.fe.widths().rw;
    let mut calc_load = vec![set("div_cnt", lit(cnt_w, (recip_w - 1) as u64)), set("st", "DIV")];
    for (r, v) in [
        ("s_first", "first_u"),
        ("s_last", "last_u"),
        ("s_an", "an"),
        ("s_tn", "tn0"),
        ("s_gxn", "gxn0"),
        ("s_dyn", "dyn0"),
        ("s_sat", "di_sat"),
        ("s_dineg", "nx_neg"),
    ] {
        calc_load.push(set(r, st.at(v)));
    }
    if super::incremental::on(hw) {
        calc_load.extend(super::incremental::setup_load(st));
    }
    calc_load
}

/// CALC's stage registers and their moves; returns the vertex registers' move.
fn calc_stages(st: &Stager, body: &mut Vec<Item>) -> String {
    let last = st.stage();
    // The stages' moves: stage j's triangle moves into stage j + 1 when that one is empty or
    // moving on; the last stage moves on into the dividers (calc).
    let mv = |j: usize| mv(j, last);
    let v_go = mv(0);
    for j in 1..=last {
        body.push(reg(&valid(j), 1));
    }
    body.push(wire("calc", 1, format!("{} && (st == IDLE || take)", valid(last))));
    for j in (0..last).rev() {
        body.push(wire(&mv(j), 1, format!("{} && (!{} || {})", valid(j), valid(j + 1), mv(j + 1))));
    }
    body.push(assign("in_ready", format!("!v_full || {}", mv(0))));
    // Stages hand on whole values and read slices of some: unused bits are expected here.
    body.push(comment("verilator lint_off UNUSEDSIGNAL"));
    body.extend(st.items());
    body.push(comment("verilator lint_on UNUSEDSIGNAL"));
    if last > 0 {
        let mut moves = Vec::new();
        let mut data = Vec::new();
        for j in 1..=last {
            moves.push(Stmt::If(mv(j - 1), vec![set(valid(j), "1'b1")], vec![Stmt::If(mv(j), vec![set(valid(j), "1'b0")], vec![])]));
            data.push(Stmt::If(mv(j - 1), st.loads(j - 1), vec![]));
        }
        body.push(Item::Always(vec![Stmt::If("rst".into(), (1..=last).map(|j| set(valid(j), "1'b0")).collect(), moves)]));
        body.push(Item::Always(data));
    }
    body.push(Item::Blank);
    v_go
}

/// The set-up result's triangle-wide registers, and its dividers.
fn results_regs(hw: &Hw, divs: Vec<Item>, body: &mut Vec<Item>) {
    let Widths { yw: row_w, aw: area_w, k: sum_w, .. } = hw.fe.widths();
    body.push(comment("The set-up result, complete when the dividers are (HOLD): the edges' in g_edge[k].u_edge, and:"));
    for (n, ww) in [("s_first", row_w), ("s_last", row_w), ("s_an", area_w), ("s_tn", sum_w), ("s_gxn", sum_w), ("s_dyn", sum_w)] {
        body.push(reg(n, ww));
    }
    body.push(reg("s_sat", 1));
    body.push(reg("s_dineg", 1));
    body.extend(divs);
    if super::incremental::on(hw) {
        super::incremental::setup_regs(hw, body);
    }
    body.push(Item::Blank);
}

/// The set-up's state machine: take a triangle, CALC (drop it, or load the dividers), DIV, HOLD.
fn control(hw: &Hw, cnt_w: u32, calc_load: Vec<Stmt>, v_go: &str, guard: &str, cull: &str, body: &mut Vec<Item>) {
    let bits = hw.div_bits;
    let div_run = vec![Stmt::If(
        format!("div_cnt < {}", lit(cnt_w, bits as u64)),
        vec![set("st", "HOLD")],
        vec![set("div_cnt", format!("div_cnt - {}", lit(cnt_w, bits as u64)))],
    )];
    let mut take_in = vec![set("v_full", "1'b1")];
    for k in 0..3 {
        take_in.push(set(format!("vx{k}"), format!("in_x{k}")));
        take_in.push(set(format!("vy{k}"), format!("in_y{k}")));
        take_in.push(set(format!("vi{k}"), format!("in_i{k}")));
    }
    body.push(Item::Always(vec![Stmt::If(
        "rst".into(),
        vec![set("st", "IDLE"), set("v_full", "1'b0"), set("err", "1'b0")],
        vec![
            set("err", "1'b0"),
            Stmt::If("in_valid && in_ready".into(), take_in, vec![Stmt::If(v_go.into(), vec![set("v_full", "1'b0")], vec![])]),
            Stmt::If(
                "calc".into(),
                vec![Stmt::If(
                    format!("!{guard}"),
                    vec![set("err", "1'b1"), set("st", "IDLE")],
                    vec![Stmt::If(cull.into(), vec![set("st", "IDLE")], calc_load)],
                )],
                vec![Stmt::If("st == DIV".into(), div_run, vec![]), Stmt::If("take".into(), vec![set("st", "IDLE")], vec![])],
            ),
        ],
    )]));
    body.push(Item::Blank);
}

/// dI as the walker loads it: the quotient with its sign, or saturated.
fn results(hw: &Hw, body: &mut Vec<Item>) {
    let (iw, dw) = (hw.fe.cfg.iw(), hw.fe.cfg.dw());
    let max_pos = format!("{{1'b0, {{{iw}{{1'b1}}}}}}");
    let max_neg = format!("{{1'b1, {}}}", lit(iw, 0));
    body.push(wire(
        "r_di",
        dw,
        format!("s_sat ? (s_dineg ? {max_neg} : {max_pos}) : (s_dineg ? -{} : {})", zext("ddi_q", iw, dw), zext("ddi_q", iw, dw)),
    ));
    body.push(Item::Blank);
}
