//! The walk's constants in block RAM (the iCE40 targets at level 0: the sequential engine and
//! span path, no row stages). `An`, `Gxn` and `Rn`, which the span path reads one at a time at
//! its phases' loads, and `dYn`, which the walker adds once a row, are constant through a
//! triangle's walk. Held in flip-flops they were stored twice, in the queue's entry and in the
//! walker's copy (about 360 logic cells on the UP5K, each a flip-flop no LUT feeds): here the
//! engine writes each of them into a two-slot memory as it produces it (the slot the queue's
//! next push takes) and the span path reads `An`, `Gxn`, `Rn` from the slot of the triangle
//! being walked, which changes at the take. `Tn`, which the walker loads at the take and steps,
//! is in a second memory, read from the queued triangle's slot in the clock before a take can
//! come. Where `dYn` is depends on the plan ([`registered`]): on the HX8K beside `An`, `Gxn`,
//! `Rn`, read from the queued triangle's slot in the clock before a take can come and loaded at
//! the take into the walker's register, so that the row step's 64-bit add starts from a
//! flip-flop (read straight from the memory's RDATA it was every HX8K seed's critical path,
//! 51.9 MHz, docs/fpga.md, *Stop 34's changes together*); on the UP5K, which needs the cells,
//! beside `Tn`, read every clock the walker steps, the add's operand itself. A slot is never read
//! where it is written: the engine writes only while the queue is empty, and its slot is then the
//! one the walker does not hold (`no_rw_check`, so Yosys adds no collision logic).
//!
//! On the UP5K ([`Hw::edges_in_walk_ram`]) the second memory also holds the edges' set-up fields, which
//! were the queue entry's 354 flip-flops: the walker reads them into the edges' registers, one a
//! clock, while it is idle and a triangle is queued, and takes the triangle after the last
//! ([`PRELOAD_CLOCKS`] after a push into an empty queue; behind a covered last row the span path's
//! 36 clocks cover them). docs/queue-in-walk-ram.md (issue 27, stop 36).
//!
//! The memories' reads are registered, so each read is addressed a clock before its load: the
//! span path's phase names the field its next load reads ([`read_order`]), and the slot is the
//! walked triangle's, or at the take already the taken one's. docs/fpga.md, *The walk's
//! constants in block RAM*.

use crate::frontend::hw::{Hw, PRELOAD_CLOCKS};
use crate::verilog::{comment, lit, reg, set, wire, Item, Stmt};
use crate::widths::bits_for;
use golden::frontend::engine::SetupForm;
use golden::frontend::span_seq::{Multiplicand, Multiplier, SpanSeq};
use golden::frontend::Widths;

/// The fields the span path reads from the first memory, in its address order.
const SPAN_FIELDS: [&str; 3] = ["an", "gxn", "rn"];
/// The field the walker's row step adds: where [`registered`], the first memory's fourth word,
/// read from the queued triangle's slot in the clock before a take can come (when the span path
/// reads none of its fields in the next clock); else the second memory's first, read every
/// clock the walker steps (a read port of its own: the walker steps while the span path reads).
const STEP_FIELD: &str = "dyn";
/// The field the walker loads at the take and then steps, in the second memory (its second word
/// beside `dYn`, or alone where `dYn` is [`registered`]).
const TAKE_FIELD: &str = "tn";

/// Whether the walker holds `dYn` in a register loaded at the take (the HX8K's plan), not
/// reading it from the memory every row (the UP5K's): the register costs the UP5K, which
/// does not fit, about 110 logic cells (7,205 against 7,095), and it is the HX8K's clock
/// (docs/fpga.md, *The walk memories on the HX8K*).
fn registered(hw: &Hw) -> bool {
    hw.fe.setup == SetupForm::Ice40Hx8k
}

/// The fields of the first memory, in its address order.
fn span_memory(hw: &Hw) -> Vec<&'static str> {
    let step = registered(hw).then_some(STEP_FIELD);
    SPAN_FIELDS.iter().copied().chain(step).collect()
}

/// The write enable of field `name` (a bit of the engine's `res_we`), as the set-up names it.
pub(crate) fn we(name: &str) -> String {
    format!("wk_we_{name}")
}

