//! What a generated front-end is (golden's configuration and the hardware's choices: divider
//! rate, pipeline level) and its ports: the types every part of the generator shares.

use crate::verilog::Port;
use golden::frontend::{DiMode, FrontEnd, I0Form, Widths};

/// Quotient bits the set-up's dividers take per clock (`--fe-div-bits`): area against rate.
pub const DIV_BITS: [u32; 3] = [1, 2, 4];
pub const DEFAULT_DIV_BITS: u32 = 4;

/// A front-end as generated: golden's configuration and the hardware's own choices.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Hw {
    pub fe: FrontEnd,
    /// Quotient bits per clock of every set-up divider (one of [`DIV_BITS`]).
    pub div_bits: u32,
    /// The chain's register stages (`--pipeline`): the shader's, and the set-up's CALC stages.
    pub pipeline: golden::pipeline::Pipeline,
}

/// Clocks from a push into an empty queue to the earliest take where the walk memory holds the
/// edges' fields ([`Hw::edges_in_walk_ram`]): a read a field (three edges of nine), then the
/// clock the last is loaded, which reads `Tn`.
pub const PRELOAD_CLOCKS: u32 = 3 * 9 + 1;

/// Entries of the set-up result queue behind the sequential engine (`--fe-setup ice40-hx8k`):
/// two, so the next triangle's set-up waits behind the one being walked without freezing the
/// engine. The pipelined engine's queue is deeper ([`Hw::queue_depth`]).
pub const QUEUE_DEPTH: u32 = 2;

impl Hw {
    /// Whether the set-up is the shared engine (`--fe-setup` not `parallel`).
    pub fn engine_form(&self) -> bool {
        self.fe.setup.plan().is_some()
    }

    /// The shared set-up engine's schedule (golden's, the one the RTL runs), `None` for the
    /// parallel set-up.
    pub fn engine(&self) -> Option<golden::frontend::engine::schedule::Schedule> {
        self.fe.engine().map(|s| s.expect("the named plans schedule (golden's tests)"))
    }

    /// The sequential engine's microprogram (golden's), for the form that has one
    /// (`--fe-setup ice40-hx8k`): it replaces the pipelined engine's RTL, on the same ports.
    pub fn sequential(&self) -> Option<golden::frontend::engine::sequential::SeqSchedule> {
        self.fe.sequential_engine().map(|s| s.expect("the sequential plans schedule (golden's tests)"))
    }

    /// The engine's clocks, whichever form: clocks between entries (II), from an entry to its
    /// result (latency), and the binding's period in triangles. The sequential engine runs a
    /// triangle a period and offers its result as the next enters: II = latency.
    pub fn engine_timing(&self) -> Option<(u32, u32, u32)> {
        if let Some(s) = self.sequential() {
            return Some((s.clocks, s.clocks, 1));
        }
        self.engine().map(|s| (s.ii, s.latency, s.epochs().expect("a periodic binding (golden's tests)")))
    }

    /// Whether the plan takes the smaller of two equal forms where the larger one is only for
    /// the clock: the UP5K's (`--fe-setup ice40-up5k`), which needs the cells (its aim is 40 MHz,
    /// the HX8K's 60). Its choices keep golden's values and the front-end's clocks: no span FIFO
    /// (`chain`), the row's pixel test after the ends' picks (`walker`). docs/fpga.md, issue 27,
    /// stop 36.
    pub fn fewest_cells(&self) -> bool {
        self.fe.setup == golden::frontend::engine::SetupForm::Ice40Up5k
    }

    /// Whether the engine never freezes (the pipelined engine): the front-end takes a triangle
    /// only with a queue entry reserved for its result (a credit), so no register of the engine
    /// has a clock enable wider than its phase (a freeze's fan-out was the 25F's critical path).
    pub fn queue_credit(&self) -> bool {
        self.engine_form() && self.sequential().is_none()
    }

