//! The shapes the front-end's properties are written from (the stages, the set-up's form, the
//! widths) and the reference model's small helpers: what the shared properties and the parallel
//! and engine forms' parts all read, kept apart so neither part depends on the other or on the
//! module that puts them together.

use crate::formal::{assert, when};
use crate::verilog::{lit, zext, Item, Stmt};
pub(super) use crate::widths::bits_for;

/// What the front-end's proof needs from its generator: widths, screen, its set-up's shape.
pub struct FrontendShape {
    /// Row bits (`out_y`), vertex x and y bits.
    pub yw: u32,
    pub cx: u32,
    pub cy: u32,
    pub xw: u32,
    /// `dI`'s bits (`out_di`).
    pub dw: u32,
    /// Screen width and height, pixels.
    pub width: u64,
    pub height: u64,
    /// Clocks from a triangle's transfer to its first span (`Hw::latency`): the cover search's depth.
    pub latency: u32,
    /// The set-up in front of the walker.
    pub setup: SetupShape,
    /// The row stages between the walker and the span path (`--pipeline 1`, reciprocal `I0`),
    /// in order; the row's coverage is decided from the last; without them the walker's row is.
    pub row_stages: Vec<RowStage>,
    /// The span path's register stages between the walker (or the row stage) and the output, in order.
    pub span_stages: Vec<SpanStage>,
    /// Where the walker holds its triangle's `dI` without row stages: `w_di`, or the walk
    /// memory's (`span_seq::walker_di`).
    pub walker_di: String,
    /// The incremental I0 (`--fe-i0 incremental`): its start engine's clocks a product (1, or
    /// the HX8K's shift-add's RW, counted by `ie_k`). The walker then
    /// waits while a source starts (`ie_wait`, a data decision taken as given, like a row's
    /// coverage) and the held triangle is taken once its first row is started (`ie_pv`); the
    /// engine's own properties bound both waits.
    pub starts: Option<u32>,
    /// The sequential span path (`--fe-span sequential`): its one stage (`span_stages`' only)
    /// holds a covered row for its clocks, and the walker moves while it is idle or writing its
    /// result.
    pub span_unit: Option<SpanUnit>,
    /// The edges' registers the proof reads (`(wire, register, width)`, driven by
    /// `scripts/prove`) and what holds of them while the walker walks a triangle
    /// (`edge::formal_probes`): none without the row stages.
    pub edge_probes: Vec<(String, String, u32)>,
    pub edge_holds: Vec<String>,
}

/// The sequential span path's shape: its clocks from an accept to its result's write, where the
/// design counts them (the clocks left, from its phase and step count), and whether the walker
/// takes the next triangle only once its last row has left (the unit reads the walker's registers).
pub struct SpanUnit {
    pub row_clocks: u32,
    pub left: String,
    pub bounds: Vec<String>,
    pub take_when_empty: bool,
}

/// The set-up the reference follows in front of the walker.
pub enum SetupShape {
    /// CALC (in one clock or in stages), the dividers and the DIV/HOLD state machine.
    Parallel(ParallelSetup),
    /// The shared engine (`--fe-setup` a plan) and its result queue.
    Engine(EngineShape),
}

/// The parallel set-up's shape.
pub struct ParallelSetup {
    /// The dividers' counter width, quotient bits per clock, the reciprocal's quotient bits,
    /// and the clocks they run (`Hw::div_clocks`).
    pub cnt_w: u32,
    pub bits: u32,
    pub rw: u32,
    pub div_clocks: u32,
    /// The set-up dividers' registers (partial remainder, divisor, quotient of each), as Yosys
    /// names them once the design is flattened (`instance.register`, `*` for a generate loop's
    /// index): cut.
    pub div_regs: Vec<String>,
    /// CALC's stages after the vertex register (none at level 0), in order.
    pub calc_stages: Vec<CalcStage>,
    /// The names under which the last CALC stage holds the guard-band check and the cull.
    pub guard: String,
    pub cull: String,
}

