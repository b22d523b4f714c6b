//! The sequential set-up engine for the iCE40 plans (issue 27): the same program
//! ([`Program::setup`]) run one triangle at a time on one shared ALU beside the plan's units,
//! every value in a block-RAM register file instead of a register of its own.
//!
//! Why: in the pipelined engine ([`super::schedule`]) every logic operation is its own logic
//! and its own register and every value a register (7,454 value bits at 640x480): on an iCE40
//! the flip-flops alone nearly fill the device (docs/fpga.md). The iCE40s have block RAM the
//! engine does not use (HX8K 32 EBR of 256 x 16, UP5K 30 and 4 SPRAM), and for these devices
//! several hundred clocks a triangle are fine (docs/design.md, *Targets*).
//!
//! - **The machine.** A register file of `read_ports` copies of one bank (EBRs of
//!   [`SeqPlan::bank_bits`] side by side for the widest value, each copy a read port, all
//!   written together through one write port), registered reads ([`READ`] clock); one ALU
//!   (adds, compares, selects, leading zeros, shifts by a constant or by a value:
//!   [`SeqPlan::alu_lat`] clocks); the plan's multipliers and dividers, each loading its
//!   operands from the read ports and holding its result until it is written; every value
//!   wrapped to its width and sign as it is written. One operation issues a clock (reads its operands), the ALU's or a unit's.
//!   One-bit unsigned values (compares, their `and`/`or`/`not`) live in a flag file of
//!   flip-flops, read without a port. Constants are the RAM's initial contents, never
//!   overwritten; the triangle's nine inputs are written first, from the input ports (the stream
//!   holds the triangle there until the engine takes it, after their last read).
//! - **The microprogram** ([`SeqSchedule`]): a list schedule by each operation's longest path
//!   to the results, under one issue, `read_ports` RAM reads and one write (the register
//!   file's or the flag file's: one write bus) a clock and each unit busy from its load to its
//!   write; then addresses by a linear scan over the
//!   values' lifetimes (a value holds its address from its write to its last read, so two
//!   values share an address only one after the other). A result is captured into the queue
//!   entry as it is written. The next triangle enters when the last value is written.
//! - **The clocked evaluation** ([`SeqSchedule::run`]) executes the microprogram on a real RAM
//!   (poisoned at reset but for the constants) and flag file, reads before writes in a clock as
//!   an EBR does, so a wrong address, a read before its write or a value overwritten while live
//!   gives a wrong set-up, which the tests compare with [`FrontEnd::setup`].
//!
//! The RTL: `hdl-gen`'s `frontend/engine/seq.rs`; docs/design.md, *A sequential engine for the iCE40 HX8K*.

use super::placement::{class, timing, Class};
use super::schedule::Result3;
use super::{compute, Kind, MulUnit, Plan, Program, SetupForm, V};
use crate::frontend::{FixedTriangle, FrontEnd};
use std::collections::HashMap;

/// Clocks from a read address to its data: an EBR with registered output.
pub const READ: u32 = 1;
/// Clocks from an ALU operation's operands to its registered result in the first form (one
/// clock: the operand select, the full-width adder and the result multiplexer in one path).
/// A plan's own is [`SeqPlan::alu_lat`].
pub const ALU_LAT: u32 = 1;
/// The split ALU's latency: the operands registered, the adder in two halves with the carry
/// registered between them (and the shift and the leading-zero count in two steps), the
/// result's kinds chosen among in the write bus's source select (a clock and a word of
/// flip-flops of their own until issue 27's stop 35: about 60 logic cells on the UP5K).
pub const ALU_LAT_SPLIT: u32 = 3;

/// iCE40 SB_LUT4 a bit of the ALU, not calibrated (the estimate puts the HX8K plan's engine at
/// 2,182 SB_LUT4; its RTL measures 3,281, docs/fpga.md): the adder-subtractor with its operand
/// inversion (1, and the carry chain's SB_CARRY), the select (1), the result multiplexer over
/// sum, select, wrap and the leading-zero count (2), the wrap to the operation's width with its
/// sign (1), the compares' zero test and the leading-zero count (about 1).
pub const ALU_LUT4_PER_BIT: u32 = 6;

