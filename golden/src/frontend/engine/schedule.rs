//! The engine's static schedule: a modulo schedule of the set-up program on the plan's units,
//! its cost, and the clocked evaluation that streams triangles through it.
//!
//! - **Timing.** Wiring (constant shifts, a remainder, a copy, a negation of a flag) takes no
//!   clock; every other logic operation one (a register after it, as CALC's stages have). A
//!   product takes one clock a pass on its unit and is ready [`MUL_PIPE`] clocks after its last
//!   pass (operand register, the tile's registered output, the accumulator); a division takes
//!   a load clock and `ceil(qb / R)` clocks of `R` restoring steps.
//! - **Overlap.** Triangle `j` enters the engine at clock `j II`. A unit is free for an operation
//!   when, over the interval's clocks modulo II, fewer operations of its kind are busy than
//!   there are units; the smallest II that schedules is the sustained rate. A value held longer
//!   than II needs `copies` registers (the next triangle writes the next one).
//! - **Units.** Products are placed on a modulo table per tile, so each keeps one tile on every
//!   triangle ([`per_tile`]: a search over their clocks and tiles at the least latency; when it
//!   finds none, the tiles are counted by kind as the dividers are). Divisions and shifts keep
//!   one unit each, or a division busier than II alternates over a pair by the triangle's
//!   parity (or runs on both in series: [`Plan::div_chain`]), where the units' two-period
//!   tables allow (`fixed_rotation`); otherwise they are
//!   bound by start time over an unrolled stretch of triangles (a unit that ran the same
//!   operation is preferred), and a division may rotate over three units or more.

use super::placement::{ceil, class, modulo, pairs, per_tile, timing, Placed};
pub use super::placement::{Class, MUL_PIPE, SHIFT_PIPE};
use super::{compute, DivForm, Kind, MulUnit, Plan, Program, V};
use crate::frontend::incremental::Steps;
use crate::frontend::{FixedTriangle, FrontEnd, Outcome, TriSetup};

/// LUT4 of a barrel shifter per result bit per amount bit: Yosys 0.23 `synth_ecp5` maps a
/// 64-bit shift by a 6-bit amount onto 637 LUT4 (and 292 PFUMX, 141 L6MUX21), docs/fpga.md.
pub const LUT4_PER_SHIFT_BIT: f64 = 637.0 / (64.0 * 6.0);

/// The measured anchor of the LUT estimate: `tri_frontend` at `--pipeline 1`, ECP5-85F, with
/// today's eight dividers at 1 and 4 quotient bits a clock (docs/fpga.md, stop 24:
/// `scripts/synth --family ecp5 --device 85k --speed 6 --p "" --no-specular --frontend
/// --pipeline 1 --fe-div-bits "4 2 1"`).
pub const MEASURED_LUT4: [(u32, u32); 2] = [(1, 4786), (4, 13329)];

/// Why a plan cannot be scheduled.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum EngineError {
    #[error("the plan has no multiplier, and the set-up has {0} products")]
    NoMultiplier(usize),
    #[error("the plan has no divider, and the set-up has {0} divisions")]
    NoDivider(usize),
    #[error("{what} {value} is outside 1..={max}")]
    Range { what: &'static str, value: u32, max: u32 },
}

/// One operation's place: its unit (index among the multipliers or the dividers, for a
/// steady-state triangle), the clock it starts, how long it holds the unit, the clock its
/// value is ready, counted from the triangle's entry.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Slot {
    pub class: Class,
    pub unit: Option<u32>,
    pub start: u32,
    pub busy: u32,
    pub ready: u32,
}

/// The engine's cost.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Cost {
    /// Hard multiplier tiles (MULT18X18D or SB_MAC16).
    pub tiles: u32,
    /// Tile passes and divider clocks a triangle.
    pub mul_passes: u32,
    pub div_clocks: u32,
    /// Estimated LUT4: the dividers (and shift-add multipliers), the barrel shifters (shared
    /// or each shift's own), the units' operand multiplexers.
    pub lut_units: u32,
    pub lut_mux: u32,
    /// Register bits: every value's copies, and one set-up result (a queue entry).
    pub reg_bits: u32,
    pub result_bits: u32,
}

