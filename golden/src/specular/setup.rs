//! Host set-up of one specular span (SPEC §1): from the normals and half-vectors at the
//! span's first and last pixel to the unit's port values `C, theta0, dtheta`.
//!
//! Geometry. H2 is rotated by the rotation that takes N2 to N1 (Rodrigues), so N can stay
//! at N1 while H moves on the great circle H1 -> H2'. With the orthonormal pair
//! `e1 = H1`, `e2 = (H2' - cos(gamma) H1) / sin(gamma)` the circle is
//! `H(t) = cos(t gamma) e1 + sin(t gamma) e2`, hence
//! `N1·H(t) = c1 cos(t gamma) + s sin(t gamma) = A cos(t gamma - lambda)` with
//! `c1 = N1·e1 = cos theta1`, `s = N1·e2`, `A = hypot(c1, s)`, `lambda = atan2(s, c1)`.
//! This is the patent's `P = s/c1 = tan lambda`, `A = cos theta1 / cos lambda`, but it never
//! divides by `cos theta1` or `sin gamma`, so neither a light behind the surface nor a huge
//! `|P|` can produce NaN or infinity.
//!
//! Fallbacks (each reported in [`Fallbacks`]):
//! * non-finite or zero-length vectors, or non-finite/negative `Il ks`: a dark span
//!   (C = 0, theta0 = dtheta = 0).
//! * antiparallel normals (N1·N2 = -1): the rotation N2 -> N1 is not unique; a half turn
//!   about a fixed axis perpendicular to N1 is used ([`perpendicular`]).
//! * gamma = 0 (H2' = H1), or a one-pixel span (l = 0): N1·H is constant `c1`;
//!   `A = |c1|`, theta0 = dtheta = 0, which is also exact (no table approximation at 0).
//! * gamma = pi (H2' = -H1): the great circle is not unique; it is taken through the
//!   projection of N1 (so the highlight, if any, is on it), or a fixed perpendicular.
//! * the lit part of the circle: `lambda` is in (-pi, pi] and theta runs from `-lambda` to
//!   `gamma - lambda`, inside [-pi, 2pi]. The unit only lights `|theta| < pi/2`, so when the
//!   run ends beyond 3pi/2 (lit again modulo 2pi) theta0 moves down by 2pi. Every theta
//!   then lies in [-3pi/2, 3pi/2], far inside Q3.28's [-8, 8): no span overflows.
//! * no pixel lit (cos delta <= 0 on the whole span, light behind the surface): C = 0,
//!   theta0 = dtheta = 0.
//! * C beyond UQ8.8 saturates to 65535/256.

use super::contract::{C_FRAC, THETA_FRAC};
use super::geometry::{add, angle, cross, dot, norm, normalize, perpendicular, rotate, scale, SpanEnds, Vec3};
use super::unit::{span_overflows, SpecularSpan};
use serde::{Deserialize, Serialize};
use std::f64::consts::{FRAC_PI_2, PI};

/// The rotation taking unit n2 to unit n1, applied to v; the second value says whether the
/// antiparallel fallback was used.
fn rotate_n2_to_n1(n1: Vec3, n2: Vec3, v: Vec3) -> (Vec3, bool) {
    let u = cross(n2, n1);
    let (s, c) = (norm(u), dot(n1, n2));
    if s > 1e-12 {
        // Near antiparallel, u is small and its rounding tilts the axis out of the plane
        // perpendicular to N1, which a half turn doubles; removing the N1 part keeps the
        // result on N1 to rounding (any axis perpendicular to N1 works for a half turn).
        let axis = normalize(add(u, scale(n1, -dot(u, n1)))).unwrap_or(scale(u, 1.0 / s));
        return (rotate(v, axis, s.atan2(c)), false);
    }
    if c > 0.0 {
        (v, false)
    } else {
        (rotate(v, perpendicular(n1), PI), true)
    }
}

/// Which fallbacks a set-up took.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Fallbacks {
    pub bad_input: bool,
    pub antiparallel_normals: bool,
    pub gamma_zero: bool,
    pub gamma_pi: bool,
    pub single_pixel: bool,
    pub shifted_2pi: bool,
    pub dark: bool,
    pub c_saturated: bool,
}

