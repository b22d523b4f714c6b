//! The UART source in simulation: the bench's stimulus (what the host's serial port does on
//! the line, byte by byte, with faults and F1 presses), and what comes back: the frame buffer's
//! writes, replayed into a picture, and the bytes the board sent.

use golden::writer::Writer;

/// One step of the serial line, as the bench plays it (board/sim/board_tb.v).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Op {
    /// A byte, 8N1.
    Byte(u8),
    /// A byte whose stop bit is low: a framing error.
    BadStop(u8),
    /// The line idle (high) for this many ns.
    Idle(u32),
    /// The line low for this many ns (a break, or a glitch when short).
    Low(u32),
    /// F1 pressed this many ns from now (for 2 us), while the line goes on.
    Press(u32),
}

/// The bench's stimulus file: a line `OP V` a step.
pub fn stimulus(ops: &[Op]) -> String {
    ops.iter()
        .map(|op| match *op {
            Op::Byte(b) => format!("0 {b}\n"),
            Op::BadStop(b) => format!("1 {b}\n"),
            Op::Idle(ns) => format!("2 {ns}\n"),
            Op::Low(ns) => format!("3 {ns}\n"),
            Op::Press(ns) => format!("4 {ns}\n"),
        })
        .collect()
}

/// Bytes as steps.
pub fn bytes(b: &[u8]) -> Vec<Op> {
    b.iter().map(|&b| Op::Byte(b)).collect()
}

#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum StreamError {
    #[error("line {line} of the write log: {text:?} is not `addr we data` in hexadecimal")]
    Write { line: usize, text: String },
}

fn hex_bytes(text: &str) -> Option<Vec<u8>> {
    // Least significant byte first; an odd leading digit is its own byte.
    let digits: Vec<u32> = text.chars().map(|c| c.to_digit(16)).collect::<Option<_>>()?;
    Some(digits.rchunks(2).map(|c| c.iter().fold(0, |a, &d| a << 4 | d) as u8).collect())
}

/// The picture the frame buffer holds after the writes of `log` (the bench's `+writes` file),
/// starting from a cleared buffer (the bench logs from the end of the power-up clear).
pub fn replay(log: &str, w: &Writer) -> Result<Vec<u8>, StreamError> {
    let (width, p, bpr) = (w.screen.width as usize, w.cfg.p as usize, w.blocks_per_row() as usize);
    let mut frame = vec![0u8; width * w.screen.height as usize];
    for (n, line) in log.lines().enumerate() {
        let bad = || StreamError::Write { line: n + 1, text: line.into() };
        let f: Vec<&str> = line.split_whitespace().collect();
        let [addr, we, data] = f[..] else { return Err(bad()) };
        let addr = usize::from_str_radix(addr, 16).map_err(|_| bad())?;
        let we = hex_bytes(we).ok_or_else(bad)?;
        let data = hex_bytes(data).ok_or_else(bad)?;
        let (y, bx) = (addr / bpr, addr % bpr);
        for lane in 0..p {
            let on = we.get(lane / 8).is_some_and(|b| b >> (lane % 8) & 1 == 1);
            let x = bx * p + lane;
            if on && x < width && y < w.screen.height as usize {
                frame[y * width + x] = data.get(lane).copied().unwrap_or(0);
            }
        }
    }
    Ok(frame)
}

/// The bytes the board sent on its serial line, from the bench's output.
pub fn sent(log: &str) -> Vec<u8> {
    log.lines().filter_map(|l| l.strip_prefix("board_tb: tx ")).filter_map(|h| u8::from_str_radix(h.trim(), 16).ok()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replay_puts_lanes_at_their_pixels() {
        let cfg = crate::config(8).unwrap();
        let w = Writer::new(cfg, crate::SCREEN).unwrap();
        // Block 41 = row 1, block 1 (x 8..15); lanes 0 and 7 enabled.
        let f = replay("29 81 0800000000000001\n", &w).unwrap();
        assert_eq!(f[320 + 8], 1);
        assert_eq!(f[320 + 15], 8);
        assert_eq!(f.iter().filter(|&&v| v != 0).count(), 2);
        assert!(replay("29 81\n", &w).is_err());
        assert_eq!(sent("board_tb: tx 5a\nother\nboard_tb: tx a5\n"), vec![0x5a, 0xa5]);
    }
}
