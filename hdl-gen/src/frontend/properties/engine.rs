//! The engine form's part of the front-end's properties (`--fe-setup`): the engine's and the
//! queue's registers the proof reads, and the reference's declarations, updates, port checks
//! and links for the sequenced set-up and its result queue.

use super::shape::*;
use crate::formal::*;
use crate::verilog::*;

/// The engine's and the queue's registers the properties read, by the names Yosys gives them
/// once the design is flattened (`instance.register`; `mem[k]`, the queue's entry k, once
/// `memory_map` has run): `scripts/prove` drives each formal-only wire from its register
/// (`connect -set`), since Yosys reads no hierarchical reference.
pub(super) fn engine_probes(e: &EngineShape) -> Vec<(String, String, u32)> {
    let pw = bits_for(e.depth - 1);
    // The sequential engine (`held`) keeps no triangle of its own: no vertex register to read.
    let mut v = if e.held.is_some() { Vec::new() } else { vec![("f_e_vfull".to_string(), "u_engine.v_full".to_string(), 1)] };
    v.push(("f_e_vld".into(), "u_engine.vld".into(), e.periods()));
    if e.binary_phase {
        v.push(("f_e_ph".into(), "u_engine.pc".into(), e.phw()));
    } else if e.ii > 1 {
        v.push(("f_e_ph".into(), "u_engine.ph".into(), e.ii));
    }
    if e.epochs > 1 {
        v.push(("f_e_ep".into(), "u_engine.ep".into(), e.epochs));
    }
    v.push(("f_q_cnt".into(), "u_queue.cnt".into(), pw + 1));
    // A one-entry queue's pointers stay 0 and synthesis drops them: [`constant_probes`].
    if e.depth > 1 {
        v.extend([("f_q_rd".into(), "u_queue.rd".into(), pw), ("f_q_wr".into(), "u_queue.wr".into(), pw)]);
    }
    v.extend((0..e.depth).map(|k| (format!("f_q_mem{k}"), format!("u_queue.mem[{k}]"), e.entry_w)));
    if e.head {
        v.extend([
            ("f_q_hd".into(), "u_queue.hd".into(), e.entry_w),
            ("f_q_hv".into(), "u_queue.hv".into(), 1),
            ("f_q_mc".into(), "u_queue.mc".into(), pw + 1),
            ("f_q_mne".into(), "u_queue.ne".into(), 1),
        ]);
    }
    v
}

/// Whether the reference's queue has a head the walker can take: an entry, or with a
/// registered head ([`EngineShape::head`]) the head register's (`f_qh`).
pub(super) fn head_ready(e: &EngineShape) -> String {
    if e.head {
        "f_qh".into()
    } else {
        format!("f_qn != {}", lit(e.qw(), 0))
    }
}

/// The take's wait for the edges' preload from the walk memory (`EngineShape::preload`): the
/// reference's count at its end, else nothing.
pub(super) fn preloaded(e: &EngineShape) -> String {
    e.preload.map(|n| format!(" && f_lk == {}", lit(bits_for(n), n as u64))).unwrap_or_default()
}

/// The probes a one-entry queue has no register for: its pointers, always 0.
pub(super) fn constant_probes(e: &EngineShape) -> Vec<Item> {
    if e.depth > 1 {
        return Vec::new();
    }
    vec![wire("f_q_rd", 1, "1'b0"), wire("f_q_wr", 1, "1'b0")]
}

/// The triangles the queue holds or will, at `w` bits: its entries, and each period's triangle in
/// flight until its result is due (every period before the result's, the result's up to its
/// phase).
pub(super) fn held(e: &EngineShape, w: u32) -> String {
    let (q, n) = (e.latency / e.ii, e.periods());
    let mut s = zext("f_qn", e.qw(), w);
    s += &(0..q).map(|j| format!(" + {}", zext(&bit("f_vld", n, j), 1, w))).collect::<String>();
    s + &format!(" + {}", zext(&format!("({} && f_ph <= {})", bit("f_vld", n, q), lit(e.phw(), (e.latency % e.ii) as u64)), 1, w))
}