/// Whether set-up result field `name` is in the memories, not in the queue's entry nor the
/// walker's registers.
pub(crate) fn holds(hw: &Hw, name: &str) -> bool {
    hw.walk_ram()
        && (SPAN_FIELDS.contains(&name)
            || name == STEP_FIELD
            || name == TAKE_FIELD
            || edge_field(hw, name).is_some()
            || (name == DI_FIELD && hw.edges_in_walk_ram()))
}

/// The triangle's `dI`, which the output register loads with every span. Where
/// [`Hw::edges_in_walk_ram`] it is in `An`'s word of the first memory, not in the queue's entry
/// and the walker's copy (42 flip-flops, 41 UP5K logic cells): the span path's last phase
/// addresses `An`'s word for the next accept, so `wk_q` holds both when its result is done, and
/// the output loads `dI` from it in the same clock as the next row's accept loads `An`. `An`
/// fills its word's low columns and `dI` its top ([`di_columns`]): a fifth block RAM's
/// [`EBR_COLUMNS`] above the span fields' 64, then the columns above `An` and `Rn`.
/// docs/queue-in-walk-ram.md, stop 37.
const DI_FIELD: &str = "di";

/// An iCE40 block RAM's columns at its widest (256 x 16).
const EBR_COLUMNS: u32 = 16;

/// Where [`DI_FIELD`] is in the first memory: its low bits (up to [`EBR_COLUMNS`]) in an added
/// block RAM's columns, from the span fields' width up, and any above those at the top of the
/// span fields' columns, above `An` and `Rn` (`Gxn` writes up to its own top, [`Hw::s2n_bits`],
/// so only the columns below that take a select of the write's data).
#[derive(Clone, Copy)]
struct DiColumns {
    /// The span fields' width: the low bits' first column.
    sw: u32,
    low: u32,
    high: u32,
}

impl DiColumns {
    /// The first and last columns dI's write covers.
    fn span(self) -> (u32, u32) {
        (self.sw - self.high, self.sw + self.low - 1)
    }

    /// `dI` from a word `w` of the first memory (`An`'s): its high columns, then its low.
    fn of(self, w: &str) -> String {
        let low = format!("{w}[{}:{}]", self.sw + self.low - 1, self.sw);
        if self.high == 0 {
            return low;
        }
        format!("{{{w}[{}:{}], {low}}}", self.sw - 1, self.sw - self.high)
    }

    /// The write's data over [`Self::span`]: `dI`'s low bits at the top, its high bits below.
    fn data(self) -> String {
        let low = format!("res_bus[{}:0]", self.low - 1);
        if self.high == 0 {
            return low;
        }
        format!("{{{low}, res_bus[{}:{}]}}", self.low + self.high - 1, self.low)
    }
}

fn di_columns(hw: &Hw) -> Option<DiColumns> {
    if !holds(hw, DI_FIELD) {
        return None;
    }
    let (sw, dw) = (span_width(hw), hw.fe.cfg.dw());
    let Widths { aw, rw, .. } = hw.fe.widths();
    let low = dw.min(EBR_COLUMNS);
    let high = dw - low;
    assert!(sw - high >= aw.max(rw), "dI's high bits above An's and Rn's columns");
    Some(DiColumns { sw, low, high })
}

/// The first memory's columns: the span fields', and [`DI_FIELD`]'s added block RAM's.
fn m_width(hw: &Hw) -> u32 {
    di_columns(hw).map_or(span_width(hw), |c| c.sw + c.low)
}

/// For the proofs, where `dI` is in the first memory: the declarations of `f_wdi`, the walked
/// triangle's `dI` there (its slot `wk_rs`, `An`'s word), which the read register's `wk_di`
/// equals whenever the span path's result is done.
pub(crate) fn formal_di(hw: &Hw) -> Option<Vec<Item>> {
    let cols = di_columns(hw)?;
    let word = format!("wk_m[{{wk_rs, {}}}]", lit(field_bits(hw), index(SPAN_FIELDS[0])));
    Some(vec![
        comment("dI in the first walk memory: the walked triangle's, in its slot's An word."),
        wire("f_wk_an", m_width(hw), word),
        wire("f_wdi", hw.fe.cfg.dw(), cols.of("f_wk_an")),
    ])
}

/// The output register's `dI` source, where the memory holds it: the read register's, `An`'s
/// word when the span path is done.
pub(crate) fn di_value(hw: &Hw) -> Option<&'static str> {
    holds(hw, DI_FIELD).then_some("wk_di")
}