    /// Whether the set-up result queue's head is a register of its own (the pipelined engine's
    /// queue, behind credits): the walker's loads then read a register, not the queue's memory
    /// (its distributed RAM's read into an edge's load was a 25F critical path, docs/fpga.md).
    pub fn queue_head(&self) -> bool {
        self.queue_credit()
    }

    /// Clocks from a result's push into an empty queue until the walker can take it: 1, or 2
    /// with a registered head, refilled from the memory the clock after the push.
    pub fn queue_head_clocks(&self) -> u32 {
        1 + self.queue_head() as u32
    }

    /// The set-up result queue's entries: [`QUEUE_DEPTH`] behind the sequential engine; behind
    /// the pipelined one, with credits, as many as the freeze held (the two entries, a triangle
    /// per period in flight and the vertex register's), so the rate is kept.
    pub fn queue_depth(&self) -> u32 {
        match self.engine_timing() {
            Some((ii, latency, _)) if self.queue_credit() => QUEUE_DEPTH + latency / ii + 2,
            // Behind the sequential span path one entry: the walker copies it as it takes it, and
            // a second entry (its read multiplexer and 689 flip-flops at 640x480) was about a
            // fifth of the HX8K's logic cells (docs/fpga.md).
            _ if self.fe.span_seq().is_some() => 1,
            _ => QUEUE_DEPTH,
        }
    }

    /// Clocks the dividers run: the reciprocal's RW quotient bits, `div_bits` a clock.
    pub fn div_clocks(&self) -> u32 {
        self.fe.widths().rw.div_ceil(self.div_bits)
    }

    /// Clocks the per-scanline divider runs for a span of two pixels or more (`DiMode::Scanline`,
    /// the comparison option; 0 with the per-triangle `dI`): IW quotient bits, `div_bits` a clock.
    pub fn span_div_clocks(&self) -> u32 {
        match self.fe.di {
            DiMode::Triangle => 0,
            DiMode::Scanline => self.fe.cfg.iw().div_ceil(self.div_bits),
        }
    }

    /// Clocks CALC takes: 1, or its stages at `--pipeline 1` and above.
    pub fn calc_clocks(&self) -> u32 {
        self.pipeline.calc_clocks()
    }

    /// Bits of `S2n` the span path keeps: it is formed modulo 2^(K-1) (golden's
    /// `Widths::reciprocal_quotient`: at a covered pixel it is below that), so the row's sums
    /// `Tn` and `Gxn lo` are read modulo 2^(K-2).
    pub fn s2n_bits(&self) -> u32 {
        self.fe.widths().k - 1
    }

    /// Whether the span path takes `Gxn lo` from the walker's two left slots' running sums, not a
    /// product a row (golden's `Plan::run_sums`, `golden::frontend::sums`): the engine form on
    /// the ECP5-25F plan, `I0` by the reciprocal.
    pub fn run_sums(&self) -> bool {
        self.fe.setup.plan().is_some_and(|p| p.run_sums) && self.fe.i0 == I0Form::Reciprocal
    }

    /// Whether the 18 x 18 tiles (the engine's and the span path's) are `tri_fe_mul18`
    /// instances, the ECP5's MULT18X18D with its own input and product registers in place of the
    /// fabric's: the engine form on the ECP5-25F plan from level 1, where every tile already sits
    /// between an operand register and a product register, so golden's latencies hold.
    pub fn dsp_regs(&self) -> bool {
        self.fe.setup == golden::frontend::SetupForm::Ecp5_25f && self.pipeline.level() >= 1
    }

    /// Whether the walker's row is registered before its span is decided
    /// ([`golden::pipeline::Pipeline::row_stage`]).
    pub fn row_stage(&self) -> bool {
        self.pipeline.row_stage(self.fe.i0)
    }

    /// The row stages' count ([`golden::pipeline::Pipeline::row_stages`]): 0 or 2.
    pub fn row_stages(&self) -> u32 {
        self.pipeline.row_stages(self.fe.i0)
    }