/// A span's set-up: the port values and the f64 quantities behind them (all finite).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpecularSetup {
    pub port: SpecularSpan,
    /// `Il ks A^n` before quantization.
    pub c: f64,
    pub a: f64,
    pub lambda: f64,
    pub gamma: f64,
    pub theta1: f64,
    pub theta2: f64,
    /// theta of the first pixel and per pixel, before quantization.
    pub theta0: f64,
    pub dtheta: f64,
    pub fallbacks: Fallbacks,
}

impl SpecularSetup {
    /// The f64 model the set-up encodes, `C cos^n(theta0 + j dtheta)` (0 where cos <= 0), on
    /// the unquantized values: against [`super::reference::blinn_phong_slerp`] it measures the
    /// rotated-frame geometry alone.
    pub fn model(&self, j: u32) -> f64 {
        super::reference::exact(self.c, self.port.n as u32, self.theta0 + j as f64 * self.dtheta)
    }
}

fn quantize_theta(x: f64) -> i32 {
    (x * (1u64 << THETA_FRAC) as f64).round() as i32
}

/// Set-up of one span: `l = Xend - Xstart`, so the span has `l + 1` pixels (`port.len`).
/// `il * ks` is the highlight's peak intensity in output units (0..256 before
/// saturation); n is passed through as is, the unit itself flags an n outside 1..=1000.
pub fn setup_span(ends: &SpanEnds, il: f64, ks: f64, n: u16, l: u32) -> SpecularSetup {
    let mut fb = Fallbacks::default();
    let len = l.saturating_add(1);
    let dark = |fb: Fallbacks, gamma: f64| SpecularSetup {
        port: SpecularSpan { c: 0, n, theta0: 0, dtheta: 0, len },
        c: 0.0,
        a: 0.0,
        lambda: 0.0,
        gamma,
        theta1: 0.0,
        theta2: 0.0,
        theta0: 0.0,
        dtheta: 0.0,
        fallbacks: fb,
    };
    let ilks = il * ks;
    let (Some(n1), Some(h1), Some(n2), Some(h2), true) =
        (normalize(ends.n1), normalize(ends.h1), normalize(ends.n2), normalize(ends.h2), ilks.is_finite() && ilks >= 0.0)
    else {
        fb.bad_input = true;
        return dark(fb, 0.0);
    };
    let (h2r, anti) = rotate_n2_to_n1(n1, n2, h2);
    fb.antiparallel_normals = anti;
    let c1 = dot(n1, h1);
    let theta1 = c1.clamp(-1.0, 1.0).acos();
    let theta2 = dot(n1, h2r).clamp(-1.0, 1.0).acos();
    let gamma = angle(h1, h2r);
    // e2: unit vector along the circle from H1 toward H2'.
    let off = add(h2r, scale(h1, -dot(h1, h2r)));
    let e2 = if l == 0 {
        fb.single_pixel = true;
        None
    } else if let (Some(e2), true) = (normalize(off), norm(off) > 1e-12) {
        Some(e2)
    } else if gamma < FRAC_PI_2 {
        fb.gamma_zero = true;
        None
    } else {
        fb.gamma_pi = true;
        Some(normalize(add(n1, scale(h1, -c1))).filter(|_| c1.abs() < 1.0 - 1e-12).unwrap_or_else(|| perpendicular(h1)))
    };
    let (a, lambda, gamma_used) = match e2 {
        Some(e2) => {
            let s = dot(n1, e2);
            // |N1| = 1 bounds A by 1; the min keeps rounding from pushing A^n past Il ks.
            (c1.hypot(s).min(1.0), s.atan2(c1), if fb.gamma_pi { PI } else { gamma })
        }
        // Constant N·H: exact, and theta stays at 0 where the table is exact too.
        None => (c1.abs().min(1.0), if c1 > 0.0 { 0.0 } else { PI }, 0.0),
    };
    let mut theta0 = -lambda;
    if theta0 + gamma_used > 1.5 * PI {
        theta0 -= 2.0 * PI;
        fb.shifted_2pi = true;
    }
    // Lit somewhere iff [theta0, theta0 + gamma] meets (-pi/2, pi/2).
    if theta0 >= FRAC_PI_2 || theta0 + gamma_used <= -FRAC_PI_2 || a == 0.0 {
        fb.dark = true;
        return SpecularSetup { theta1, theta2, ..dark(fb, gamma) };
    }
    let dtheta = if l == 0 { 0.0 } else { gamma_used / l as f64 };
    let (theta0_q, mut dtheta_q) = (quantize_theta(theta0), quantize_theta(dtheta));
    if span_overflows(theta0_q, dtheta_q, len) {
        // Only reachable for spans far longer than any port carries (l beyond ~10^9): l
        // rounding errors of half an LSB each. Truncation keeps the end inside theta0 + gamma.
        dtheta_q = (dtheta * (1u64 << THETA_FRAC) as f64).trunc() as i32;
    }
    let c = ilks * a.powi(n as i32);
    let cq = (c * (1u32 << C_FRAC) as f64).round();
    fb.c_saturated = cq > u16::MAX as f64;
    SpecularSetup {
        port: SpecularSpan { c: cq.min(u16::MAX as f64) as u16, n, theta0: theta0_q, dtheta: dtheta_q, len },
        c,
        a,
        lambda,
        gamma,
        theta1,
        theta2,
        theta0,
        dtheta,
        fallbacks: fb,
    }
}