/// The sequential engine's parameters: the units of a [`Plan`] (its multipliers, dividers and
/// shifter; one ALU beside them) and the register file's shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SeqPlan {
    pub units: Plan,
    /// Copies of the register file's bank, each a read port.
    pub read_ports: u32,
    /// One EBR's word width and depth (iCE40 SB_RAM40_4K as 256 x 16).
    pub bank_bits: u32,
    pub bank_depth: u32,
    /// Clocks from an ALU operation's operands (on the read ports) to its registered result:
    /// [`ALU_LAT`] (one path through the whole adder) or [`ALU_LAT_SPLIT`]. On the UP5K the
    /// one-clock ALU set the engine's clock at 15.1 MHz (its 67-bit carry chain alone about
    /// 26 ns, docs/fpga.md); the schedule keeps the ALU issuing a clock, so the extra clocks
    /// only lengthen dependent chains.
    pub alu_lat: u32,
    /// Clocks a tile product's sum takes after golden's `MUL_PIPE` (0, or 1 where the
    /// accumulator adds in two halves, the high one a clock behind the low one's carry: on
    /// the UP5K its 66-bit add in one clock was the next path after the ALU's).
    pub acc_lag: u32,
    /// Clocks from a source's value (the ALU's result, a unit's, an input) to its write: 0, or
    /// 1 where the write bus is registered (its source and wrap selected from the microword a
    /// clock before, the wrapped value written from a register: on the UP5K the write bus from
    /// the microword's EBR through the source and wrap multiplexers was the path after the
    /// ALU's and the tiles' sums, 43 ns).
    pub bus_lat: u32,
    /// Clocks from a unit's operands on the read ports to its load: 0, or 1 where the units
    /// load them from the split ALU's operand registers (on the UP5K the operand select, the
    /// flag file's read among it, then a tile's chunk select was the path after the ALU's).
    pub load_lag: u32,
    /// Whether the left shift's low bits are products by `2^k` on 16 x 16 multipliers (the
    /// UP5K's SB_MAC16, one a 16 bits of the widest shift, their output registers the shift's
    /// first clock), its high bits a choice among 16-bit steps. The shifter's 8:1 multiplexers
    /// were about 400 logic cells on the UP5K (docs/fpga.md), where 6 of its 8 SB_MAC16 were
    /// idle; the HX8K has none. The same clocks either way: golden's schedule does not change.
    pub shift_on_macs: bool,
}

impl SeqPlan {
    /// The HX8K: no multiplier, so one shift-add unit and one divider, a bit a clock. The
    /// UP5K's latencies (issue 27, stop 34): with the one-clock ALU its 66-bit subtract behind
    /// the register file's read was every seed's critical path (37-40 MHz, 25-27 ns); split, the
    /// engine leaves it for about 40 clocks a triangle more (docs/fpga.md).
    pub const ICE40_HX8K: SeqPlan = SeqPlan {
        units: Plan::ICE40_HX8K,
        read_ports: 2,
        bank_bits: 16,
        bank_depth: 256,
        alu_lat: ALU_LAT_SPLIT,
        acc_lag: 1,
        bus_lat: 1,
        load_lag: 1,
        shift_on_macs: false,
    };
    /// The UP5K: 2 of its SB_MAC16 as tiles, the left shift on 4 more, and one divider.
    pub const ICE40_UP5K: SeqPlan = SeqPlan {
        units: Plan::ICE40_UP5K,
        read_ports: 2,
        bank_bits: 16,
        bank_depth: 256,
        alu_lat: ALU_LAT_SPLIT,
        acc_lag: 1,
        bus_lat: 1,
        load_lag: 1,
        shift_on_macs: true,
    };

