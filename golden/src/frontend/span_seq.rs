//! The sequential span path (`SpanForm::Sequential`, the iCE40 targets, issue 27): a covered
//! row's three reciprocal products (`Gxn lo`, the estimate, the correction) formed one after the
//! other on ONE shift-add unit, a few multiplier bits a clock, while the walker waits. The
//! parallel span path's products are most of the iCE40 front-end's logic (docs/fpga.md); at
//! ~350 set-up clocks a triangle the walker need not take a row every clock.
//!
//! The unit is an accumulator `acc` modulo 2^W (W = K - 1, `S2n`'s width), a multiplicand `mc`
//! shifted left `B` bits a step and a multiplier `mp` shifted right: a step adds
//! `mc * (mp mod 2^B)`. Its phases ([`SpanSeq::PHASES`]), each a load clock (the accept clock
//! for the first) then `ceil(bits / B)` steps:
//!
//! 1. `acc = 2 Tn`, `+ An`: then `2 Tn + An`;
//! 2. `+ ((Gxn >> 8) << 9) lo`: `acc = S2n` modulo 2^(K-1) (the parallel path's `2 (Tn + Gxn
//!    lo) + An`; `Gxn`'s low 8 bits are zero, [`Widths::GXN_ZEROS`]);
//! 3. `L = S2n[AW+2:1]` kept, `acc = H Rn` with `H = S2n >> t`: the estimate `q~` is its bits
//!    from K - t up ([`Widths::quotient_estimate`]);
//! 4. `q~` kept, `acc = ~L + An (q~ + 1)`: its bit AW + 1 is `R >= 2An` (below);
//! 5. that bit kept, `acc += An`: its bit AW + 1 is `R >= 4An`.
//!
//! `I0 = q~ + (R >= 2An) + (R >= 4An)` as [`Widths::corrected_quotient`]. Why the bits: the
//! parallel correction reads the top bit of `X = (S2n - 2An (q~ + k)) mod 2^(AW+3)` for k = 1, 2.
//! `S2n`'s residue is `2L + b`, so `X = 2 (L - An (q~ + k)) + b` and its top bit is bit AW + 1 of
//! `Y = (L - An (q~ + k)) mod 2^(AW+2)`; `~L + An (q~ + k) = -(L - An (q~ + k)) - 1 = ~Y`, so that
//! bit of the accumulator is the complement of the sign: the compare itself, with no subtractor
//! beside the unit.

use super::{mask, FrontEnd, SpanForm, Widths};

/// What a phase loads into the accumulator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AccLoad {
    /// `2 Tn` modulo 2^W (the row's sum, in the accept clock).
    Tn2,
    /// The accumulator as it is.
    Keep,
    Zero,
    /// `~L` modulo 2^W, `L = S2n[AW+2:1]` (kept at phase 3's load).
    NotL,
}

/// What a phase loads into the multiplicand.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Multiplicand {
    An,
    /// `(Gxn >> 8) << 9` modulo 2^W.
    Gx,
    /// `H = acc >> t` (`S2n`'s top bits).
    H,
}

/// What a phase loads into the multiplier.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Multiplier {
    One,
    /// The span's first column.
    Lo,
    Rn,
    /// `q~ + 1` (`q~` read from the accumulator as the phase loads).
    Qt1,
}

/// One phase of the unit: its loads and its multiplier's bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Phase {
    pub acc: AccLoad,
    pub mc: Multiplicand,
    pub mp: Multiplier,
}

/// A fault planted in the model (the tests' negative controls).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum SeqFault {
    None,
    /// The column's phase adds its multiplicand unshifted at its second step.
    UnshiftedColumn,
}

/// The sequential span path of a front-end ([`FrontEnd::span_seq`]): the unit's widths and
/// rate, and its arithmetic step by step as the RTL runs it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SpanSeq {
    /// Multiplier bits a step (radix 2^B).
    pub bits: u32,
    pub wd: Widths,
    /// The multiplier's bits in each of the phases' operands: the column (XW), `Rn` (RW), `q~ + 1`
    /// (IW + 1).
    pub xw: u32,
    pub iw: u32,
}

/// Multiplier bits the unit takes a step on the iCE40 targets: 2, a radix-4 step of two
/// shifted adds into one adder. 1 bit a step made a row 63 clocks at 640x480, ~880 clocks for a
/// ~100 px triangle's 14 rows against the engine's ~350; 2 bits 36.
pub const SPAN_SEQ_BITS: u32 = 2;