impl Reference<'_> {
    /// The engine's reference registers: the vertex register, the phase and the valid bits of
    /// the periods in flight, and the queue (its count and entries, in order).
    pub(super) fn engine_declarations(&self, e: &EngineShape) -> Vec<Item> {
        let mut b = vec![
            comment("The reference. The vertex register, the engine's phase (0 .. II - 1) and the valid bits of the"),
            comment("periods in flight (a triangle or a bubble enters at the last phase), the queue's count, and one"),
            comment("tracked entry: a result the solver picks freely as it enters the queue (f_pick), kept as the"),
            comment("engine offered it (the result's bits, taken as given) with its place from the head. Whatever"),
            comment("holds of it holds of every entry, so one entry's bits stand for the queue's."),
        ];
        b.extend([reg("f_vf", 1), reg("f_ph", e.phw()), reg("f_vld", e.periods()), reg("f_qn", e.qw())]);
        b.extend([wire("f_pick", 1, "$anyseq"), reg("f_tin", 1), reg("f_tp", bits_for(e.depth - 1)), reg("f_tv", e.entry_w)]);
        if e.head {
            b.push(comment("The registered head holds an entry (f_qh): refilled from the memory only while empty."));
            b.push(reg("f_qh", 1));
        }
        if let Some(n) = e.preload {
            b.push(comment("The edges' preload (f_lk): a field a clock while a triangle is queued and none walked."));
            b.push(reg("f_lk", bits_for(n)));
        }
        b.extend(e.di_in_ram.iter().flatten().cloned());
        b
    }

    /// The engine's clock: (its reset, its update). The phase and the valid bits move only while
    /// the engine is not frozen; the queue shifts its head out on the walker's take and writes a
    /// result behind the entries that stay.
    pub(super) fn engine_update(&self, e: &EngineShape) -> (Vec<Stmt>, Vec<Stmt>) {
        let (phw, qw, n) = (e.phw(), e.qw(), e.periods());
        let inc1 = |x: &str| set(x, format!("{x} + {}", one(self.cw)));
        let last = lit(phw, (e.ii - 1) as u64);
        // With `held`, the triangle on the port at the last phase enters (the port holds it until
        // it is taken, at phase `held`); one gone from the port by then is dropped, a bubble.
        let entering = if e.held.is_some() { "in_valid" } else { "f_vf" };
        let shift_in = if n == 1 { entering.to_string() } else { format!("{{f_vld[{}:0], {entering}}}", n - 2) };
        let mut step = vec![set("f_ph", format!("f_ph + {}", one(phw)))];
        if let Some(h) = e.held {
            let v0 = bit("f_vld", n, 0);
            step.push(when(format!("f_ph == {} && {v0} && !in_valid", lit(phw, h as u64)), vec![set(v0, "1'b0")]));
        }
        let mut st = vec![
            set("f_errp", "f_due && !res_guard"),
            when("f_due && f_en && res_guard && res_cull", vec![inc1("f_ncull")]),
            when("f_en", vec![Stmt::If(format!("f_ph == {last}"), vec![set("f_ph", lit(phw, 0)), set("f_vld", shift_in)], step)]),
        ];
        if e.held.is_none() {
            st.insert(2, Stmt::If("f_acc".into(), vec![set("f_vf", "1'b1")], vec![when("f_enter", vec![set("f_vf", "1'b0")])]));
        }
        // The slot the pushed result lands in: behind the entries that stay. With the capture,
        // the result is the tail entry as the engine wrote it (the queue's word at wr), so a
        // field written over an entry still held breaks the queue's links.
        let pushed = if e.capture {
            let pw = bits_for(e.depth - 1);
            (0..e.depth).rev().fold(format!("{}'d0", e.entry_w), |acc, k| format!("(f_q_wr == {}) ? f_q_mem{k} : {acc}", lit(pw, k as u64)))
        } else {
            "res".to_string()
        };
        // The tracked entry moves up a place on each take and leaves from the head; a result is
        // picked only while none is tracked, behind the entries that stay.
        let pw = bits_for(e.depth - 1);
        st.push(when(
            "f_tin && f_take",
            vec![Stmt::If(format!("f_tp == {}", lit(pw, 0)), vec![set("f_tin", "1'b0")], vec![set("f_tp", format!("f_tp - {}", one(pw)))])],
        ));
        // Its place, below the depth (a result enters only with room), so within the pointer's bits.
        let place = format!("f_qn - {}", zext("f_take", 1, qw));
        st.push(when("f_qin && !f_tin && f_pick", vec![set("f_tin", "1'b1"), set("f_tv", pushed), set("f_tp", place)]));
        if e.head {
            // Empty, the head takes the memory's oldest entry (with no head, all f_qn are there).
            st.push(Stmt::If("f_qh".into(), vec![set("f_qh", "!f_take")], vec![set("f_qh", format!("f_qn != {}", lit(qw, 0)))]));
        }
        st.push(set("f_qn", format!("f_qn + {} - {}", zext("f_qin", 1, qw), zext("f_take", 1, qw))));
        let mut reset =
            vec![set("f_vf", "1'b0"), set("f_ph", lit(phw, 0)), set("f_vld", lit(n, 0)), set("f_qn", lit(qw, 0)), set("f_tin", "1'b0")];
        if e.head {
            reset.push(set("f_qh", "1'b0"));
        }
        if let Some(n) = e.preload {
            let w = bits_for(n);
            let more = when(
                format!("f_qn != {} && !f_wv && f_lk != {}", lit(qw, 0), lit(w, n as u64)),
                vec![set("f_lk", format!("f_lk + {}", one(w)))],
            );
            st.push(Stmt::If("f_take".into(), vec![set("f_lk", lit(w, 0))], vec![more]));
            reset.push(set("f_lk", lit(w, 0)));
        }
        (reset, st)
    }

    /// The engine and its queue at their boundary with the front-end: results due when the
    /// reference says, the freeze, the queue's writes and reads, its order.
    pub(super) fn engine_ports(&self, e: &EngineShape) -> Vec<Item> {
        let depth = lit(e.qw(), e.depth as u64);
        let mut b = vec![comment("The engine: a result is due exactly at its schedule's latency after its entry plus the clocks")];
        if e.credit {
            b.push(comment("frozen (none: it never freezes, and the queue never holds more than its entries and those"));
            b.push(comment("reserved, so a due result always finds room)."));
            let all = lit(e.qw() + 1, e.depth as u64);
            b.push(Item::Comb(vec![when("f_past", vec![assert("res_v == f_due"), assert(format!("f_held <= {all}"))])]));
        } else {
            b.push(comment("frozen; the engine freezes exactly while that result finds the queue full."));
            b.push(Item::Comb(vec![when("f_past", vec![assert("res_v == f_due"), assert("en == f_en")])]));
        }
        b.push(comment("The queue: never written when full, never read when empty, written exactly when a result"));
        b.push(comment("for it is due and it has room, read exactly when the walker takes; its head is the oldest"));
        b.push(comment("entry not yet taken (entries leave in the order they came, none lost or repeated)."));
        b.push(Item::Comb(vec![when(
            "f_past",
            vec![
                assert("!(q_in && q_full)"),
                assert("!(take && !q_ne)"),
                assert(format!("f_q_cnt <= {depth}")),
                assert("q_in == f_qin"),
                assert("take == f_take"),
                assert(format!("q_ne == ({})", head_ready(e))),
                assert(format!("q_full == (f_qn == {depth})")),
                when(
                    format!("f_tin && f_tp == {}{}", lit(bits_for(e.depth - 1), 0), if e.head { " && f_qh" } else { "" }),
                    vec![assert("q_head == f_tv")],
                ),
            ],
        )]));
        if !e.credit {
            b.push(comment("The freeze: while en is low the phase ring, the valid bits of the periods in flight and"));
            b.push(comment("the epoch ring hold, and the queue is not written."));
            let mut hold = vec![assert("f_e_vld == $past(f_e_vld)")];
            if e.ii > 1 {
                hold.push(assert("f_e_ph == $past(f_e_ph)"));
            }
            if e.epochs > 1 {
                hold.push(assert("f_e_ep == $past(f_e_ep)"));
            }
            b.push(Item::Comb(vec![when("f_past && !en", vec![assert("!q_in")])]));
            b.push(Item::Always(vec![when("f_past && !$past(rst) && !$past(en)", hold)]));
        }
        if e.capture {
            b.push(comment("The capture: no field is written into the tail while the queue is full (the tail is its oldest entry)."));
            b.push(Item::Comb(vec![when("f_past && q_full", vec![assert("res_we == 0")])]));
        }
        if e.walk_ram {
            // The memories have no collision logic (`no_rw_check`): their write slot is never read.
            b.push(comment("The walk's memories: the engine's slot is the walked one's exactly while the queue is full, so it never writes the slot read."));
            b.push(Item::Comb(vec![when("f_past", vec![assert("(wk_ws == wk_rs) == q_full"), assert("wk_ws != wk_slot || q_full")])]));
        }
        if let Some(n) = e.preload {
            b.extend(preload_reads(n));
        }
        if e.di_in_ram.is_some() {
            // The output register loads dI from the read register with the span path's result.
            b.push(comment("Output dI: when the span path's result is done, the read register holds the walked triangle's An word."));
            b.push(Item::Comb(vec![when("f_past && sq_done", vec![assert("wk_di == f_wdi")])]));
        }
        b
    }

    /// The engine's, the queue's and the walker's links. The rows the walker loads are the
    /// engine's data (taken as given: where they lie is co-simulated), so its links are its
    /// registers only.
    pub(super) fn engine_links(&self, e: &EngineShape) -> Vec<Stmt> {
        let (phw, qw, pw) = (e.phw(), e.qw(), bits_for(e.depth - 1));
        // With `held` no triangle waits in the engine: the entered one waits on the port.
        let vfull = if e.held.is_some() { "!f_vf" } else { "f_e_vfull == f_vf" };
        let mut link = vec![assert(vfull), assert("f_e_vld == f_vld"), assert(format!("f_ph <= {}", lit(phw, (e.ii - 1) as u64)))];
        if e.binary_phase {
            link.push(assert("f_e_ph == f_ph"));
        } else if e.ii > 1 {
            link.push(assert(format!("f_e_ph == {} << f_ph", lit(e.ii, 1))));
        }
        if e.epochs > 1 {
            link.push(assert(format!("f_e_ep != {} && (f_e_ep & (f_e_ep - {})) == {}", lit(e.epochs, 0), one(e.epochs), lit(e.epochs, 0))));
        }
        // The queue's pointers: the tail is the count past the head, modulo the depth; entry i
        // from the head is its memory word (rd + i) mod depth.
        let rd = "{1'b0, f_q_rd}";
        let wrap = |x: String, k: u32| format!("({x} == {} || {x} == {})", lit(pw + 1, k as u64), lit(pw + 1, (k + e.depth) as u64));
        if !e.depth.is_power_of_two() {
            // The pointers stay below the depth (a word past it is no entry).
            let last = lit(pw, (e.depth - 1) as u64);
            link.extend([assert(format!("f_q_rd <= {last}")), assert(format!("f_q_wr <= {last}"))]);
        }
        // The memory's count: every entry, or with a registered head those behind it.
        let mem_cnt = if e.head { "f_q_mc" } else { "f_q_cnt" };
        link.extend([
            assert(format!("f_q_cnt == {}", zext("f_qn", qw, pw + 1))),
            assert(format!(
                "{rd} + {mem_cnt} == {{1'b0, f_q_wr}} || {rd} + {mem_cnt} == {{1'b0, f_q_wr}} + {}",
                lit(pw + 1, e.depth as u64)
            )),
        ]);
        // The tracked entry is one the queue holds, in its memory word (rd + place) mod depth;
        // with a registered head the head's entry is in hd, the others a place nearer rd.
        link.push(when("f_tin", vec![assert(format!("{} < f_qn", zext("f_tp", pw, qw)))]));
        let mut place = format!("{rd} + {{1'b0, f_tp}}");
        if e.head {
            let qh = zext("f_qh", 1, pw + 1);
            link.extend([
                assert("f_q_hv == f_qh"),
                assert(format!("!f_qh || f_qn != {}", lit(qw, 0))),
                assert(format!("f_q_mc == {} - {qh}", zext("f_qn", qw, pw + 1))),
                assert(format!("f_q_mne == (f_q_mc != {})", lit(pw + 1, 0))),
                when(format!("f_tin && f_qh && f_tp == {}", lit(pw, 0)), vec![assert("f_q_hd == f_tv")]),
            ]);
            place = format!("{place} - {qh}");
        }
        for k in 0..e.depth {
            let at = if e.head {
                format!("f_tin && !(f_qh && f_tp == {}) && {}", lit(pw, 0), wrap(place.clone(), k))
            } else {
                format!("f_tin && {}", wrap(place.clone(), k))
            };
            link.push(when(at, vec![assert(format!("f_q_mem{k} == f_tv"))]));
        }
        if e.credit {
            // The credits: the entries neither held nor reserved.
            let w = e.qw() + 1;
            link.push(assert(format!("{} == {} - f_held", zext("cr", bits_for(e.depth), w), lit(w, e.depth as u64))));
        }
        link.extend([assert("w_valid == f_wv"), when("f_wv", vec![assert("w_row == f_wrow"), assert("w_last == f_wlast")])]);
        if let Some(n) = e.preload {
            // The preload runs only while a triangle is queued and none walked, until the take.
            let w = bits_for(n);
            link.push(assert("wk_lk == f_lk"));
            link.push(assert(format!("f_lk <= {}", lit(w, n as u64))));
            link.push(assert(format!("f_lk == {} || (f_qn != {} && !f_wv)", lit(w, 0), lit(qw, 0))));
        }
        link
    }
}

/// The preload's reads (`EngineShape::preload`, `n` the count at its end): each edge field is
/// loaded (its bit of `e_ld`) only from its own word of the queued triangle's slot, read in the
/// clock before, and the take's `Tn` likewise. The second memory's words: `dYn`, `Tn`, then
/// the fields, edge by edge (`span_seq::walk_ram`).
fn preload_reads(n: u32) -> Vec<Item> {
    let fields = n - 1;
    let db = bits_for(fields + 1);
    let word = |j: u32| format!("$past(wk_pre) && $past(wk_da) == {{!$past(wk_rs), {}}}", lit(db, j as u64));
    let mut per = vec![assert(format!("(e_ld & (e_ld - {})) == {}", lit(fields, 1), lit(fields, 0)))];
    per.extend((0..fields).map(|j| when(format!("e_ld[{j}]"), vec![assert(word(j + 2))])));
    per.push(when("take", vec![assert(word(1))]));
    vec![
        comment(
            "The edges' preload: every field loaded from its word of the queued triangle's slot, read the clock before; Tn so at the take.",
        ),
        Item::Always(vec![when("f_past && !$past(rst)", per)]),
    ]
}
