//! Parameters and number formats of SPEC §2, and the bit-exact pixel rule.
//!
//! Everything that depends on the configuration (widths of every port and internal
//! register) is derived here, so the golden model, the generator and the harness can
//! never disagree about a width.

use serde::{Deserialize, Serialize};
use std::fmt;

/// How a span is cut into segments (SPEC §1 "Video memory blocks").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum Align {
    /// The seed's scheme: the first segment starts at the span's first pixel.
    Span,
    /// Segments start on multiples of P; leading lanes of the first segment are masked.
    Screen,
}

impl Align {
    pub const ALL: [Align; 2] = [Align::Span, Align::Screen];

    pub fn name(self) -> &'static str {
        match self {
            Align::Span => "span",
            Align::Screen => "screen",
        }
    }
}

impl fmt::Display for Align {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Allowed ranges of SPEC §2.
pub const P_MAX: u32 = 256;
pub const FRAC_RANGE: std::ops::RangeInclusive<u32> = 4..=20;
pub const XBITS_RANGE: std::ops::RangeInclusive<u32> = 4..=16;
pub const DEFAULT_P: u32 = 8;
pub const DEFAULT_FRAC: u32 = 12;
pub const DEFAULT_XBITS: u32 = 12;

/// One configuration of the segment shader: SPEC §2's `p`, `F`, `XW` and `align`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Config {
    pub p: u32,
    pub frac: u32,
    pub xbits: u32,
    pub align: Align,
}

impl Default for Config {
    fn default() -> Self {
        Config { p: DEFAULT_P, frac: DEFAULT_FRAC, xbits: DEFAULT_XBITS, align: Align::Span }
    }
}

/// A configuration outside SPEC §2's ranges; the message names the parameter.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ConfigError {
    #[error("segment width p = {0} must be a power of two in 1..{P_MAX}")]
    P(u32),
    #[error("fraction bits F = {0} is outside {lo}..{hi}", lo = FRAC_RANGE.start(), hi = FRAC_RANGE.end())]
    Frac(u32),
    #[error("screen-x bits XW = {0} is outside {lo}..{hi}", lo = XBITS_RANGE.start(), hi = XBITS_RANGE.end())]
    Xbits(u32),
    /// A segment wider than the whole screen could never be filled.
    #[error("segment width p = {p} exceeds the screen width 2^XW = {w}", w = 1u32 << xbits)]
    WiderThanScreen { p: u32, xbits: u32 },
}

impl Config {
    /// A configuration checked against SPEC §2's ranges.
    pub fn new(p: u32, frac: u32, xbits: u32, align: Align) -> Result<Config, ConfigError> {
        check_p(p)?;
        if !FRAC_RANGE.contains(&frac) {
            return Err(ConfigError::Frac(frac));
        }
        if !XBITS_RANGE.contains(&xbits) {
            return Err(ConfigError::Xbits(xbits));
        }
        if p > 1 << xbits {
            return Err(ConfigError::WiderThanScreen { p, xbits });
        }
        Ok(Config { p, frac, xbits, align })
    }

    /// log2 P.
    pub fn log2p(&self) -> u32 {
        self.p.trailing_zeros()
    }
    /// Intensity width, UQ8.F.
    pub fn iw(&self) -> u32 {
        8 + self.frac
    }
    /// Increment width, signed, value dI / 2^F in [-256, 256).
    pub fn dw(&self) -> u32 {
        self.iw() + 1
    }
    /// Lane width of the BFPI output: holds every multiple 1..P of dI.
    pub fn mw(&self) -> u32 {
        self.dw() + self.log2p()
    }
    /// Width of the segment accumulator. `I0 + j*dI` for every `j < 2^XW` needs XW + DW
    /// signed bits; the BFPI lanes are added to it, so it is never narrower than them.
    pub fn aw(&self) -> u32 {
        (self.xbits + self.dw()).max(self.mw())
    }
    /// Largest span length the `in_len` port can carry (and the widest screen).
    pub fn max_len(&self) -> u32 {
        1 << self.xbits
    }
    /// Number of segments a span of `len` pixels starting at `x0` yields (SPEC §3).
    pub fn segment_count(&self, x0: u32, len: u32) -> u32 {
        if len == 0 {
            return 0;
        }
        let lead = match self.align {
            Align::Span => 0,
            Align::Screen => x0 % self.p,
        };
        (lead + len).div_ceil(self.p)
    }
}

/// P must be a power of two in 1..=256.
pub fn check_p(p: u32) -> Result<(), ConfigError> {
    if p == 0 || p > P_MAX || !p.is_power_of_two() {
        return Err(ConfigError::P(p));
    }
    Ok(())
}

/// The pixel rule of SPEC §2: `clamp((V + 2^(F-1)) >> F, 0, 255)` with a floor shift.
pub fn pixel_of(v: i64, frac: u32) -> u8 {
    ((v + (1i64 << (frac - 1))) >> frac).clamp(0, 255) as u8
}

/// One span of SPEC §3: `in_len = len` pixels from `x0`, first intensity `i0` (UQ8.F),
/// increment `di` (signed, DW bits).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Span {
    pub x0: u32,
    pub len: u32,
    pub i0: u32,
    pub di: i32,
}