#[cfg(test)]
mod tests {
    use super::super::reference::{approx_error, blinn_phong_slerp, epicentre_code};
    use super::super::unit::SpecularUnit;
    use super::*;
    use crate::rng::SeedRng;
    use rand::{Rng, SeedableRng};

    /// Seeded from GOLDEN_SEED if set, else fresh ([`crate::rng::test_seed`]).
    fn rng() -> SeedRng {
        SeedRng::seed_from_u64(crate::rng::test_seed("specular setup"))
    }

    fn unit(r: &mut SeedRng) -> Vec3 {
        loop {
            let v = [r.gen_range(-1.0..1.0), r.gen_range(-1.0..1.0), r.gen_range(-1.0..1.0)];
            if let Some(u) = normalize(v).filter(|_| norm(v) <= 1.0) {
                return u;
            }
        }
    }

    fn nudge(r: &mut SeedRng, v: Vec3) -> Vec3 {
        let e = [0.0, 1e-15, 1e-9, 1e-6][r.gen_range(0..4)];
        add(v, scale(unit(r), e))
    }

    /// Random ends with the degenerate configurations over-represented.
    fn ends(r: &mut SeedRng) -> SpanEnds {
        let (n1, h1) = (unit(r), unit(r));
        let mut e = SpanEnds { n1, h1, n2: unit(r), h2: unit(r) };
        match r.gen_range(0..12) {
            0 => e.n2 = nudge(r, scale(n1, -1.0)),
            1 => e.n2 = nudge(r, n1),
            2 => e.h2 = nudge(r, h1),
            3 => (e.n2, e.h2) = (n1, nudge(r, scale(h1, -1.0))),
            4 => e.h1 = nudge(r, n1),
            5 => e.h1 = nudge(r, scale(n1, -1.0)),
            6 => e.h1 = nudge(r, normalize(add(h1, scale(n1, -dot(h1, n1)))).unwrap_or(h1)),
            7 => e.n2 = [0.0; 3],
            8 => e.h1[r.gen_range(0..3)] = [f64::NAN, f64::INFINITY, 1e300][r.gen_range(0..3)],
            _ => {}
        }
        e
    }

    fn finite(s: &SpecularSetup) -> bool {
        [s.c, s.a, s.lambda, s.gamma, s.theta1, s.theta2, s.theta0, s.dtheta].iter().all(|x| x.is_finite())
    }

