//! The front-end's formal properties (scripts/prove): where the per-triangle dI's control keeps
//! its state, handed to the property writer. The scanline comparison option's divider adds a
//! stall of its own and is left to co-simulation.

mod engine;
mod parallel;
mod shape;

use shape::*;
pub use shape::{CalcStage, EngineShape, FrontendShape, ParallelSetup, RowStage, SetupShape, SpanStage, SpanUnit};

use super::hw::Hw;
use super::setup::{self, Setup};
use super::span;
use super::stager::Stager;
use crate::formal::{assert, covers, past_flags, reset_and_stability, when, CUT_TAG, OUT};
use crate::verilog::{bit, comment, lit, net, reg, set, wire, zext, Item, Stmt};

pub(super) fn emit(hw: &Hw, set_up: Setup, sp: &Stager) -> Item {
    let fe = &hw.fe;
    let Setup { st, div_regs, cnt_w, guard, cull } = set_up;
    let mut shape = shape(
        hw,
        sp,
        SetupShape::Parallel(ParallelSetup {
            cnt_w,
            bits: hw.div_bits,
            rw: fe.widths().rw,
            div_clocks: hw.div_clocks(),
            div_regs,
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
        }),
    );
    shape.starts = super::incremental::on(hw).then_some(hw.fe.start_product_clocks());
    frontend_properties(&shape)
}

/// The engine form's properties (`--fe-setup` a plan): the same walker and span path, behind
/// the shared engine and its result queue.
pub(super) fn emit_engine(hw: &Hw, sp: &Stager) -> Item {
    let s = hw.engine().expect("the engine form");
    let (ii, latency, epochs) = hw.engine_timing().expect("the engine form");
    if hw.sequential().is_none() {
        s.verify_binding().unwrap_or_else(|e| panic!("golden's binding: {e}"));
    }
    let engine = EngineShape {
        ii,
        latency,
        epochs,
        depth: hw.queue_depth(),
        credit: hw.queue_credit(),
        entry_w: super::engine::entry_bits(hw, &s),
        binary_phase: hw.sequential().is_some(),
        capture: hw.sequential().is_some(),
        held: hw.sequential().map(|s| s.inputs_read_by()),
        walk_ram: hw.walk_ram(),
        preload: Some(hw.preload_clocks()).filter(|&n| n > 0),
        di_in_ram: super::span_seq::walk_ram::formal_di(hw),
        head: hw.queue_head(),
    };
    let mut shape = shape(hw, sp, SetupShape::Engine(engine));
    shape.starts = super::incremental::on(hw).then_some(hw.fe.start_product_clocks());
    frontend_properties(&shape)
}

/// Row stage `j` (1, 2): where it holds the row, and what holds of its registers as the
/// walker's signals they load: each edge's bound (the first), the span's ends (the second) are
/// the screen's or inside it, and at least a sign-extended `g`'s least (so `-mg` does not
/// overflow).
fn row_stage(hw: &Hw, j: u32) -> RowStage {
    let w = super::edge::end_width(hw);
    let least = super::hw::slit(w, -(1i64 << (w - 2)));
    // Per group (an edge's pair of bounds, or the span's two ends): each within the screen's,
    // then each at least `least`.
    let groups: Vec<[(String, &str); 2]> = if j == 1 {
        let b = super::walker::bound_registers(hw);
        let (lo, hi) = b.split_at(b.len() / 2);
        lo.iter().zip(hi).map(|((l, _, sl), (h, _, sh))| [(l.clone(), *sl), (h.clone(), *sh)]).collect()
    } else {
        vec![[("we_mg".into(), "lo0"), ("we_hi3".into(), "hi0")]]
    };
    let holds = groups
        .iter()
        .flat_map(|g| {
            g.iter()
                .map(|(r, screen)| format!("{r} <= {screen}"))
                .chain(g.iter().map(|(r, _)| format!("{r} >= {least}")))
                .collect::<Vec<_>>()
        })
        .collect();
    RowStage {
        valid: super::walker::row_valid(j).into(),
        y: super::walker::row_at(hw, "w_row", j),
        di: super::walker::row_at(hw, "w_di", j),
        holds,
    }
}