    /// The forms whose engine is sequential: the iCE40s' (`--fe-setup ice40-hx8k`, whose
    /// multiplier is shift-add, and `ice40-up5k`, whose products are SB_MAC16 passes: the
    /// pipelined UP5K engine's registers alone were more than the device's 5,280 cells,
    /// docs/fpga.md); the ECP5 and the parallel set-up keep theirs.
    pub fn for_form(form: SetupForm) -> Option<SeqPlan> {
        match form {
            SetupForm::Ice40Hx8k => Some(SeqPlan::ICE40_HX8K),
            SetupForm::Ice40Up5k => Some(SeqPlan::ICE40_UP5K),
            SetupForm::Parallel | SetupForm::Ecp5_25f => None,
        }
    }

    /// The set-up program, sequenced on this machine.
    pub fn schedule(&self, fe: &FrontEnd) -> Result<SeqSchedule, SeqError> {
        SeqSchedule::new(Program::setup(fe, &self.units), *self)
    }
}

/// Why a program cannot be sequenced.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum SeqError {
    #[error("the plan has no {0} unit, and the program needs one")]
    NoUnit(&'static str),
    #[error("the sequential engine needs {0} read ports or more (an operation reads that many values)")]
    Ports(u32),
}

/// What executes an operation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Exec {
    /// Read by nobody: not executed.
    Dead,
    /// A constant: the register file's initial contents.
    Const,
    /// An input, written from its input port.
    Input,
    Alu,
    /// A shift, a product or a division on unit `n` of its class.
    Unit(Class, u32),
    /// A division's remainder, written by its divider a clock after the quotient.
    Rem,
}

/// Where a value lives.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Loc {
    None,
    Ram(u32),
    Flag(u32),
}

/// One operation in the microprogram: what runs it, the clock it reads its operands (its
/// issue), the clock its value is written, where the value lives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SeqSlot {
    pub exec: Exec,
    pub issue: u32,
    pub write: u32,
    pub loc: Loc,
}

/// The sequential engine's size, by golden's estimate (iCE40: SB_LUT4, flip-flops, EBR).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SeqCost {
    /// Clocks a triangle (the next enters when the last value is written).
    pub clocks: u32,
    /// The register file: word width (the widest value, one bit more if unsigned), words used
    /// (constants included), EBRs (every read port's copy).
    pub ram_width: u32,
    pub ram_words: u32,
    pub ebr_regfile: u32,
    /// The microprogram's word and its EBRs (one word a clock).
    pub micro_bits: u32,
    pub ebr_micro: u32,
    /// Flags live at once (the flag file's flip-flops).
    pub flags: u32,
    /// The program's value bits held in the register file over a triangle (every value's
    /// width, constants but not flags), against the pipelined engine's registers.
    pub value_bits_ram: u32,
    /// Estimated SB_LUT4: the ALU, the shifter, the multipliers, the dividers, the write
    /// multiplexer and the sequencer's decode.
    pub lut_alu: u32,
    pub lut_shift: u32,
    pub lut_mul: u32,
    pub lut_div: u32,
    pub lut_ctl: u32,
    /// Estimated flip-flops: the ALU's and the units' registers, the flags, the sequencer, and
    /// the queue entry the results are captured into.
    pub ff: u32,
    pub result_bits: u32,
}

impl SeqCost {
    pub fn lut4(&self) -> u32 {
        self.lut_alu + self.lut_shift + self.lut_mul + self.lut_div + self.lut_ctl
    }
    pub fn ebr(&self) -> u32 {
        self.ebr_regfile + self.ebr_micro
    }
}

/// A sequenced program.
#[derive(Clone, Debug)]
pub struct SeqSchedule {
    pub plan: SeqPlan,
    pub prog: Program,
    pub slots: Vec<SeqSlot>,
    /// Clocks a triangle.
    pub clocks: u32,
    /// Register-file addresses with their initial contents (the constants).
    pub preload: Vec<(u32, i128)>,
    pub cost: SeqCost,
}

/// Whether a value lives in the flag file: one unsigned bit, computed (not a constant or input).
fn is_flag(prog: &Program, v: V) -> bool {
    let op = &prog.ops[v.0 as usize];
    op.w == 1 && !op.signed && !matches!(op.kind, Kind::Const(_) | Kind::In(_))
}