/// The first memory's writes: every span field's whole word; where it holds [`DI_FIELD`],
/// `An` and `Rn` in their columns, `Gxn` up to its top, `dI` in its own (`An`'s word: the engine
/// addresses a field's word by its enable, `An`'s being the default).
fn m_writes(hw: &Hw) -> Vec<Stmt> {
    let (sw, at) = (span_width(hw), "wk_m[{wk_ws, wk_wa}]");
    let Some(cols) = di_columns(hw) else {
        let m_we: Vec<String> = span_memory(hw).into_iter().map(we).collect();
        return vec![Stmt::If(m_we.join(" || "), vec![set(at, format!("res_bus[{}:0]", sw - 1))], vec![])];
    };
    assert_eq!(span_memory(hw), SPAN_FIELDS, "dYn not in the first memory");
    let Widths { aw, rw, .. } = hw.fe.widths();
    let (low, gx) = (aw.max(rw) - 1, hw.s2n_bits() - 2);
    let (first, last) = cols.span();
    vec![
        Stmt::If(format!("{} || {}", we("an"), we("rn")), vec![set(format!("{at}[{low}:0]"), format!("res_bus[{low}:0]"))], vec![]),
        Stmt::If(we("gxn"), vec![set(format!("{at}[{gx}:0]"), format!("res_bus[{gx}:0]"))], vec![]),
        Stmt::If(we(DI_FIELD), vec![set(format!("{at}[{last}:{first}]"), cols.data())], vec![]),
    ]
}

/// The edges' fields in the second memory, per edge in the edge's input order
/// ([`crate::frontend::edge::input_buses`]): field `j` of edge `k` is number `EDGE_FIELDS * k + j`.
const EDGE_FIELDS: [&str; 9] = ["act", "right", "rs", "re", "d", "g", "rem", "qs", "rs256"];

/// The second memory's word of the first edge field: after `dYn` (0) and `Tn` (1).
const EDGE_BASE: u64 = 2;

// Hw's preload clocks are one read a field of these, then the clock the last one is loaded,
// which reads `Tn`.
const _: () = assert!(PRELOAD_CLOCKS == 3 * EDGE_FIELDS.len() as u32 + 1, "a read a field, then Tn's");

/// The number of edge field `name` (`e<k>_<port>`), where the memory holds the edges' fields.
fn edge_field(hw: &Hw, name: &str) -> Option<u64> {
    let (e, port) = name.split_once('_')?;
    let k: u64 = e.strip_prefix('e')?.parse().ok()?;
    let j = EDGE_FIELDS.iter().position(|f| *f == port)? as u64;
    (hw.edges_in_walk_ram() && k < 3).then_some(EDGE_FIELDS.len() as u64 * k + j)
}

/// Whether the walker's register for field `name` is gone: the memories' read is it.
pub(crate) fn replaces(hw: &Hw, name: &str) -> bool {
    holds(hw, name) && (SPAN_FIELDS.contains(&name) || name == DI_FIELD || (name == STEP_FIELD && !registered(hw)))
}

/// What the walker loads field `name` from at the take, where the memories hold it.
pub(crate) fn take_value(hw: &Hw, name: &str) -> Option<&'static str> {
    match name {
        TAKE_FIELD if holds(hw, name) => Some("wk_tn"),
        STEP_FIELD if holds(hw, name) && registered(hw) => Some("wk_dyn"),
        _ => None,
    }
}

/// The first memory's word: its widest field.
fn span_width(hw: &Hw) -> u32 {
    let Widths { aw, k, rw, .. } = hw.fe.widths();
    aw.max(k).max(rw)
}

/// The bits the engine offers the memories (`res_bus`): the widest field's.
pub(crate) fn bus_width(hw: &Hw) -> u32 {
    span_width(hw).max(hw.fe.widths().k)
}

/// The field each of the span path's loads reads from the first memory, if any: load 0 the
/// accept's, load k + 1 the one at phase k's end.
fn load_reads(k: usize) -> Option<&'static str> {
    let p = SpanSeq::PHASES[k];
    let mc = match p.mc {
        Multiplicand::An => Some("an"),
        Multiplicand::Gx => Some("gxn"),
        Multiplicand::H => None,
    };
    let mp = match p.mp {
        Multiplier::Rn => Some("rn"),
        Multiplier::One | Multiplier::Lo | Multiplier::Qt1 => None,
    };
    assert!(mc.is_none() || mp.is_none(), "phase {k} loads two of the memory's fields in one clock");
    mc.or(mp)
}

