//! The width of a register, a counter or an address: one rule for every block the generator
//! emits, so two blocks that hold the same count agree on its width.

/// Bits to hold every value in `0..=max`, at least 1 (a register of 0 bits is not Verilog).
pub fn bits_for(max: impl Into<u64>) -> u32 {
    (64 - max.into().leading_zeros()).max(1)
}

#[cfg(test)]
mod tests {
    use super::bits_for;

    #[test]
    fn widths_hold_their_maximum_and_no_more() {
        assert_eq!(bits_for(0u32), 1);
        assert_eq!(bits_for(1u32), 1);
        assert_eq!(bits_for(2u32), 2);
        assert_eq!(bits_for(255u32), 8);
        assert_eq!(bits_for(256u64), 9);
        assert_eq!(bits_for(u64::MAX), 64);
    }
}
