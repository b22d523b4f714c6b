//! The edge walker: one row per clock, one DDA step per active edge (in each `tri_fe_edge`),
//! the span's ends compared side by side; it loads the next triangle in the clock its current
//! one finishes.

use super::divider::Div;
use super::edge;
use super::hw::{slit, Hw};
use crate::verilog::{assign, comment, lit, net, reg, set, sext, sreg, swire, wire, Item, Stmt};
use crate::Names;
use golden::frontend::sums::LEFT_SLOTS;
use golden::frontend::{DiMode, Widths};

/// The per-scanline dI's divider (the comparison option `--fe-di scanline`), and its counter's
/// width: IW quotient bits.
pub(super) fn scanline_divider(hw: &Hw) -> (Div, u32) {
    let (xw, iw) = (hw.fe.cfg.xbits, hw.fe.cfg.iw());
    (Div { name: "u_sdv", pw: xw + iw + 2, qb: iw }, 32 - (iw - 1).leading_zeros())
}

/// The walker's values the span path reads (`w_row`, `w_tn`, ...) where it reads them: the
/// last row stage's registers when there are row stages ([`Hw::row_stages`]).
pub(super) fn row(hw: &Hw, walker: &str) -> String {
    row_at(hw, walker, hw.row_stages())
}

/// A walker's value in row stage `j` (1, 2): `wr_<name>` in the first, `we_<name>` in the
/// second; the walker's own register in stage 0.
pub(super) fn row_at(hw: &Hw, walker: &str, j: u32) -> String {
    assert!(j <= hw.row_stages(), "row stage {j} of {}", hw.row_stages());
    match (walker.strip_prefix("w_"), j) {
        (Some(name), 1) => format!("wr_{name}"),
        (Some(name), 2) => format!("we_{name}"),
        _ => walker.into(),
    }
}

/// The least of `<side>0`, `<side>1`, `<side>2`: the three compares side by side, then a select.
fn least_of_three(side: &str) -> String {
    let c = |i: u32, j: u32| format!("{side}{i} <= {side}{j}");
    format!("({} && {}) ? {side}0 : ({}) ? {side}1 : {side}2", c(0, 1), c(0, 2), c(1, 2))
}