/// Operations that read a value: every one whose arguments name it.
fn readers(prog: &Program) -> Vec<Vec<usize>> {
    let mut r = vec![Vec::new(); prog.ops.len()];
    for (o, op) in prog.ops.iter().enumerate() {
        for a in op.kind.args() {
            r[a.0 as usize].push(o);
        }
    }
    r
}

/// The operations a result depends on (the others are not executed).
fn live(prog: &Program) -> Vec<bool> {
    let mut live = vec![false; prog.ops.len()];
    for v in prog.out.all() {
        live[v.0 as usize] = true;
    }
    for o in (0..prog.ops.len()).rev() {
        if live[o] {
            for a in prog.ops[o].kind.args() {
                live[a.0 as usize] = true;
            }
        }
    }
    live
}

/// Reservation tables, grown as the schedule reaches later clocks.
#[derive(Default)]
struct Tables {
    reads: Vec<u32>,
    writes: Vec<bool>,
    /// The clocks an operation issues (reads its operands).
    issue: Vec<bool>,
    /// Per unit class (mul, div) and unit: busy clocks.
    units: [Vec<Vec<bool>>; 2],
}

/// The clock after a unit's last busy one: it loads its operands [`READ`] clocks after its
/// issue and holds its result until written (a division's remainder a clock after the quotient).
fn busy_until(write: u32, rem: Option<usize>) -> u32 {
    write + 1 + rem.is_some() as u32
}

fn at<T: Clone + Default>(v: &mut Vec<T>, t: u32) -> &mut T {
    if v.len() <= t as usize {
        v.resize(t as usize + 1, T::default());
    }
    &mut v[t as usize]
}

fn get<T: Clone + Default>(v: &[T], t: u32) -> T {
    v.get(t as usize).cloned().unwrap_or_default()
}

fn pool(c: Class) -> usize {
    match c {
        Class::Mul => 0,
        _ => 1,
    }
}