/// The field addressed while the unit is in phase k (the one its next load reads), and while it
/// is idle or in its last phase (the next accept's). A phase's load is at least a clock after
/// the phase begins (it has steps), so the address is on the memory a clock before; the last
/// phase has steps too, so the clock before the unit's result is done it loads nothing ([`dyn_read`]).
fn read_order(q: &SpanSeq) -> (Vec<&'static str>, &'static str) {
    let n = SpanSeq::PHASES.len();
    let accept = load_reads(0).unwrap_or(SPAN_FIELDS[0]);
    let during = (0..n - 1)
        .map(|k| {
            assert!(q.steps(&SpanSeq::PHASES[k]) > 0, "phase {k} loads the next in its first clock");
            load_reads(k + 1).unwrap_or(accept)
        })
        .collect();
    assert!(q.steps(&SpanSeq::PHASES[n - 1]) > 0, "the last phase is done in its first clock");
    (during, accept)
}

/// The first memory's word of field `name` in a slot.
fn index(name: &str) -> u64 {
    if name == STEP_FIELD {
        return SPAN_FIELDS.len() as u64;
    }
    SPAN_FIELDS.iter().position(|f| *f == name).expect("a field of the first memory") as u64
}

/// When the first memory reads `dYn` of the queued triangle instead of the span path's field:
/// a take can come next clock (the queue is full or being pushed, no take now, and the walker
/// has no row next clock: idle, or accepting its last row now), and the span path loads nothing
/// next clock (idle, in its last phase, or accepting now: the phase it starts has steps). A take
/// needs all of these the clock before, so the walker's `dYn` is on `wk_q` at every take.
fn dyn_read(last_phase: &str) -> String {
    format!("(q_full || q_in) && !take && (w_valid ? w_end && adv : !sq_busy || sq_ph == {last_phase})")
}

/// The address bits of a field in a slot: the first memory's fields'.
fn field_bits(hw: &Hw) -> u32 {
    bits_for(span_memory(hw).len() as u32 - 1)
}

/// Where [`Hw::edges_in_walk_ram`]: the second memory's read register (`wk_dq`, declared here, before the
/// edges read it), the preload's count (`wk_lk`: the field read, then 27 and 28 reading `Tn`;
/// `wk_ldd`, the take's condition) and each field's load, its bit of `e_ld` in the clock after
/// its read. With the queue's head fields, before the walker.
pub(crate) fn edge_inputs(hw: &Hw, body: &mut Vec<Item>) {
    let k = hw.fe.widths().k;
    let n = 3 * EDGE_FIELDS.len() as u64;
    let lw = bits_for(n as u32 + 1);
    body.push(comment("The edges' fields from the second walk memory, one a clock while the walker is idle and a triangle"));
    body.push(comment("queued (wk_lk the field read, then Tn's read): a field is loaded (e_ld) the clock after its read."));
    body.push(reg("wk_dq", k));
    body.push(reg("wk_lk", lw));
    body.push(wire("wk_ldd", 1, format!("wk_lk == {}", lit(lw, n + 1))));
    // Each field's own compare, not a generate loop of them (22 more UP5K cells under ABC9) nor a
    // shifted one-hot `1 << (wk_lk - 1)` (22 more under the default ABC): measured, stop 36.
    let ld: Vec<String> = (0..n).rev().map(|j| format!("wk_lk == {}", lit(lw, j + 1))).collect();
    body.push(wire("e_ld", n as u32, format!("{{{}}}", ld.join(", "))));
}

/// Whether `port` is an edge field the memory holds, in the edge's input order (`engine.rs`
/// wires every edge's input `port` from the read register's low bits).
pub(crate) fn edge_port(port: &str) -> bool {
    EDGE_FIELDS.contains(&port)
}

/// The second memory's address bits in a slot.
fn d_bits(hw: &Hw) -> u32 {
    if hw.edges_in_walk_ram() {
        bits_for((EDGE_BASE + 3 * EDGE_FIELDS.len() as u64) as u32 - 1)
    } else {
        field_bits(hw)
    }
}

