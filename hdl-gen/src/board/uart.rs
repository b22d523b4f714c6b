//! The board's UART wire format (docs/spec.md, "Board serial packets"; docs/board.md) and the
//! receiver's generated half: the byte receiver `board_uart_rx`, the status sender
//! `board_uart_tx`, and the packet check's equations for `board_draw`'s deframer.
//!
//! A packet is [`LEN`] bytes: the sync `A5 5A`, a command byte, 27 payload bytes, and the
//! CRC-16/IBM-3740 of the command and payload, high byte first (so the CRC of bytes 2..32 is 0).
//! The receiver looks at the last [`LEN`] bytes it received after every byte: a window that
//! starts with the sync and whose CRC is zero is a packet. It has no state to lose, so garbage,
//! a truncated packet or a framing error cost only the packets they touch; the next whole packet
//! is found at whatever byte it starts.

use crate::verilog::{lit, reg, set, wire, Item, Module, Port, Stmt};
use crate::widths::bits_for;
use golden::frontend::FixedTriangle;

pub const LEN: usize = 32;
pub const SYNC: [u8; 2] = [0xA5, 0x5A];
/// Commands: draw the payload's triangle; clear the frame buffer (once what came before is
/// drawn); send the status record back.
pub const TRIANGLE: u8 = b'T';
pub const CLEAR: u8 = b'C';
pub const STATUS: u8 = b'S';
/// The status record's start (the sync reversed, so an echo of the host's bytes is no record).
pub const STATUS_SYNC: [u8; 2] = [0x5A, 0xA5];
/// The status record: sync, `S`, five little-endian u16 counters, their XOR.
pub const STATUS_LEN: usize = 14;
/// Bytes of one vertex field: x and y signed in 1/256 pixel, i unsigned UQ8.F.
pub const FIELD: usize = 3;
/// The CRC (polynomial 0x1021, initial 0xFFFF, not reflected, no final XOR): every error of 1
/// to 3 bits and every burst up to 16 bits in a packet is caught.
pub const CRC: crc::Crc<u16> = crc::Crc::<u16>::new(&crc::CRC_16_IBM_3740);
/// The FT231X's highest rate: 3 MBd (its 3 MHz baud clock divided by 1).
pub const FT231X_MAX_BAUD: u32 = 3_000_000;
/// The rates a Linux serial port is set to (termios' B constants) up to the FT231X's highest.
pub const TTY_BAUDS: [u32; 16] =
    [9600, 19200, 38400, 57600, 115200, 230400, 460800, 500000, 576000, 921600, 1000000, 1152000, 1500000, 2000000, 2500000, 3000000];
/// The rate the board is built for unless told otherwise: the FT231X's highest.
pub const DEFAULT_BAUD: u32 = FT231X_MAX_BAUD;
/// Largest mismatch between the baud and the drawing clock's whole divider, in parts per
/// thousand: 1 % drifts a tenth of a bit over a frame of 10 bits.
const MAX_ERROR_PERMILLE: u32 = 10;

#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum WireError {
    #[error("{0} baud: the board's FT231X takes at most {FT231X_MAX_BAUD}")]
    BaudTooHigh(u32),
    #[error("{0} baud: not a rate a serial port is set to ({list})", list = TTY_BAUDS.map(|b| b.to_string()).join(", "))]
    BaudNotStandard(u32),
    #[error("{baud} baud: {div} drawing clocks a bit is {permille}/1000 off (at most {MAX_ERROR_PERMILLE})")]
    BaudDivider { baud: u32, div: u32, permille: u32 },
    #[error("triangle {triangle}: a vertex does not fit the packet's 24-bit fields")]
    Field { triangle: usize },
}

/// The receiver's clocks a bit at `clock_hz` for `baud`, if the baud is one a port is set to,
/// the FT231X takes, and the whole divider matches within 1 %.
pub fn divider(baud: u32, clock_hz: f64) -> Result<u32, WireError> {
    if baud > FT231X_MAX_BAUD {
        return Err(WireError::BaudTooHigh(baud));
    }
    if !TTY_BAUDS.contains(&baud) {
        return Err(WireError::BaudNotStandard(baud));
    }
    let exact = clock_hz / baud as f64;
    let div = exact.round() as u32;
    let permille = ((div as f64 - exact).abs() / exact * 1000.0).round() as u32;
    if permille > MAX_ERROR_PERMILLE {
        return Err(WireError::BaudDivider { baud, div, permille });
    }
    Ok(div)
}