/// What both forms share: widths, screen, the span path's stages.
fn shape(hw: &Hw, sp: &Stager, setup: SetupShape) -> FrontendShape {
    let fe = &hw.fe;
    let (edge_probes, edge_holds) = super::edge::formal_probes(hw);
    let wd = fe.widths();
    FrontendShape {
        yw: wd.yw,
        cx: wd.cx,
        cy: wd.cy,
        xw: fe.cfg.xbits,
        dw: fe.cfg.dw(),
        width: fe.screen.width as u64,
        height: fe.screen.height as u64,
        latency: hw.latency(),
        setup,
        row_stages: (1..=hw.row_stages()).map(|j| row_stage(hw, j)).collect(),
        span_stages: match super::span_seq::unit(hw) {
            Some(_) => vec![super::span_seq::stage(hw)],
            None => (1..=sp.stage())
                .map(|j| {
                    let held = |n: &str| sp.held(n, j).expect("a span's fields reach the output");
                    SpanStage { valid: span::valid(j), y: held("y"), x: held("x"), len: held("len"), di: held("di") }
                })
                .collect(),
        },
        walker_di: super::span_seq::walker_di(hw).into(),
        starts: None,
        span_unit: super::span_seq::shape(hw),
        edge_probes,
        edge_holds,
    }
}

/// Properties of `tri_frontend` (SPEC §6; names as `frontend::module` declares them), with the
/// per-triangle `dI`: its control against a reference model of its stages kept at the ports.
///
/// The reference, written from SPEC §6: a triangle waits in the vertex register until the
/// set-up is free; the set-up drops it with one `err` pulse when a vertex lies outside the
/// guard band (decided by the reference itself from the ports, SPEC's `-W <= x < 2W`,
/// `-H <= y < 2H`), yields nothing for a culled one, and otherwise divides for `div_clocks`
/// clocks and holds the result until the walker is free (idle, or on its last row with the
/// output free: the next triangle's set-up overlaps the walk); the walker walks the rows from
/// first to last, one per free clock, and each row with covered pixels becomes a span that
/// moves through the I0 stages (two, or six when pipelined) to the output, every stage moving
/// when the output is free; with the row stage (`--pipeline 1`, the reciprocal `I0`) every
/// walked row moves into it first, and whether it has covered pixels is decided there. With CALC in stages, a triangle moves through them as a queue
/// between the vertex register and the set-up.
/// Whether a row has covered pixels (the walker's `lo <= hi`), whether a triangle is culled
/// (its area and row range) and the rows' first and last are the design's data decisions the
/// reference takes as given; it checks them where SPEC constrains them: every walked row's
/// centre lies within the triangle's vertical extent and on the screen, and every span is on
/// the screen with at least one pixel (`out_x + out_len <= W`). Asserted: `in_ready`, `err`,
/// `out_valid` and `out_y` equal the reference's (no triangle dropped or invented, spans top
/// to bottom in order, a triangle's spans before the next one's, `err` exactly once per
/// triangle outside the band and never otherwise); the triangle count (accepted = flagged +
/// culled + walked + in flight) and the span count (every covered row's span offered once);
/// `dI` once per triangle (a span that is not its triangle's first carries the `dI` of the one
/// before it); the rate (a row every free clock, no bubble between triangles when the set-up is
/// done, a dropped triangle costs one clock); reset and stability; and the linking invariants. Every multiplier is cut (area, edge and plane products, I0's product and
/// correction) and so are the set-up dividers' registers (free every clock): their values never
/// decide the control beyond what the reference takes as given, and the values are
/// co-simulated bit-exactly against golden. The dividers' cut is for speed: a run from reset
/// through their restoring steps (66 bits wide at 640x480) is more than twice as slow.
pub fn frontend_properties(s: &FrontendShape) -> Item {
    // No `*` below: the proof cuts every multiplier, the properties' own too.
    let r = Reference {
        s,
        // The span path's stages: the reference's f_<i>v, f_<i>y, f_<i>n for i = 1..=nsp.
        nsp: s.span_stages.len(),
        // Reference counters: wide enough for the stages they count through, modulo 2^cw.
        cw: 4,
    };
    let mut b = r.declarations();
    b.push(r.update());
    b.extend(r.at_the_ports());
    b.extend(r.linking());
    match &s.setup {
        SetupShape::Parallel(_) => b.extend(covers(
            s.latency + 3,
            &[("Span taken: a triangle walked.", "out_valid && out_ready"), ("Guard band drop: a triangle outside it.", "err")],
        )),
        // A triangle's first span is the schedule's latency away (39 to 318 clocks) and its entry
        // up to II (8 to 314): a cover search costs about a second a clock, so the covers are the
        // port's and, where II is short (the ECP5 plan), the entry's.
        SetupShape::Engine(e) => {
            // The sequential engine takes a triangle at its inputs' last read in the period after
            // the boot one (II + held clocks, 350 cover clocks at 16x8): its port's cover is the
            // triangle offered and waiting, which an environment offering none never reaches; the
            // take itself is co-simulated.
            let port = if e.held.is_some() {
                ("Triangle offered, waiting for the engine's read.", "in_valid && !in_ready")
            } else {
                ("Triangle taken at the port.", "in_valid && in_ready")
            };
            let mut c = vec![port];
            if e.ii + 2 <= ENTRY_COVER_DEPTH {
                c.push(("A triangle enters the schedule.", "f_enter && f_vf"));
            }
            b.extend(covers(if c.len() > 1 { e.ii + 2 } else { 4 }, &c));
        }
    }
    Item::Formal(b)
}