    /// Register stages between the walker and the output register: 2, or at `--pipeline 1`
    /// and above the row stages and 8 ([`golden::pipeline::i0_registers`]; 8 alone with the
    /// incremental `I0`).
    pub fn i0_stages(&self) -> u32 {
        // The sequential span path: its clocks from a covered row's accept to the output write.
        if let Some(q) = self.fe.span_seq() {
            return q.row_clocks() + self.row_stages();
        }
        golden::pipeline::i0_registers(self.pipeline).iter().filter(|&&r| r).count() as u32 + self.row_stages()
    }

    /// Clocks from a triangle's transfer to the first span's `out_valid` when the walker is
    /// idle: CALC, the dividers, the hand-off, the walker's clock, the span path's stages (and,
    /// per scanline, the span's division when it has two pixels or more).
    ///
    /// With the shared engine: up to II - 1 clocks waiting for the engine's entry slot, the
    /// entry clock, the schedule's latency, the queue ([`Hw::queue_head_clocks`]), the walker's load and the span path: the
    /// figure is the worst case of the slot's wait.
    pub fn latency(&self) -> u32 {
        if let Some((ii, latency, _)) = self.engine_timing() {
            return ii + latency + 2 + self.queue_head_clocks() + self.i0_stages() + self.start_clocks() + self.preload_clocks();
        }
        self.calc_clocks() + self.div_clocks() + 2 + self.i0_stages() + self.span_div_clocks() + self.start_clocks()
    }

    /// Clocks the walker waits after a push into an empty queue while it reads the edges' fields
    /// from the walk memory (`span_seq::walk_ram::edges_in_ram`, the UP5K's plan), else 0.
    pub fn preload_clocks(&self) -> u32 {
        if self.edges_in_walk_ram() {
            PRELOAD_CLOCKS
        } else {
            0
        }
    }

    /// Whether this front-end holds the walk's constants in block RAM (`span_seq::walk_ram`,
    /// whose doc says why): the sequential engine (its fields written one at a time, `res_we`)
    /// behind the sequential span path without row stages (whose reads are the walker's
    /// registers' own), the reciprocal `I0` (the incremental one reads them every row) and no
    /// running sums (which read `Gxn` at the take; without them the walker reads it). Both iCE40
    /// plans: the UP5K needs the cells, and on the HX8K (88 % with them, 92 % without) the placer
    /// did not place every seed without them (docs/fpga.md).
    pub fn walk_ram(&self) -> bool {
        // Both iCE40 plans are a sequential engine's; `self.sequential()` would schedule it again
        // for every field this is asked about.
        use golden::frontend::engine::SetupForm;
        matches!(self.fe.setup, SetupForm::Ice40Up5k | SetupForm::Ice40Hx8k)
            && self.fe.span_seq().is_some()
            && !self.row_stage()
            && self.fe.i0 == I0Form::Reciprocal
            && !self.run_sums()
    }

    /// Whether the walk memory also holds the edges' set-up fields, not the queue's entry: the
    /// UP5K's plan ([`Hw::fewest_cells`]), the walker preloading them ([`PRELOAD_CLOCKS`], docs/queue-in-walk-ram.md).
    pub fn edges_in_walk_ram(&self) -> bool {
        self.walk_ram() && self.fewest_cells()
    }

    /// Clocks a start takes in the incremental I0 (at most: a start at an edge; one at column 0
    /// takes fewer); 0 in the reciprocal form, which has none. A triangle's first row is started
    /// while it is held, before the walker takes it, so each walked triangle's set-up takes
    /// these clocks more; a later start (an edge taking over the left end) holds the walker
    /// as long.
    pub fn start_clocks(&self) -> u32 {
        self.fe.start_clocks().0
    }