/// A command the board receives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Command {
    Triangle(FixedTriangle),
    Clear,
    Status,
}

fn field(v: i64, signed: bool) -> Option<[u8; 3]> {
    let ok = if signed { (-(1 << 23)..1 << 23).contains(&v) } else { (0..1 << 24).contains(&v) };
    ok.then_some([v as u8, (v >> 8) as u8, (v >> 16) as u8])
}

/// The packet of a command; `None` when a vertex does not fit the 24-bit fields.
pub fn encode(cmd: &Command) -> Option<[u8; LEN]> {
    let mut p = [0u8; LEN];
    p[..2].copy_from_slice(&SYNC);
    match cmd {
        Command::Triangle(t) => {
            p[2] = TRIANGLE;
            for v in 0..3 {
                let at = 3 + 9 * v;
                p[at..at + 3].copy_from_slice(&field(t.x[v], true)?);
                p[at + 3..at + 6].copy_from_slice(&field(t.y[v], true)?);
                p[at + 6..at + 9].copy_from_slice(&field(t.i[v] as i64, false)?);
            }
        }
        Command::Clear => p[2] = CLEAR,
        Command::Status => p[2] = STATUS,
    }
    let crc = CRC.checksum(&p[2..LEN - 2]);
    p[LEN - 2..].copy_from_slice(&crc.to_be_bytes());
    Some(p)
}

/// What `board send` writes: a clear, then every triangle in order.
pub fn stream(tris: &[FixedTriangle]) -> Result<Vec<u8>, WireError> {
    let mut out = Vec::with_capacity((tris.len() + 1) * LEN);
    out.extend(encode(&Command::Clear).expect("a clear fits"));
    for (k, t) in tris.iter().enumerate() {
        out.extend(encode(&Command::Triangle(*t)).ok_or(WireError::Field { triangle: k + 1 })?);
    }
    Ok(out)
}

fn sext24(b: &[u8]) -> i64 {
    let v = b[0] as i64 | (b[1] as i64) << 8 | (b[2] as i64) << 16;
    (v << 40) >> 40
}

/// The window's verdict after a byte.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// Not a packet start, or fewer than [`LEN`] bytes since the last packet or reset.
    Nothing,
    /// The sync, but the CRC or the command is wrong.
    Bad,
    Packet(Command),
}

/// The receiver's deframer as the RTL has it: the last [`LEN`] bytes, and how many came since the
/// last packet (a packet's bytes are not looked at again).
#[derive(Debug, Clone, Default)]
pub struct Deframer {
    window: std::collections::VecDeque<u8>,
}

impl Deframer {
    pub fn push(&mut self, byte: u8) -> Verdict {
        if self.window.len() == LEN {
            self.window.pop_front();
        }
        self.window.push_back(byte);
        if self.window.len() < LEN || self.window[0] != SYNC[0] || self.window[1] != SYNC[1] {
            return Verdict::Nothing;
        }
        let p: Vec<u8> = self.window.iter().copied().collect();
        if CRC.checksum(&p[2..]) != 0 {
            return Verdict::Bad;
        }
        let cmd = match p[2] {
            TRIANGLE => {
                let mut t = FixedTriangle { x: [0; 3], y: [0; 3], i: [0; 3] };
                for v in 0..3 {
                    let at = 3 + 9 * v;
                    t.x[v] = sext24(&p[at..]);
                    t.y[v] = sext24(&p[at + 3..]);
                    t.i[v] = (p[at + 6] as u32) | (p[at + 7] as u32) << 8 | (p[at + 8] as u32) << 16;
                }
                Command::Triangle(t)
            }
            CLEAR => Command::Clear,
            STATUS => Command::Status,
            _ => return Verdict::Bad,
        };
        self.window.clear();
        Verdict::Packet(cmd)
    }
}

/// Every command in a byte stream, and how many windows had the sync but failed the check.
pub fn decode(bytes: &[u8]) -> (Vec<Command>, usize) {
    let mut d = Deframer::default();
    let (mut cmds, mut bad) = (Vec::new(), 0);
    for &b in bytes {
        match d.push(b) {
            Verdict::Packet(c) => cmds.push(c),
            Verdict::Bad => bad += 1,
            Verdict::Nothing => {}
        }
    }
    (cmds, bad)
}