impl SpanSeq {
    pub const PHASES: [Phase; 5] = [
        Phase { acc: AccLoad::Tn2, mc: Multiplicand::An, mp: Multiplier::One },
        Phase { acc: AccLoad::Keep, mc: Multiplicand::Gx, mp: Multiplier::Lo },
        Phase { acc: AccLoad::Zero, mc: Multiplicand::H, mp: Multiplier::Rn },
        Phase { acc: AccLoad::NotL, mc: Multiplicand::An, mp: Multiplier::Qt1 },
        Phase { acc: AccLoad::Keep, mc: Multiplicand::An, mp: Multiplier::One },
    ];

    /// The accumulator's width W: `S2n`'s K - 1 bits, which the estimate's product (K - t + IW
    /// bits) and the correction's (AW + 2) do not exceed at any configuration the front-end
    /// takes (asserted).
    pub fn acc_bits(&self) -> u32 {
        let w = self.wd.k - 1;
        assert!(self.estimate_bits() <= w && self.wd.aw + 2 <= w, "the span unit's products fit S2n's width: {self:?}");
        w
    }

    /// Bits of the estimate's product `H Rn` the quotient needs: modulo 2^(K - t + IW).
    pub fn estimate_bits(&self) -> u32 {
        self.wd.k - self.wd.i0_shift() + self.iw
    }

    /// `H`'s bits: `S2n >> t`.
    pub fn h_bits(&self) -> u32 {
        self.wd.k - 1 - self.wd.i0_shift()
    }

    /// The multiplier's width: its widest operand.
    pub fn mp_bits(&self) -> u32 {
        Self::PHASES.iter().map(|p| self.operand_bits(p.mp)).max().expect("phases")
    }

    /// A multiplier operand's bits.
    pub fn operand_bits(&self, mp: Multiplier) -> u32 {
        match mp {
            Multiplier::One => 1,
            Multiplier::Lo => self.xw,
            Multiplier::Rn => self.wd.rw,
            Multiplier::Qt1 => self.iw + 1,
        }
    }

    /// Steps of a phase: its multiplier's bits, B a step.
    pub fn steps(&self, p: &Phase) -> u32 {
        self.operand_bits(p.mp).div_ceil(self.bits)
    }

    /// Clocks between two covered rows' accepts with the output free: the accept (phase 1's
    /// load), every phase's steps, the other phases' loads, and the clock the result is written
    /// to the output (in which the next row is accepted).
    pub fn row_clocks(&self) -> u32 {
        Self::PHASES.iter().map(|p| self.steps(p)).sum::<u32>() + Self::PHASES.len() as u32
    }

    /// Clocks from a covered row's accept to its span's `out_valid`: [`SpanSeq::row_clocks`]
    /// and the output register.
    pub fn latency(&self) -> u32 {
        self.row_clocks() + 1
    }

    /// `I0` of a span at column `lo` from the row's `Tn` and the triangle's `Gxn`, `An`, `Rn`, as
    /// the unit forms it (the module documentation).
    pub fn i0(&self, tn: u128, gxn: u128, an: u128, rn: u128, lo: u32) -> u32 {
        self.i0_with(tn, gxn, an, rn, lo, SeqFault::None)
    }

    pub(crate) fn i0_with(&self, tn: u128, gxn: u128, an: u128, rn: u128, lo: u32, fault: SeqFault) -> u32 {
        let (w, t, aw, iw) = (self.acc_bits(), self.wd.i0_shift(), self.wd.aw, self.iw);
        let wm = mask(w);
        let mut acc = 0u128;
        let (mut l, mut qt, mut ge2) = (0u128, 0u128, false);
        for (k, p) in Self::PHASES.iter().enumerate() {
            // What the loads read of the accumulator, before it is loaded.
            match k {
                2 => l = (acc >> 1) & mask(aw + 2),
                3 => qt = (acc >> (self.estimate_bits() - iw)) & mask(iw),
                4 => ge2 = acc >> (aw + 1) & 1 == 1,
                _ => {}
            }
            let h = (acc >> t) & mask(self.h_bits());
            acc = match p.acc {
                AccLoad::Tn2 => (tn << 1) & wm,
                AccLoad::Keep => acc,
                AccLoad::Zero => 0,
                AccLoad::NotL => !l & wm,
            };
            let mut mc = match p.mc {
                Multiplicand::An => an,
                Multiplicand::Gx => ((gxn >> Widths::GXN_ZEROS) << (Widths::GXN_ZEROS + 1)) & wm,
                Multiplicand::H => h,
            };
            let mut mp = match p.mp {
                Multiplier::One => 1,
                Multiplier::Lo => lo as u128,
                Multiplier::Rn => rn,
                Multiplier::Qt1 => qt + 1,
            };
            for step in 0..self.steps(p) {
                for b in 0..self.bits {
                    if mp >> b & 1 == 1 {
                        acc = (acc + (mc << b)) & wm;
                    }
                }
                if !(k == 1 && step == 0 && fault == SeqFault::UnshiftedColumn) {
                    mc = (mc << self.bits) & wm;
                }
                mp >>= self.bits;
            }
        }
        let ge4 = acc >> (aw + 1) & 1 == 1;
        ((qt + u128::from(ge2) + u128::from(ge4)) & mask(iw)) as u32
    }
}

