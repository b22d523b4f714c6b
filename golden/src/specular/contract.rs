//! The specular unit's contract in numbers: its port formats, the valid n and SPEC §4's
//! tolerances. Every file of the unit, and every checker outside it, reads them here.

/// `theta0`, `dtheta`: signed Q3.28 radians (SPEC §3).
pub const THETA_FRAC: u32 = 28;
/// `in_c` and `out_spec`: UQ8.8.
pub const C_FRAC: u32 = 8;
/// `in_n` port width and the valid range of n.
pub const N_BITS: u32 = 10;
pub const N_MIN: u32 = 1;
pub const N_MAX: u32 = 1000;
/// The n-table ROM is addressed by the whole `in_n` port.
pub const NK_DEPTH: usize = 1 << N_BITS;
/// Largest k a table may use (SPEC §2 `brdf-k`).
pub const K_MAX: u32 = 64;

/// SPEC §4 tolerances on `|out - approx|`: `INSIDE_REL * approx + ABS` inside the epicentre,
/// `OUTSIDE_REL * C + ABS` elsewhere.
pub const INSIDE_REL: f64 = 0.0025;
pub const OUTSIDE_REL: f64 = 0.005;
pub const ABS_TOL: f64 = 2.0 / 256.0;

/// SPEC §4's allowance for `|out - approx|`, in output units (UQ8.8 as a real): `approx` is the
/// table approximation `C * a`, `c` the input C, `inside` whether the pixel is in the epicentre.
/// Every checker takes its bound from here.
pub fn tolerance(inside: bool, approx: f64, c: f64) -> f64 {
    if inside {
        INSIDE_REL * approx + ABS_TOL
    } else {
        OUTSIDE_REL * c + ABS_TOL
    }
}

/// Whether `n` is one the unit computes; the others give `out_err = 1`, `out_spec = 0`.
pub fn n_valid(n: u32) -> bool {
    (N_MIN..=N_MAX).contains(&n)
}
