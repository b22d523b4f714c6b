//! The program's values in registers: which operation's register a value lives in (its
//! *root*: wiring reads its operand's), how many copies each needs, and the Verilog that names
//! copy `k` of a value, a slice of it, or a logic operation's result.
//!
//! Copies are a shift across periods, not registers indexed by triangle number: a value's copy
//! `k` holds the triangle that entered `k` periods after the one in copy 0's place, so a
//! reader at schedule clock `t` always reads copy `floor((t - ready) / II)`, a constant. No
//! reader needs a triangle counter or a multiplexer over copies, and a value with one copy
//! (most of them) is one register.

use golden::frontend::engine::schedule::{Class, Schedule};
use golden::frontend::engine::{Kind, Op, V};

/// A value as Verilog reads it: a net of its width and signedness, or a constant.
#[derive(Clone, Debug)]
pub(super) enum Src {
    Net { name: String, w: u32, signed: bool },
    Const(i128),
}

fn mask(v: i128, w: u32) -> String {
    let m = if w >= 127 { v } else { v & ((1i128 << w) - 1) };
    format!("{w}'h{:x}", m as u128)
}

impl Src {
    /// The value wrapped or extended to `to` bits.
    pub fn ext(&self, to: u32) -> String {
        match self {
            Src::Const(c) => mask(*c, to),
            Src::Net { name, w, signed } => {
                let (w, signed) = (*w, *signed);
                if to == w {
                    name.clone()
                } else if to < w {
                    if to == 1 {
                        format!("{name}[0]")
                    } else {
                        format!("{name}[{}:0]", to - 1)
                    }
                } else if signed {
                    crate::verilog::sext(name, w, to)
                } else {
                    crate::verilog::zext(name, w, to)
                }
            }
        }
    }

    /// Bits `lo .. lo + len` of the value extended past its width (its sign, or zeros).
    pub fn bits(&self, lo: u32, len: u32) -> String {
        match self {
            Src::Const(c) => mask(c >> lo.min(126), len),
            Src::Net { name, w, signed } => {
                let (w, signed) = (*w, *signed);
                let top = if w == 1 { name.clone() } else { format!("{name}[{}]", w - 1) };
                if lo >= w {
                    return if signed { format!("{{{len}{{{top}}}}}") } else { format!("{len}'d0") };
                }
                let hi = (lo + len).min(w);
                let slice = if w == 1 {
                    name.clone()
                } else if hi - 1 == lo {
                    format!("{name}[{lo}]")
                } else {
                    format!("{name}[{}:{lo}]", hi - 1)
                };
                let got = hi - lo;
                if got == len {
                    slice
                } else if signed && hi == w {
                    format!("{{{{{}{{{top}}}}}, {slice}}}", len - got)
                } else {
                    format!("{{{}'d0, {slice}}}", len - got)
                }
            }
        }
    }
}

/// A net a logic operation's result reads: a wire, or a register loaded with `e` at schedule
/// clock `load`.
pub(super) struct LogicNet {
    pub name: String,
    pub w: u32,
    pub e: String,
    pub load: Option<u32>,
}

/// Where every value lives and how many copies it has.
pub(super) struct Values<'a> {
    pub s: &'a Schedule,
    /// The operation whose registers hold each value (itself, or the operand wiring reads);
    /// `None` for a constant.
    pub root: Vec<Option<usize>>,
    /// Copies of each root's registers (0 for the others).
    pub copies: Vec<u32>,
}

/// Whether an operation is wiring over one operand (its value is its operand's, rewired).
fn rewires(k: &Kind) -> Option<V> {
    match *k {
        Kind::Wire(a) | Kind::Shl(a, _) | Kind::Shr(a, _) | Kind::Not(a) => Some(a),
        _ => None,
    }
}

