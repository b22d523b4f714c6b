//! The bit-exact specular unit: one span in, its pixels out, stage by stage as the RTL computes
//! them (the datapath and every rounding: the `specular` module's comment).

use super::contract::NK_DEPTH;
use super::plan::SpecularPlan;
use crate::rom::Rom;
use serde::{Deserialize, Serialize};

/// One span as the unit's input port carries it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct SpecularSpan {
    /// UQ8.8
    pub c: u16,
    /// 10-bit port; valid 1..=1000
    pub n: u16,
    /// sQ3.28 radians, `-lambda`
    pub theta0: i32,
    /// sQ3.28 radians per pixel, `gamma / l`
    pub dtheta: i32,
    /// pixels
    pub len: u32,
}

/// One output pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SpecPixel {
    pub spec: u16,
    pub err: bool,
    pub last: bool,
}

/// `theta_j` as the 32-bit accumulator holds it: `theta0 + j*dtheta` modulo 2^32.
///
/// The register is exactly 32 bits, so a span whose true `theta_j` leaves
/// [-8, 8) rad wraps around (two's complement) and its pixels are garbage. The set-up
/// never sends such a span ([`span_overflows`] checks it); the model wraps the way the
/// register does so that RTL and model still agree bit for bit if one is sent anyway.
pub fn theta_at(theta0: i32, dtheta: i32, j: u32) -> i32 {
    theta0.wrapping_add((j as i64 * dtheta as i64) as i32)
}

/// Whether some `theta_j`, `j < len`, leaves the 32-bit range (the accumulation is linear,
/// so its two ends decide).
pub fn span_overflows(theta0: i32, dtheta: i32, len: u32) -> bool {
    if len == 0 {
        return false;
    }
    let end = theta0 as i64 + (len as i64 - 1) * dtheta as i64;
    end < i32::MIN as i64 || end > i32::MAX as i64
}

/// The specular unit: its plan plus the two ROM images, computed once.
#[derive(Clone, Debug)]
pub struct SpecularUnit {
    plan: SpecularPlan,
    brdf: Rom,
    nk: Rom,
}

impl Default for SpecularUnit {
    fn default() -> Self {
        SpecularUnit::new(SpecularPlan::patent())
    }
}

impl SpecularUnit {
    pub fn new(plan: SpecularPlan) -> SpecularUnit {
        let brdf = plan.brdf_rom();
        let nk = plan.nk_rom();
        SpecularUnit { plan, brdf, nk }
    }

    pub fn plan(&self) -> &SpecularPlan {
        &self.plan
    }
    pub fn brdf_rom(&self) -> &Rom {
        &self.brdf
    }
    pub fn nk_rom(&self) -> &Rom {
        &self.nk
    }

    /// Pixel `j` of a span: `(out_spec, out_err)`.
    pub fn pixel(&self, c: u16, n: u16, theta0: i32, dtheta: i32, j: u32) -> (u16, bool) {
        self.pixel_at(c, n, theta_at(theta0, dtheta, j))
    }

    /// The datapath for one accumulator value, stage by stage as the RTL computes it.
    pub fn pixel_at(&self, c: u16, n: u16, theta: i32) -> (u16, bool) {
        let p = &self.plan;
        // Stage 1: |theta| (exact, 2^31 included) with the bits below 2^-20 rad dropped,
        // and the n-table read. An n the 10-bit port cannot carry is invalid too.
        let mag = (theta.unsigned_abs() >> p.theta_drop) as u64;
        let nk = if (n as usize) < NK_DEPTH { self.nk.words[n as usize] } else { 0 };
        let m = nk & ((1u64 << p.nk_mant_bits) - 1);
        let sel = (nk >> p.nk_mant_bits) as usize;
        // Stage 2: the one argument multiplier.
        if m == 0 {
            return (0, true);
        }
        let prod = mag * m;
        // Stage 3: index, range cut, BRDF read.
        let t = &p.tables[sel];
        let idx = prod >> t.shift;
        if idx >= t.len as u64 {
            return (0, false);
        }
        let w = self.brdf.words[(t.base as u64 + idx) as usize];
        // Stage 4: C * (w + 1) / 2^W, rounded half up to UQ8.8. Never exceeds C.
        let out = (c as u64 * (w + 1) + (1 << (p.word_bits - 1))) >> p.word_bits;
        (out as u16, false)
    }