/// The span's ends from the edges' bounds `gb0..2` and their side tests (`bl`, `bh`: the lean
/// edges, [`edge::end_ports`]): the three bounds compared pairwise from the edges' registers,
/// beside the side tests, each end then the bound that bounds its side and is the least there,
/// or the screen's. The same ends as [`least_of_three`] of the bounds chosen first, whose
/// compares followed the choice: the edge's test, its choice, the compare, the pick and the
/// length's add in one clock were the HX8K's critical path once its engine's ALU was split
/// (docs/fpga.md, issue 27). With `pairwise` the row's pixel test is formed the same way, from
/// the bounds' pairwise sums (`covered`); without (the plan's [`Hw::fewest_cells`]) it is the
/// sign of `hi3 + mg` after the picks, one add where the pairs were ten.
fn side_by_side_ends(end_w: u32, pairwise: bool, body: &mut Vec<Item>) {
    body.push(comment("The span's ends: the three bounds compared pairwise beside their side tests (bl: bounds the"));
    body.push(comment("left end, as -x; bh: the right), each end the least bound of its side, else the screen's."));
    let pairs = [(0, 1), (0, 2), (1, 2)];
    for (i, j) in pairs {
        body.push(wire(&format!("le{i}{j}"), 1, format!("gb{i} <= gb{j}")));
    }
    // k wins its side when it bounds it and no other bound there is less (ties to the lower k).
    let wins = |side: &str, k: u32| -> String {
        let mut terms = vec![format!("{side}{k}")];
        for o in (0..3).filter(|&o| o != k) {
            let le = if k < o { format!("le{k}{o}") } else { format!("!le{o}{k}") };
            terms.push(format!("(!{side}{o} || {le})"));
        }
        terms.join(" && ")
    };
    for (end, side, screen) in [("mg", "bl", "lo0"), ("hi3", "bh", "hi0")] {
        for k in 0..3 {
            body.push(wire(&format!("{side}w{k}"), 1, wins(side, k)));
        }
        let picks: Vec<String> = (0..3).map(|k| format!("({{{end_w}{{{side}w{k}}}}} & gb{k})")).collect();
        let none = format!("({{{end_w}{{!({side}w0 || {side}w1 || {side}w2)}}}} & {screen})");
        body.push(swire(end, end_w, format!("{} | {none}", picks.join(" | "))));
    }
    if !pairwise {
        return;
    }
    // hi3 + mg >= 0 for the least bound on each side is every right bound plus every left bound
    // >= 0: the sums are formed from the registers beside the compares, not after the picks.
    body.push(comment("The row has a pixel (hi3 + mg >= 0) when every right bound plus every left bound is >= 0, the"));
    body.push(comment("screen's among them: each pair's sum formed beside the compares, then only the side tests."));
    let sw = end_w + 1;
    let sum = |a: &str, b: &str| format!("{} + {}", sext(a, end_w, sw), sext(b, end_w, sw));
    let mut ok = Vec::new();
    // Only the sums' signs are read.
    body.push(comment("verilator lint_off UNUSEDSIGNAL"));
    for (i, j) in pairs {
        body.push(wire(&format!("sg{i}{j}"), sw, sum(&format!("gb{i}"), &format!("gb{j}"))));
        ok.push(format!("(!((bl{i} && bh{j}) || (bh{i} && bl{j})) || !sg{i}{j}[{end_w}])"));
    }
    for k in 0..3 {
        body.push(wire(&format!("sl{k}"), sw, sum(&format!("gb{k}"), "hi0")));
        body.push(wire(&format!("sh{k}"), sw, sum(&format!("gb{k}"), "lo0")));
        ok.push(format!("(!bl{k} || !sl{k}[{end_w}])"));
        ok.push(format!("(!bh{k} || !sh{k}[{end_w}])"));
    }
    body.push(wire("ss", sw, sum("hi0", "lo0")));
    ok.push(format!("!ss[{end_w}]"));
    body.push(comment("verilator lint_on UNUSEDSIGNAL"));
    body.push(wire("covered", 1, ok.join(" && ")));
}

/// The first row stage's bound registers: `(register, the walker's value it loads, the screen's
/// bound it lies within)`, each edge's two bounds, or each slot's ([`super::sums::slotted`]).
pub(super) fn bound_registers(hw: &Hw) -> Vec<(String, String, &'static str)> {
    if super::sums::slotted(hw) {
        let [(a, a_other), (b, b_other)] = LEFT_SLOTS;
        let pick = |sel: String, own: usize, other: usize, side: &str| format!("{sel} ? {side}{own} : {side}{other}");
        return vec![
            ("wr_la".into(), pick(format!("w_sa[{a}]"), a, a_other, "lg"), "lo0"),
            ("wr_lb".into(), pick(format!("w_sb[{b}]"), b, b_other, "lg"), "lo0"),
            ("wr_ra".into(), pick("w_ra".into(), a, a_other, "ha"), "hi0"),
            ("wr_rb".into(), pick("w_rb".into(), b, b_other, "ha"), "hi0"),
        ];
    }
    let mut v = Vec::new();
    for (side, screen) in [("lg", "lo0"), ("ha", "hi0")] {
        v.extend((0..3).map(|k| (format!("wr_{side}{k}"), format!("{side}{k}"), screen)));
    }
    v
}

/// The least of two registers, `a` when they tie.
fn least_of_two(a: &str, b: &str) -> String {
    format!("({a} <= {b}) ? {a} : {b}")
}

/// Row stage `j`'s valid (1, 2): a row, with a pixel or not.
pub(super) fn row_valid(j: u32) -> &'static str {
    ["wr_v", "we_v"][j as usize - 1]
}