    /// The incremental I0's shift-add start (`FrontEnd::start_product_clocks` above 1): the
    /// width of its clock count within a product, `ie_k` (0 .. clocks - 1).
    pub fn start_count_bits(&self) -> u32 {
        crate::widths::bits_for(self.fe.start_product_clocks() - 1)
    }

    /// The exact plane's widths, CALC's oriented `Nx` and `Ny` (signed), as the incremental I0's
    /// range checks read them.
    pub fn plane_widths(&self) -> (u32, u32) {
        let Widths { cx, cy, .. } = self.fe.widths();
        let iw = self.fe.cfg.iw();
        (iw + cy + 3, iw + cx + 3)
    }

    /// Clocks from a triangle's transfer to the first segment out of `tri_shader_p<P>` when idle:
    /// the front-end's latency, then the shader's at the chain's pipeline level.
    pub fn shader_latency(&self) -> u32 {
        self.latency() + golden::segment::latency(&self.fe.cfg, self.pipeline)
    }

    /// Set-up clocks per triangle that is walked (the rate limit for tiny triangles: the
    /// dividers, then the hand-off clock, which is also the next triangle's last CALC clock),
    /// and per triangle dropped in set-up (its last CALC clock). CALC's earlier stages overlap
    /// the triangle ahead's division, so neither depends on the pipeline level.
    /// With the shared engine every triangle takes one entry slot, II clocks, walked or dropped.
    pub fn setup_clocks(&self) -> (u32, u32) {
        if let Some((ii, ..)) = self.engine_timing() {
            return (ii, ii);
        }
        (self.div_clocks() + 1 + self.start_clocks(), 1)
    }
}

pub(super) fn slit(w: u32, v: i64) -> String {
    if v < 0 {
        format!("-{w}'sd{}", -v)
    } else {
        format!("{w}'sd{v}")
    }
}

pub fn ports(fe: &FrontEnd, wd: &Widths) -> Vec<Port> {
    let cfg = &fe.cfg;
    let mut v = vec![
        Port::input("clk", 1, "", "rising edge"),
        Port::input("rst", 1, "", "synchronous, active high; drops the triangles in progress"),
        Port::input("in_valid", 1, "", "triangle valid"),
        Port::output("in_ready", 1, "", "triangle accepted when in_valid && in_ready"),
    ];
    for k in 0..3 {
        v.push(Port::input(&format!("in_x{k}"), wd.cx, &format!("signed Q{}.8", cfg.xbits + 2), &format!("vertex {k} x, pixels")).signed());
        v.push(Port::input(&format!("in_y{k}"), wd.cy, &format!("signed Q{}.8", wd.yw + 2), &format!("vertex {k} y, pixels")).signed());
        v.push(Port::input(&format!("in_i{k}"), cfg.iw(), &format!("UQ8.{}", cfg.frac), &format!("vertex {k} intensity")));
    }
    v.push(Port::output("err", 1, "", "one-clock pulse: a triangle with a vertex outside the guard band was dropped").reg());
    v
}

pub fn span_ports(fe: &FrontEnd, wd: &Widths) -> Vec<Port> {
    let cfg = &fe.cfg;
    vec![
        Port::output("out_valid", 1, "", "span valid").reg(),
        Port::input("out_ready", 1, "", "span taken when out_valid && out_ready"),
        Port::output("out_y", wd.yw, "unsigned integer", "scanline").reg(),
        Port::output("out_x", cfg.xbits, "unsigned integer", "x0, first covered pixel").reg(),
        Port::output("out_len", cfg.xbits + 1, "unsigned integer", "m >= 1, covered pixels").reg(),
        Port::output("out_i0", cfg.iw(), &format!("UQ8.{}", cfg.frac), "intensity at the first pixel's centre").reg(),
        Port::output("out_di", cfg.dw(), &format!("signed Q8.{}", cfg.frac), "dI/dx, once per triangle").signed().reg(),
    ]
}