/// The shared engine's shape (golden's schedule and the queue behind it).
pub struct EngineShape {
    /// Clocks between entries (II), the schedule's latency from the entry to the result, and
    /// the binding's period in triangles (the epoch ring's length).
    pub ii: u32,
    pub latency: u32,
    pub epochs: u32,
    /// The queue's entries and an entry's bits.
    pub depth: u32,
    pub entry_w: u32,
    /// The front-end takes a triangle only with a queue entry for its result (`cr`), and the
    /// engine never freezes (the pipelined engine's); else a due result freezes it (`en`).
    pub credit: bool,
    /// The engine's phase is a binary counter (`pc`, the sequential engine's), not a one-hot ring.
    pub binary_phase: bool,
    /// The engine writes the result's fields into the queue's tail as it produces them (the
    /// sequential engine's `res_we`, taken as given), and the push makes the tail an entry.
    pub capture: bool,
    /// The sequential engine keeps no copy of a triangle: the one on the port at the last phase
    /// enters, stays on the port and is taken at this phase (its inputs' last read); one gone
    /// from the port by then is dropped. Else a vertex register takes a triangle whenever it is
    /// free and passes it on at the entry.
    pub held: Option<u32>,
    /// The walk's constants in block RAM (`span_seq::walk_ram`): its two slots, the engine's
    /// and the walked triangle's, are one exactly while the queue is full.
    pub walk_ram: bool,
    /// The edges' fields in the walk's second memory (`span_seq::walk_ram::edges_in_ram`): the
    /// walker reads them one a clock while idle and a triangle is queued, and takes it once its
    /// preload count (`wk_lk`) is this, the fields' count + 1.
    pub preload: Option<u32>,
    /// `dI` in the walk's first memory (`span_seq::walk_ram::formal_di`): the declarations of
    /// `f_wdi`, the walked triangle's there, which the read register's `wk_di` is when the span
    /// path's result is done.
    pub di_in_ram: Option<Vec<Item>>,
    /// The queue's head is a register of its own (`u_queue.hd`, valid `hv`), refilled from its
    /// memory while empty: an entry is the head a clock after it is in the memory.
    pub head: bool,
}

/// A register stage of the front-end's span path: where it holds a span's valid, row, columns
/// and `dI`.
pub struct SpanStage {
    pub valid: String,
    pub y: String,
    pub x: String,
    pub len: String,
    pub di: String,
}

/// A row stage: where it holds the walked row's valid (a row, covered or not), row and `dI`.
pub struct RowStage {
    pub valid: String,
    pub y: String,
    pub di: String,
    /// What holds of its registers as the walker's signals they load (each edge's bounds
    /// within the screen's): conditions on a valid row.
    pub holds: Vec<String>,
}

/// A CALC stage of the pipelined set-up: its valid register and where it holds what the
/// reference follows (the guard-band check; the vertical extent, or the rows made of it).
pub struct CalcStage {
    pub valid: String,
    pub guard: String,
    pub ymin: Option<String>,
    pub ymax: Option<String>,
    /// The first and last rows, signed (`ryw` bits) and clipped, and the cull decision.
    pub first_s: Option<String>,
    pub last_s: Option<String>,
    pub cull: Option<String>,
    /// Candidates for the last row held before the choice between them (each as `last_s`).
    pub last_alt: Vec<String>,
}

impl EngineShape {
    /// The valid bits of the periods in flight (the sequencer's `vld`).
    pub(super) fn periods(&self) -> u32 {
        self.latency / self.ii + 1
    }
    /// The phase counter's width.
    pub(super) fn phw(&self) -> u32 {
        bits_for(self.ii - 1)
    }
    /// The queue's count width (holds `depth`).
    pub(super) fn qw(&self) -> u32 {
        bits_for(self.depth)
    }
}

/// The deepest cover search for the engine's entry (II + 2 clocks).
pub(super) const ENTRY_COVER_DEPTH: u32 = 16;

/// The reference model's shape: the stages it follows and its counters' widths.
#[derive(Clone, Copy)]
pub(super) struct Reference<'a> {
    pub(super) s: &'a FrontendShape,
    pub(super) nsp: usize,
    pub(super) cw: u32,
}

/// The reference's CALC stage j's valid bit (0: the vertex register).
pub(super) fn f_v(j: usize) -> String {
    if j == 0 {
        "f_vf".to_string()
    } else {
        format!("f_c{j}v")
    }
}
/// What the reference holds of a triangle in CALC stage j (`g`: the guard-band check, `ymin`,
/// `ymax`: its vertical extent); stage 0 is the vertex register.
pub(super) fn f_held(j: usize, what: &str) -> String {
    if j == 0 {
        format!("f_v{what}")
    } else {
        format!("f_c{j}{what}")
    }
}
/// Stage j's triangle moves on; the last stage's move is the set-up's load.
pub(super) fn f_mv(j: usize, last: usize) -> String {
    if j == last {
        "f_calc".to_string()
    } else {
        format!("f_mv{j}")
    }
}
pub(super) fn one(w: u32) -> String {
    lit(w, 1)
}
/// A valid span (`v`) is on the screen with at least one pixel.
pub(super) fn on_screen(v: &str, x: &str, len: &str, xw: u32, width: u64) -> Stmt {
    let wlim = lit(xw + 2, width);
    when(
        v,
        vec![
            assert(format!("{len} != {}", lit(xw + 1, 0))),
            assert(format!("{} + {} <= {wlim}", zext(x, xw, xw + 2), zext(len, xw + 1, xw + 2))),
        ],
    )
}