/// A scheduled program.
#[derive(Clone, Debug)]
pub struct Schedule {
    pub plan: Plan,
    pub prog: Program,
    /// Clocks between two triangles entering the engine (the sustained set-up rate).
    pub ii: u32,
    /// Clocks from a triangle's entry to its result in the queue.
    pub latency: u32,
    pub slots: Vec<Slot>,
    pub copies: Vec<u32>,
    pub cost: Cost,
    /// Every (operation, unit) of a stretch of steady-state triangles.
    pub rotation: Vec<(usize, u32)>,
    /// Per operation on a unit, the unit it runs on for each triangle of a stretch of
    /// steady-state triangles, in entry order (empty for the others).
    pub binding: Vec<Vec<u32>>,
}

/// What feeds a unit's port: (value, chunk) pairs, or a product's chunk weights.
type Sources = Vec<(u32, u32)>;

fn gcd(a: u32, b: u32) -> u32 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

impl FrontEnd {
    /// The set-up engine's schedule, for a form with one (`None`: the parallel set-up).
    pub fn engine(&self) -> Option<Result<Schedule, EngineError>> {
        self.setup.plan().map(|p| p.schedule(self))
    }
}

impl Plan {
    /// The units of a kind the plan has (0 for wiring and logic).
    pub fn units(&self, c: Class) -> u32 {
        match c {
            Class::Mul => self.mults,
            Class::Div => self.dividers,
            Class::Shift => self.shifters,
            Class::Wire | Class::Logic => 0,
        }
    }

    fn check(&self) -> Result<(), EngineError> {
        let r = |what, value, max| if (1..=max).contains(&value) { Ok(()) } else { Err(EngineError::Range { what, value, max }) };
        r("divider quotient bits a clock", self.div_bits, 16)?;
        match self.mul {
            MulUnit::Tile { bits } => r("tile bits", bits, 36),
            MulUnit::ShiftAdd { bits } => r("shift-add bits a clock", bits, 16),
        }
    }

    /// The program for this plan, scheduled.
    pub fn schedule(&self, fe: &FrontEnd) -> Result<Schedule, EngineError> {
        self.check()?;
        Schedule::new(Program::setup(fe, self), *self)
    }
}

impl Schedule {
    /// Schedules `prog` (which need not be `Program::setup`'s: the tests plant faults in it).
    pub fn new(prog: Program, plan: Plan) -> Result<Schedule, EngineError> {
        let n = prog.ops.len();
        let count = |c| prog.ops.iter().filter(|o| class(&o.kind) == c).count();
        if plan.mults == 0 && count(Class::Mul) > 0 {
            return Err(EngineError::NoMultiplier(count(Class::Mul)));
        }
        if plan.dividers == 0 && count(Class::Div) > 0 {
            return Err(EngineError::NoDivider(count(Class::Div)));
        }
        let timing: Vec<(Class, u32, u32)> = prog.ops.iter().map(|o| timing(&prog, o, &plan)).collect();
        let caps = |c| plan.units(c);
        let need = |c| timing.iter().filter(|t| t.0 == c).map(|t| t.1).sum::<u32>();
        let mut ii = [Class::Mul, Class::Div, Class::Shift]
            .iter()
            .map(|&c| if need(c) == 0 { 1 } else { ceil(need(c), caps(c)) })
            .max()
            .unwrap_or(1)
            .max(1);
        let Placed { start, unit } = loop {
            if let Some(start) = modulo(&prog, &timing, ii, caps) {
                let latency = prog.out.all().iter().map(|v| start[v.0 as usize] + timing[v.0 as usize].2).max().unwrap_or(0);
                break per_tile(&prog, &timing, ii, &caps, latency).unwrap_or(Placed { start, unit: vec![None; n] });
            }
            ii += 1;
        };
        let ready: Vec<u32> = (0..n).map(|o| start[o] + timing[o].2).collect();
        let latency = prog.out.all().iter().map(|v| ready[v.0 as usize]).max().unwrap_or(0);
        let slots =
            (0..n).map(|o| Slot { class: timing[o].0, unit: unit[o], start: start[o], busy: timing[o].1, ready: ready[o] }).collect();
        let mut s = Schedule {
            plan,
            prog,
            ii,
            latency,
            slots,
            copies: vec![1; n],
            cost: Cost::default(),
            rotation: Vec::new(),
            binding: vec![Vec::new(); n],
        };
        s.copies = s.copies_needed();
        s.bind();
        s.cost = s.cost();
        Ok(s)
    }

