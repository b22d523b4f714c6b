//! What both engine forms (the pipelined one and the HX8K's sequential one, [`super::seq`])
//! share: the set-up result's fields, in the queue entry's order, and the engine's ports.

use crate::frontend::hw::Hw;
use crate::verilog::Port;
use golden::frontend::engine::schedule::Schedule;
use golden::frontend::engine::V;
use golden::frontend::Widths;

/// One field of the set-up result the walker reads: its name, the program's value and its
/// width in the queue, the value's bits from `lo` up.
pub(crate) struct Field {
    pub name: String,
    pub v: V,
    pub w: u32,
    /// Low bits of the value no reader takes (the edges' `D`, `rem`, `rs256` behind the row
    /// stages: `edge::dropped_low_bits`).
    pub lo: u32,
}

/// The set-up result's fields, in the queue entry's order (the first least significant).
pub(crate) fn fields(hw: &Hw, s: &Schedule) -> Vec<Field> {
    let Widths { yw, aw, k, rw, gw, dw_edge, .. } = hw.fe.widths();
    let o = &s.prog.out;
    let f = |name: &str, v: V, w: u32| Field { name: name.into(), v, w, lo: 0 };
    // The edges take D, rem and rs256 without the low bits they never read.
    let cut = crate::frontend::edge::dropped_low_bits(hw);
    let mut v = vec![
        f("first", o.first, yw),
        f("last", o.last, yw),
        f("di", o.di, hw.fe.cfg.dw()),
        f("an", o.an, aw),
        f("rn", o.rn, rw),
        f("tn", o.tn, k),
        f("dyn", o.dyn_, k),
        f("gxn", o.gxn, k),
    ];
    if hw.fe.i0 == golden::frontend::I0Form::Incremental {
        // The incremental I0's starts check their steps' range on the exact plane.
        let (nx_w, ny_w) = hw.plane_widths();
        v.extend([f("nx", o.nx, nx_w), f("ny", o.ny, ny_w), f("a", o.a, aw)]);
    }
    // The left slots' running sums' starts and steps (`Hw::run_sums`), the walker's `s_pga`...
    if let (Some(sums), true) = (o.sums, hw.run_sums()) {
        for (slot, (pg, pq)) in ["a", "b"].iter().zip(sums) {
            v.extend([f(&format!("pg{slot}"), pg, hw.fe.widths().sum_bits()), f(&format!("pq{slot}"), pq, hw.fe.widths().sum_bits())]);
        }
    }
    let from_engine = crate::frontend::edge::start_from_engine(hw);
    for (j, e) in o.edges.iter().enumerate() {
        // The DDA's start thr and t (`Plan::edge_t`) in place of D and rem, where the edges take it.
        let (d, rem) = match e.dda {
            Some((thr, t)) if from_engine => (("thr", thr, dw_edge - cut, 0), ("t", t, dw_edge - cut + 1, 0)),
            _ => (("d", e.d, dw_edge - cut, cut), ("rem", e.rem, dw_edge - cut, cut)),
        };
        for (n, x, w, lo) in [
            ("act", e.active, 1, 0),
            ("right", e.right, 1, 0),
            ("rs", e.rs, yw, 0),
            ("re", e.re, yw, 0),
            d,
            ("g", e.g, gw, 0),
            rem,
            ("qs", e.qs, gw, 0),
            ("rs256", e.rs256, dw_edge - cut, cut),
        ] {
            v.push(Field { lo, ..f(&format!("e{j}_{n}"), x, w) });
        }
    }
    v
}

/// The engine's ports, whichever form (the pipelined engine and the sequential one share them
/// and their contract).
pub(crate) fn ports(hw: &Hw, res_w: u32) -> Vec<Port> {
    let wd = hw.fe.widths();
    let iw = hw.fe.cfg.iw();
    let mut p = vec![
        Port::input("clk", 1, "", "rising edge"),
        Port::input("rst", 1, "", "synchronous, active high: drops the triangles in flight"),
        Port::input("en", 1, "", "low: the whole engine holds (the queue cannot take the result due)"),
        Port::input("in_valid", 1, "", "triangle valid"),
        Port::output("in_ready", 1, "", "triangle accepted when in_valid && in_ready"),
    ];
    for k in 0..3 {
        p.push(Port::input(&format!("in_x{k}"), wd.cx, "", &format!("vertex {k} x")).signed());
        p.push(Port::input(&format!("in_y{k}"), wd.cy, "", &format!("vertex {k} y")).signed());
        p.push(Port::input(&format!("in_i{k}"), iw, "", &format!("vertex {k} intensity")));
    }
    p.push(Port::output("res_v", 1, "", "a triangle's result is due this clock"));
    p.push(Port::output("res_guard", 1, "", "its vertices are inside the guard band"));
    p.push(Port::output("res_cull", 1, "", "it covers no pixel"));
    p.push(Port::output("res", res_w, "", "its set-up result, the walker's fields (tri_frontend unpacks them)"));
    p
}