/// Formal-only wires `scripts/prove` drives from the flattened design's registers, `(wire,
/// register, width)`: Yosys reads no hierarchical reference.
fn probe_nets(probes: &[(String, String, u32)]) -> Vec<Item> {
    probes.iter().flat_map(|(w, r, n)| [comment(format!("{CUT_TAG}connect -set {w} {r}")), net(w, *n)]).collect()
}

impl Reference<'_> {
    /// The reference's registers and the wires it reads.
    fn declarations(&self) -> Vec<Item> {
        let FrontendShape { yw, cy, dw, .. } = *self.s;
        let Reference { nsp, cw, .. } = *self;
        let mut b = match &self.s.setup {
            SetupShape::Parallel(p) => vec![
                comment(format!("{CUT_TAG}cutpoint t:$mul {}", p.div_regs.iter().map(|r| format!("w:{r}")).collect::<Vec<_>>().join(" "))),
                comment("(the multipliers: area, edges, plane, I0; and the set-up dividers' registers, free every clock:"),
                comment("only the coverage decision, taken as given, depends on them; values are left to co-simulation)"),
            ],
            SetupShape::Engine(e) => {
                let mut b = vec![
                    comment(format!("{CUT_TAG}cutpoint t:$mul")),
                    comment("(the multipliers, the engine's tiles and the span path's: the values are left to co-simulation)"),
                    comment("The engine's and the queue's registers, each driven by scripts/prove from the flattened design:"),
                ];
                b.extend(probe_nets(&engine::engine_probes(e)));
                b.extend(engine::constant_probes(e));
                b
            }
        };
        b.extend(probe_nets(&self.s.edge_probes));
        b.extend(past_flags());
        b.extend(reset_and_stability("span", OUT, &["out_y", "out_x", "out_len", "out_i0", "out_di"]));
        b.push(comment("Reset: no error pulse out of reset either."));
        b.push(Item::Always(vec![when("f_past && $past(rst)", vec![assert("!err")])]));
        match &self.s.setup {
            SetupShape::Parallel(p) => b.extend(self.parallel_declarations(p)),
            SetupShape::Engine(e) => b.extend(self.engine_declarations(e)),
        }
        let parallel_form = matches!(self.s.setup, SetupShape::Parallel(_));
        b.push(comment(if parallel_form {
            "The walker: the triangle being walked, its row and last row, its extent."
        } else {
            "The walker: the triangle being walked, its row and last row."
        }));
        b.extend([reg("f_wv", 1), reg("f_wrow", yw), reg("f_wlast", yw)]);
        if parallel_form {
            b.push(Item::Reg { name: "f_wymin".into(), width: cy, signed: true });
            b.push(Item::Reg { name: "f_wymax".into(), width: cy, signed: true });
        }
        if !self.s.row_stages.is_empty() {
            b.push(comment("The row stages: the walker's row (valid, row, tag), its coverage decided in the last."));
            for j in 1..=self.s.row_stages.len() {
                b.extend([reg(&format!("f_r{j}v"), 1), reg(&format!("f_r{j}y"), yw), reg(&format!("f_r{j}n"), 1)]);
            }
        }
        b.push(comment("The spans: the walker's row in the I0 stages and the output (valid, row)."));
        for i in 1..=nsp {
            b.extend([reg(&format!("f_{i}v"), 1), reg(&format!("f_{i}y"), yw)]);
        }
        b.extend([reg("f_ov", 1), reg("f_oy", yw)]);
        b.push(comment(if !self.s.row_stages.is_empty() {
            "Each span's tag: its triangle's first (f_wnew: the walker's row is its triangle's first)."
        } else {
            "Each span's tag: its triangle's first (the walker has emitted none of it yet: f_wnew)."
        }));
        b.push(reg("f_wnew", 1));
        for i in 1..=nsp {
            b.push(reg(&format!("f_{i}n"), 1));
        }
        b.push(reg("f_on", 1));
        b.push(comment("The dI of the last span offered, and whether the output register could load (f_free):"));
        b.push(comment("a span on the output is new when it is valid and f_free."));
        b.extend([reg("f_pdi", dw), reg("f_free", 1)]);
        b.push(Item::Always(vec![set("f_free", "rst || !out_valid || out_ready"), when("out_valid", vec![set("f_pdi", "out_di")])]));
        b.push(comment("The error pulse owed, and counts: triangles accepted, flagged (at the port), culled,"));
        b.push(comment("walked; spans the walker produced (covered rows) and spans taken at the port."));
        b.extend([reg("f_errp", 1), reg("f_nacc", cw), reg("f_nerr", cw), reg("f_ncull", cw), reg("f_nwalk", cw)]);
        b.extend([reg("f_nrow", cw), reg("f_nout", cw)]);

        if let Some(u) = &self.s.span_unit {
            b.push(comment("The sequential span path: busy (f_1v) for its clocks (f_sc left to its result), the walker"));
            b.push(comment("moving while it is idle or writing its result to a free output."));
            b.push(reg("f_sc", bits_for(u.row_clocks)));
            b.push(wire("f_sdone", 1, format!("f_1v && f_sc == {}", lit(bits_for(u.row_clocks), 0))));
            b.push(wire("f_adv", 1, "!f_1v || (f_sdone && (!out_valid || out_ready))"));
        } else {
            b.push(wire("f_adv", 1, "!out_valid || out_ready"));
        }
        b.push(wire("f_wend", 1, "f_wrow == f_wlast"));
        let empty = self.s.span_unit.as_ref().is_some_and(|u| u.take_when_empty);
        let take = match (&self.s.setup, self.s.starts) {
            (SetupShape::Engine(e), None) if empty => format!("{} && f_adv && !f_wv{}", engine::head_ready(e), engine::preloaded(e)),
            (SetupShape::Engine(e), None) => format!("{} && f_adv && (!f_wv || f_wend)", engine::head_ready(e)),
            (SetupShape::Engine(e), Some(_)) => format!("{} && ie_pv && f_adv && !ie_wait && (!f_wv || f_wend)", engine::head_ready(e)),
            (_, Some(_)) => "f_sb && f_sh && ie_pv && f_adv && !ie_wait && (!f_wv || f_wend)".into(),
            (_, None) => "f_sb && f_sh && f_adv && (!f_wv || f_wend)".into(),
        };
        b.push(wire("f_take", 1, take));
        match &self.s.setup {
            SetupShape::Parallel(p) => {
                let (last, _) = parallel::parallel(p);
                b.push(wire("f_calc", 1, format!("{} && (!f_sb || f_take)", f_v(last))));
                for j in (0..last).rev() {
                    b.push(wire(&f_mv(j, last), 1, format!("{} && (!{} || {})", f_v(j), f_v(j + 1), f_mv(j + 1, last))));
                }
                b.push(wire("f_rdy", 1, format!("!f_vf || {}", f_mv(0, last))));
            }
            SetupShape::Engine(e) => {
                let q = e.latency / e.ii;
                let (phw, qw) = (e.phw(), e.qw());
                b.push(comment("A result is due at the schedule's latency: period q = latency / II, phase latency mod II."));
                b.push(wire("f_due", 1, format!("{} && f_ph == {}", bit("f_vld", e.periods(), q), lit(phw, (e.latency % e.ii) as u64))));
                b.push(comment("The design's data decisions, taken as given: the result's guard-band check and cull."));
                b.push(wire("f_push", 1, "f_due && res_guard && !res_cull"));
                b.push(wire("f_full", 1, format!("f_qn == {}", lit(qw, e.depth as u64))));
                if e.credit {
                    b.push(comment("The engine never freezes; a triangle is taken only while the queue has an entry neither"));
                    b.push(comment("held nor reserved for the triangle in the vertex register or one in flight."));
                    b.push(wire("f_en", 1, "1'b1"));
                    b.push(wire("f_qin", 1, "f_push"));
                    let held = format!("{} + {}", zext("f_vf", 1, qw + 1), engine::held(e, qw + 1));
                    b.push(wire("f_held", qw + 1, held));
                    b.push(wire("f_room", 1, format!("f_held < {}", lit(qw + 1, e.depth as u64))));
                } else {
                    if e.capture {
                        b.push(comment("The engine freezes exactly while the queue is full and a result for it is due or the engine"));
                        b.push(comment("has a field of one to write into its tail (res_wr, taken as given)."));
                        b.push(wire("f_en", 1, "!(f_full && (f_push || res_wr))"));
                    } else {
                        b.push(comment("The engine freezes exactly while a result for the queue is due and the queue is full."));
                        b.push(wire("f_en", 1, "!(f_push && f_full)"));
                    }
                    b.push(wire("f_qin", 1, "f_push && !f_full"));
                    b.push(wire("f_room", 1, "1'b1"));
                }
                b.push(wire("f_enter", 1, format!("f_en && f_ph == {}", lit(phw, (e.ii - 1) as u64))));
                if let Some(h) = e.held {
                    assert!(!e.credit, "the sequential engine freezes, it takes no credits");
                    b.push(comment("The entered triangle waits on the port (f_hold) and is taken at its inputs' last read."));
                    let v0 = bit("f_vld", e.periods(), 0);
                    b.push(wire("f_hold", 1, format!("{v0} && f_ph <= {}", lit(phw, h as u64))));
                    b.push(wire("f_rdy", 1, format!("f_en && {v0} && f_ph == {}", lit(phw, h as u64))));
                } else {
                    b.push(wire("f_rdy", 1, "(!f_vf || f_enter) && f_room"));
                }
            }
        }
        b.push(wire("f_acc", 1, "in_valid && f_rdy"));
        if let SetupShape::Parallel(p) = &self.s.setup {
            b.push(comment("The design's data decisions, taken as given: culled, and a walked row's covered pixels."));
            b.push(wire("f_cull", 1, p.cull.as_str()));
        } else {
            b.push(comment("The design's data decisions, taken as given: a walked row's covered pixels."));
        }
        b.push(wire("f_cover", 1, "lo3 <= hi3"));
        b
    }

    /// The reference's clock: input, set-up, walker, spans and the counts.
    fn update(&self) -> Item {
        let FrontendShape { yw, .. } = *self.s;
        let Reference { nsp, cw, .. } = *self;
        let inc1 = |n: &str| set(n, format!("{n} + {}", one(cw)));
        // The walker moves when the output is free (and, with starts, no source is starting).
        // `row`: a span leaves the walker, or the row stage, for the span path.
        let rows = self.s.row_stages.len();
        let staged = rows > 0;
        assert!(!staged || self.s.starts.is_none(), "the incremental walker has no row stage");
        let (wgo, row) = match self.s.starts {
            Some(_) => ("f_adv && !ie_wait", "f_wv && f_cover && !ie_wait".to_string()),
            None if staged => ("f_adv", format!("f_r{rows}v && f_cover")),
            None => ("f_adv", "f_wv && f_cover".to_string()),
        };
        let row = row.as_str();
        // The walker's row is no longer its triangle's first once it moves on, or (no row stage)
        // once one of its rows is a span.
        let first_gone = if staged { "f_adv && f_wv" } else { row };
        let inc = |n: &str, c: &str| when(c, vec![inc1(n)]);
        let mut load = vec![set("f_wv", "1'b1"), set("f_wrow", "s_first"), set("f_wlast", "s_last")];
        if let SetupShape::Parallel(_) = self.s.setup {
            load.extend([set("f_wymin", "f_symin"), set("f_wymax", "f_symax")]);
        }
        load.extend([set("f_wnew", "1'b1"), inc1("f_nwalk")]);
        let walker = Stmt::If(
            "f_take".into(),
            load,
            vec![
                when(if staged { first_gone.to_string() } else { format!("f_adv && {first_gone}") }, vec![set("f_wnew", "1'b0")]),
                when(
                    format!("{wgo} && f_wv"),
                    vec![Stmt::If("f_wend".into(), vec![set("f_wv", "1'b0")], vec![set("f_wrow", format!("f_wrow + {}", one(yw)))])],
                ),
            ],
        );
        // With row stages a row is tagged its triangle's first as it leaves the walker, or, in
        // the last (where its coverage is decided), when the row ahead of it (its triangle's)
        // was tagged and had no pixel.
        let into_spans = if staged {
            let mut v = Vec::new();
            for j in 1..=rows {
                let (pv, py, pn) = if j == 1 {
                    ("f_wv".into(), "f_wrow".into(), "f_wnew".into())
                } else {
                    (format!("f_r{}v", j - 1), format!("f_r{}y", j - 1), format!("f_r{}n", j - 1))
                };
                let n = if j == rows { format!("{pn} || (f_r{j}n && !(f_r{j}v && f_cover))") } else { pn };
                v.extend([set(format!("f_r{j}v"), pv), set(format!("f_r{j}y"), py), set(format!("f_r{j}n"), n)]);
            }
            v.extend([set("f_1v", row), set("f_1y", format!("f_r{rows}y")), set("f_1n", format!("f_r{rows}n"))]);
            v
        } else {
            vec![set("f_1v", row), set("f_1y", "f_wrow"), set("f_1n", "f_wnew")]
        };
        let spans = match &self.s.span_unit {
            // The unit takes a row when the walker moves, and writes its result when done and the
            // output is free.
            Some(u) => {
                let sw = bits_for(u.row_clocks);
                let count = Stmt::If(
                    "f_adv".into(),
                    vec![set("f_sc", lit(sw, (u.row_clocks - 1) as u64))],
                    vec![when(format!("f_1v && f_sc != {}", lit(sw, 0)), vec![set("f_sc", format!("f_sc - {}", one(sw)))])],
                );
                let out = ["y", "n"].map(|f| set(format!("f_o{f}"), format!("f_1{f}")));
                vec![
                    when("!out_valid || out_ready", std::iter::once(set("f_ov", "f_sdone")).chain(out).collect()),
                    count,
                    when("f_adv", into_spans),
                ]
            }
            None => vec![when(
                "f_adv",
                into_spans
                    .into_iter()
                    .chain((2..=nsp).flat_map(|i| ["v", "y", "n"].map(|f| set(format!("f_{i}{f}"), format!("f_{}{f}", i - 1)))))
                    .chain(["v", "y", "n"].map(|f| set(format!("f_o{f}"), format!("f_{nsp}{f}"))))
                    .collect(),
            )],
        };
        let (reset, front) = match &self.s.setup {
            SetupShape::Parallel(p) => self.parallel_update(p),
            SetupShape::Engine(e) => self.engine_update(e),
        };
        let zero = lit(cw, 0);
        Item::Always(vec![Stmt::If(
            "rst".into(),
            reset
                .into_iter()
                .chain([set("f_wv", "1'b0")])
                .chain((1..=rows).map(|j| set(format!("f_r{j}v"), "1'b0")))
                .chain((1..=nsp).map(|i| set(format!("f_{i}v"), "1'b0")))
                .chain([
                    set("f_ov", "1'b0"),
                    set("f_errp", "1'b0"),
                    set("f_nacc", zero.clone()),
                    set("f_nerr", zero.clone()),
                    set("f_ncull", zero.clone()),
                    set("f_nwalk", zero.clone()),
                    set("f_nrow", zero.clone()),
                    set("f_nout", zero.clone()),
                ])
                .collect(),
            vec![
                set("f_errp", "1'b0"),
                inc("f_nacc", "f_acc"),
                inc("f_nerr", "err"),
                inc("f_nrow", &format!("f_adv && {row}")),
                inc("f_nout", "out_valid && out_ready"),
            ]
            .into_iter()
            .chain(front)
            .chain([walker])
            .chain(spans)
            .collect(),
        )])
    }

    /// At the ports: the reference's stream, the rate, and nothing lost or invented.
    fn at_the_ports(&self) -> Vec<Item> {
        let FrontendShape { yw, xw, width, .. } = *self.s;
        let Reference { nsp, cw, .. } = *self;

        let mut b = vec![
            comment("The front-end is the reference at its ports: it takes a triangle exactly when the"),
            comment("vertex register is free or handing its triangle to the set-up, pulses err once per"),
            comment("triangle outside the guard band and never otherwise, and offers exactly the reference's"),
            comment("spans, row by row: a triangle's rows top to bottom, then the next triangle's."),
        ];
        let mut ports = vec![
            assert("in_ready == f_rdy"),
            assert("err == f_errp"),
            assert("out_valid == f_ov"),
            when("f_ov", vec![assert("out_y == f_oy")]),
        ];
        ports.push(on_screen("out_valid", "out_x", "out_len", xw, width));
        ports.push(Stmt::Comment("dI once per triangle: a new span that is not its triangle's first carries the dI of".into()));
        ports.push(Stmt::Comment("the span before it (the same triangle's).".into()));
        ports.push(when("out_valid && f_free && !f_on", vec![assert("out_di == f_pdi")]));
        b.push(Item::Comb(vec![when("f_past", ports)]));
        b.push(comment("Rate (SPEC §6), in the design's terms: the walker takes a row every clock the output is"));
        b.push(comment("free; a set-up result waiting when the walker is on its last row follows it with no"));
        b.push(comment(match self.s.setup {
            SetupShape::Parallel(_) => "bubble (set-up overlapped with the walk); a dropped or culled triangle costs its CALC clock.",
            SetupShape::Engine(_) => "bubble (set-up overlapped with the walk).",
        }));
        let (go, held) = if self.s.starts.is_some() { (" && !ie_wait", " && ie_pv") } else { ("", "") };
        let waiting = match self.s.setup {
            SetupShape::Parallel(_) => "st == HOLD",
            SetupShape::Engine(_) => "q_ne",
        };
        let mut rate = vec![
            when(
                format!("$past(w_valid && adv && !w_end{go})"),
                vec![assert("w_valid"), assert(format!("w_row == $past(w_row) + {}", one(yw)))],
            ),
            if self.s.span_unit.as_ref().is_some_and(|u| u.take_when_empty) {
                // The next triangle is taken once the last row has left the walker.
                let preloaded = if let SetupShape::Engine(e) = &self.s.setup { engine::preloaded(e) } else { String::new() };
                when(format!("$past(!w_valid && adv && {waiting}{preloaded})"), vec![assert("w_valid"), assert("w_row == $past(s_first)")])
            } else {
                when(
                    format!("$past(w_valid && adv && w_end && {waiting}{held}{go})"),
                    vec![assert("w_valid"), assert("w_row == $past(s_first)")],
                )
            },
        ];
        if let SetupShape::Parallel(p) = &self.s.setup {
            let last = p.calc_stages.len();
            // A dropped or culled triangle costs its CALC clock: the triangle behind it moves up
            // in the same clock, into the last CALC stage, or (CALC in one clock) straight into
            // it from the port.
            rate.push(when(
                format!("$past(calc && (!{} || {}))", p.guard, p.cull),
                vec![match last {
                    0 => assert("in_ready"),
                    1 => assert(format!("!$past(v_full) || {}", p.calc_stages[0].valid)),
                    _ => assert(format!("!$past({}) || {}", p.calc_stages[last - 2].valid, p.calc_stages[last - 1].valid)),
                }],
            ));
        }
        b.push(Item::Always(vec![when("f_past && !$past(rst)", rate)]));
        if let Some(m) = self.s.starts {
            b.extend(starts(m, waiting));
        }
        let in_flight = match &self.s.setup {
            SetupShape::Parallel(p) => {
                let last = p.calc_stages.len();
                format!(" + {}", zext("f_sb", 1, cw)) + &(1..=last).map(|j| format!(" + {}", zext(&f_v(j), 1, cw))).collect::<String>()
            }
            SetupShape::Engine(e) => {
                b.extend(self.engine_ports(e));
                // With `held`, a triangle in the engine's first phases is not yet taken.
                let waiting = if e.held.is_some() { format!(" - {}", zext("f_hold", 1, cw)) } else { String::new() };
                format!(" + {}{waiting}", engine::held(e, cw))
            }
        };
        b.push(comment("Nothing lost or invented: every accepted triangle was flagged, culled or walked, or is"));
        b.push(comment(match self.s.setup {
            SetupShape::Parallel(_) => "still waiting or in set-up (counts modulo 16).",
            SetupShape::Engine(_) => "still waiting, in the engine or in the queue (counts modulo 16).",
        }));
        b.push(Item::Comb(vec![when(
            "f_past",
            vec![assert(format!("f_nacc == f_nerr + {} + f_ncull + f_nwalk + {}{in_flight}", zext("err", 1, cw), zext("f_vf", 1, cw),))],
        )]));
        b.push(comment("Every span the walker produced is offered once: taken at the port, or still in a stage."));
        b.push(Item::Comb(vec![when(
            "f_past",
            vec![assert(format!(
                "f_nrow == f_nout{} + {}",
                (1..=nsp).map(|i| format!(" + {}", zext(&format!("f_{i}v"), 1, cw))).collect::<String>(),
                zext("f_ov", 1, cw)
            ))],
        )]));
        b
    }

    /// Linking invariants: every stage's registers are the reference's.
    fn linking(&self) -> Vec<Item> {
        let FrontendShape { xw, width, ref span_stages, .. } = *self.s;
        let Reference { nsp, .. } = *self;

        let mut b = Vec::new();
        b.push(comment("Linking invariants: every stage's registers are the reference's; a row's centre"));
        b.push(comment("(256 r + 128 sub-pixels) lies within its triangle's vertical extent and on the screen."));
        let mut link = match &self.s.setup {
            SetupShape::Parallel(p) => self.parallel_links(p),
            SetupShape::Engine(e) => self.engine_links(e),
        };
        for (i, sp) in span_stages.iter().enumerate().map(|(k, sp)| (k + 1, sp)) {
            link.push(assert(format!("{} == f_{i}v", sp.valid)));
            link.push(when(format!("f_{i}v"), vec![assert(format!("{} == f_{i}y", sp.y))]));
        }
        link.push(Stmt::Comment("A span that is not its triangle's first has the dI of the span ahead of it.".into()));
        link.push(when("f_ov && !f_free", vec![assert("out_di == f_pdi")]));
        // The dI ahead of stage i (i = nsp + 1: the output's): the nearest valid stage's, else the
        // output's or the last span offered.
        let ahead = |i: usize| {
            (i..=nsp).rev().fold("f_ov ? out_di : f_pdi".to_string(), |acc, k| format!("f_{k}v ? {} : {acc}", span_stages[k - 1].di))
        };
        for (i, sp) in span_stages.iter().enumerate().map(|(k, sp)| (k + 1, sp)).rev() {
            link.push(when(format!("f_{i}v && !f_{i}n"), vec![assert(format!("{} == ({})", sp.di, ahead(i + 1)))]));
        }
        let rows = &self.s.row_stages;
        if rows.is_empty() {
            link.push(when("f_wv && !f_wnew", vec![assert(format!("{} == ({})", self.s.walker_di, ahead(1)))]));
        }
        // The dI ahead of row stage j (1-based; j = rows.len() + 1: the span path's).
        let ahead_row = |j: usize| (j..=rows.len()).rev().fold(ahead(1), |acc, k| format!("f_r{k}v ? {} : {acc}", rows[k - 1].di));
        for (j, r) in rows.iter().enumerate().map(|(k, r)| (k + 1, r)) {
            link.push(assert(format!("{} == f_r{j}v", r.valid)));
            link.push(when(
                format!("f_r{j}v"),
                std::iter::once(assert(format!("{} == f_r{j}y", r.y))).chain(r.holds.iter().map(assert)).collect(),
            ));
            link.push(when(format!("f_r{j}v && !f_r{j}n"), vec![assert(format!("{} == ({})", r.di, ahead_row(j + 1)))]));
        }
        if let Some(r) = rows.first() {
            // A walked row after its triangle's first has that triangle's row ahead of it.
            link.push(when("f_wv && !f_wnew", vec![assert("f_r1v"), assert(format!("w_di == {}", r.di))]));
            // Behind the row stages the walk's end is a register: its row's compare, set while
            // no row is walked.
            link.push(assert("w_end == (!f_wv || f_wend)"));
            // The edges' state the row stages' bounds are made of (`edge::formal_probes`).
            link.push(when("w_valid", self.s.edge_holds.iter().map(assert).collect()));
        }
        for sp in span_stages {
            link.push(on_screen(&sp.valid, &sp.x, &sp.len, xw, width));
        }
        if let Some(u) = &self.s.span_unit {
            link.push(Stmt::Comment("The unit's clocks left are the reference's; its phase and count within bounds.".into()));
            link.push(when("f_1v", u.bounds.iter().map(assert).chain([assert(format!("f_sc == {}", u.left))]).collect()));
        }
        b.push(Item::Comb(vec![when("f_past", link)]));
        b
    }
}