    /// The pixels of a span in output order (`len = 0` yields nothing).
    pub fn span(&self, s: &SpecularSpan) -> impl Iterator<Item = SpecPixel> + '_ {
        let s = *s;
        (0..s.len).map(move |j| {
            let (spec, err) = self.pixel(s.c, s.n, s.theta0, s.dtheta, j);
            SpecPixel { spec, err, last: j + 1 == s.len }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::contract::THETA_FRAC;
    use super::*;
    use crate::rom::RomFormat;

    #[test]
    fn specular_theta_wraps_like_a_32_bit_register() {
        assert_eq!(theta_at(5, -2, 3), -1);
        assert_eq!(theta_at(i32::MAX, 1, 1), i32::MIN);
        assert!(span_overflows(i32::MAX - 2, 1, 4));
        assert!(!span_overflows(i32::MAX - 2, 1, 3));
        assert!(!span_overflows(i32::MIN, -1, 1));
        assert!(span_overflows(0, -(1 << 30), 4));
        assert!(!span_overflows(0, i32::MIN, 0));
    }

    #[test]
    fn specular_pixel_basics() {
        let u = SpecularUnit::default();
        // At theta = 0 the table starts at 1.0: out = C.
        for c in [0u16, 1, 255, 256, 65535] {
            assert_eq!(u.pixel(c, 1, 0, 0, 0), (c, false));
            assert_eq!(u.pixel(c, 1000, 0, 0, 0), (c, false));
        }
        // Symmetric in theta, including the most negative accumulator value.
        for th in [1i32 << 20, 12345678, 1 << 28, (3 << 27) + 5] {
            for n in [1u16, 3, 50, 1000] {
                assert_eq!(u.pixel_at(65535, n, th), u.pixel_at(65535, n, -th));
            }
        }
        assert_eq!(u.pixel_at(65535, 1, i32::MIN), (0, false));
        // Invalid n: zero and flagged, whatever theta.
        for n in [0u16, 1001, 1023, 1024, 65535] {
            assert_eq!(u.pixel(65535, n, 0, 3, 7), (0, true));
        }
        // Beyond pi/2 nothing is lit.
        let half_pi = (std::f64::consts::FRAC_PI_2 * (1u64 << THETA_FRAC) as f64) as i32;
        for n in 1..=1000u16 {
            assert_eq!(u.pixel_at(65535, n, half_pi), (0, false), "n = {n}");
        }
    }

    #[test]
    fn specular_rom_images_round_trip() {
        let u = SpecularUnit::default();
        for rom in [u.brdf_rom(), u.nk_rom()] {
            for f in RomFormat::ALL {
                let back = Rom::parse(&rom.name, rom.width, f, &rom.to_text(f)).unwrap();
                assert_eq!(&back, rom);
            }
        }
    }

    #[test]
    fn specular_span_yields_len_pixels_and_marks_the_last() {
        let u = SpecularUnit::default();
        let s = SpecularSpan { c: 200 << 8, n: 20, theta0: -(1 << 26), dtheta: 1 << 20, len: 130 };
        let px: Vec<_> = u.span(&s).collect();
        assert_eq!(px.len(), 130);
        assert!(px[..129].iter().all(|p| !p.last) && px[129].last);
        assert_eq!(px[64].spec, 200 << 8, "theta crosses 0 at j = 64");
        assert_eq!(u.span(&SpecularSpan { len: 0, ..s }).count(), 0);
        let bad: Vec<_> = u.span(&SpecularSpan { n: 0, len: 3, ..s }).collect();
        assert!(bad.iter().all(|p| p.err && p.spec == 0) && bad[2].last);
    }
}
