//! f64 references, one per error source, so each can be measured on its own:
//!
//! * [`blinn_phong_slerp`]: true Blinn–Phong with N and H interpolated spherically along
//!   the span: what an ideal renderer shows.
//! * [`exact`]: `C cos^n(delta)`: the patent's rotated-frame model, exact in n
//!   (the set-up's geometry is the only approximation against the line above).
//! * [`approx`]: `C cos^k(sqrt(n/k) delta)`: the table approximation the unit implements.
//! * the bit-exact unit itself, judged against [`approx`] by SPEC §4.

use super::contract::THETA_FRAC;
use super::geometry::{dot, slerp, SpanEnds};
use std::f64::consts::{FRAC_PI_2, FRAC_PI_3};

/// SPEC §4 epicentre of the highlight: `delta <= atan(1/sqrt(n-1))`, the inflection point of
/// `cos^n`, for n >= 2; `pi/3` for n = 1.
pub fn epicentre(n: u32) -> f64 {
    if n <= 1 {
        FRAC_PI_3
    } else {
        (1.0 / ((n - 1) as f64).sqrt()).atan()
    }
}

/// The largest `theta` code (Q3.28 magnitude) inside the epicentre of n.
pub fn epicentre_code(n: u32) -> u32 {
    (epicentre(n) * (1u64 << THETA_FRAC) as f64).floor() as u32
}

/// `C cos^n(delta)`, 0 where the cosine is not positive (Blinn–Phong clamps N·H at 0).
pub fn exact(c: f64, n: u32, delta: f64) -> f64 {
    let x = delta.cos();
    if x <= 0.0 {
        0.0
    } else {
        c * x.powi(n as i32)
    }
}

/// `C cos^k(sqrt(n/k) |delta|)`, 0 when that argument reaches pi/2 (SPEC §3).
pub fn approx(c: f64, n: u32, k: u32, delta: f64) -> f64 {
    c * cos_k(k, (n as f64 / k as f64).sqrt() * delta.abs())
}

/// `cos^k(x)` for `x >= 0`, 0 from pi/2 on: the curve a BRDF table samples.
pub fn cos_k(k: u32, x: f64) -> f64 {
    if x >= FRAC_PI_2 {
        0.0
    } else {
        x.cos().powi(k as i32)
    }
}

/// Argument of table k at the epicentre edge of n: the largest `sqrt(n/k) delta` the table
/// must reproduce to the tight tolerance.
pub fn epicentre_arg(n: u32, k: u32) -> f64 {
    (n as f64 / k as f64).sqrt() * epicentre(n)
}

/// Max relative error of `cos^k(sqrt(n/k) d)` against `cos^n(d)` over the epicentre.
///
/// Closed form: with `a = sqrt(n/k)`, `g(d) = k ln cos(a d) - n ln cos d` has
/// `g'(d) = n (tan d - tan(a d)/a)`, whose sign is fixed (tan x / x increases), so
/// `|e^g - 1|` grows monotonically with d and its maximum is at the epicentre's edge.
/// (`approx_error_sampled` in the tests confirms this against dense sampling.)
pub fn approx_error(n: u32, k: u32) -> f64 {
    let d = epicentre(n);
    (cos_k(k, epicentre_arg(n, k)) / d.cos().powi(n as i32) - 1.0).abs()
}

/// True Blinn–Phong at span position `t` in [0, 1]: `Il ks max(0, N(t)·H(t))^n` with N and H
/// each moved along its great circle (slerp) from the first pixel's to the last pixel's.
pub fn blinn_phong_slerp(ends: &SpanEnds, il: f64, ks: f64, n: u32, t: f64) -> f64 {
    let nt = slerp(ends.n1, ends.n2, t);
    let ht = slerp(ends.h1, ends.h2, t);
    let x = dot(nt, ht);
    if x <= 0.0 {
        0.0
    } else {
        il * ks * x.powi(n as i32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn approx_error_sampled(n: u32, k: u32) -> f64 {
        let e = epicentre(n);
        (0..=2000)
            .map(|i| {
                let d = e * i as f64 / 2000.0;
                (approx(1.0, n, k, d) / exact(1.0, n, d) - 1.0).abs()
            })
            .fold(0.0, f64::max)
    }

    #[test]
    fn specular_reference_closed_form_error_is_the_sampled_maximum() {
        for n in [1u32, 2, 3, 5, 6, 7, 8, 17, 100, 999, 1000] {
            for k in [1u32, 2, 3, 4, 9, 16, 64] {
                let (c, s) = (approx_error(n, k), approx_error_sampled(n, k));
                assert!((c - s).abs() <= 1e-12 + 1e-9 * c, "n={n} k={k}: {c} vs {s}");
            }
        }
    }

    #[test]
    fn specular_reference_epicentre_is_the_inflection_point() {
        assert_eq!(epicentre(1), FRAC_PI_3);
        for n in [2u32, 3, 10, 1000] {
            // d2/dd2 cos^n = n cos^(n-2) (n sin^2 - 1): zero at tan^2 = 1/(n-1).
            let d = epicentre(n);
            assert!((n as f64 * d.sin().powi(2) - 1.0).abs() < 1e-12);
            assert!(epicentre_code(n) as f64 / (1u64 << 28) as f64 <= d);
        }
        assert_eq!(cos_k(4, FRAC_PI_2), 0.0);
        assert_eq!(exact(2.0, 3, 2.0), 0.0);
        assert!((approx(2.0, 8, 2, -0.1) - 2.0 * (0.2f64).cos().powi(2)).abs() < 1e-15);
    }
}