/// The incremental I0's start engine (`--fe-i0 incremental`): what bounds the walker's waits
/// and the held triangle's. A walker's start runs at once, taking the engine from a held
/// triangle's start; the engine's job counts its steps (and, `m` clocks a product, each step's
/// clocks) and ends within its program, and then the source is started (the walker goes on); a
/// held triangle's start runs whenever the walker needs none, and a held start belongs to the
/// held triangle (`held`: the set-up result is held for the walker).
fn starts(m: u32, held: &str) -> Vec<Item> {
    let t = |v: u32| lit(4, v as u64);
    let mut engine = vec![assert(format!(
        "ie_busy ? (ie_t >= {} && ie_t <= {}) : ie_t == {}",
        t(1),
        t(golden::frontend::incremental::EDGE_PRODUCTS),
        t(0)
    ))];
    if m > 1 {
        let kw = bits_for(m - 1);
        engine.push(assert(format!("ie_busy ? ie_k <= {} : ie_k == {}", lit(kw, (m - 1) as u64), lit(kw, 0))));
    }
    engine.extend([
        when("ie_busy && !ie_pre", vec![assert("ie_wait"), assert("ie_src == ie_sel")]),
        when("ie_busy && ie_pre", vec![assert(held), assert("!ie_pv")]),
        when("ie_pv", vec![assert(held)]),
    ]);
    vec![
        comment("Starts (incremental I0): the walker's start runs at once and ends within the engine's clocks,"),
        comment("then the walker goes on; the held triangle's start runs when the walker needs none."),
        Item::Comb(vec![when("f_past", engine)]),
        Item::Always(vec![when(
            "f_past && !$past(rst)",
            vec![
                when("$past(ie_wait) && ie_wait", vec![assert("ie_busy && !ie_pre")]),
                when(format!("$past({held} && !ie_pv && !ie_wait && !ie_busy)"), vec![assert("ie_busy && ie_pre")]),
            ],
        )]),
    ]
}