impl FrontEnd {
    /// The sequential span path, if this front-end's span form is it.
    pub fn span_seq(&self) -> Option<SpanSeq> {
        (self.span == SpanForm::Sequential).then(|| SpanSeq {
            bits: SPAN_SEQ_BITS,
            wd: self.widths(),
            xw: self.cfg.xbits,
            iw: self.cfg.iw(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frontend::tests::{random_tri, Rng};
    use crate::setup::Screen;
    use crate::Config;

    /// Every span of `quarters` / 4 times 2,000 + 1,000 + 1,000 random triangles: the unit's `I0` is the
    /// parallel path's (which the walk checks against the exact plane), at the default formats
    /// and at small ones; a fault (the column's multiplicand not shifted once) is caught on more
    /// than a quarter of them. Returns the spans compared.
    fn unit_against_parallel(quarters: usize) -> u64 {
        let mut total = 0;
        for (cfg, screen, n) in [
            (Config::default(), Screen { width: 640, height: 480 }, 2_000),
            (Config::new(8, 4, 6, crate::Align::Span).expect("cfg"), Screen { width: 16, height: 8 }, 1_000),
            (Config::default(), Screen { width: 37, height: 23 }, 1_000),
        ] {
            let fe = FrontEnd::new(cfg, screen).expect("fe");
            let seq = fe.with_span(SpanForm::Sequential);
            let q = seq.span_seq().expect("sequential");
            let mut rng = Rng(0x5eed_5ca1);
            let (mut spans, mut caught) = (0u64, 0u64);
            for _ in 0..n * quarters / 4 {
                let t = random_tri(&mut rng, &fe);
                let list = fe.span_list(&t);
                assert_eq!(list, seq.span_list(&t), "{t:?}");
                let (_, Some(st)) = fe.setup(&t) else { continue };
                let mut tn = st.tn;
                for r in st.first..=st.last {
                    if let Some((_, s)) = list.1.iter().find(|(y, _)| *y == r) {
                        let want = fe.i0(&st, tn, s.x0);
                        assert_eq!(q.i0(tn, st.gxn, st.an, st.rn, s.x0), want, "row {r}, {t:?}");
                        spans += 1;
                        caught += u64::from(q.i0_with(tn, st.gxn, st.an, st.rn, s.x0, SeqFault::UnshiftedColumn) != want);
                    }
                    tn = (tn + st.dyn_) & mask(fe.widths().k);
                }
            }
            assert!(spans > 100, "{spans} spans at {screen:?}");
            assert!(caught * 4 > spans, "the unshifted column is caught on {caught} of {spans} spans");
            total += spans;
        }
        total
    }

    /// [`unit_against_parallel`] on 1,000 triangles: about half a second (the suite's time budget).
    #[test]
    fn the_sequential_unit_gives_the_parallel_i0_on_every_span() {
        unit_against_parallel(1);
    }

    /// The same on over 10^6 spans (slow tier, about a minute in debug).
    #[test]
    #[ignore]
    fn the_sequential_unit_gives_the_parallel_i0_on_a_million_spans() {
        let spans = unit_against_parallel(40);
        println!("{spans} spans");
        assert!(spans > 1_000_000, "{spans}");
    }

    /// The rate the RTL keeps (its co-simulation measures it): 36 clocks a covered row at
    /// 640x480 and radix 4.
    #[test]
    fn a_covered_row_takes_its_steps_and_one_clock_a_phase() {
        let fe = FrontEnd::new(Config::default(), Screen { width: 640, height: 480 }).expect("fe").with_span(SpanForm::Sequential);
        let q = fe.span_seq().expect("sequential");
        // 1 + ceil(10 / 2)... the column is XW = 12 bits: 1 + 6 + 12 + 11 + 1 steps, 5 loads.
        assert_eq!((q.acc_bits(), q.mp_bits(), q.row_clocks(), q.latency()), (63, 23, 36, 37));
        assert_eq!(FrontEnd::new(Config::default(), Screen { width: 640, height: 480 }).expect("fe").span_seq(), None);
    }
}