/// The status record's counters, in its order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Status {
    /// Packets taken (triangle, clear or status).
    pub packets: u16,
    /// Windows with the sync that failed the CRC or named no command.
    pub bad: u16,
    /// Bytes whose stop bit was low.
    pub framing: u16,
    /// Triangles dropped on receipt: a field wider than the front-end's port, or the queue full.
    pub dropped: u16,
    /// Triangles the front-end dropped for leaving its guard band.
    pub guard: u16,
}

/// Reads a status record from the start of `bytes`.
pub fn status(bytes: &[u8]) -> Option<Status> {
    let r = bytes.get(..STATUS_LEN)?;
    if r[..2] != STATUS_SYNC || r[2] != STATUS || r[2..STATUS_LEN - 1].iter().fold(0, |a, b| a ^ b) != r[STATUS_LEN - 1] {
        return None;
    }
    let u = |k: usize| u16::from_le_bytes([r[3 + 2 * k], r[4 + 2 * k]]);
    Some(Status { packets: u(0), bad: u(1), framing: u(2), dropped: u(3), guard: u(4) })
}

/// The check as the RTL computes it, from the window `win` (`win[255:248]` the oldest byte):
/// bit j of the CRC over bytes 2..32 is the parity of `win[239:0] & masks[j]`, XOR `constant`
/// bit j. The CRC is affine in its input bits: its value on one set bit, less its value on none.
pub fn check_equations() -> (Vec<u128>, Vec<u128>, u16) {
    let n = LEN - 2;
    let zero = CRC.checksum(&vec![0u8; n]);
    let (mut hi, mut lo) = (vec![0u128; 16], vec![0u128; 16]);
    for j in 0..n {
        for k in 0..8 {
            let mut bytes = vec![0u8; n];
            bytes[j] = 1 << k;
            let c = CRC.checksum(&bytes) ^ zero;
            // Packet byte 2 + j sits at win[8 * (LEN - 1 - (2 + j)) + k].
            let bit = 8 * (LEN - 3 - j) + k;
            for (s, (h, l)) in hi.iter_mut().zip(lo.iter_mut()).enumerate() {
                if c >> s & 1 == 1 {
                    if bit >= 128 {
                        *h |= 1 << (bit - 128);
                    } else {
                        *l |= 1 << bit;
                    }
                }
            }
        }
    }
    (hi, lo, zero)
}

/// The byte receiver's and the status sender's module names.
pub const RX: &str = "board_uart_rx";
pub const TX: &str = "board_uart_tx";

/// `board_uart_rx`: 8N1 bytes at `div` clocks a bit, sampled at each bit's middle. A stop bit
/// found low is a framing error (`ferr`), after which the line must be seen high before the next
/// start bit is looked for; a start bit gone high by its middle was a glitch and is ignored. From
/// any state, the next byte that starts on an idle line is received.
pub fn rx_module(div: u32) -> Module {
    assert!(div >= 4, "{div} clocks a bit");
    let cw = bits_for(div as u64 - 1);
    let header = vec![
        format!("{RX} — the board's UART receiver: 8 data bits, no parity, 1 stop bit, {div} clocks a bit."),
        "Generated by segshade hdl-gen (board); do not edit.".into(),
        String::new(),
        "rx passes two flops (it is asynchronous). A low level on an idle line starts a byte; each bit is sampled at".into(),
        "its middle. A start bit high at its middle was a glitch: ignored. A stop bit low is a framing error: the byte".into(),
        "is dropped, ferr pulses, and the line must be high again before the next start bit (a break ends first).".into(),
    ];
    let ports = vec![
        Port::input("clk", 1, "", "the drawing clock, rising edge"),
        Port::input("rst", 1, "", "synchronous, active high: abandons a byte, then waits for an idle line"),
        Port::input("rx", 1, "", "the serial line, asynchronous, idle high"),
        Port::output("valid", 1, "", "a byte is in data (one clock)").reg(),
        Port::output("data", 8, "byte", "the last byte received, bit 0 first on the line").reg(),
        Port::output("ferr", 1, "", "a byte's stop bit was low (one clock)").reg(),
    ];
    let body = vec![
        Item::Localparam { name: "DIV_M1".into(), width: cw, value: lit(cw, div as u64 - 1) },
        Item::Localparam { name: "HALF_M1".into(), width: cw, value: lit(cw, (div / 2 - 1) as u64) },
        reg("rs", 2),
        reg("busy", 1),
        reg("wait_idle", 1),
        reg("cnt", cw),
        reg("nbit", 4),
        Item::Always(vec![
            set("rs", "{rs[0], rx}"),
            set("valid", "1'b0"),
            set("ferr", "1'b0"),
            Stmt::If(
                "rst".into(),
                vec![set("busy", "1'b0"), set("wait_idle", "1'b1")],
                vec![Stmt::If(
                    "!busy".into(),
                    vec![Stmt::If(
                        "wait_idle".into(),
                        vec![Stmt::If("rs[1]".into(), vec![set("wait_idle", "1'b0")], vec![])],
                        vec![Stmt::If("!rs[1]".into(), vec![set("busy", "1'b1"), set("cnt", "HALF_M1"), set("nbit", "4'd0")], vec![])],
                    )],
                    vec![Stmt::If(
                        format!("cnt != {}", lit(cw, 0)),
                        vec![set("cnt", format!("cnt - {}", lit(cw, 1)))],
                        vec![
                            set("cnt", "DIV_M1"),
                            set("nbit", "nbit + 4'd1"),
                            Stmt::If(
                                "nbit == 4'd0".into(),
                                vec![Stmt::If("rs[1]".into(), vec![set("busy", "1'b0")], vec![])],
                                vec![Stmt::If(
                                    "nbit == 4'd9".into(),
                                    vec![
                                        set("busy", "1'b0"),
                                        Stmt::If(
                                            "rs[1]".into(),
                                            vec![set("valid", "1'b1")],
                                            vec![set("ferr", "1'b1"), set("wait_idle", "1'b1")],
                                        ),
                                    ],
                                    vec![set("data", "{rs[1], data[7:1]}")],
                                )],
                            ),
                        ],
                    )],
                )],
            ),
        ]),
    ];
    Module { name: RX.into(), header, params: vec![], ports, body }
}