    /// The clock of an operation's last read of its operands: a product reads a chunk each pass.
    fn last_read(&self, o: usize) -> u32 {
        let s = &self.slots[o];
        s.start + if s.class == Class::Mul { s.busy.saturating_sub(1) } else { 0 }
    }

    /// Registers each value needs: held from its ready clock to its last reader's, while the
    /// next triangles' values arrive every II clocks.
    fn copies_needed(&self) -> Vec<u32> {
        let mut last: Vec<u32> = self.slots.iter().map(|s| s.ready).collect();
        for (o, op) in self.prog.ops.iter().enumerate() {
            for a in op.kind.args() {
                last[a.0 as usize] = last[a.0 as usize].max(self.last_read(o));
            }
        }
        for v in self.prog.out.all() {
            last[v.0 as usize] = last[v.0 as usize].max(self.latency);
        }
        (0..last.len()).map(|o| (last[o] - self.slots[o].ready) / self.ii + 1).collect()
    }
}

/// An operation's class, clocks on its unit and latency.
impl Schedule {
    /// Binds operations to units over an unrolled stretch of triangles, by start clock, and
    /// keeps a steady-state triangle's binding in the slots.
    fn bind(&mut self) {
        let span = ceil(self.latency + 1, self.ii) as usize;
        // The binding is kept over 8 span steady triangles, which end a span before the
        // unrolled stretch does: the last triangles see fewer contenders and bind otherwise.
        // They start 6 spans in: the first triangles' greedy choices take a few spans to
        // settle into the period (at F = 20, XW = 16 with a shared shifter, 2 were too few).
        let tris = 16 * span + 4;
        let steady = 6 * span + 2;
        for c in [Class::Mul, Class::Div, Class::Shift] {
            // Products the scheduler placed tile by tile keep their tile on every triangle.
            let fixed: Vec<(usize, u32)> =
                self.slots.iter().enumerate().filter(|(_, s)| s.class == c).filter_map(|(o, s)| s.unit.map(|u| (o, u))).collect();
            if !fixed.is_empty() {
                for j in 0..tris {
                    for &(o, u) in &fixed {
                        self.note(o, j, u as usize, steady, span);
                    }
                }
                continue;
            }
            if let Some(fixed) = self.fixed_rotation(c) {
                for j in steady..tris {
                    for (o, us) in &fixed {
                        self.note(*o, j, us[(j - steady) % us.len()] as usize, steady, span);
                    }
                }
                continue;
            }
            let mut iv: Vec<(u32, usize, usize)> = Vec::new();
            for j in 0..tris {
                for (o, s) in self.slots.iter().enumerate().filter(|(_, s)| s.class == c) {
                    iv.push((j as u32 * self.ii + s.start, o, j));
                }
            }
            iv.sort();
            let cap = self.plan.units(c) as usize;
            let mut until = vec![0u32; cap];
            let mut last: Vec<Option<usize>> = vec![None; cap];
            let mut seen: Vec<Vec<usize>> = vec![Vec::new(); cap];
            let mut wide = vec![0u32; cap];
            // Those starting together: first each on the unit it ran on before, if free.
            for group in iv.chunk_by(|a, b| a.0 == b.0) {
                let t = group[0].0;
                let mut todo: Vec<(usize, usize)> = Vec::new();
                for &(_, o, j) in group {
                    match (0..cap).find(|&u| until[u] <= t && last[u] == Some(o)) {
                        Some(u) => {
                            until[u] = t + self.slots[o].busy;
                            self.note(o, j, u, steady, span);
                        }
                        None => todo.push((o, j)),
                    }
                }
                // The others: a unit that ran this operation before, else one that need not
                // grow for it, the least oversized.
                for (o, j) in todo {
                    let wo = self.unit_width(o);
                    let u = (0..cap)
                        .filter(|&u| until[u] <= t)
                        .min_by_key(|&u| (!seen[u].contains(&o), wo.saturating_sub(wide[u]), wide[u].saturating_sub(wo), u))
                        .expect("a unit is free: the modulo table holds at most its units");
                    until[u] = t + self.slots[o].busy;
                    last[u] = Some(o);
                    seen[u].push(o);
                    wide[u] = wide[u].max(wo);
                    self.note(o, j, u, steady, span);
                }
            }
        }
    }