    #[test]
    fn specular_setup_never_sends_nan_inf_or_an_overflowing_span() {
        let mut r = rng();
        let u = SpecularUnit::default();
        let bound = (1.5 * PI * (1u64 << THETA_FRAC) as f64) as i64 + (1 << 15);
        for _ in 0..20_000 {
            let e = ends(&mut r);
            let il = [0.0, 1.0, 255.0, 1e9, f64::NAN, -1.0][r.gen_range(0..6)];
            let ks = r.gen_range(0.0..1.0);
            let n = [1u16, 2, 3, 7, 100, 1000, 0, 1023][r.gen_range(0..8)];
            let l = [0u32, 1, 2, 639, 4095, 65535][r.gen_range(0..6)];
            let s = setup_span(&e, il, ks, n, l);
            assert!(finite(&s), "{e:?} -> {s:?}");
            assert_eq!(s.port.len, l + 1);
            assert!(s.a >= 0.0 && s.a <= 1.0 && s.c >= 0.0);
            let p = s.port;
            assert!(!span_overflows(p.theta0, p.dtheta, p.len), "{s:?}");
            for end in [p.theta0 as i64, p.theta0 as i64 + l as i64 * p.dtheta as i64] {
                assert!(end.abs() <= bound, "{s:?}");
            }
            // Spans the unit lights have their lit part where the unit looks for it.
            if !s.fallbacks.bad_input && !s.fallbacks.dark && l > 0 && (1..=1000).contains(&n) {
                let (px, _) = u.pixel(p.c, p.n, p.theta0, p.dtheta, l / 2);
                assert!(px <= p.c);
            }
        }
    }

    #[test]
    fn specular_setup_matches_the_slerp_reference_when_the_normal_is_fixed() {
        let mut r = rng();
        for _ in 0..2000 {
            let (n1, h1, h2) = (unit(&mut r), unit(&mut r), unit(&mut r));
            let e = SpanEnds { n1, h1, n2: n1, h2 };
            let (n, l) = (r.gen_range(1..=200u16), r.gen_range(1..=500u32));
            let s = setup_span(&e, 200.0, 1.0, n, l);
            if s.fallbacks != Fallbacks::default() && s.fallbacks != (Fallbacks { shifted_2pi: true, ..Fallbacks::default() }) {
                assert!(s.fallbacks.dark, "{s:?}");
            }
            for j in [0, l / 3, l / 2, l] {
                let want = blinn_phong_slerp(&e, 200.0, 1.0, n as u32, j as f64 / l as f64);
                assert!((s.model(j) - want).abs() <= 1e-9 * 200.0, "j={j}: {} vs {want}, {s:?}", s.model(j));
            }
        }
    }

    #[test]
    fn specular_setup_through_the_unit_tracks_blinn_phong() {
        // With N fixed the rotated-frame model is exact, so inside the epicentre the unit
        // differs from true Blinn–Phong only by the table approximation, its SPEC §4 error
        // and the port quantization.
        let mut r = rng();
        let u = SpecularUnit::default();
        let mut checked = 0;
        for k in 0..400 {
            // The first two spans sit on the highlight (H = N all along, theta 0 at every one of
            // their 601 pixels), so at least 1,202 pixels are checked whatever the seed.
            let centred = k < 2;
            let n1 = unit(&mut r);
            let near = |r: &mut SeedRng| normalize(add(n1, scale(unit(r), r.gen_range(0.0..0.6) * !centred as u8 as f64))).unwrap();
            let (h1, h2) = (near(&mut r), near(&mut r));
            let e = SpanEnds { n1, h1, n2: n1, h2 };
            let (n, l) = (r.gen_range(1..=1000u32), if centred { 600 } else { r.gen_range(1..=600u32) });
            let s = setup_span(&e, 255.0, 1.0, n as u16, l);
            let p = s.port;
            let k = u.plan().decoder.k_of(n).unwrap();
            let rel = approx_error(n, k) + 0.0025 + 1e-4;
            for j in 0..=l {
                let code = (p.theta0 as i64 + j as i64 * p.dtheta as i64).unsigned_abs();
                if code > epicentre_code(n) as u64 {
                    continue;
                }
                let bp = blinn_phong_slerp(&e, 255.0, 1.0, n, j as f64 / l as f64);
                let out = u.pixel(p.c, p.n, p.theta0, p.dtheta, j).0 as f64 / 256.0;
                assert!((out - bp).abs() <= rel * bp + 3.0 / 256.0, "n={n} l={l} j={j}: {out} vs {bp}");
                checked += 1;
            }
        }
        assert!(checked > 1000, "{checked}");
    }

