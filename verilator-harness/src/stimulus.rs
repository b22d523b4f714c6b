//! Triangles to drive the co-simulation: golden's generators ([`golden::stimulus`], the one
//! module every seeded stimulus comes from), where the suites and binaries import them.

pub use golden::stimulus::{directed, random_triangle, sliver, triangle_of_radius};