    /// Units for every operation of a kind such that each keeps one unit, or, when busier than
    /// II (up to 2 II), alternates between two by the triangle's parity: `(operation, units by
    /// parity)`. Each unit has a modulo table of two periods. An operation takes a unit no other
    /// one uses when there is one (a unit shared by two operations needs an operand multiplexer
    /// and is as wide as the wider), else the free unit its width fits best. `None` if an
    /// operation is busier than 2 II or finds no free unit: the binding is then unrolled
    /// ([`Schedule::bind`]) and may rotate an operation over three units or more, which makes
    /// each unit's operand multiplexer select by epoch among every operation it runs.
    fn fixed_rotation(&self, c: Class) -> Option<Vec<(usize, Vec<u32>)>> {
        let (ii, cap) = (self.ii, self.plan.units(c) as usize);
        let mut table = vec![vec![false; 2 * ii as usize]; cap];
        let mut users: Vec<Vec<usize>> = vec![Vec::new(); cap];
        let mut wide = vec![0u32; cap];
        let mut ops: Vec<usize> = (0..self.slots.len()).filter(|&o| self.slots[o].class == c).collect();
        // The busiest first (they need the longest free runs), then by start.
        ops.sort_by_key(|&o| (std::cmp::Reverse(self.slots[o].busy), self.slots[o].start, o));
        let mut out = Vec::new();
        for o in ops {
            let (t, b) = (self.slots[o].start, self.slots[o].busy);
            if b > 2 * ii {
                return None;
            }
            // The clocks of the two-period table unit `k` of the operation's units takes.
            let clocks = |k: u32, n: u32| -> Vec<usize> {
                let starts: Vec<u32> = if n == 1 { vec![t, t + ii] } else { vec![t + k * ii] };
                starts.iter().flat_map(|&s| (s..s + b).map(|x| (x % (2 * ii)) as usize)).collect()
            };
            let n = if b > ii { 2 } else { 1 };
            let wo = self.unit_width(o);
            let mut units = Vec::new();
            for k in 0..n {
                let cl = clocks(k, n);
                let u = (0..cap)
                    .filter(|u| !units.contains(u) && cl.iter().all(|&x| !table[*u][x]))
                    .min_by_key(|&u| (!users[u].is_empty(), wo.saturating_sub(wide[u]), wide[u].saturating_sub(wo), u))?;
                cl.iter().for_each(|&x| table[u][x] = true);
                users[u].push(o);
                wide[u] = wide[u].max(wo);
                units.push(u);
            }
            out.push((o, units.into_iter().map(|u| u as u32).collect()));
        }
        Some(out)
    }

    /// The subtractor a division needs on a divider of the plan's form (0 for a product).
    fn unit_width(&self, o: usize) -> u32 {
        match self.prog.ops[o].kind {
            Kind::Div { d, pw, .. } => match self.plan.div_form {
                DivForm::ShiftDivisor => pw,
                DivForm::ShiftRemainder => self.prog.ops[d.0 as usize].w + 1,
            },
            _ => 0,
        }
    }