/// The memories, their writes from the engine (`res_bus`, a field's `we` bit of `res_we`) and
/// their reads, the walker's `w_an`, `w_gxn`, `w_rn` (the span path's, valid at its loads),
/// `wk_tn` (the queued triangle's, at the take) and `wk_dyn` (the same, where [`registered`]) or
/// `w_dyn` (the walked or taken one's, from the clock after the take). After the span path's
/// control (`sq_busy`, `sq_ph`), the queue's `q_in` and the fields' write enables ([`we`]);
/// [`emit_ports`] after the walker.
pub(crate) fn emit(hw: &Hw, body: &mut Vec<Item>) {
    let q = hw.fe.span_seq().expect("the sequential span path");
    let Widths { aw, k, rw, .. } = hw.fe.widths();
    let fw = field_bits(hw);
    let aw_ram = 1 + fw;
    let reg_dyn = registered(hw);
    if reg_dyn {
        body.push(comment("The walk's constants in block RAM: An, Gxn, Rn (the span path's, one a load) and dYn (the walker's step's),"));
        body.push(comment("and Tn (its load at the take), written by the engine into the slot of the queue's next push (wk_ws), read"));
        body.push(comment(
            "from the walked triangle's (wk_rs, the taken one's from the take; dYn and Tn the queued one's), a clock ahead.",
        ));
    } else {
        body.push(comment("The walk's constants in block RAM: An, Gxn, Rn (the span path's, one a load), dYn (the walker's step's)"));
        body.push(comment("and Tn (its load at the take), written by the engine into the slot of the queue's next push (wk_ws), read"));
        body.push(comment("from the walked triangle's (wk_rs, the taken one's from the take; Tn the queued one's), a clock ahead."));
    }
    body.push(Item::Memory { name: "wk_m".into(), width: m_width(hw), depth: 1 << aw_ram, no_rw_check: true });
    // As deep as the first: Yosys keeps a two-word memory in flip-flops.
    body.push(Item::Memory { name: "wk_d".into(), width: k, depth: 1 << (1 + d_bits(hw)), no_rw_check: true });
    body.push(reg("wk_q", m_width(hw)));
    if !hw.edges_in_walk_ram() {
        body.push(reg("wk_dq", k));
    }
    body.extend([reg("wk_ws", 1), reg("wk_rs", 1)]);
    body.push(wire("wk_slot", 1, "wk_rs ^ take"));
    let (during, accept) = read_order(&q);
    let phase_w = bits_for(SpanSeq::PHASES.len() as u32 - 1);
    let ra = during.iter().enumerate().rev().fold(lit(fw, index(accept)), |acc, (p, f)| {
        format!("(sq_busy && sq_ph == {}) ? {} : {acc}", lit(phase_w, p as u64), lit(fw, index(f)))
    });
    body.push(wire("wk_ra", fw, ra));
    let wa = span_memory(hw).iter().skip(1).rev().fold(lit(fw, 0), |acc, f| format!("{} ? {} : {acc}", we(f), lit(fw, index(f))));
    body.push(wire("wk_wa", fw, wa));
    let step = if reg_dyn { ("wk_dyn", k, "wk_q") } else { ("w_dyn", k, "wk_dq") };
    for (n, w, from) in [("w_an", aw, "wk_q"), ("w_gxn", k, "wk_q"), ("w_rn", rw, "wk_q"), step, ("wk_tn", k, "wk_dq")] {
        body.push(wire(n, w, format!("{from}[{}:0]", w - 1)));
    }
    if let Some(cols) = di_columns(hw) {
        body.push(wire("wk_di", hw.fe.cfg.dw(), cols.of("wk_q")));
    }
    body.push(Item::Blank);
}