/// The walker's values the row stage holds besides the edges' bounds: the span path's inputs.
fn row_values(hw: &Hw) -> Vec<(&'static str, u32)> {
    let Widths { yw: row_w, aw: area_w, rw: recip_w, .. } = hw.fe.widths();
    // The span path reads the sums modulo 2^(K-2) only ([`Hw::s2n_bits`]).
    let sums = hw.s2n_bits() - 1;
    let mut v = vec![("w_row", row_w), ("w_tn", sums), ("w_gxn", sums), ("w_an", area_w), ("w_rn", recip_w)];
    if !reads_gxn(hw) {
        v.retain(|(n, _)| *n != "w_gxn");
    }
    // Per scanline the span's dI is its own division's: the triangle's is not read.
    if hw.fe.di == DiMode::Triangle {
        v.push(("w_di", hw.fe.cfg.dw()));
    }
    v
}

/// Whether the span path reads the row's `Gxn` (for a product by the column): not when the
/// running sums give the left end's (`Hw::run_sums`), unless the scanline `dI`'s last pixel
/// needs its own.
pub(super) fn reads_gxn(hw: &Hw) -> bool {
    !hw.run_sums() || hw.fe.di == DiMode::Scanline
}

/// The running sums' row-stage registers (`Hw::run_sums`): the slots' sums with the row's
/// bounds, then the two sums again with the left end's choice (`we_ga`: slot a's bound is the
/// lesser) beside the span's ends. The source is selected from these registers
/// ([`sum_source`]): the compares, the choice and a 54-bit select in one clock into `we_gxs`
/// were the merged front-end's critical path (docs/fpga.md).
fn sum_stage_registers(hw: &Hw) -> [Vec<(String, u32)>; 2] {
    if !hw.run_sums() {
        return [Vec::new(), Vec::new()];
    }
    let sb = hw.fe.widths().sum_bits();
    // The row stages hold the bounds by slot ([`super::sums::slotted`]): slot a wins where its bound is the
    // lesser, so the slots' edges are not registered.
    assert!(super::sums::slotted(hw), "the running sums' row stages hold the bounds by slot");
    [vec![("wr_pa".into(), sb), ("wr_pb".into(), sb)], vec![("we_pa".into(), sb), ("we_pb".into(), sb), ("we_ga".into(), 1)]]
}

/// The span's `Gxn lo` source in the second row stage, `we_gxs`: selected from its registers, so
/// the span path's first register (`p1_gxs`) is one select away from them.
fn sum_source(hw: &Hw, body: &mut Vec<Item>) {
    if hw.run_sums() {
        body.push(comment("The span's Gxn lo source: the winning slot's sum, or 0 at the screen's clamp."));
        body.push(wire("we_gxs", hw.fe.widths().sum_bits(), super::sums::source(hw, ("we_pa", "we_pb", "we_ga"), "we_mg")));
    }
}

