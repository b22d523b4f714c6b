//! Vectors on the unit sphere: what the specular set-up and the f64 references share (the
//! renderer's mesh and visibility code use them too).

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

pub type Vec3 = [f64; 3];

pub fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
pub fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
pub fn norm(a: Vec3) -> f64 {
    dot(a, a).sqrt()
}
pub fn scale(a: Vec3, s: f64) -> Vec3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
pub fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
/// `a / |a|`, `None` for a zero or non-finite vector.
pub fn normalize(a: Vec3) -> Option<Vec3> {
    let l = norm(a);
    (l.is_finite() && l > 1e-150).then(|| scale(a, 1.0 / l))
}
/// Angle between unit vectors, accurate near 0 and pi (unlike acos of the dot product).
pub fn angle(a: Vec3, b: Vec3) -> f64 {
    norm(cross(a, b)).atan2(dot(a, b))
}
/// A fixed unit vector perpendicular to unit `a`: `a` crossed with the coordinate axis it is
/// least aligned with.
pub fn perpendicular(a: Vec3) -> Vec3 {
    let i = (0..3).min_by(|&i, &j| a[i].abs().total_cmp(&a[j].abs())).unwrap_or(0);
    let mut e = [0.0; 3];
    e[i] = 1.0;
    normalize(cross(a, e)).unwrap_or([1.0, 0.0, 0.0])
}
/// Rotation of v about unit axis u by phi (Rodrigues).
pub fn rotate(v: Vec3, u: Vec3, phi: f64) -> Vec3 {
    let (s, c) = phi.sin_cos();
    add(add(scale(v, c), scale(cross(u, v), s)), scale(u, dot(u, v) * (1.0 - c)))
}
/// Spherical interpolation of unit vectors; for antiparallel ends the half circle through
/// [`perpendicular`] of `a`.
pub fn slerp(a: Vec3, b: Vec3, t: f64) -> Vec3 {
    match normalize(cross(a, b)) {
        Some(axis) => rotate(a, axis, t * angle(a, b)),
        None if dot(a, b) > 0.0 => a,
        None => rotate(a, perpendicular(a), t * PI),
    }
}

/// Normals and half-vectors at a span's first (1) and last (2) pixel. Need not be unit.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SpanEnds {
    pub n1: Vec3,
    pub h1: Vec3,
    pub n2: Vec3,
    pub h2: Vec3,
}