impl SeqSchedule {
    /// Sequences `prog` (the tests plant faults in the result, not here).
    pub fn new(prog: Program, plan: SeqPlan) -> Result<SeqSchedule, SeqError> {
        let n = prog.ops.len();
        let rd = readers(&prog);
        let live = live(&prog);
        // What runs each live operation, and its latency from its operands. Shifts (by a
        // constant or a value) are the ALU's: its shifter is one of its functions.
        let units = plan.units;
        let exec_of = |o: usize| -> Result<(Exec, u32), SeqError> {
            let op = &prog.ops[o];
            if !live[o] {
                return Ok((Exec::Dead, 0));
            }
            Ok(match (op.kind, class(&op.kind)) {
                (Kind::Const(_), _) => (Exec::Const, 0),
                (Kind::In(_), _) => (Exec::Input, 0),
                (Kind::Rem(_), _) => (Exec::Rem, 0),
                (_, c @ (Class::Mul | Class::Div)) => {
                    if units.units(c) == 0 {
                        return Err(SeqError::NoUnit(if c == Class::Mul { "multiplier" } else { "divider" }));
                    }
                    // A tile product's passes then its pipeline; a shift-add's steps then its
                    // register; a division's load and steps: the unit holds until the write.
                    let lag = if matches!((c, units.mul), (Class::Mul, MulUnit::Tile { .. })) { plan.acc_lag } else { 0 };
                    (Exec::Unit(c, 0), timing(&prog, op, &units).2 + lag + plan.bus_lat + plan.load_lag)
                }
                _ => (Exec::Alu, plan.alu_lat + plan.bus_lat),
            })
        };
        let mut ex = Vec::with_capacity(n);
        for o in 0..n {
            ex.push(exec_of(o)?);
        }
        let wide_reads = |o: usize| prog.ops[o].kind.args().iter().filter(|a| !is_flag(&prog, **a)).count() as u32;
        if let Some(k) = (0..n).filter(|&o| !matches!(ex[o].0, Exec::Dead | Exec::Rem)).map(wide_reads).max() {
            if k > plan.read_ports {
                return Err(SeqError::Ports(k));
            }
        }
        // A division's live remainder, written the clock after its quotient.
        let mut rem_of = vec![None; n];
        for (o, op) in prog.ops.iter().enumerate() {
            if let (Kind::Rem(d), true) = (op.kind, live[o]) {
                rem_of[d.0 as usize] = Some(o);
            }
        }
        // Each operation's longest path to a result, in clocks: the list's priority.
        let span = |o: usize| -> u32 {
            match ex[o].0 {
                Exec::Alu | Exec::Unit(..) => READ + ex[o].1 + 1,
                Exec::Input | Exec::Rem => 1,
                Exec::Dead | Exec::Const => 0,
            }
        };
        let mut height = vec![0u32; n];
        for o in (0..n).rev() {
            height[o] = span(o) + rd[o].iter().filter(|&&r| live[r]).map(|&r| height[r]).max().unwrap_or(0);
        }
        let mut slots = vec![SeqSlot { exec: Exec::Dead, issue: 0, write: 0, loc: Loc::None }; n];
        let mut placed = vec![false; n];
        let mut waiting: Vec<usize> = Vec::new();
        for o in 0..n {
            match ex[o].0 {
                Exec::Dead => placed[o] = true,
                Exec::Const => {
                    slots[o].exec = Exec::Const;
                    placed[o] = true;
                }
                Exec::Rem => {}
                _ => waiting.push(o),
            }
        }
        let avail = |slots: &[SeqSlot], a: usize| if slots[a].exec == Exec::Const { 0 } else { slots[a].write + 1 };
        let mut tb = Tables::default();
        for (c, k) in [(Class::Mul, units.mults), (Class::Div, units.dividers)] {
            tb.units[pool(c)] = vec![Vec::new(); k as usize];
        }
        while !waiting.is_empty() {
            // The ready operation with the longest path left, the earliest in the program on a tie.
            let (i, o) = waiting
                .iter()
                .enumerate()
                .filter(|(_, &o)| prog.ops[o].kind.args().iter().all(|a| placed[a.0 as usize]))
                .max_by_key(|(_, &o)| (height[o], std::cmp::Reverse(o)))
                .map(|(i, &o)| (i, o))
                .expect("the program lists every operand first");
            waiting.swap_remove(i);
            let (e, lat) = ex[o];
            let earliest = prog.ops[o].kind.args().iter().map(|a| avail(&slots, a.0 as usize)).max().unwrap_or(0);
            let reads = wide_reads(o);
            let rem = rem_of[o];
            // A registered bus selects its source two clocks before the write (its select, then
            // its register): an input's write no earlier than the period's clock 2, whose select
            // is this period's microword.
            let mut t = if e == Exec::Input { earliest.max(2 * plan.bus_lat) } else { earliest };
            let (issue, write, unit) = loop {
                let write = match e {
                    Exec::Input => t,
                    _ => t + READ + lat,
                };
                let fits_io = get(&tb.reads, t) + reads <= plan.read_ports
                    && !get(&tb.writes, write)
                    && !(rem.is_some() && get(&tb.writes, write + 1));
                // One operation issues a clock (the read ports' consumer is the microword's).
                let unit = match e {
                    Exec::Alu => (!get(&tb.issue, t)).then_some(0),
                    Exec::Unit(c, _) if !get(&tb.issue, t) => (0..tb.units[pool(c)].len() as u32)
                        .find(|&u| (t + READ..busy_until(write, rem)).all(|k| !get(&tb.units[pool(c)][u as usize], k))),
                    Exec::Unit(..) => None,
                    _ => Some(0),
                };
                match unit {
                    Some(u) if fits_io => break (t, write, u),
                    _ => t += 1,
                }
            };
            *at(&mut tb.reads, issue) += reads;
            *at(&mut tb.writes, write) = true;
            let exec = match e {
                Exec::Alu => {
                    *at(&mut tb.issue, issue) = true;
                    Exec::Alu
                }
                Exec::Unit(c, _) => {
                    *at(&mut tb.issue, issue) = true;
                    for k in issue + READ..busy_until(write, rem) {
                        *at(&mut tb.units[pool(c)][unit as usize], k) = true;
                    }
                    Exec::Unit(c, unit)
                }
                other => other,
            };
            slots[o] = SeqSlot { exec, issue, write, loc: Loc::None };
            placed[o] = true;
            if let Some(r) = rem {
                *at(&mut tb.writes, write + 1) = true;
                slots[r] = SeqSlot { exec: Exec::Rem, issue, write: write + 1, loc: Loc::None };
                placed[r] = true;
            }
        }
        let clocks = slots.iter().filter(|s| !matches!(s.exec, Exec::Dead | Exec::Const)).map(|s| s.write + 1).max().unwrap_or(1);
        let mut s = SeqSchedule { plan, prog, slots, clocks, preload: Vec::new(), cost: SeqCost::default() };
        s.allocate();
        s.cost = s.cost();
        Ok(s)
    }