/// The memories' writes and reads, after the walker (whose `w_valid`, `w_end` choose a word).
/// Where `dYn` is [`registered`]: the first memory reads `dYn` of the queued triangle (the slot
/// the walker does not hold) while a take can come next clock ([`dyn_read`]), else the span
/// path's field, and the second `Tn` of the queued triangle always. Else the second memory
/// reads `Tn` of the queued triangle while a take can come next clock and the walker does not
/// step, else `dYn` of the walked (or taken) one. Neither is written then: the engine writes no
/// field while the queue is full nor at its push.
pub(crate) fn emit_ports(hw: &Hw, body: &mut Vec<Item>) {
    let k = hw.fe.widths().k;
    let fw = field_bits(hw);
    let (m_read, d_write, d_read) = if registered(hw) {
        let phase_w = bits_for(SpanSeq::PHASES.len() as u32 - 1);
        body.push(wire("wk_dnr", 1, dyn_read(&lit(phase_w, SpanSeq::PHASES.len() as u64 - 1))));
        body.push(wire("wk_ma", fw + 1, format!("wk_dnr ? {{!wk_rs, {}}} : {{wk_slot, wk_ra}}", lit(fw, index(STEP_FIELD)))));
        let tn = lit(fw, 0);
        ("wk_m[wk_ma]".to_string(), (we(TAKE_FIELD), format!("wk_d[{{wk_ws, {tn}}}]")), format!("wk_d[{{!wk_rs, {tn}}}]"))
    } else if hw.edges_in_walk_ram() {
        // Tn's read (the walked triangle's dYn otherwise) waits for the edges' fields: a take
        // comes only once they are loaded.
        let db = d_bits(hw);
        let lw = bits_for(3 * EDGE_FIELDS.len() as u32 + 1);
        let n = 3 * EDGE_FIELDS.len() as u64;
        body.push(wire("wk_pre", 1, "q_full && !w_valid && !take"));
        let lk = if db > lw { format!("{{{}, wk_lk}}", lit(db - lw, 0)) } else { "wk_lk".to_string() };
        let field = format!("wk_lk < {} ? {lk} + {} : {}", lit(lw, n), lit(db, EDGE_BASE), lit(db, 1));
        body.push(wire("wk_da", db + 1, format!("wk_pre ? {{!wk_rs, {field}}} : {{wk_slot, {}}}", lit(db, 0))));
        // The engine writes one field a clock (its microword's capture, `res_we` one-hot or
        // zero), so the word is an OR of the enables' indices, not a priority chain.
        let mut wes = vec![we(STEP_FIELD), we(TAKE_FIELD)];
        let mut terms = vec![format!("({{{db}{{{}}}}} & {})", we(TAKE_FIELD), lit(db, 1))];
        for kk in 0..3 {
            for (j, f) in EDGE_FIELDS.iter().enumerate() {
                let name = format!("e{kk}_{f}");
                terms.push(format!("({{{db}{{{}}}}} & {})", we(&name), lit(db, EDGE_BASE + EDGE_FIELDS.len() as u64 * kk + j as u64)));
                wes.push(we(&name));
            }
        }
        let wa = terms.join(" | ");
        body.push(wire("wk_dwa", db, wa));
        body.push(Item::Always(vec![Stmt::If(
            "rst || take".into(),
            vec![set("wk_lk", lit(lw, 0))],
            vec![Stmt::If("q_full && !w_valid && !wk_ldd".into(), vec![set("wk_lk", format!("wk_lk + {}", lit(lw, 1)))], vec![])],
        )]));
        ("wk_m[{wk_slot, wk_ra}]".to_string(), (wes.join(" || "), "wk_d[{wk_ws, wk_dwa}]".to_string()), "wk_d[wk_da]".to_string())
    } else {
        body.push(wire("wk_tnr", 1, "(q_full || q_in) && !take && !(w_valid && !w_end)"));
        body.push(wire("wk_da", fw + 1, format!("wk_tnr ? {{!wk_rs, {}}} : {{wk_slot, {}}}", lit(fw, 1), lit(fw, 0))));
        let dwe = format!("{} || {}", we(STEP_FIELD), we(TAKE_FIELD));
        let dwa = format!("{{wk_ws, {} ? {} : {}}}", we(TAKE_FIELD), lit(fw, 1), lit(fw, 0));
        ("wk_m[{wk_slot, wk_ra}]".to_string(), (dwe, format!("wk_d[{dwa}]")), "wk_d[wk_da]".to_string())
    };
    let mut ports = m_writes(hw);
    ports.extend([
        Stmt::If(d_write.0, vec![set(d_write.1, format!("res_bus[{}:0]", k - 1))], vec![]),
        set("wk_q", m_read),
        set("wk_dq", d_read),
        Stmt::If(
            "rst".into(),
            vec![set("wk_ws", "1'b0"), set("wk_rs", "1'b1")],
            vec![
                Stmt::If("q_in".into(), vec![set("wk_ws", "!wk_ws")], vec![]),
                Stmt::If("take".into(), vec![set("wk_rs", "!wk_rs")], vec![]),
            ],
        ),
    ]);
    body.push(Item::Always(ports));
    body.push(Item::Blank);
}