impl Span {
    /// `V_j = I0 + j*dI`, exact.
    pub fn value(&self, j: u32) -> i64 {
        self.i0 as i64 + j as i64 * self.di as i64
    }
    /// Output pixel `j` of the span by the pixel rule.
    pub fn pixel(&self, j: u32, frac: u32) -> u8 {
        pixel_of(self.value(j), frac)
    }
    /// Whether the span fits the ports of `cfg` and the screen: everything the RTL can take.
    pub fn check(&self, cfg: &Config) -> Result<(), SpanError> {
        let max = cfg.max_len();
        if self.len > max {
            return Err(SpanError::Len { len: self.len, max });
        }
        if self.x0 as u64 + self.len as u64 > max as u64 || self.x0 >= max {
            return Err(SpanError::Beyond { x0: self.x0, len: self.len, max });
        }
        if self.i0 >= 1 << cfg.iw() {
            return Err(SpanError::I0 { i0: self.i0, frac: cfg.frac });
        }
        let half = 1i64 << (cfg.dw() - 1);
        if (self.di as i64) < -half || self.di as i64 >= half {
            return Err(SpanError::Di { di: self.di, bits: cfg.dw() });
        }
        Ok(())
    }
}

/// A span the ports of a configuration cannot carry ([`Span::check`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum SpanError {
    #[error("span length {len} exceeds 2^XW = {max}")]
    Len { len: u32, max: u32 },
    #[error("span x0 = {x0} + len = {len} reaches beyond the screen width 2^XW = {max}")]
    Beyond { x0: u32, len: u32, max: u32 },
    #[error("span I0 = {i0} does not fit UQ8.{frac}")]
    I0 { i0: u32, frac: u32 },
    #[error("span dI = {di} does not fit {bits} signed bits")]
    Di { di: i32, bits: u32 },
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn widths_of_the_default_configuration() {
        let c = Config::default();
        assert_eq!((c.iw(), c.dw(), c.mw(), c.aw()), (20, 21, 24, 33));
    }

    #[test]
    fn pixel_rule_rounds_half_up_and_clamps() {
        let f = 12;
        assert_eq!(pixel_of(0, f), 0);
        assert_eq!(pixel_of((1 << 11) - 1, f), 0);
        assert_eq!(pixel_of(1 << 11, f), 1);
        assert_eq!(pixel_of(255 << 12, f), 255);
        assert_eq!(pixel_of((255 << 12) + (1 << 11) - 1, f), 255);
        assert_eq!(pixel_of(256 << 12, f), 255);
        assert_eq!(pixel_of(i64::from(i32::MAX) << 2, f), 255);
        // Negative values floor toward -inf before clamping: -0.5 rounds to 0, below that clamps.
        assert_eq!(pixel_of(-(1 << 11), f), 0);
        assert_eq!(pixel_of(-(1 << 11) - 1, f), 0);
        assert_eq!(pixel_of(-(300 << 12), f), 0);
    }

    #[test]
    fn largest_span_has_no_wrap() {
        let c = Config::default();
        let s = Span { x0: 0, len: c.max_len(), i0: (1 << c.iw()) - 1, di: (1 << (c.dw() - 1)) - 1 };
        s.check(&c).unwrap();
        assert_eq!(Span { len: c.max_len() + 1, ..s }.check(&c), Err(SpanError::Len { len: c.max_len() + 1, max: c.max_len() }));
        assert_eq!(Span { x0: 1, ..s }.check(&c), Err(SpanError::Beyond { x0: 1, len: c.max_len(), max: c.max_len() }));
        assert_eq!(Span { i0: 1 << c.iw(), ..s }.check(&c), Err(SpanError::I0 { i0: 1 << c.iw(), frac: c.frac }));
        assert_eq!(Span { di: 1 << (c.dw() - 1), ..s }.check(&c), Err(SpanError::Di { di: 1 << (c.dw() - 1), bits: c.dw() }));
        let v = s.value(s.len - 1);
        assert!(v < 1i64 << (c.aw() - 1), "accumulator width must hold {v}");
        let s = Span { di: -(1 << (c.dw() - 1)), i0: 0, ..s };
        assert!(s.value(s.len - 1) >= -(1i64 << (c.aw() - 1)));
        assert_eq!(s.pixel(s.len - 1, c.frac), 0);
    }

    #[test]
    fn segment_counts() {
        let span = Config::default();
        let screen = Config { align: Align::Screen, ..span };
        assert_eq!(span.segment_count(3, 0), 0);
        assert_eq!(span.segment_count(3, 8), 1);
        assert_eq!(span.segment_count(3, 9), 2);
        assert_eq!(screen.segment_count(3, 5), 1);
        assert_eq!(screen.segment_count(3, 6), 2);
        assert_eq!(screen.segment_count(8, 8), 1);
    }

    #[test]
    fn rejects_bad_configurations() {
        assert_eq!(Config::new(3, 12, 12, Align::Span), Err(ConfigError::P(3)));
        assert_eq!(Config::new(512, 12, 12, Align::Span), Err(ConfigError::P(512)));
        assert_eq!(Config::new(0, 12, 12, Align::Span), Err(ConfigError::P(0)));
        assert_eq!(Config::new(8, 3, 12, Align::Span), Err(ConfigError::Frac(3)));
        assert_eq!(Config::new(8, 12, 17, Align::Span), Err(ConfigError::Xbits(17)));
        assert!(Config::new(256, 20, 16, Align::Screen).is_ok());
        assert_eq!(Config::new(32, 12, 4, Align::Span), Err(ConfigError::WiderThanScreen { p: 32, xbits: 4 }));
        assert!(Config::new(16, 12, 4, Align::Screen).is_ok());
        // The messages the CLIs print name the parameter and its range.
        assert_eq!(ConfigError::P(3).to_string(), "segment width p = 3 must be a power of two in 1..256");
        assert_eq!(ConfigError::Frac(3).to_string(), "fraction bits F = 3 is outside 4..20");
        assert_eq!(ConfigError::WiderThanScreen { p: 32, xbits: 4 }.to_string(), "segment width p = 32 exceeds the screen width 2^XW = 16");
    }
}