    /// Keeps a binding: the steady triangle's in the slots, and every one of a stretch of
    /// steady triangles (an operation busier than II alternates) in `rotation`.
    fn note(&mut self, o: usize, j: usize, u: usize, steady: usize, span: usize) {
        if j == steady {
            self.slots[o].unit = Some(u as u32);
        }
        if (steady..steady + 8 * span).contains(&j) {
            if j < steady + span {
                self.rotation.push((o, u as u32));
            }
            let b = &mut self.binding[o];
            if b.len() <= j - steady {
                b.resize(j - steady + 1, u32::MAX);
            }
            b[j - steady] = u as u32;
        }
    }

    fn cost(&self) -> Cost {
        let plan = &self.plan;
        let ops = &self.prog.ops;
        let w = |v: V| ops[v.0 as usize].w;
        let mut c = Cost { tiles: if matches!(plan.mul, MulUnit::Tile { .. }) { plan.mults } else { 0 }, ..Cost::default() };
        let per_bit = lut_per_bit_step();
        // Sources of each unit's ports (a multiplier's: the operand chunks and the weights).
        let mut mul_src: Vec<[Sources; 3]> = vec![Default::default(); plan.mults as usize];
        let mut div_src: Vec<([Sources; 2], [u32; 3])> = vec![Default::default(); plan.dividers as usize];
        let mut width = vec![0u32; plan.mults as usize];
        // A shifter's operand and amount sources, and its widths.
        let mut shl_src: Vec<([Sources; 2], [u32; 2])> = vec![Default::default(); plan.shifters as usize];
        for (o, (op, s)) in ops.iter().zip(&self.slots).enumerate() {
            match s.class {
                Class::Mul => c.mul_passes += s.busy,
                Class::Div => c.div_clocks += s.busy,
                _ => {}
            }
            if s.class != Class::Wire {
                c.reg_bits += self.copies[o] * op.w;
            }
            // A shift by a value left to logic is a barrel shifter of its own.
            if let (Class::Logic, Kind::ShlBy(_, n)) = (s.class, op.kind) {
                c.lut_units += (LUT4_PER_SHIFT_BIT * (op.w * w(n)) as f64).round() as u32;
            }
        }
        for &(o, u) in &self.rotation {
            let (op, u) = (&ops[o], u as usize);
            match op.kind {
                Kind::Mul(a, b) => {
                    let m = &mut mul_src[u];
                    match plan.mul {
                        MulUnit::Tile { bits } => {
                            for (i, j) in pairs(w(a), w(b), op.w, bits) {
                                m[0].push((a.0, i));
                                m[1].push((b.0, j));
                                m[2].push((i + j, 0));
                            }
                        }
                        MulUnit::ShiftAdd { .. } => {
                            m[0].push((a.0, 0));
                            m[1].push((b.0, 0));
                            width[u] = width[u].max(op.w.min(w(a) + w(b)));
                        }
                    }
                }
                Kind::Div { n, d, pw, .. } => {
                    let u = &mut div_src[u];
                    u.0[0].push((n.0, 0));
                    u.0[1].push((d.0, 0));
                    // The subtractor and the ports: today's form shifts the divisor across the
                    // whole partial remainder; the other shifts the remainder past the divisor.
                    let ws = match plan.div_form {
                        DivForm::ShiftDivisor => [pw; 3],
                        DivForm::ShiftRemainder => [w(d) + 1, w(n), w(d)],
                    };
                    (0..3).for_each(|k| u.1[k] = u.1[k].max(ws[k]));
                }
                Kind::ShlBy(a, n) => {
                    let u = &mut shl_src[u];
                    u.0[0].push((a.0, 0));
                    u.0[1].push((n.0, 0));
                    u.1 = [u.1[0].max(op.w), u.1[1].max(w(n))];
                }
                _ => unreachable!("only units are bound"),
            }
        }
        let mux = |k: usize, bits: u32| if k < 2 { 0 } else { bits * ceil(k as u32, 2) };
        let distinct = |v: &mut Vec<_>| {
            v.sort();
            v.dedup();
            v.len()
        };
        for (u, m) in mul_src.iter_mut().enumerate() {
            match plan.mul {
                MulUnit::Tile { bits } => {
                    c.lut_mux += mux(distinct(&mut m[0]), bits) + mux(distinct(&mut m[1]), bits) + mux(distinct(&mut m[2]), 2 * bits);
                }
                MulUnit::ShiftAdd { bits } => {
                    c.lut_units += (per_bit * (width[u] * bits) as f64).round() as u32;
                    c.lut_mux += mux(distinct(&mut m[0]), width[u]) + mux(distinct(&mut m[1]), width[u]);
                }
            }
        }
        for (src, [wv, wn]) in shl_src.iter_mut() {
            c.lut_units += (LUT4_PER_SHIFT_BIT * (*wv * *wn) as f64).round() as u32;
            c.lut_mux += mux(distinct(&mut src[0]), *wv) + mux(distinct(&mut src[1]), *wn);
        }
        for (src, ws) in div_src.iter_mut() {
            c.lut_units += (per_bit * (ws[0] * plan.div_bits) as f64).round() as u32;
            c.lut_mux += mux(distinct(&mut src[0]), ws[1]) + mux(distinct(&mut src[1]), ws[2]);
        }
        c.result_bits = self.prog.out.all().iter().map(|&v| w(v)).sum();
        c
    }
}