impl<'a> Values<'a> {
    pub fn new(s: &'a Schedule) -> Values<'a> {
        let ops = &s.prog.ops;
        let n = ops.len();
        let mut root: Vec<Option<usize>> = vec![None; n];
        for (o, op) in ops.iter().enumerate() {
            root[o] = match (op.kind, rewires(&op.kind)) {
                (Kind::Const(_), _) => None,
                (_, Some(a)) => {
                    let r = root[a.0 as usize];
                    assert!(r.is_some(), "{}: wiring over a constant (fold it in golden's program)", op.name);
                    r
                }
                _ => Some(o),
            };
        }
        // Each root is held until the last clock any reader of it, or of wiring over it, reads.
        let mut last: Vec<u32> = s.slots.iter().map(|sl| sl.ready).collect();
        for (o, op) in ops.iter().enumerate() {
            let read = s.slots[o].start + if s.slots[o].class == Class::Mul { s.slots[o].busy - 1 } else { 0 };
            for a in op.kind.args() {
                if let Some(r) = root[a.0 as usize] {
                    last[r] = last[r].max(read);
                }
            }
        }
        for v in s.prog.out.all() {
            if let Some(r) = root[v.0 as usize] {
                last[r] = last[r].max(s.latency);
            }
        }
        let copies = (0..n).map(|o| if root[o] == Some(o) { (last[o] - s.slots[o].ready) / s.ii + 1 } else { 0 }).collect();
        Values { s, root, copies }
    }

    pub fn op(&self, o: usize) -> &Op {
        &self.s.prog.ops[o]
    }

    /// A readable name: the operation's index and its name's letters.
    pub fn name(&self, o: usize) -> String {
        let clean: String = self.op(o).name.chars().map(|c| if c.is_ascii_alphanumeric() { c } else { '_' }).collect();
        format!("v{o}_{}", clean.trim_matches('_'))
    }

    /// Copy `k` of value `o`'s register (or wiring net).
    pub fn copy(&self, o: usize, k: u32) -> Src {
        let op = self.op(o);
        match op.kind {
            Kind::Const(c) => Src::Const(c),
            _ => Src::Net { name: format!("{}_{k}", self.name(o)), w: op.w, signed: op.signed },
        }
    }

    /// Value `v` as read at schedule clock `t` by its triangle.
    pub fn at(&self, v: V, t: u32) -> Src {
        let o = v.0 as usize;
        let ready = self.s.slots[o].ready;
        assert!(t >= ready, "{} read at clock {t}, ready at {ready}", self.op(o).name);
        self.copy(o, (t - ready) / self.s.ii)
    }

    /// The copies a value has (its root's).
    pub fn copies_of(&self, o: usize) -> u32 {
        self.root[o].map_or(0, |r| self.copies[r])
    }

    /// Wiring op `o`'s copy `k` from its operand's copy `k`.
    pub fn wiring(&self, o: usize, k: u32) -> String {
        let op = self.op(o);
        let w = op.w;
        let a = |v: V| self.copy(v.0 as usize, k);
        match op.kind {
            Kind::Wire(x) => a(x).ext(w),
            Kind::Not(x) => format!("{} == {}'d0", a(x).ext(self.op(x.0 as usize).w), self.op(x.0 as usize).w),
            Kind::Shl(x, n) => {
                if n >= w {
                    format!("{w}'d0")
                } else if n == 0 {
                    a(x).ext(w)
                } else {
                    format!("{{{}, {n}'d0}}", a(x).ext(w - n))
                }
            }
            Kind::Shr(x, n) => a(x).bits(n, w),
            _ => unreachable!("{} is not wiring", op.name),
        }
    }

    /// The nets a logic operation's result reads besides its operands: wires, and registers
    /// loaded at a schedule clock (`load`).
    ///
    /// The leading-zero count's: its operand reversed above a one, `r`, and `r`'s lowest one,
    /// `r & (~r + 1)`, an add that maps to the carry chain (CCU2C on the ECP5). Its index is
    /// the count (`n` for zero). As a chain of selects the count was the engine's deepest
    /// logic (43 selects, 11-12.5 ns on the 25F); the carry and an OR of the one-hot in one
    /// clock were still the 25F's worst path at stop 34 (`t290_r -> t290_h`, 9.8-10.2 ns). So
    /// the one-hot is registered a clock before the count's start, from the operand as it will
    /// be then ([`Values::early`]): the carry in one clock, the OR in the next, the same
    /// schedule. ABC maps the rest of the block under a smaller depth, in more LUT4, unless
    /// given the chain's depth as its target (`scripts/synth --abc-depth 7`, docs/fpga.md).
    ///
    /// A compare of two values' difference: its sign (`wide` bits hold it without overflow), a
    /// subtract on the carry chain. As `$signed(a) < $signed(b)` Yosys 0.23 mapped each into
    /// LUT4 beside its carry chain (a 19-bit compare 36-38 LUT4).
    pub fn logic_nets(&self, o: usize) -> Vec<LogicNet> {
        let op = self.op(o);
        if let Some((a, b, wide)) = self.lt_by_difference(o) {
            return vec![LogicNet { name: format!("t{o}_d"), w: wide, e: format!("{a} - {b}"), load: None }];
        }
        let Kind::Lzc(a, n) = op.kind else { return vec![] };
        let t = self.s.slots[o].start;
        let early = self.early(a, t);
        let v = early.clone().unwrap_or_else(|| self.at(a, t));
        let (r, h) = (format!("t{o}_r"), format!("t{o}_h"));
        let rev: Vec<String> = (0..n).map(|i| v.bits(i, 1)).collect();
        let one = format!("{r} & (~{r} + {}'d1)", n + 1);
        let r_net = LogicNet { name: r.clone(), w: n + 1, e: format!("{{1'b1, {}}}", rev.join(", ")), load: None };
        match early {
            Some(_) => vec![
                r_net,
                LogicNet { name: format!("{h}n"), w: n + 1, e: one, load: None },
                LogicNet { name: h.clone(), w: n + 1, e: format!("{h}n"), load: Some(t - 1) },
            ],
            None => vec![r_net, LogicNet { name: h, w: n + 1, e: one, load: None }],
        }
    }

    /// Value `v` as it will be at clock `t`, read the clock before: its register's copy when
    /// it is already held then, or the logic result its register loads then (its root a logic
    /// operation ready at `t`, as wide as it); `None` otherwise.
    fn early(&self, v: V, t: u32) -> Option<Src> {
        let o = v.0 as usize;
        let ready = self.s.slots[o].ready;
        if t == 0 || matches!(self.op(o).kind, Kind::Const(_)) {
            return None;
        }
        if t > ready {
            return Some(self.at(v, t - 1));
        }
        let logic = self.root[o] == Some(o) && self.s.slots[o].class == Class::Logic && ready == t;
        (logic && self.logic(o).1 >= self.op(o).w).then(|| Src::Net { name: format!("t{o}"), w: self.op(o).w, signed: self.op(o).signed })
    }

    /// A compare of two values (no constant) as its operands extended to the width its
    /// difference needs, and that width.
    fn lt_by_difference(&self, o: usize) -> Option<(String, String, u32)> {
        let Kind::Lt(a, b) = self.op(o).kind else { return None };
        let t = self.s.slots[o].start;
        let (x, y) = (self.at(a, t), self.at(b, t));
        if matches!(x, Src::Const(_)) || matches!(y, Src::Const(_)) {
            return None;
        }
        let wide = self.op(a.0 as usize).w.max(self.op(b.0 as usize).w).max(self.op(o).w) + 2;
        Some((x.ext(wide), y.ext(wide), wide))
    }

    /// A logic operation's result from its operands read at its start, and the result's width.
    pub fn logic(&self, o: usize) -> (String, u32) {
        let op = self.op(o);
        let t = self.s.slots[o].start;
        let x = |v: V| self.at(v, t);
        let wide = op.kind.args().iter().map(|a| self.op(a.0 as usize).w).max().unwrap_or(1).max(op.w) + 2;
        match op.kind {
            Kind::Add(a, b) => (format!("{} + {}", x(a).ext(wide), x(b).ext(wide)), wide),
            Kind::Sub(a, b) => (format!("{} - {}", x(a).ext(wide), x(b).ext(wide)), wide),
            Kind::Lt(a, b) => match (self.lt_by_difference(o), x(b)) {
                (Some((_, _, d)), _) => (format!("t{o}_d[{}]", d - 1), 1),
                // Below zero is the sign bit: Yosys 0.23 keeps `$signed(a) < 0` a compare, a carry
                // chain the operand's width long with LUT4 beside it (the 25F's critical path
                // `v75_dy1 -> v76_lt` at stop 35, docs/fpga.md).
                (None, Src::Const(0)) => match x(a) {
                    Src::Net { signed: true, w, .. } => (x(a).bits(w - 1, 1), 1),
                    _ => ("1'b0".into(), 1),
                },
                (None, y) => (format!("$signed({}) < $signed({})", x(a).ext(wide), y.ext(wide)), 1),
            },
            Kind::Eq(a, b) => (format!("{} == {}", x(a).ext(wide), x(b).ext(wide)), 1),
            Kind::And(a, b) => (format!("(|{}) && (|{})", x(a).ext(self.op(a.0 as usize).w), x(b).ext(self.op(b.0 as usize).w)), 1),
            Kind::Or(a, b) => (format!("(|{}) || (|{})", x(a).ext(self.op(a.0 as usize).w), x(b).ext(self.op(b.0 as usize).w)), 1),
            Kind::Sel(c, a, b) => (format!("(|{}) ? {} : {}", x(c).ext(self.op(c.0 as usize).w), x(a).ext(op.w), x(b).ext(op.w)), op.w),
            Kind::ShlBy(a, s) => (format!("{} << {}", x(a).ext(op.w), x(s).ext(self.op(s.0 as usize).w)), op.w),
            // Each bit of the count ORs the one-hot's positions that have that bit (`logic_nets`).
            Kind::Lzc(_, n) => {
                let h = format!("t{o}_h");
                let bit = |b: u32| {
                    let m: u128 = (0..=n).filter(|i| i >> b & 1 == 1).map(|i| 1u128 << i).sum();
                    format!("|({h} & {}'h{m:x})", n + 1)
                };
                (format!("{{{}}}", (0..op.w).rev().map(bit).collect::<Vec<_>>().join(", ")), op.w)
            }
            _ => unreachable!("{} is not logic", op.name),
        }
    }
}
