//! A TMDS decoder (DVI 1.0, section 3.3.3), written from the specification and independent of
//! the encoder RTL: what a monitor does with each 10-bit symbol.

/// One decoded symbol.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Symbol {
    /// A control period's symbol: the two control bits (channel 0: hsync, vsync).
    Control { c0: bool, c1: bool },
    /// A video period's byte.
    Data(u8),
}

/// The four control symbols, for (c1, c0) = 00, 01, 10, 11.
pub const CONTROL: [u16; 4] = [0b1101010100, 0b0010101011, 0b0101010100, 0b1010101011];

/// Decodes a symbol (bits 9..0; bit 0 is sent first). The control symbols are matched first:
/// no data byte encodes to one of them.
pub fn decode(q: u16) -> Symbol {
    let q = q & 0x3ff;
    if let Some(k) = CONTROL.iter().position(|&c| c == q) {
        return Symbol::Control { c0: k & 1 == 1, c1: k & 2 == 2 };
    }
    // Bit 9: the low 8 bits were inverted; bit 8: XOR (1) or XNOR (0) transition coding.
    let d = if q & 0x200 != 0 { !q & 0xff } else { q & 0xff };
    let xor = q & 0x100 != 0;
    let mut out = d & 1;
    for i in 1..8 {
        let t = (d >> i ^ d >> (i - 1)) & 1;
        out |= if xor { t } else { t ^ 1 } << i;
    }
    Symbol::Data(out as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Encodes as DVI 1.0's flow chart does (disparity 0, so bit 9 follows bit 8): enough to
    /// see that every byte comes back, and that no byte encodes to a control symbol.
    fn encode_balanced(d: u8) -> u16 {
        let n1 = d.count_ones();
        let xnor = n1 > 4 || (n1 == 4 && d & 1 == 0);
        let mut qm = (d & 1) as u16;
        for i in 1..8 {
            let b = ((qm >> (i - 1)) ^ (d as u16 >> i)) & 1;
            qm |= if xnor { b ^ 1 } else { b } << i;
        }
        if xnor {
            // q_m[8] = 0: sent inverted, bit 9 set.
            0x200 | (!qm & 0xff)
        } else {
            0x100 | qm
        }
    }

    #[test]
    fn every_byte_round_trips() {
        for d in 0..=255u8 {
            let q = encode_balanced(d);
            assert!(!CONTROL.contains(&q), "byte {d} encodes to a control symbol");
            assert_eq!(decode(q), Symbol::Data(d), "byte {d} (symbol {q:010b})");
        }
    }

    #[test]
    fn control_symbols() {
        assert_eq!(decode(0b1101010100), Symbol::Control { c0: false, c1: false });
        assert_eq!(decode(0b1010101011), Symbol::Control { c0: true, c1: true });
        // Negative control: one bit off a control symbol is data, not control.
        assert!(matches!(decode(0b1101010101), Symbol::Data(_)));
    }
}