    /// The clock a value is last read in a triangle (its write, if only the queue takes it).
    fn last_read(&self, o: usize) -> u32 {
        let rd = readers(&self.prog);
        rd[o].iter().filter(|&&r| self.slots[r].exec != Exec::Dead).map(|&r| self.slots[r].issue).max().unwrap_or(self.slots[o].write)
    }

    /// Addresses: the constants first (one word per distinct value, never written), then every
    /// RAM value and every flag by a linear scan over their lifetimes, the lowest free address
    /// first. An address is free once its value's last read is before the new value's write.
    fn allocate(&mut self) {
        let n = self.prog.ops.len();
        let mut consts: HashMap<i128, u32> = HashMap::new();
        for o in 0..n {
            if let (Exec::Const, Kind::Const(c)) = (self.slots[o].exec, self.prog.ops[o].kind) {
                let k = consts.len() as u32;
                let a = *consts.entry(c).or_insert(k);
                self.slots[o].loc = Loc::Ram(a);
            }
        }
        let mut pre: Vec<(u32, i128)> = consts.iter().map(|(&c, &a)| (a, c)).collect();
        pre.sort();
        self.preload = pre;
        let base = consts.len() as u32;
        let mut vals: Vec<(u32, u32, usize, bool)> = (0..n)
            .filter(|&o| !matches!(self.slots[o].exec, Exec::Dead | Exec::Const))
            .map(|o| (self.slots[o].write, self.last_read(o), o, is_flag(&self.prog, V(o as u32))))
            .collect();
        vals.sort();
        let (mut ram_free, mut flag_free): (Vec<u32>, Vec<u32>) = (Vec::new(), Vec::new());
        for (w, last, o, flag) in vals {
            let free = if flag { &mut flag_free } else { &mut ram_free };
            let a = match free.iter().position(|&l| l < w) {
                Some(a) => a,
                None => {
                    free.push(0);
                    free.len() - 1
                }
            };
            free[a] = last;
            self.slots[o].loc = if flag { Loc::Flag(a as u32) } else { Loc::Ram(base + a as u32) };
        }
    }

    /// The last clock of a period on which an input of the period's triangle is read, where
    /// its write is selected (`2 * bus_lat` clocks before the write): the engine reads the
    /// inputs from the ports and takes the triangle (`in_ready`) at this clock, so it keeps no
    /// copy of them.
    pub fn inputs_read_by(&self) -> u32 {
        let last = self.slots.iter().filter(|s| s.exec == Exec::Input).map(|s| s.write - 2 * self.plan.bus_lat).max();
        let last = last.expect("a program with inputs");
        assert!(last + 1 < self.clocks, "the inputs read before the period's last clock, the entry's");
        last
    }

