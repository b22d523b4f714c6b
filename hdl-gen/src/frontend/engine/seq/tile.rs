//! The sequential engine's tile multipliers (`MulUnit::Tile`, the UP5K's SB_MAC16): a product
//! of two register-file words as golden's chunk passes, one a clock, on a `bits + 1`-bit signed
//! multiplier with registered inputs and output (so `synth_ice40 -dsp` maps it onto one
//! SB_MAC16), accumulated as the pipelined engine's tiles are ([`super::super::units`]):
//! heaviest chunk pair first, the sum shifted one chunk up where the pair's weight drops.
//!
//! - **Timing** (golden's `timing`: `p` passes, then `MUL_PIPE`): the unit's first pass is at
//!   `L`, `SeqPlan::load_lag` (1) clocks after its operands are on the read ports; it holds
//!   them from the ports a clock before (`L - 1`, the clock golden reserves the unit from), so
//!   every pass selects its chunks from the held operands alone (a choice between the ports'
//!   word and the held one was a LUT a bit of each held operand on the UP5K). A pass's chunks are
//!   registered, their product the clock after, the sum the clock after that: the product is
//!   in the accumulator at `L + p + 2`, the clock golden writes it.
//! - **Control**: every pass's chunk indices, whether each is its operand's signed top chunk
//!   and whether the sum shifts, are microword fields of the pass's clock (per unit: the
//!   units run at once), so the unit has no sequencer of its own.

use crate::verilog::{comment, reg, set, sreg, wire, Item, Stmt};
use golden::frontend::engine::schedule::MUL_PIPE;
use golden::frontend::engine::sequential::{Exec, SeqSchedule, READ};
use golden::frontend::engine::{Kind, MulUnit};

use super::super::units::bits_for;

/// Per unit, its microword fields: load (the first pass), chunk of a, chunk of b, a's chunk
/// signed (its top one, of a signed operand), b's, the sum shifted a chunk up; where the sum
/// is split (`SeqPlan::acc_lag`), its low half's enable, a clock before it adds.
const FIELDS: [[&str; 7]; 2] =
    [["m0ld", "m0ca", "m0cb", "m0ta", "m0tb", "m0s", "m0e"], ["m1ld", "m1ca", "m1cb", "m1ta", "m1tb", "m1s", "m1e"]];

/// The tile units of a sequential schedule whose plan has them.
pub(super) struct Tiles<'a> {
    s: &'a SeqSchedule,
    bits: u32,
    mults: u32,
    /// The chunk index's bits (chunks of the widest operand).
    cbw: u32,
}