/// The calibration: today's eight dividers (`Plan` without reciprocal or steps, at the default
/// 640x480) hold `sum pw` partial-remainder bits; between 1 and 4 quotient bits a clock the
/// measured LUT4 grow by `3 sum pw` bit-steps. Returns LUT4 per partial-remainder bit per
/// quotient bit a clock.
pub fn lut_per_bit_step() -> f64 {
    let [(b1, l1), (b4, l4)] = MEASURED_LUT4;
    (l4 - l1) as f64 / ((b4 - b1) * today_pw()) as f64
}

/// The sum of today's dividers' partial-remainder widths at the defaults (357).
pub fn today_pw() -> u32 {
    let fe = FrontEnd::new(Default::default(), Default::default()).expect("the defaults");
    let plan = Plan {
        mults: 1,
        mul: Plan::TILE18,
        dividers: 1,
        div_bits: 1,
        div_form: DivForm::ShiftDivisor,
        reciprocal: false,
        i0_steps: false,
        run_sums: false,
        edge_t: false,
        div_chain: false,
        shifters: 0,
    };
    Program::setup(&fe, &plan).ops.iter().map(|o| if let Kind::Div { pw, .. } = o.kind { pw } else { 0 }).sum()
}

/// What the rest of `tri_frontend` (walker, span path, CALC's logic) takes in the calibration:
/// the measured 1-bit figure less its dividers.
pub fn lut_rest() -> u32 {
    MEASURED_LUT4[0].1 - (lut_per_bit_step() * today_pw() as f64).round() as u32
}

/// A set-up as the engine hands it on.
pub type Result3 = (Outcome, Option<TriSetup>, Option<Steps>);

impl Schedule {
    /// Streams `tris` through the schedule, one entering every II clocks, and returns each one's
    /// set-up as the queue receives it. Each read takes the register copy the value would be in
    /// at that clock: the latest triangle's value written by then into that copy (0 before any;
    /// a later triangle's, which stands as a wrong value, when the copy was overwritten).
    pub fn run(&self, tris: &[FixedTriangle]) -> Vec<Result3> {
        let n = self.prog.ops.len();
        let hold = (self.copies.iter().max().copied().unwrap_or(1) + ceil(self.latency + 1, self.ii) + 4) as i64;
        let mut hist = vec![(0i128, 0i128); n * hold as usize];
        let ii = self.ii as i64;
        let fetch = |hist: &[(i128, i128)], v: usize, u: i64, j: i64| -> (i128, i128) {
            let (c, r) = (self.copies[v] as i64, self.slots[v].ready as i64);
            let mut i = j;
            while i >= 0 && i * ii + r > u {
                i -= c;
            }
            if i < 0 || j - i >= hold {
                return (0, 0);
            }
            let got = hist[v * hold as usize + (i % hold) as usize];
            // A later triangle wrote this copy by then: its value is not computed yet here, so a
            // wrong one (the complement) stands for it.
            if (i + c) * ii + r <= u {
                (!got.0, !got.1)
            } else {
                got
            }
        };
        let mut out = Vec::with_capacity(tris.len());
        let mut x = Vec::with_capacity(3);
        for (j, t) in tris.iter().enumerate() {
            let j = j as i64;
            let inputs = Program::inputs(t);
            for (o, op) in self.prog.ops.iter().enumerate() {
                let u = j * ii + self.slots[o].start as i64;
                let late = j * ii + self.last_read(o) as i64;
                x.clear();
                for a in op.kind.args() {
                    let (first, second) = (fetch(&hist, a.0 as usize, u, j), fetch(&hist, a.0 as usize, late, j));
                    // A product reads across its passes: an operand changing meanwhile is torn.
                    let got = if second != first { second } else { first };
                    x.push(if matches!(op.kind, Kind::Rem(_)) { got.1 } else { got.0 });
                }
                hist[o * hold as usize + (j % hold) as usize] = compute(op, &x, &inputs);
            }
            let at = j * ii + self.latency as i64;
            out.push(self.prog.out.extract(t, |v| fetch(&hist, v.0 as usize, at, j).0));
        }
        out
    }

