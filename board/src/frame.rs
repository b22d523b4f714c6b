//! One DVI frame of the board: 640x480 at 60 Hz, 800 x 525 clocks, each frame-buffer pixel
//! shown as 2 x 2. Cut from the recorded symbols at the first active pixel of line 0, checked
//! clock by clock (video where the picture is, control symbols with the right syncs elsewhere,
//! grey on all three channels, every 2 x 2 alike) and decoded into the 320 x 240 frame.

use crate::tmds::{decode, Symbol};

pub const H_TOTAL: usize = 800;
pub const V_TOTAL: usize = 525;
pub const H_ACTIVE: usize = 640;
pub const V_ACTIVE: usize = 480;
/// Sync pulses (both negative: the control bit is 0 inside them).
pub const H_SYNC: std::ops::Range<usize> = 656..752;
pub const V_SYNC: std::ops::Range<usize> = 490..492;
pub const CLOCKS: usize = H_TOTAL * V_TOTAL;
pub const WIDTH: usize = H_ACTIVE / 2;
pub const HEIGHT: usize = V_ACTIVE / 2;

/// One pixel clock: the symbols of channels 0, 1, 2.
pub type Clock = [u16; 3];

#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum FrameError {
    #[error("line {line} of the recording: {text:?} is not three hexadecimal symbols")]
    Record { line: usize, text: String },
    #[error("no vertical sync followed by video in {0} recorded clocks")]
    NoFrame(usize),
    #[error("the frame starting at clock {start} needs {CLOCKS} clocks, the recording has {have}")]
    Short { start: usize, have: usize },
    #[error("({x}, {y}): channel {channel} sends {what} {symbol:#05x} where {want} belongs")]
    Period { x: usize, y: usize, channel: usize, symbol: u16, what: &'static str, want: &'static str },
    #[error("({x}, {y}): channel {channel}'s control bits (c0, c1) = ({c0}, {c1}), want ({w0}, {w1})")]
    Sync { x: usize, y: usize, channel: usize, c0: bool, c1: bool, w0: bool, w1: bool },
    #[error("({x}, {y}): not grey: channels send {0:?}", .values)]
    NotGrey { x: usize, y: usize, values: [u8; 3] },
    #[error("({x}, {y}): {got} differs from {want} at ({fx}, {fy}), the same frame-buffer pixel")]
    NotDoubled { x: usize, y: usize, fx: usize, fy: usize, got: u8, want: u8 },
}

/// The recording of `board_tb`: a line "c0 c1 c2" (hex) per clock.
pub fn parse_recording(text: &str) -> Result<Vec<Clock>, FrameError> {
    text.lines()
        .enumerate()
        .map(|(n, line)| {
            let bad = || FrameError::Record { line: n + 1, text: line.to_string() };
            let v: Vec<u16> = line.split_whitespace().map(|s| u16::from_str_radix(s, 16)).collect::<Result<_, _>>().map_err(|_| bad())?;
            match v[..] {
                [a, b, c] if a < 1024 && b < 1024 && c < 1024 => Ok([a, b, c]),
                _ => Err(bad()),
            }
        })
        .collect()
}

/// The clock of the first active pixel of line 0: the first video symbol on channel 0 after a
/// clock inside the vertical sync pulse, as a monitor finds it.
pub fn frame_start(clocks: &[Clock]) -> Result<usize, FrameError> {
    let in_vsync = clocks.iter().position(|c| matches!(decode(c[0]), Symbol::Control { c1: false, .. }));
    let start = in_vsync.and_then(|v| clocks[v..].iter().position(|c| matches!(decode(c[0]), Symbol::Data(_))).map(|d| v + d));
    let start = start.ok_or(FrameError::NoFrame(clocks.len()))?;
    if clocks.len() - start < CLOCKS {
        return Err(FrameError::Short { start, have: clocks.len() - start });
    }
    Ok(start)
}

/// `tmds.bin`: three little-endian u16 a clock.
pub fn tmds_bin(frame: &[Clock]) -> Vec<u8> {
    frame.iter().flat_map(|c| c.iter().flat_map(|s| s.to_le_bytes())).collect()
}

/// Checks one frame (`CLOCKS` clocks from the first active pixel of line 0) and decodes it into
/// the frame buffer's `WIDTH` x `HEIGHT` grey pixels, row-major.
pub fn decode_frame(frame: &[Clock]) -> Result<Vec<u8>, FrameError> {
    assert_eq!(frame.len(), CLOCKS, "decode_frame takes one frame");
    let mut out = vec![0u8; WIDTH * HEIGHT];
    for y in 0..V_TOTAL {
        for x in 0..H_TOTAL {
            let clock = frame[y * H_TOTAL + x];
            let sym = clock.map(decode);
            if x < H_ACTIVE && y < V_ACTIVE {
                let mut values = [0u8; 3];
                for (channel, s) in sym.iter().enumerate() {
                    match *s {
                        Symbol::Data(v) => values[channel] = v,
                        Symbol::Control { .. } => {
                            return Err(FrameError::Period {
                                x,
                                y,
                                channel,
                                symbol: clock[channel],
                                what: "a control symbol",
                                want: "video",
                            })
                        }
                    }
                }
                if values[1] != values[0] || values[2] != values[0] {
                    return Err(FrameError::NotGrey { x, y, values });
                }
                let (fx, fy) = (x / 2, y / 2);
                let at = &mut out[fy * WIDTH + fx];
                if x % 2 == 0 && y % 2 == 0 {
                    *at = values[0];
                } else if *at != values[0] {
                    return Err(FrameError::NotDoubled { x, y, fx: 2 * fx, fy: 2 * fy, got: values[0], want: *at });
                }
            } else {
                for (channel, s) in sym.iter().enumerate() {
                    let (w0, w1) = if channel == 0 { (!H_SYNC.contains(&x), !V_SYNC.contains(&y)) } else { (false, false) };
                    match *s {
                        Symbol::Control { c0, c1 } if (c0, c1) == (w0, w1) => {}
                        Symbol::Control { c0, c1 } => return Err(FrameError::Sync { x, y, channel, c0, c1, w0, w1 }),
                        Symbol::Data(_) => {
                            return Err(FrameError::Period {
                                x,
                                y,
                                channel,
                                symbol: clock[channel],
                                what: "video",
                                want: "a control symbol",
                            })
                        }
                    }
                }
            }
        }
    }
    Ok(out)
}
