//! The front-end's formal properties (scripts/prove): where the per-triangle dI's control keeps
//! its state, handed to the property writer. The scanline comparison option's divider adds a
//! stall of its own and is left to co-simulation.

use super::setup::{self, Setup};
use super::span;
use super::stager::Stager;
use super::Hw;
use crate::formal::{frontend_properties, CalcStage, FrontendShape, SpanStage};
use crate::verilog::Item;

pub(super) fn emit(hw: &Hw, set_up: Setup, sp: &Stager) -> Item {
    let fe = &hw.fe;
    let wd = fe.widths();
    let Setup { st, divs, cnt_w, guard, cull } = set_up;
    frontend_properties(&FrontendShape {
        yw: wd.yw,
        cx: wd.cx,
        cy: wd.cy,
        xw: fe.cfg.xbits,
        dw: fe.cfg.dw(),
        width: fe.screen.width as u64,
        height: fe.screen.height as u64,
        cnt_w,
        bits: hw.div_bits,
        rw: wd.rw,
        div_clocks: hw.div_clocks(),
        div_regs: divs.iter().flat_map(|d| ["p", "d", "q"].map(|r| format!("{}_{r}", d.name))).collect(),
        calc_stages: (1..=st.stage())
            .map(|j| CalcStage {
                valid: setup::valid(j),
                guard: st.held("guard_ok", j).expect("the guard-band check reaches the last stage"),
                ymin: st.held("ymin", j),
                ymax: st.held("ymax", j),
                first_s: st.held("first_s", j),
                last_s: st.held("last_s", j),
                cull: st.held("cull", j),
                last_alt: ["last_s0", "last_s1"].iter().filter_map(|n| st.held(n, j)).collect(),
            })
            .collect(),
        guard,
        cull,
        span_stages: (1..=sp.stage())
            .map(|j| {
                let held = |n: &str| sp.held(n, j).expect("a span's fields reach the output");
                SpanStage { valid: span::valid(j), y: held("y"), x: held("x"), len: held("len"), di: held("di") }
            })
            .collect(),
    })
}
