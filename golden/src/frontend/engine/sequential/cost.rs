//! The sequential engine's size by golden's estimate ([`SeqCost`]): iCE40 SB_LUT4,
//! flip-flops and EBR, from the microprogram's widths and the plan's units.

use super::super::placement::ceil;
use super::super::schedule::lut_per_bit_step;
use super::super::{Kind, MulUnit, V};
use super::{Exec, Loc, SeqCost, SeqSchedule, ALU_LUT4_PER_BIT};

impl SeqSchedule {
    pub(super) fn cost(&self) -> SeqCost {
        let ops = &self.prog.ops;
        let units = &self.plan.units;
        let (words, flags) = self.words();
        let ram_ops: Vec<usize> = (0..ops.len()).filter(|&o| matches!(self.slots[o].loc, Loc::Ram(_))).collect();
        let ram_width = ram_ops.iter().map(|&o| ops[o].w + !ops[o].signed as u32).max().unwrap_or(1);
        let ebr = |width: u32, depth: u32| ceil(width, self.plan.bank_bits) * ceil(depth.max(1), self.plan.bank_depth);
        let abits = |k: u32| 32 - k.max(2).saturating_sub(1).leading_zeros();
        let wbits = abits(ram_width + 1);
        // The microword: two read addresses and a write address, the ALU's function and the
        // width and sign to wrap to, the flag file's addresses (two read, one write), the
        // shift amount, each unit's start, the write bus's source, the queue field to capture.
        let outs = self.prog.out.all().len() as u32;
        let micro_bits = 3 * abits(words) + 4 + wbits + 1 + 3 * abits(flags) + wbits + 3 + 3 + abits(outs + 1);
        let per_bit = lut_per_bit_step();
        let w = |v: V| ops[v.0 as usize].w;
        let (mut mul_w, mut div_w, mut div_q) = (0u32, 0u32, 0u32);
        for (op, _) in ops.iter().zip(&self.slots).filter(|(_, s)| s.exec != Exec::Dead) {
            match op.kind {
                Kind::Mul(a, b) => mul_w = mul_w.max(op.w.min(w(a) + w(b))),
                Kind::Div { d, qb, .. } => {
                    div_w = div_w.max(w(d) + 1);
                    div_q = div_q.max(qb);
                }
                _ => {}
            }
        }
        let lut_mul = match units.mul {
            // The accumulator and the chunk multiplexers of each operand.
            MulUnit::Tile { bits } => units.mults * (2 * mul_w + 2 * bits * ceil(ceil(ram_width, bits), 2)),
            // An adder as wide as the product, its operand gated by the multiplier's bit.
            MulUnit::ShiftAdd { bits } => units.mults * (per_bit * (mul_w * bits) as f64).round() as u32,
        };
        let lut_div = units.dividers * (per_bit * (div_w * units.div_bits) as f64).round() as u32;
        // Left by a value or a constant, right by a constant: one barrel shifter and the
        // operand's reversal on each side; its four lowest stages products on SB_MAC16 where
        // the plan puts them there.
        let stages = abits(ram_width) - if self.plan.shift_on_macs { 4 } else { 0 };
        let lut_shift = units.shifters * (ram_width * stages + 2 * ram_width);
        // The write bus: ALU, shifter, product, quotient, remainder, input.
        let lut_ctl = ram_width * 3 + flags * 3 + outs + abits(self.clocks) * 4;
        let result_bits: u32 = self.prog.out.all().iter().map(|&v| w(v)).sum();
        let ff = ram_width * 2 // ALU and shifter results
            + units.mults * (2 * mul_w) + units.dividers * (2 * div_w + div_q)
            + flags + abits(self.clocks) + result_bits;
        SeqCost {
            clocks: self.clocks,
            ram_width,
            ram_words: words,
            ebr_regfile: self.plan.read_ports * ebr(ram_width, words),
            micro_bits,
            ebr_micro: ebr(micro_bits, self.clocks),
            flags,
            value_bits_ram: ram_ops.iter().map(|&o| ops[o].w).sum(),
            lut_alu: ram_width * ALU_LUT4_PER_BIT,
            lut_shift,
            lut_mul,
            lut_div,
            lut_ctl,
            ff,
            result_bits,
        }
    }
}