/// The row stages: the walked row (valid, each edge's bound, the span path's inputs)
/// registered; then the span's ends chosen from those bounds and registered with the row
/// (valid, the span path's inputs) a clock later; all moving on the one stall.
fn row_stages(hw: &Hw, body: &mut Vec<Item>) {
    assert_eq!(hw.row_stages(), 2, "the row stages are the walked row, then its span's ends");
    let end_w = edge::end_width(hw);
    body.push(comment("Row stages: the walked row registered, each edge's bound on it and the row's sums (wr_*); its"));
    body.push(comment("span's ends chosen from these and registered with the row a clock later (we_*); the span is"));
    body.push(comment("decided from those (wr_v, we_v: a row, with a pixel or not)."));
    let (v1, v2) = (row_valid(1), row_valid(2));
    body.push(reg(v1, 1));
    let mut moves = vec![set(v1, "w_valid")];
    for (r, v, _) in bound_registers(hw) {
        body.push(sreg(&r, end_w));
        moves.push(set(r, v));
    }
    for (n, w) in row_values(hw) {
        body.push(reg(&row_at(hw, n, 1), w));
        let sums = matches!(n, "w_tn" | "w_gxn");
        moves.push(set(row_at(hw, n, 1), if sums { format!("{n}[{}:0]", w - 1) } else { n.to_string() }));
    }
    // The edges compared side by side, each end a three-way select: these compares and selects
    // then the add of the pixel test were one clock, the staged front-end's longest in the
    // walker (docs/fpga.md).
    if super::sums::slotted(hw) {
        body.push(comment("The span's ends from the row's slots, each end's two compared: mg the smallest left-edge g"));
        body.push(comment("(x = -mg), hi3 the smallest right bound."));
        body.push(swire("mg_w", end_w, least_of_two("wr_la", "wr_lb")));
        body.push(swire("hi3_w", end_w, least_of_two("wr_ra", "wr_rb")));
    } else {
        body.push(comment("The span's ends from the row's bounds, the edges compared side by side: mg the smallest"));
        body.push(comment("left-edge g (x = -mg), hi3 the smallest right bound."));
        for (end, side) in [("mg", "wr_lg"), ("hi3", "wr_ha")] {
            body.push(swire(&format!("{end}_w"), end_w, least_of_three(side)));
        }
    }
    let [first, second] = sum_stage_registers(hw);
    for (n, w) in first.iter().chain(&second) {
        body.push(reg(n, *w));
    }
    for (n, _) in &first {
        let v = super::sums::slot_sum(n.strip_prefix("wr_p").expect("a slot's sum"));
        moves.push(set(n, v));
    }
    for (n, _) in &second {
        let v = match n.as_str() {
            "we_ga" => "wr_la <= wr_lb".to_string(),
            _ => n.replace("we_", "wr_"),
        };
        moves.push(set(n, v));
    }
    body.push(reg(v2, 1));
    body.extend([sreg("we_mg", end_w), sreg("we_hi3", end_w)]);
    moves.extend([set(v2, v1), set("we_mg", "mg_w"), set("we_hi3", "hi3_w")]);
    for (n, w) in row_values(hw) {
        body.push(reg(&row_at(hw, n, 2), w));
        moves.push(set(row_at(hw, n, 2), row_at(hw, n, 1)));
    }
    let reset = vec![set(v1, "1'b0"), set(v2, "1'b0")];
    body.push(Item::Always(vec![Stmt::If("rst".into(), reset, vec![Stmt::If("adv".into(), moves, vec![])])]));
    sum_source(hw, body);
}

/// The row stages' registers for the manifest, one list a stage: `(name, bits, signed)`; none
/// without them.
pub(super) fn row_registers(hw: &Hw) -> Vec<Vec<(String, u32, bool)>> {
    if !hw.row_stage() {
        return Vec::new();
    }
    let end_w = edge::end_width(hw);
    let mut first = vec![(row_valid(1).to_string(), 1, false)];
    first.extend(bound_registers(hw).into_iter().map(|(r, ..)| (r, end_w, true)));
    first.extend(row_values(hw).into_iter().map(|(n, w)| (row_at(hw, n, 1), w, false)));
    let [sums1, sums2] = sum_stage_registers(hw);
    first.extend(sums1.into_iter().map(|(n, w)| (n, w, false)));
    let mut second = vec![(row_valid(2).to_string(), 1, false), ("we_mg".to_string(), end_w, true), ("we_hi3".to_string(), end_w, true)];
    second.extend(row_values(hw).into_iter().map(|(n, w)| (row_at(hw, n, 2), w, false)));
    second.extend(sums2.into_iter().map(|(n, w)| (n, w, false)));
    vec![first, second]
}

/// When the walker steps (outside the row stages' form): not loading, not stalled, a row after
/// this one.
const STEP_WHEN: &str = "!rst && !take && adv && w_valid && !w_end";