    /// The binding's period in triangles: the smallest `R` for which every operation on a unit
    /// runs on the same unit as `R` triangles before (the least common multiple of each
    /// operation's own period over the steady stretch [`Schedule::bind`] unrolls; `None` if one
    /// has none there). An operation no busier than II keeps one unit
    /// (`R = 1`); one busier alternates. The RTL selects a unit's operands by phase and by the
    /// triangle's number modulo `R` (its epoch).
    pub fn epochs(&self) -> Option<u32> {
        let mut r = 1u32;
        for o in 0..self.binding.len() {
            // A chained division runs on both its dividers for every triangle.
            if !self.binding[o].is_empty() && self.div_stages(o).is_none() {
                let p = self.period(o)?;
                r = r / gcd(r, p) * p;
            }
        }
        Some(r)
    }

    /// Operation `o`'s own period: the smallest `p` with every triangle on the unit of the one
    /// `p` before, seen at least twice over the stretch. [`Schedule::epochs`] is their least
    /// common multiple.
    fn period(&self, o: usize) -> Option<u32> {
        let b = &self.binding[o];
        (1..=b.len() / 2).find(|&p| b.iter().enumerate().all(|(i, &u)| u == b[i % p] && u != u32::MAX)).map(|p| p as u32)
    }

    /// Checks the periodic binding ([`Schedule::epochs`]) from the first triangle on: no unit
    /// runs two operations in one clock. The RTL binds by epoch from reset.
    pub fn verify_binding(&self) -> Result<u32, String> {
        let r = self.epochs().ok_or("the binding has no period")?;
        let span = ceil(self.latency + 1, self.ii);
        for c in [Class::Mul, Class::Div, Class::Shift] {
            let mut iv: Vec<(u32, u32, u32, usize)> = Vec::new();
            for j in 0..r * (span + 2) {
                for (o, s) in self.slots.iter().enumerate().filter(|(_, s)| s.class == c) {
                    let at = j * self.ii;
                    match self.div_stages(o) {
                        Some(stages) => stages.iter().for_each(|&(u, a, b)| iv.push((u, at + a, at + b, o))),
                        None => {
                            let u = self.unit_of(o, j % r).ok_or("an operation on no unit")?;
                            iv.push((u, at + s.start, at + s.start + s.busy, o));
                        }
                    }
                }
            }
            iv.sort();
            for w in iv.windows(2) {
                if w[0].0 == w[1].0 && w[1].1 < w[0].2 {
                    let name = |o: usize| &self.prog.ops[o].name;
                    return Err(format!("{:?} unit {}: {} and {} overlap at clock {}", c, w[0].0, name(w[0].3), name(w[1].3), w[1].1));
                }
            }
        }
        Ok(r)
    }

    /// The products that do not keep one tile on every triangle of the steady stretch (none
    /// when [`per_tile`] placed them): each of those makes its tiles' operand multiplexers select
    /// by epoch as well as by phase.
    pub fn rotating_products(&self) -> Vec<&str> {
        (0..self.slots.len())
            .filter(|&o| self.slots[o].class == Class::Mul && self.binding[o].iter().any(|&u| u != self.binding[o][0]))
            .map(|o| self.prog.ops[o].name.as_str())
            .collect()
    }