    /// Register-file words and flags in use.
    pub fn words(&self) -> (u32, u32) {
        let mut w = 0;
        let mut f = 0;
        for s in &self.slots {
            match s.loc {
                Loc::Ram(a) => w = w.max(a + 1),
                Loc::Flag(a) => f = f.max(a + 1),
                Loc::None => {}
            }
        }
        (w, f)
    }

    /// The microprogram's own rules: the ALU's results written at its latency; one operation issued (the ALU's or a unit's load),
    /// `read_ports` RAM reads and one RAM write a clock; no unit running two operations at once; every operand written before
    /// it is read; and every read finding its value at its address (the last write to that
    /// address before the read is the value's, or the address holds a constant never written).
    /// The tests' planted faults must fail here too.
    pub fn verify(&self) -> Result<(), String> {
        let ops = &self.prog.ops;
        let name = |o: usize| ops[o].name.as_str();
        let mut reads: HashMap<u32, u32> = HashMap::new();
        let mut writes: HashMap<u32, usize> = HashMap::new();
        let mut issues: HashMap<u32, usize> = HashMap::new();
        let mut busy: HashMap<(Class, u32, u32), usize> = HashMap::new();
        let rd = readers(&self.prog);
        for (o, s) in self.slots.iter().enumerate() {
            if matches!(s.exec, Exec::Dead | Exec::Const) {
                continue;
            }
            if !matches!(s.exec, Exec::Rem | Exec::Input) {
                *reads.entry(s.issue).or_default() += ops[o].kind.args().iter().filter(|a| !is_flag(&self.prog, **a)).count() as u32;
            }
            if s.loc != Loc::None {
                if let Some(p) = writes.insert(s.write, o) {
                    return Err(format!("{} and {} both write at clock {}", name(p), name(o), s.write));
                }
            }
            // The RTL's ALU writes its result at a fixed distance from the issue.
            let alu = READ + self.plan.alu_lat + self.plan.bus_lat;
            if s.exec == Exec::Alu && s.write != s.issue + alu {
                return Err(format!("{} issued at {} is written at {}, not {alu} clocks later", name(o), s.issue, s.write));
            }
            if matches!(s.exec, Exec::Alu | Exec::Unit(..)) {
                if let Some(p) = issues.insert(s.issue, o) {
                    return Err(format!("{} and {} both issue at clock {}", name(p), name(o), s.issue));
                }
            }
            if let Exec::Unit(c, u) = s.exec {
                let rem = rd[o].iter().find(|&&r| self.slots[r].exec == Exec::Rem).copied();
                for k in s.issue + READ..busy_until(s.write, rem) {
                    if let Some(p) = busy.insert((c, u, k), o) {
                        return Err(format!("{} and {} both on {c:?} unit {u} at clock {k}", name(p), name(o)));
                    }
                }
            }
        }
        if let Some((t, k)) = reads.iter().find(|(_, &k)| k > self.plan.read_ports) {
            return Err(format!("{k} reads at clock {t}, {} ports", self.plan.read_ports));
        }
        // Each location's writes in clock order, to find what a read sees.
        let mut hist: HashMap<Loc, Vec<(u32, usize)>> = HashMap::new();
        for (o, s) in self.slots.iter().enumerate() {
            if !matches!(s.exec, Exec::Dead | Exec::Const) && s.loc != Loc::None {
                hist.entry(s.loc).or_default().push((s.write, o));
            }
        }
        let consts: HashMap<Loc, ()> = self.slots.iter().filter(|s| s.exec == Exec::Const).map(|s| (s.loc, ())).collect();
        for (l, h) in hist.iter_mut() {
            if consts.contains_key(l) {
                return Err(format!("{} overwrites a constant at {l:?}", name(h[0].1)));
            }
            h.sort();
        }
        for (o, op) in ops.iter().enumerate() {
            let s = &self.slots[o];
            if matches!(s.exec, Exec::Dead | Exec::Const | Exec::Rem | Exec::Input) {
                continue;
            }
            for a in op.kind.args() {
                let sa = &self.slots[a.0 as usize];
                if sa.exec == Exec::Const {
                    continue;
                }
                if sa.write >= s.issue {
                    return Err(format!("{} reads {} at clock {}, written at {}", op.name, name(a.0 as usize), s.issue, sa.write));
                }
                let seen = hist.get(&sa.loc).and_then(|h| h.iter().rfind(|(t, _)| *t < s.issue)).map(|x| x.1);
                if seen != Some(a.0 as usize) {
                    return Err(format!(
                        "{} reads {} at {:?} at clock {}, which then holds {}",
                        op.name,
                        name(a.0 as usize),
                        sa.loc,
                        s.issue,
                        seen.map_or("nothing", name)
                    ));
                }
            }
        }
        Ok(())
    }