/// The walker's stall (`adv`), its end of walk, its take and its load or step.
fn control(hw: &Hw, body: &mut Vec<Item>) {
    if hw.fe.di == DiMode::Scanline {
        let (_, sd_cnt_w) = scanline_divider(hw);
        body.push(comment("Per-scanline dI (the comparison option): a restoring divider, busy for each span of m >= 2."));
        body.extend([reg("sd_busy", 1), reg("sd_cnt", sd_cnt_w), reg("sd_neg", 1)]);
        body.push(wire("adv", 1, "(!out_valid || out_ready) && !sd_busy"));
    } else if hw.fe.span_seq().is_none() {
        body.push(wire("adv", 1, "!out_valid || out_ready"));
    }
    // Behind the row stages the walk's end is a register, `!w_valid || w_row == w_last` made as
    // the row is loaded or stepped (set in a reset and kept while no row is walked): compared in
    // the clock it is read, it led the take and the walker's loads (`w_row == w_last`, then
    // `w_next` into every walker and edge register's enable) on the merged front-end's critical
    // path (docs/fpga.md). Now the take and the loads' enable are one LUT4 of registers.
    let tracked = hw.row_stage();
    let free = if tracked {
        body.push(comment("w_end: no row after the walked one (its triangle's last row, or none walked)."));
        body.push(reg("w_end", 1));
        "w_end"
    } else {
        body.push(wire("w_end", 1, "w_row == w_last"));
        // The sequential span path (its own `adv`) reads the walker's registers without row
        // stages: the next triangle is taken once the last row has left.
        if hw.fe.span_seq().is_some() && hw.engine_form() {
            "!w_valid"
        } else {
            "(!w_valid || w_end)"
        }
    };
    let inc = super::incremental::on(hw);
    let engine = hw.engine_form();
    let waiting = if engine { "q_ne" } else { "st == HOLD" };
    // Where the edges' fields are in the walk memory, the take waits for their preload.
    let preloaded = if hw.edges_in_walk_ram() { " && wk_ldd" } else { "" };
    if !inc {
        body.push(assign("take", format!("{waiting} && adv && {free}{preloaded}")));
    }
    let end_w = edge::end_width(hw);
    body.push(swire("lo0", end_w, slit(end_w, 0)));
    body.push(swire("hi0", end_w, slit(end_w, hw.fe.screen.width as i64 - 1)));
    body.push(comment("The edges: loaded with the set-up result, stepped a row; each one's bound on the row."));
    // The incremental I0's walker also waits for its start engine (`ie_wait`, declared below).
    // Behind the row stages the walker's load and step are chosen from its registers (w_next,
    // w_more) and its stall gates the registers' enables alone (`adv`, the edges' `go`): `take`,
    // the two together, fanned out to every walker and edge register was a long path
    // (docs/fpga.md). The edges' enables leave out the reset: an edge's state matters only under
    // the walker's valid, which the reset clears, and its next load sets all of it.
    if tracked {
        body.push(wire("w_next", 1, format!("{waiting} && {free}")));
        body.push(wire("w_more", 1, "!w_end"));
    } else {
        if !hw.edges_in_walk_ram() {
            body.push(wire("w_load", 1, "!rst && take"));
        }
        if inc {
            body.push(net("w_step", 1));
        } else {
            body.push(wire("w_step", 1, STEP_WHEN));
        }
    }
}

