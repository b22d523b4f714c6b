//! The parallel form's part of the front-end's properties: CALC's stages, the DIV/HOLD state
//! machine and the dividers' registers in the reference's declarations, updates and links.

use super::shape::*;
use crate::formal::*;
use crate::verilog::*;

/// The parallel set-up's reference: its shape, CALC's last stage (0: the vertex register) and
/// the divider-clock counter's width.
pub(super) fn parallel(p: &ParallelSetup) -> (usize, u32) {
    assert!(p.bits.is_power_of_two(), "divider bits per clock: {}", p.bits);
    (p.calc_stages.len(), 32 - p.div_clocks.leading_zeros())
}

impl Reference<'_> {
    /// The parallel set-up's reference registers: the input stage with its guard-band decision
    /// and extent, CALC's stages, the dividers.
    pub(super) fn parallel_declarations(&self, p: &ParallelSetup) -> Vec<Item> {
        let FrontendShape { cx, cy, width, height, .. } = *self.s;
        let (last, nw) = parallel(p);
        let mut b = vec![
            comment("The reference. The input stage: the triangle waiting for the set-up, whether its"),
            comment("vertices lie in SPEC §6's guard band (decided here from the ports), its vertical extent."),
        ];
        b.extend([reg("f_vf", 1), reg("f_vg", 1), Item::Reg { name: "f_vymin".into(), width: cy, signed: true }]);
        b.push(Item::Reg { name: "f_vymax".into(), width: cy, signed: true });
        let (gxl, gxh) = (-(width as i64) * 256, 2 * width as i64 * 256);
        let (gyl, gyh) = (-(height as i64) * 256, 2 * height as i64 * 256);
        let mut band = Vec::new();
        for k in 0..3 {
            b.push(Item::Wire {
                name: format!("f_ix{k}"),
                width: cx + 2,
                signed: true,
                value: Some(sext(&format!("in_x{k}"), cx, cx + 2)),
            });
            b.push(Item::Wire {
                name: format!("f_iy{k}"),
                width: cy + 2,
                signed: true,
                value: Some(sext(&format!("in_y{k}"), cy, cy + 2)),
            });
            band.push(format!(
                "f_ix{k} >= {} && f_ix{k} < {} && f_iy{k} >= {} && f_iy{k} < {}",
                slit(cx + 2, gxl),
                slit(cx + 2, gxh),
                slit(cy + 2, gyl),
                slit(cy + 2, gyh)
            ));
        }
        b.push(wire("f_band", 1, band.join(" && ")));
        let min3 = |op: &str| format!("((in_y0 {op} in_y1) ? ((in_y0 {op} in_y2) ? in_y0 : in_y2) : ((in_y1 {op} in_y2) ? in_y1 : in_y2))");
        b.push(Item::Wire { name: "f_iymin".into(), width: cy, signed: true, value: Some(min3("<")) });
        b.push(Item::Wire { name: "f_iymax".into(), width: cy, signed: true, value: Some(min3(">")) });

        for j in 1..=last {
            if j == 1 {
                b.push(comment("CALC's stages: each triangle's guard-band check and vertical extent, as the vertex register's."));
            }
            b.extend([reg(&f_v(j), 1), reg(&f_held(j, "g"), 1)]);
            b.push(Item::Reg { name: f_held(j, "ymin"), width: cy, signed: true });
            b.push(Item::Reg { name: f_held(j, "ymax"), width: cy, signed: true });
        }
        b.push(comment("The set-up: busy (dividing, f_sn + 1 clocks left, or holding its result: f_sh), its extent."));
        b.extend([reg("f_sb", 1), reg("f_sh", 1), reg("f_sn", nw)]);
        b.push(Item::Reg { name: "f_symin".into(), width: cy, signed: true });
        b.push(Item::Reg { name: "f_symax".into(), width: cy, signed: true });
        b
    }

    /// The parallel set-up's clock: (its reset, its update).
    pub(super) fn parallel_update(&self, p: &ParallelSetup) -> (Vec<Stmt>, Vec<Stmt>) {
        let (last, nw) = parallel(p);
        let cw = self.cw;
        let f_mv = |j: usize| f_mv(j, last);
        let inc1 = |n: &str| set(n, format!("{n} + {}", one(cw)));
        let calc_go = vec![
            set("f_sb", "1'b1"),
            set("f_sh", "1'b0"),
            set("f_sn", lit(nw, (p.div_clocks - 1) as u64)),
            set("f_symin", f_held(last, "ymin")),
            set("f_symax", f_held(last, "ymax")),
        ];
        let setup = Stmt::If(
            "f_calc".into(),
            vec![Stmt::If(
                format!("!{}", f_held(last, "g")),
                vec![set("f_errp", "1'b1"), set("f_sb", "1'b0")],
                vec![Stmt::If("f_cull".into(), vec![set("f_sb", "1'b0"), inc1("f_ncull")], calc_go)],
            )],
            vec![Stmt::If(
                "f_take".into(),
                vec![set("f_sb", "1'b0")],
                vec![when(
                    "f_sb && !f_sh",
                    vec![Stmt::If(
                        format!("f_sn == {}", lit(nw, 0)),
                        vec![set("f_sh", "1'b1")],
                        vec![set("f_sn", format!("f_sn - {}", one(nw)))],
                    )],
                )],
            )],
        );
        let input = Stmt::If(
            "f_acc".into(),
            vec![set("f_vf", "1'b1"), set("f_vg", "f_band"), set("f_vymin", "f_iymin"), set("f_vymax", "f_iymax")],
            vec![when(f_mv(0), vec![set("f_vf", "1'b0")])],
        );
        let stages = (1..=last).map(|j| {
            Stmt::If(
                f_mv(j - 1),
                vec![
                    set(f_v(j), "1'b1"),
                    set(f_held(j, "g"), f_held(j - 1, "g")),
                    set(f_held(j, "ymin"), f_held(j - 1, "ymin")),
                    set(f_held(j, "ymax"), f_held(j - 1, "ymax")),
                ],
                vec![when(f_mv(j), vec![set(f_v(j), "1'b0")])],
            )
        });
        let reset = [set("f_vf", "1'b0")].into_iter().chain((1..=last).map(|j| set(f_v(j), "1'b0"))).chain([set("f_sb", "1'b0")]).collect();
        (reset, [input].into_iter().chain(stages).chain([setup]).collect())
    }

    /// The parallel set-up's and the walker's links.
    pub(super) fn parallel_links(&self, p: &ParallelSetup) -> Vec<Stmt> {
        let FrontendShape { yw, cy, height, .. } = *self.s;
        let ParallelSetup { cnt_w, bits, rw, div_clocks, ref calc_stages, .. } = *p;
        let (_, nw) = parallel(p);
        let centre = |r: &str| format!("$signed({{2'b00, {r}, 8'd128}})");
        let within = |r: &str, lo: &str, hi: &str| vec![assert(format!("{} >= {lo}", centre(r))), assert(format!("{} <= {hi}", centre(r)))];
        let hmax = lit(yw, height - 1);
        let st_is = "(f_sb ? (f_sh ? HOLD : DIV) : IDLE)";
        let mut su = vec![assert(format!("{} <= f_symax", centre("s_last"))), assert(format!("{} >= f_symin", centre("s_first")))];
        su.extend([assert("s_first <= s_last"), assert(format!("s_last <= {hmax}"))]);
        let mut wk = vec![assert("w_row == f_wrow"), assert("w_last == f_wlast"), assert("f_wrow <= f_wlast")];
        wk.extend(within("f_wrow", "f_wymin", "f_wymax"));
        wk.extend([assert(format!("{} <= f_wymax", centre("f_wlast"))), assert(format!("f_wlast <= {hmax}"))]);
        let mut link = vec![
            assert("v_full == f_vf"),
            when("f_vf", vec![assert("guard_ok == f_vg"), assert("ymin == f_vymin"), assert("ymax == f_vymax")]),
        ];
        let ryc = |r: &str| format!("$signed({{{r}, 8'd128}})");
        for (j, c) in calc_stages.iter().enumerate().map(|(i, c)| (i + 1, c)) {
            let mut held = vec![assert(format!("{} == {}", c.guard, f_held(j, "g")))];
            if let Some(r) = &c.ymin {
                held.push(assert(format!("{r} == {}", f_held(j, "ymin"))));
            }
            if let Some(r) = &c.ymax {
                held.push(assert(format!("{r} == {}", f_held(j, "ymax"))));
            }
            if let Some(r) = &c.first_s {
                held.push(assert(format!("!{r}[{}]", cy - 8)));
                held.push(assert(format!("{} >= {}", ryc(r), f_held(j, "ymin"))));
            }
            for r in c.last_s.iter().chain(&c.last_alt) {
                held.push(assert(format!("{r} <= {}", slit(cy - 7, height as i64 - 1))));
                held.push(assert(format!("{} <= {}", ryc(r), f_held(j, "ymax"))));
            }
            if let (Some(k), Some(a), Some(z)) = (&c.cull, &c.first_s, &c.last_s) {
                held.push(when(format!("!{k}"), vec![assert(format!("{a} <= {z}"))]));
            }
            link.push(assert(format!("{} == {}", c.valid, f_v(j))));
            link.push(when(f_v(j), held));
        }
        link.extend([
            assert(format!("st == {st_is}")),
            when(
                "f_sb && !f_sh",
                vec![assert(format!(
                    "div_cnt == ({} << {}) + {}",
                    zext("f_sn", nw, cnt_w.max(nw)),
                    bits.trailing_zeros(),
                    lit(cnt_w.max(nw), ((rw - 1) % bits) as u64)
                ))],
            ),
            when(format!("f_sn > {}", lit(nw, (div_clocks - 1) as u64)), vec![assert("!(f_sb && !f_sh)")]),
            when("f_sb", su),
            assert("w_valid == f_wv"),
            when("f_wv", wk),
        ]);
        link
    }
}