impl<'a> Tiles<'a> {
    pub(super) fn new(s: &'a SeqSchedule) -> Option<Tiles<'a>> {
        let MulUnit::Tile { bits } = s.plan.units.mul else { return None };
        let mults = s.plan.units.mults;
        assert!((1..=FIELDS.len() as u32).contains(&mults), "{mults} tile multipliers (the RTL has fields for 1 or 2)");
        let chunks = s.cost.ram_width.div_ceil(bits);
        Some(Tiles { s, bits, mults, cbw: bits_for(chunks - 1) })
    }

    pub(super) fn fields(&self) -> Vec<(&'static str, u32)> {
        let n = 6 + (self.s.plan.acc_lag > 0) as usize;
        (0..self.mults as usize)
            .flat_map(|u| FIELDS[u][..n].iter().zip([1, self.cbw, self.cbw, 1, 1, 1, 1]).map(|(n, w)| (*n, w)))
            .collect()
    }

    /// Unit `u`'s chunks of its widest first and second operands: the chunks it holds.
    fn held(&self, u: u32) -> [u32; 2] {
        let ops = &self.s.prog.ops;
        let mut n = [1, 1];
        for (o, op) in ops.iter().enumerate() {
            if let (Kind::Mul(a, b), Exec::Unit(_, k)) = (op.kind, self.s.slots[o].exec) {
                if k == u {
                    n[0] = n[0].max(ops[a.0 as usize].w.div_ceil(self.bits));
                    n[1] = n[1].max(ops[b.0 as usize].w.div_ceil(self.bits));
                }
            }
        }
        n
    }

    /// Product `o` on unit `u`: its passes' fields, `(clock, field, value)`, from its load (the
    /// clock before its first pass) on.
    pub(super) fn passes(&self, o: usize, u: u32) -> Vec<(u32, &'static str, u64)> {
        let ops = &self.s.prog.ops;
        let sl = self.s.slots[o];
        let Kind::Mul(a, b) = ops[o].kind else { unreachable!("a product on a multiplier") };
        let (a, b) = (&ops[a.0 as usize], &ops[b.0 as usize]);
        let (ca, cb) = (a.w.div_ceil(self.bits), b.w.div_ceil(self.bits));
        // Golden's pairs (those wholly above the kept bits left out), heaviest first (Horner).
        let mut p: Vec<(u32, u32)> =
            (0..ca).flat_map(|i| (0..cb).map(move |j| (i, j))).filter(|&(i, j)| (i + j) * self.bits < ops[o].w).collect();
        p.sort_by_key(|&(i, j)| std::cmp::Reverse(i + j));
        assert_eq!(self.s.plan.load_lag, 1, "the tiles hold their operands from the read ports, a clock before the first pass");
        let l = sl.issue + READ + self.s.plan.load_lag;
        assert_eq!(sl.exec, Exec::Unit(golden::frontend::engine::schedule::Class::Mul, u));
        let lag = self.s.plan.acc_lag;
        assert!(lag <= 1, "a sum split in {} parts (the RTL has one or two)", lag + 1);
        assert_eq!(sl.write, l + p.len() as u32 + MUL_PIPE + lag + self.s.plan.bus_lat, "{}: golden's passes", ops[o].name);
        let f = &FIELDS[u as usize];
        let mut set = Vec::new();
        for (k, &(i, j)) in p.iter().enumerate() {
            let t = l + k as u32;
            set.extend([
                (t - (k == 0) as u32, f[0], (k == 0) as u64),
                (t, f[1], i as u64),
                (t, f[2], j as u64),
                (t, f[3], (i + 1 == ca && a.signed) as u64),
                (t, f[4], (j + 1 == cb && b.signed) as u64),
                (t, f[5], (k > 0 && i + j < p[k - 1].0 + p[k - 1].1) as u64),
            ]);
        }
        if lag > 0 {
            // The low half adds a clock after each pass's chunks, and once more for the last product.
            set.extend((0..=p.len() as u32).map(|k| (l + k, f[6], 1)));
        }
        set
    }

    /// The units: per unit the held operands, the chunk selection, the tile and the sum.
    /// `w`: the register file's word; `x0`, `x1`: the read ports, which the units hold (their
    /// operands are never flags: the generator asserts it).
    pub(super) fn units(&self, w: u32, (x0, x1): (&str, &str), b: &mut Vec<Item>) {
        let bits = self.bits;
        let (pw, cbw) = (2 * bits + 2, self.cbw);
        b.push(comment(format!(
            "The tile multipliers: a product as golden's passes of {bits}-bit chunks on a {0} x {0} signed multiplier (SB_MAC16),",
            bits + 1
        )));
        b.push(comment("the operands held from the read ports a clock before the first pass (m*a, m*b), every pass on them; the"));
        b.push(comment("sum cleared for the first pass and shifted a chunk up where the weight drops, modulo W."));
        for u in 0..self.mults {
            let m = |x: &str| format!("m{u}{x}");
            let uf = |x: &str| format!("u_m{u}{x}");
            let held = self.held(u);
            let mut loads = Vec::new();
            for (side, (o, x)) in [("a", x0), ("b", x1)].into_iter().enumerate() {
                // The operand held only as wide as this unit's widest on this side needs: its
                // chunks and the sign bit above them (a register-file word holds its value sign-
                // or zero-extended to W: unsigned values have a zero bit on top), sign-extended
                // past the top chunk's sign bit where that is beyond the word.
                let n = held[side];
                let (hw, ew) = ((n * bits + 1).min(w), n * bits + 1);
                b.push(reg(&m(o), hw));
                let at = if hw < w { format!("{x}[{}:0]", hw - 1) } else { x.to_string() };
                loads.push(set(m(o), at));
                b.push(wire(&m(&format!("e{o}")), ew, crate::verilog::sext(&m(o), hw, ew)));
                // The chunk the microword names, its sign bit the operand's where it is the
                // signed top chunk.
                let c = m(&format!("c{o}"));
                b.push(reg(&c, bits + 1));
                let e = m(&format!("e{o}"));
                let top = uf(&format!("t{o}"));
                let chunk = |i: u32| {
                    let x = format!("{{{top} & {e}[{}], {e}[{}:{}]}}", (i + 1) * bits, (i + 1) * bits - 1, i * bits);
                    vec![Stmt::Blocking(c.clone(), x)]
                };
                // No pass names a chunk beyond the held ones: the top one is the default.
                let arms = (0..n - 1).map(|i| (format!("{cbw}'d{i}"), chunk(i))).collect();
                if n == 1 {
                    // One chunk: the microword's field for it (sized for the other unit's) is not read.
                    b.push(comment("verilator lint_off UNUSEDSIGNAL"));
                    b.push(wire(&format!("unused_{c}"), cbw, uf(&format!("c{o}"))));
                    b.push(comment("verilator lint_on UNUSEDSIGNAL"));
                }
                b.push(Item::Comb(if n > 1 {
                    vec![Stmt::Case { sel: uf(&format!("c{o}")), arms, default: chunk(n - 1) }]
                } else {
                    chunk(0)
                }));
            }
            b.extend([sreg(&m("ra"), bits + 1), sreg(&m("rb"), bits + 1), reg(&m("f0"), 1), reg(&m("f1"), 1), reg(&m("s1"), 1)]);
            if w < pw {
                b.push(comment("verilator lint_off UNUSEDSIGNAL"));
                b.push(sreg(&m("pr"), pw));
                b.push(comment("verilator lint_on UNUSEDSIGNAL"));
            } else {
                b.push(sreg(&m("pr"), pw));
            }
            let mut regs = vec![
                Stmt::If(uf("ld"), loads, vec![]),
                set(m("ra"), m("ca")),
                set(m("rb"), m("cb")),
                // The first pass is the clock after the load.
                set(m("f0"), uf("ld")),
                set(m("f1"), m("f0")),
                set(m("s1"), uf("s")),
                set(m("pr"), format!("{} * {}", m("ra"), m("rb"))),
            ];
            if self.s.plan.acc_lag == 0 {
                b.push(reg(&m("acc"), w));
                let pe = if w > pw { crate::verilog::sext(&m("pr"), pw, w) } else { format!("{}[{}:0]", m("pr"), w - 1) };
                b.push(wire(&m("accn"), w, format!("{} + {pe}", m("acc"))));
                let up = if w > bits { format!("{{{}[{}:0], {bits}'d0}}", m("accn"), w - bits - 1) } else { format!("{w}'d0") };
                b.push(wire(&m("held"), w, format!("{} ? {w}'d0 : {} ? {up} : {}", m("f1"), m("s1"), m("accn"))));
                regs.push(set(m("acc"), m("held")));
            } else {
                self.split_sum(u, &mut regs, b);
            }
            b.push(Item::Always(vec![Stmt::If("en".into(), regs, vec![])]));
        }
        b.push(Item::Blank);
    }

    /// Unit `u`'s sum in two halves (`SeqPlan::acc_lag` = 1): the low half (`h` bits, at
    /// least the product's) adds the product and registers its carry, the product's sign (or
    /// its bits above `h`) and the bits a shift moves up; the high half adds them a clock later,
    /// so neither carry chain is the word's. Each half runs only while its enable is on (the
    /// low half's from the microword, the high half's a clock after), so the sum holds until
    /// golden's write. The sum is `m<u>acc`, as in the one-clock form.
    fn split_sum(&self, u: u32, regs: &mut Vec<Stmt>, b: &mut Vec<Item>) {
        let (w, bits) = (self.s.cost.ram_width, self.bits);
        let pw = 2 * bits + 2;
        let h = w.div_ceil(2).max(pw.min(w - bits - 1));
        let hw = w - h;
        assert!(h > bits && hw > bits, "a {w}-bit sum split in halves wider than a chunk of {bits}");
        let m = |x: &str| format!("m{u}{x}");
        // The product's bits above the low half: its sign where it fits in it.
        let (pt, ptw) = if pw <= h { (format!("{}[{}]", m("pr"), pw - 1), 1) } else { (format!("{}[{}:{h}]", m("pr"), pw - 1), pw - h) };
        let plo = if pw <= h { crate::verilog::sext(&m("pr"), pw, h) } else { format!("{}[{}:0]", m("pr"), h - 1) };
        b.push(comment(format!("Unit {u}'s sum in halves: the low {h} bits, then the high {hw} a clock later from its carry.")));
        b.extend([reg(&m("e1"), 1), reg(&m("e2"), 1), reg(&m("lo"), h), reg(&m("hi"), hw)]);
        b.extend([reg(&m("c2"), 1), reg(&m("p2"), ptw), reg(&m("t2"), bits), reg(&m("s2"), 1), reg(&m("f2"), 1)]);
        b.push(wire(&m("los"), h + 1, format!("{{1'b0, {}}} + {{1'b0, {plo}}}", m("lo"))));
        let lup = format!("{{{}[{}:0], {bits}'d0}}", m("los"), h - bits - 1);
        b.push(wire(&m("lon"), h, format!("{} ? {h}'d0 : {} ? {lup} : {}[{}:0]", m("f1"), m("s1"), m("los"), h - 1)));
        // The carry rides as a low bit: {hi, 1} + {p, c} carries c into bit 0.
        b.push(comment("verilator lint_off UNUSEDSIGNAL"));
        let pe = crate::verilog::sext(&m("p2"), ptw, hw);
        b.push(wire(&m("his"), hw + 1, format!("{{{}, 1'b1}} + {{{pe}, {}}}", m("hi"), m("c2"))));
        b.push(comment("verilator lint_on UNUSEDSIGNAL"));
        let hup = format!("{{{}[{}:1], {}}}", m("his"), hw - bits, m("t2"));
        b.push(wire(&m("hin"), hw, format!("{} ? {hw}'d0 : {} ? {hup} : {}[{hw}:1]", m("f2"), m("s2"), m("his"))));
        b.push(wire(&m("acc"), w, format!("{{{}, {}}}", m("hi"), m("lo"))));
        regs.extend([
            set(m("e1"), format!("u_m{u}e")),
            set(m("e2"), m("e1")),
            Stmt::If(
                m("e1"),
                vec![
                    set(m("lo"), m("lon")),
                    set(m("c2"), format!("{}[{h}]", m("los"))),
                    set(m("p2"), pt),
                    set(m("t2"), format!("{}[{}:{}]", m("los"), h - 1, h - bits)),
                    set(m("s2"), m("s1")),
                    set(m("f2"), m("f1")),
                ],
                vec![],
            ),
            Stmt::If(m("e2"), vec![set(m("hi"), m("hin"))], vec![]),
        ]);
    }
}