    /// With [`Plan::div_chain`], a division that alternates between two dividers by the
    /// triangle's parity runs on both in series instead: `(unit, from, to)` per stage, the
    /// schedule clocks each holds it. The first takes the load clock and the steps up to half
    /// the division's clocks (at most II: a division alternates only when busier than II, and
    /// never busier than 2 II); the second loads the first's partial remainder, quotient bits
    /// and divisor as the first's next step forms them, and takes the remaining steps, its last
    /// step the value's as before. `None` for any other operation.
    pub fn div_stages(&self, o: usize) -> Option<[(u32, u32, u32); 2]> {
        let s = &self.slots[o];
        if !self.plan.div_chain || s.class != Class::Div || self.period(o) != Some(2) {
            return None;
        }
        let (u0, u1) = (self.binding[o][0], self.binding[o][1]);
        let a = s.start + s.busy.div_ceil(2);
        (u0 != u1).then_some([(u0, s.start, a), (u1, a, s.start + s.busy)])
    }

    /// The unit operation `o` runs on for a triangle of epoch `e` (its number modulo
    /// [`Schedule::epochs`]).
    pub fn unit_of(&self, o: usize, e: u32) -> Option<u32> {
        let p = self.period(o)?;
        self.binding[o].get((e % p) as usize).copied()
    }

    /// The unit operations in start order: `clock unit name (busy)`, for documents and reviews.
    pub fn listing(&self) -> String {
        let mut rows: Vec<(u32, Class, u32, &str, String)> = Vec::new();
        for (o, (s, op)) in self.slots.iter().zip(&self.prog.ops).enumerate() {
            if let Some(u) = s.unit {
                // A chained division: its first divider, then the second's clock and unit.
                let (u, busy) = match self.div_stages(o) {
                    Some([(u0, _, _), (u1, a, _)]) => (u0, format!("{}, then div{u1} from clock {a}", s.busy)),
                    None => (u, s.busy.to_string()),
                };
                rows.push((s.start, s.class, u, &op.name, busy));
            }
        }
        rows.sort_by_key(|r| (r.0, r.1 == Class::Div, r.2));
        rows.iter()
            .map(|(t, c, u, n, b)| {
                format!(
                    "{t:3} {}{u} {n} ({b})\n",
                    match c {
                        Class::Mul => "mul",
                        Class::Shift => "shl",
                        _ => "div",
                    }
                )
            })
            .collect()
    }

    /// Checks the schedule's own rules: every operand ready by its reader's start, no register
    /// copy overwritten before its last read, never more operations on a kind of unit than it
    /// has. The tests' planted faults must fail here too.
    pub fn verify(&self) -> Result<(), String> {
        for (o, op) in self.prog.ops.iter().enumerate() {
            for a in op.kind.args() {
                let s = &self.slots[a.0 as usize];
                if s.ready > self.slots[o].start {
                    return Err(format!(
                        "{} reads {} at clock {}, ready at {}",
                        op.name, self.prog.ops[a.0 as usize].name, self.slots[o].start, s.ready
                    ));
                }
            }
        }
        let need = self.copies_needed();
        if let Some(o) = (0..need.len()).find(|&o| self.copies[o] < need[o]) {
            return Err(format!("{} has {} register copies, needs {}", self.prog.ops[o].name, self.copies[o], need[o]));
        }
        for c in [Class::Mul, Class::Div, Class::Shift] {
            let cap = self.plan.units(c);
            let mut u = vec![0u32; self.ii as usize];
            for s in self.slots.iter().filter(|s| s.class == c) {
                (s.start..s.start + s.busy).for_each(|k| u[(k % self.ii) as usize] += 1);
            }
            if let Some(p) = u.iter().position(|&k| k > cap) {
                return Err(format!("{} {c:?} operations at phase {p} of {} units", u[p], cap));
            }
        }
        Ok(())
    }
}