/// The walker's moves behind the row stages. As the edges: the stall gates the enables, the
/// registers choose the load or the step. Only the walk's valid and end are reset; the triangle's
/// registers matter only under the valid and the next load sets them all, so their enables are
/// `adv && w_next` and `adv && !w_end`, one LUT4 of registers each (`!w_end` holds only while a
/// row is walked), where the reset and the valid made them two LUTs in front of hundreds of
/// enables (docs/fpga.md).
fn tracked_moves(body: &mut Vec<Item>, load: Vec<Stmt>, step: Vec<Stmt>) {
    let control = |st: &Stmt| matches!(st, Stmt::Set(l, _) if l == "w_valid" || l == "w_end");
    let (load_c, load_d): (Vec<_>, Vec<_>) = load.into_iter().partition(control);
    let (step_c, step_d): (Vec<_>, Vec<_>) = step.into_iter().partition(control);
    let walked = vec![Stmt::If("w_end".into(), vec![set("w_valid", "1'b0")], step_c)];
    let moves = vec![Stmt::If("adv".into(), vec![Stmt::If("w_next".into(), load_c, walked)], vec![])];
    let reset = vec![set("w_valid", "1'b0"), set("w_end", "1'b1")];
    body.push(Item::Always(vec![Stmt::If("rst".into(), reset, moves)]));
    let data = Stmt::If("w_next".into(), load_d, vec![Stmt::If("!w_end".into(), step_d, vec![])]);
    body.push(Item::Always(vec![Stmt::If("adv".into(), vec![data], vec![])]));
}