    #[test]
    fn specular_setup_rotates_n2_onto_n1_and_keeps_the_angle_to_h2() {
        let mut r = rng();
        for _ in 0..2000 {
            let e = ends(&mut r);
            let (Some(n1), Some(n2), Some(h2)) = (normalize(e.n1), normalize(e.n2), normalize(e.h2)) else {
                continue;
            };
            let (n2r, _) = rotate_n2_to_n1(n1, n2, n2);
            let (h2r, _) = rotate_n2_to_n1(n1, n2, h2);
            assert!(norm(add(n2r, scale(n1, -1.0))) < 1e-6, "{e:?}");
            assert!((dot(n1, h2r) - dot(n2, h2)).abs() < 1e-6);
            // SPEC's Rodrigues form, where it is well conditioned.
            let d = dot(n1, n2);
            if d > -0.9 {
                let u = cross(n2, n1);
                let want = add(add(scale(h2, d), cross(u, h2)), scale(u, dot(u, h2) / (1.0 + d)));
                assert!(norm(add(h2r, scale(want, -1.0))) < 1e-9);
            }
        }
    }

    #[test]
    fn specular_setup_fallbacks() {
        let x = [1.0, 0.0, 0.0];
        let y = [0.0, 1.0, 0.0];
        let h = normalize([1.0, 1.0, 0.0]).unwrap();
        // One pixel: exact c1^n, theta 0.
        let s = setup_span(&SpanEnds { n1: x, h1: h, n2: y, h2: y }, 100.0, 1.0, 2, 0);
        assert!(s.fallbacks.single_pixel);
        assert_eq!((s.port.theta0, s.port.dtheta, s.port.len), (0, 0, 1));
        assert_eq!(s.port.c, (50.0f64 * 256.0).round() as u16);
        // gamma = 0.
        let s = setup_span(&SpanEnds { n1: x, h1: h, n2: x, h2: h }, 100.0, 1.0, 2, 9);
        assert!(s.fallbacks.gamma_zero && s.port.dtheta == 0 && s.port.theta0 == 0);
        // Light behind the whole span.
        let s = setup_span(&SpanEnds { n1: x, h1: [-1.0, 0.0, 0.0], n2: x, h2: [-1.0, 0.1, 0.0] }, 100.0, 1.0, 8, 9);
        assert!(s.fallbacks.dark && s.port.c == 0);
        // Antiparallel normals.
        let s = setup_span(&SpanEnds { n1: x, h1: x, n2: [-1.0, 0.0, 0.0], h2: [-1.0, 0.0, 0.0] }, 100.0, 1.0, 8, 9);
        assert!(s.fallbacks.antiparallel_normals && s.fallbacks.gamma_zero);
        assert_eq!(s.port.c, 100 << 8);
        // gamma = pi: the circle through N1's side, lit at the start.
        let s = setup_span(&SpanEnds { n1: h, h1: x, n2: h, h2: [-1.0, 0.0, 0.0] }, 100.0, 1.0, 1, 4);
        assert!(s.fallbacks.gamma_pi && (s.a - 1.0).abs() < 1e-12);
        // Broken input.
        let s = setup_span(&SpanEnds { n1: [f64::NAN; 3], h1: x, n2: x, h2: x }, 100.0, 1.0, 8, 9);
        assert!(s.fallbacks.bad_input && s.port.c == 0);
        // C saturates.
        let s = setup_span(&SpanEnds { n1: x, h1: x, n2: x, h2: x }, 1e6, 1.0, 8, 9);
        assert!(s.fallbacks.c_saturated && s.port.c == u16::MAX);
    }
}
