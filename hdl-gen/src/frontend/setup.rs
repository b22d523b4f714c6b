//! The set-up around CALC: the vertex registers, CALC's stages and their moves, the eight
//! restoring dividers and the set-up result they complete (`IDLE`, `DIV`, `HOLD`).

use super::calc::calc;
use super::divider::{div_chain, div_iter, div_load, div_regs, Div};
use super::hw::Hw;
use super::stager::Stager;
use crate::verilog::{assign, comment, lit, net, reg, set, sreg, wire, zext, Item, Stmt};
use golden::frontend::Widths;

/// What the set-up hands on: CALC (its stage registers, for the properties), the dividers and
/// their counter's width, and CALC's decisions on the last stage.
pub(super) struct Setup {
    pub st: Stager,
    pub divs: Vec<Div>,
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

/// Clocks' worth of quotient bits the shared counter counts: the reciprocal's RW.
pub(super) fn counter_width(wd: &Widths) -> u32 {
    32 - wd.rw.leading_zeros()
}

/// The set-up, from the vertex registers to the divider results (`r_*`) the walker loads.
pub(super) fn emit(hw: &Hw, body: &mut Vec<Item>) -> Setup {
    let wd = hw.fe.widths();
    let cnt_w = counter_width(&wd);
    state(hw, cnt_w, body);
    let st = calc(hw);
    // What the last CALC stage hands on (the dividers' loads, the set-up's result, the decision)
    // is read before the stage registers are declared, so every register carrying it is among them.
    let divs = dividers(hw);
    let load = calc_load(hw, &st, &divs, cnt_w);
    let (guard, cull) = (st.at("guard_ok"), st.at("cull"));
    let v_go = calc_stages(&st, body);
    divider_regs(hw, &divs, cnt_w, body);
    control(hw, &divs, cnt_w, load, &v_go, &guard, &cull, body);
    results(hw, body);
    Setup { st, divs, cnt_w, guard, cull }
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

/// Per edge its first bound (ei) and its step (es), then dI (ddi) and the reciprocal (drn).
fn dividers(hw: &Hw) -> Vec<Div> {
    let Widths { cy: vy_w, aw: area_w, gw: bound_w, dw_edge: ediv_w, rw: recip_w, .. } = hw.fe.widths();
    let iw = hw.fe.cfg.iw();
    let (pw_init, pw_step) = (bound_w + ediv_w, bound_w + vy_w);
    (0..3)
        .flat_map(|k| {
            [
                Div { name: ["ei0", "ei1", "ei2"][k], pw: pw_init, qb: bound_w },
                Div { name: ["es0", "es1", "es2"][k], pw: pw_step, qb: bound_w },
            ]
        })
        .chain([Div { name: "ddi", pw: iw + area_w + 1, qb: iw }, Div { name: "drn", pw: area_w + recip_w + 1, qb: recip_w }])
        .collect()
}

/// CALC's last clock: load the dividers and the set-up result registers.
fn calc_load(hw: &Hw, st: &Stager, divs: &[Div], cnt_w: u32) -> Vec<Stmt> {
    let Widths { yw: row_w, cy: vy_w, aw: area_w, gw: bound_w, dw_edge: ediv_w, k: sum_w, rw: recip_w, .. } = hw.fe.widths();
    let iw = hw.fe.cfg.iw();
    let (pw_init, pw_step) = (bound_w + ediv_w, bound_w + vy_w);
    let mut calc_load = vec![set("div_cnt", lit(cnt_w, (recip_w - 1) as u64)), set("st", "DIV")];
    for k in 0..3 {
        let ei = &divs[2 * k];
        let es = &divs[2 * k + 1];
        let ady = st.at(&format!("ady{k}"));
        calc_load.extend(div_load(
            ei,
            &format!("{}[{}:0]", st.at(&format!("n{k}")), pw_init - 1),
            &format!("{} << {}", zext(&ady, vy_w, pw_init), bound_w + 7),
        ));
        calc_load.extend(div_load(
            es,
            &format!("{}[{}:0]", st.at(&format!("sn{k}")), pw_step - 1),
            &format!("{} << {}", zext(&ady, vy_w, pw_step), bound_w - 1),
        ));
        calc_load.push(set(format!("s_act{k}"), st.at(&format!("act{k}"))));
        calc_load.push(set(format!("s_right{k}"), format!("!{}", st.at(&format!("dyneg{k}")))));
        calc_load.push(set(format!("s_rs{k}"), st.at(&format!("rsu{k}"))));
        calc_load.push(set(format!("s_re{k}"), format!("{}[{}:0]", st.at(&format!("re{k}")), row_w - 1)));
        calc_load.push(set(format!("s_d{k}"), format!("{{{ady}, 8'd0}}")));
    }
    let ddi_pw = iw + area_w + 1;
    let (x2, x2w) = (st.at("x2"), st.width("x2"));
    let x2_fit = if x2w >= ddi_pw { format!("{x2}[{}:0]", ddi_pw - 1) } else { zext(&x2, x2w, ddi_pw) };
    calc_load.extend(div_load(&divs[6], &x2_fit, &format!("{} << {}", zext(&st.at("aabs"), area_w, ddi_pw), iw)));
    calc_load.extend(div_load(
        &divs[7],
        &format!("{} << {}", lit(area_w + recip_w + 1, 1), sum_w),
        &format!("{} << {}", zext(&st.at("an"), area_w, area_w + recip_w + 1), recip_w),
    ));
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

fn divider_regs(hw: &Hw, divs: &[Div], cnt_w: u32, body: &mut Vec<Item>) {
    let Widths { yw: row_w, aw: area_w, dw_edge: ediv_w, k: sum_w, .. } = hw.fe.widths();
    let bits = hw.div_bits;
    body.push(comment("Eight restoring dividers, one quotient bit per clock, sharing one counter: per edge its first"));
    body.push(comment("bound (ei) and its step (es), then dI (ddi) and the reciprocal Rn = 2^K / (2 An) (drn)."));
    for d in divs {
        body.extend(div_regs(d));
    }
    for d in divs {
        body.extend(div_chain(d, "div_cnt", cnt_w, bits));
    }
    body.push(comment("The set-up result, complete when the dividers are (HOLD)."));
    for k in 0..3 {
        body.push(reg(&format!("s_act{k}"), 1));
        body.push(reg(&format!("s_right{k}"), 1));
        body.push(reg(&format!("s_rs{k}"), row_w));
        body.push(reg(&format!("s_re{k}"), row_w));
        body.push(reg(&format!("s_d{k}"), ediv_w));
    }
    for (n, ww) in [("s_first", row_w), ("s_last", row_w), ("s_an", area_w), ("s_tn", sum_w), ("s_gxn", sum_w), ("s_dyn", sum_w)] {
        body.push(reg(n, ww));
    }
    body.push(reg("s_sat", 1));
    body.push(reg("s_dineg", 1));
    if super::incremental::on(hw) {
        super::incremental::setup_regs(hw, body);
    }
    body.push(Item::Blank);
}

/// The set-up's state machine: take a triangle, CALC (drop it, or load the dividers), DIV, HOLD.
#[allow(clippy::too_many_arguments)]
fn control(hw: &Hw, divs: &[Div], cnt_w: u32, calc_load: Vec<Stmt>, v_go: &str, guard: &str, cull: &str, body: &mut Vec<Item>) {
    let bits = hw.div_bits;
    let mut div_run: Vec<Stmt> = divs.iter().flat_map(|d| div_iter(d, bits)).collect();
    div_run.push(Stmt::If(
        format!("div_cnt < {}", lit(cnt_w, bits as u64)),
        vec![set("st", "HOLD")],
        vec![set("div_cnt", format!("div_cnt - {}", lit(cnt_w, bits as u64)))],
    ));
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

/// The dividers' results as the walker loads them.
fn results(hw: &Hw, body: &mut Vec<Item>) {
    let Widths { cy: vy_w, gw: bound_w, dw_edge: ediv_w, .. } = hw.fe.widths();
    let (iw, dw) = (hw.fe.cfg.iw(), hw.fe.cfg.dw());

    // Results of the dividers.
    body.push(comment("Divider results: bounds and steps (q - B), the remainders, dI with its sign and saturation."));
    body.push(comment("verilator lint_off UNUSEDSIGNAL"));
    for k in 0..3 {
        let flip = |q: &str| if bound_w == 1 { format!("~{q}") } else { format!("{{~{q}[{}], {q}[{}:0]}}", bound_w - 1, bound_w - 2) };
        body.push(wire(&format!("r_g{k}"), bound_w, flip(&format!("ei{k}_q"))));
        body.push(wire(&format!("r_rem{k}"), ediv_w, format!("ei{k}_p[{}:0]", ediv_w - 1)));
        body.push(wire(&format!("r_qs{k}"), bound_w, flip(&format!("es{k}_q"))));
        body.push(wire(&format!("r_rs256_{k}"), ediv_w, format!("{{es{k}_p[{}:0], 8'd0}}", vy_w - 1)));
    }
    body.push(comment("verilator lint_on UNUSEDSIGNAL"));
    let max_pos = format!("{{1'b0, {{{iw}{{1'b1}}}}}}");
    let max_neg = format!("{{1'b1, {}}}", lit(iw, 0));
    body.push(wire(
        "r_di",
        dw,
        format!("s_sat ? (s_dineg ? {max_neg} : {max_pos}) : (s_dineg ? -{} : {})", zext("ddi_q", iw, dw), zext("ddi_q", iw, dw)),
    ));
    body.push(Item::Blank);
}