pub(super) fn emit(hw: &Hw, names: &Names, body: &mut Vec<Item>) {
    let fe = &hw.fe;
    let Widths { yw: row_w, aw: area_w, k: sum_w, rw: recip_w, .. } = fe.widths();
    let (xw, dw) = (fe.cfg.xbits, fe.cfg.dw());
    body.push(comment("Walker: the triangle being walked, one row per clock (each edge's DDA in g_edge[k].u_edge)."));
    body.push(reg("w_valid", 1));
    body.push(reg("w_row", row_w));
    body.push(reg("w_last", row_w));
    let regs = [("w_di", dw), ("w_an", area_w), ("w_rn", recip_w), ("w_tn", sum_w), ("w_gxn", sum_w), ("w_dyn", sum_w)];
    // The walk's constants in block RAM are wires from its reads instead (`span_seq::walk_ram`).
    let held = |n: &str| super::span_seq::walk_ram::replaces(hw, &n[2..]);
    body.extend(regs.iter().filter(|(n, _)| (*n != "w_gxn" || reads_gxn(hw)) && !held(n)).map(|(n, ww)| reg(n, *ww)));
    let (sum_decls, sum_load, sum_step) = if hw.run_sums() { super::sums::walker(hw) } else { Default::default() };
    body.extend(sum_decls);
    control(hw, body);
    let (inc, engine, tracked) = (super::incremental::on(hw), hw.engine_form(), hw.row_stage());
    let end_w = edge::end_width(hw);
    let ends = edge::end_ports(hw);
    for (port, w) in &ends {
        body.push(net(&format!("e_{port}"), 3 * w));
    }
    let state = edge::state_outputs(hw);
    for (port, w, ..) in &state {
        body.push(net(&format!("e_{port}"), 3 * w));
    }
    body.push(edge::instances(hw, names, &edge::input_buses(hw)));
    // The incremental I0 reads each edge's state by its own names, lane k of the edges' buses.
    for (port, w, signed, _, name) in state.iter().filter(|_| inc) {
        for k in 0..3 {
            let lane = if *w == 1 { format!("e_{port}[{k}]") } else { format!("e_{port}[{}:{}]", (k + 1) * w - 1, k * w) };
            let alias = format!("{name}{k}");
            body.push(if *signed { swire(&alias, *w, lane) } else { wire(&alias, *w, lane) });
        }
    }
    for k in 0..3 {
        for (port, w) in &ends {
            let name = format!("{port}{k}");
            body.push(if *w == 1 {
                wire(&name, 1, format!("e_{port}[{k}]"))
            } else {
                swire(&name, *w, format!("e_{port}[{}:{}]", (k + 1) * w - 1, k * w))
            });
        }
    }
    // The row's span is decided from the edges' bounds in the walker's clock, or two clocks
    // later from the row stages' registers (`--pipeline 1`): the bounds then the minima, the
    // pixel test and `emit` into the span path's first valid were the staged front-end's
    // critical path.
    let row_valid = if hw.row_stage() {
        assert!(!inc, "the incremental walker decides its row in its own clock");
        row_stages(hw, body);
        row_valid(2)
    } else {
        "w_valid"
    };
    if hw.row_stage() {
        body.push(comment("The span from the row's ends: x = lo3 = -mg; the row has a pixel when hi3 + mg >= 0."));
        body.push(swire("mg", end_w, "we_mg"));
        body.push(swire("hi3", end_w, "we_hi3"));
    } else if edge::ends_side_by_side(hw) {
        side_by_side_ends(end_w, !hw.fewest_cells(), body);
    } else {
        // Side by side rather than in a chain, and no negation before the pixel test or the
        // length: this was the walker's row clock, the staged front-end's limit at 2 and 1
        // quotient bits.
        body.push(comment("The span's ends, the edges compared side by side: x = lo3 = -mg (the smallest left-edge g),"));
        body.push(comment("hi3 the smallest right bound; the row has a pixel when hi3 + mg >= 0."));
        for (end, side) in [("mg", "lg"), ("hi3", "ha")] {
            body.push(swire(end, end_w, least_of_three(side)));
        }
    }
    if hw.run_sums() && !hw.row_stage() {
        body.push(wire(
            "w_gxs",
            hw.fe.widths().sum_bits(),
            super::sums::source(
                hw,
                (&super::sums::slot_sum("a"), &super::sums::slot_sum("b"), &super::sums::slot_a_wins("lg", "w_sa")),
                "mg",
            ),
        ));
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
        body.push(assign("w_step", format!("{STEP_WHEN} && !ie_wait")));
    } else {
        let pairwise = edge::ends_side_by_side(hw) && !hw.fewest_cells();
        let covered = if pairwise { "covered".to_string() } else { format!("!room[{end_w}]") };
        body.push(wire("emit", 1, format!("{row_valid} && {covered}")));
    }
    // Behind the lean edges the span path holds the ends, not x (span_seq).
    if !edge::ends_side_by_side(hw) {
        body.push(wire("lo_u", xw, format!("lo3[{}:0]", xw - 1)));
    }
    let mut load = vec![set("w_valid", "1'b1"), set("w_row", "s_first"), set("w_last", "s_last")];
    load.extend([
        set("w_di", "r_di"),
        set("w_an", "s_an"),
        set("w_rn", if engine { "r_rn" } else { "drn_q" }),
        set("w_tn", super::span_seq::walk_ram::take_value(hw, "tn").unwrap_or("s_tn")),
        set("w_gxn", "s_gxn"),
        set("w_dyn", super::span_seq::walk_ram::take_value(hw, "dyn").unwrap_or("s_dyn")),
    ]);
    load.retain(|st| !matches!(st, Stmt::Set(l, _) if (l == "w_gxn" && !reads_gxn(hw)) || (l.starts_with("w_") && held(l))));
    load.extend(sum_load);
    let mut step = vec![set("w_row", format!("w_row + {}", lit(row_w, 1))), set("w_tn", "w_tn + w_dyn")];
    if tracked {
        load.push(set("w_end", "s_first == s_last"));
        step.push(set("w_end", format!("w_row + {} == w_last", lit(row_w, 1))));
    }
    step.extend(sum_step);
    if tracked {
        tracked_moves(body, load, step);
    } else {
        let walked = vec![Stmt::If("w_end".into(), vec![set("w_valid", "1'b0")], step)];
        let moves = vec![Stmt::If(
            "take".into(),
            load,
            vec![Stmt::If(if inc { "adv && w_valid && !ie_wait" } else { "adv && w_valid" }.into(), walked, vec![])],
        )];
        body.push(Item::Always(vec![Stmt::If("rst".into(), vec![set("w_valid", "1'b0")], moves)]));
    }
    body.push(Item::Blank);
    if inc {
        super::incremental::engine(hw, body);
    }
}