/// `board_uart_tx`: sends the `bytes` bytes of `data` (byte 0 in the low bits, first), 8N1 at
/// `div` clocks a bit, when `send` pulses and it is not busy.
pub fn tx_module(div: u32, bytes: usize) -> Module {
    let cw = bits_for(div as u64 - 1);
    // Every byte framed by its start and stop bits, and one idle bit after the last, so the
    // last stop bit lasts a whole bit before the next record may start.
    let frame_bits = 10 * bytes as u32 + 1;
    let lw = bits_for(frame_bits as u64);
    let mut frame: Vec<String> = vec!["1'b1".into()];
    for b in (0..bytes).rev() {
        frame.push(format!("1'b1, data[{}:{}], 1'b0", 8 * b + 7, 8 * b));
    }
    let header = vec![
        format!("{TX} — the board's UART sender: {bytes}-byte records, 8N1, {div} clocks a bit."),
        "Generated by segshade hdl-gen (board); do not edit.".into(),
    ];
    let ports = vec![
        Port::input("clk", 1, "", "the drawing clock, rising edge"),
        Port::input("rst", 1, "", "synchronous, active high: abandons a record, the line idles high"),
        Port::input("send", 1, "", "start sending data (ignored while busy)"),
        Port::input("data", 8 * bytes as u32, "bytes", "the record, byte 0 in bits 7:0, sent first"),
        Port::output("tx", 1, "", "the serial line, idle high").reg(),
    ];
    let body = vec![
        Item::Localparam { name: "DIV_M1".into(), width: cw, value: lit(cw, div as u64 - 1) },
        reg("sh", frame_bits),
        reg("left", lw),
        reg("cnt", cw),
        wire("busy", 1, format!("left != {}", lit(lw, 0))),
        Item::Always(vec![Stmt::If(
            "rst".into(),
            vec![set("left", lit(lw, 0)), set("tx", "1'b1")],
            vec![Stmt::If(
                "!busy".into(),
                vec![
                    set("tx", "1'b1"),
                    Stmt::If(
                        "send".into(),
                        vec![
                            set("sh", format!("{{{}}}", frame.join(", "))),
                            set("left", lit(lw, frame_bits as u64)),
                            set("cnt", lit(cw, 0)),
                        ],
                        vec![],
                    ),
                ],
                vec![Stmt::If(
                    format!("cnt != {}", lit(cw, 0)),
                    vec![set("cnt", format!("cnt - {}", lit(cw, 1)))],
                    vec![
                        set("tx", "sh[0]"),
                        set("sh", format!("{{1'b1, sh[{}:1]}}", frame_bits - 1)),
                        set("left", format!("left - {}", lit(lw, 1))),
                        set("cnt", "DIV_M1"),
                    ],
                )],
            )],
        )]),
    ];
    Module { name: TX.into(), header, params: vec![], ports, body }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(k: i64) -> FixedTriangle {
        FixedTriangle { x: [k, -300 * k, 81919], y: [5, 2 * k, -1], i: [0, 1 << 19, (1 << 20) - 1] }
    }

    #[test]
    fn packets_round_trip_and_resynchronize_after_garbage() {
        let tris: Vec<FixedTriangle> = (0..4).map(tri).collect();
        let s = stream(&tris).unwrap();
        assert_eq!(s.len(), 5 * LEN);
        let (cmds, bad) = decode(&s);
        assert_eq!(bad, 0);
        assert_eq!(cmds[0], Command::Clear);
        assert_eq!(cmds[1..], tris.iter().map(|t| Command::Triangle(*t)).collect::<Vec<_>>()[..]);
        // Garbage (with a false sync in it), a truncated packet, a flipped bit: each costs only
        // its own packet; the next whole one is found.
        let mut noisy = vec![0xA5, 0x5A, 0x13, 0xA5];
        noisy.extend(&s[LEN..LEN + 17]);
        noisy.extend(&s[2 * LEN..3 * LEN]);
        let mut flipped = s[3 * LEN..4 * LEN].to_vec();
        flipped[9] ^= 0x10;
        noisy.extend(flipped);
        noisy.extend(&s[4 * LEN..]);
        let (cmds, bad) = decode(&noisy);
        assert_eq!(cmds, vec![Command::Triangle(tris[1]), Command::Triangle(tris[3])]);
        assert!(bad >= 2, "{bad}");
        // Negative control: without the CRC the flipped packet would pass as another triangle.
        let mut d = Deframer::default();
        let got: Vec<_> = s[3 * LEN..4 * LEN].iter().map(|&b| d.push(b)).collect();
        assert_eq!(got.last(), Some(&Verdict::Packet(Command::Triangle(tris[2]))));
    }

    #[test]
    fn every_single_and_double_bit_error_is_caught() {
        let p = encode(&Command::Triangle(tri(7))).unwrap();
        let bits = 8 * (LEN - 2);
        for a in 0..bits {
            for b in a..bits {
                let mut q = p;
                q[2 + a / 8] ^= 1 << (a % 8);
                if b != a {
                    q[2 + b / 8] ^= 1 << (b % 8);
                }
                assert_ne!(CRC.checksum(&q[2..]), 0, "bits {a} and {b}");
            }
        }
        assert_eq!(CRC.checksum(&p[2..]), 0, "an intact packet checks to 0");
    }

    #[test]
    fn check_equations_are_the_crc() {
        let (hi, lo, zero) = check_equations();
        let parity = |p: &[u8]| -> u16 {
            let mut win = [0u128; 2];
            for (j, &b) in p[2..].iter().enumerate() {
                let bit = 8 * (LEN - 3 - j);
                for k in 0..8 {
                    if b >> k & 1 == 1 {
                        let at = bit + k;
                        win[(at >= 128) as usize] |= 1 << (at % 128);
                    }
                }
            }
            (0..16).fold(0u16, |a, s| a | ((((win[1] & hi[s]).count_ones() + (win[0] & lo[s]).count_ones()) & 1) as u16) << s) ^ zero
        };
        let p = encode(&Command::Triangle(tri(3))).unwrap();
        assert_eq!(parity(&p), 0);
        let mut q = p;
        q[20] ^= 4;
        assert_eq!(parity(&q), CRC.checksum(&q[2..]));
        assert_ne!(parity(&q), 0);
    }

    #[test]
    fn bauds() {
        let draw = 625e6 / 16.0;
        assert_eq!(divider(3_000_000, draw), Ok(13));
        assert_eq!(divider(115_200, draw), Ok(339));
        assert!(matches!(divider(4_000_000, draw), Err(WireError::BaudTooHigh(_))));
        assert!(matches!(divider(12345, draw), Err(WireError::BaudNotStandard(_))));
        assert!(matches!(divider(2_000_000, draw), Err(WireError::BaudDivider { div: 20, .. })));
    }

    #[test]
    fn status_record() {
        let mut r = vec![0x5A, 0xA5, b'S', 3, 0, 1, 0, 0, 2, 0, 0, 9, 0];
        r.push(r[2..].iter().fold(0, |a, b| a ^ b));
        assert_eq!(status(&r), Some(Status { packets: 3, bad: 1, framing: 512, dropped: 0, guard: 9 }));
        r[5] ^= 1;
        assert_eq!(status(&r), None);
    }
}