    /// Runs the microprogram on `tris`, one after another from reset, on a register file
    /// poisoned but for the constants; each triangle's set-up as the queue entry captures it.
    pub fn run(&self, tris: &[FixedTriangle]) -> Vec<Result3> {
        let caps = self.captures(tris);
        tris.iter().zip(caps).map(|(t, c)| self.prog.out.extract(t, |v| c[v.0 as usize])).collect()
    }

    /// The clocked run of [`SeqSchedule::run`]: per triangle, every value as it was written (a
    /// constant's own value; 0 for the dead).
    pub fn captures(&self, tris: &[FixedTriangle]) -> Vec<Vec<i128>> {
        let n = self.prog.ops.len();
        let (words, flags) = self.words();
        // Reset contents: a pattern no value is likely to equal, different at every address.
        let mut ram: Vec<i128> = (0..words as i128).map(|a| 0x5a5a_5a5a_5a5a_5a5a_5a5a ^ (a * 0x1_0001)).collect();
        for &(a, c) in &self.preload {
            ram[a as usize] = c;
        }
        let mut flag: Vec<i128> = (0..flags).map(|a| (a % 2) as i128).collect();
        // Events of a triangle in clock order, reads before writes in a clock (an EBR reads the
        // old word), a division before its remainder.
        let mut ev: Vec<(u32, u8, usize)> = Vec::new();
        for (o, s) in self.slots.iter().enumerate() {
            if !matches!(s.exec, Exec::Dead | Exec::Const) {
                ev.push((s.issue, 0, o));
                ev.push((s.write, 1, o));
            }
        }
        ev.sort();
        let mut value = vec![0i128; n];
        let mut rem = vec![0i128; n];
        let mut captured = vec![0i128; n];
        let mut out = Vec::with_capacity(tris.len());
        let mut x = Vec::with_capacity(3);
        for t in tris {
            let inputs = Program::inputs(t);
            for &(_, phase, o) in &ev {
                let op = &self.prog.ops[o];
                if phase == 0 {
                    x.clear();
                    if let Kind::Rem(d) = op.kind {
                        x.push(rem[d.0 as usize]);
                    } else {
                        for a in op.kind.args() {
                            x.push(match self.slots[a.0 as usize].loc {
                                Loc::Ram(k) => ram[k as usize],
                                Loc::Flag(k) => flag[k as usize],
                                Loc::None => unreachable!("a live operand has a place"),
                            });
                        }
                    }
                    (value[o], rem[o]) = compute(op, &x, &inputs);
                } else {
                    match self.slots[o].loc {
                        Loc::Ram(k) => ram[k as usize] = value[o],
                        Loc::Flag(k) => flag[k as usize] = value[o],
                        Loc::None => {}
                    }
                    captured[o] = value[o];
                }
            }
            for (o, op) in self.prog.ops.iter().enumerate() {
                if let Kind::Const(c) = op.kind {
                    captured[o] = c;
                }
            }
            out.push(captured.clone());
        }
        out
    }
}

impl FrontEnd {
    /// The sequential engine's microprogram, for the form that has one ([`SeqPlan::for_form`]).
    pub fn sequential_engine(&self) -> Option<Result<SeqSchedule, SeqError>> {
        SeqPlan::for_form(self.setup).map(|p| p.schedule(self))
    }
}

mod cost;
#[cfg(test)]
mod tests;
