//! Scenes through the RTL: tessellation, lighting, hidden surfaces, co-simulation of every span
//! and image assembly, with the golden model's image made by the same host logic.
//!
//! A render is a [`Job`]: the spans of every triangle, per colour channel, in stream order; the
//! specular span of each (scenes only); and the visibility of every pixel, decided on the host
//! before any shading ([`Job::owner`]). [`run`] streams the spans through one segment shader per
//! channel and one specular unit, all at full rate ([`Traffic::FULL`]), and keeps each output
//! pixel whose triangle owns it. The golden image applies the same ownership to golden's pixels,
//! so the two images agree pixel for pixel exactly when the RTL agrees with golden.
//!
//! Hidden surfaces. Scenes: back-face culling (the meshes are closed) and a host z-buffer over
//! every remaining triangle, in f64, on `1/z` interpolated linearly in screen space (exact for a
//! perspective projection). The z-buffer is resolved before shading, as a depth pre-pass: each
//! pixel records the nearest triangle (the first in stream order on a tie), and only that
//! triangle's pixel is kept when the shaded segments come back. Triangle files: no depth; later
//! triangles are drawn over earlier ones, so a pixel belongs to the last triangle covering it.
//!
//! The modules: [`mesh`] (meshes and scenes), [`visibility`] (the job: spans and ownership),
//! [`threads`] (the co-simulation threads and golden's images), [`image`] (composing, memory
//! read-out, difference images).

mod image;
mod mesh;
mod threads;
mod visibility;

pub use image::{difference_image, spec_level};
pub use mesh::{obj_mesh, scene, sphere, torus, Lighting, Mesh, MeshError, SceneKind};
pub use threads::{busy_cycles, run, run_with, Chain, Outcome};
pub use visibility::{mesh_job, obj_job, scene_job, triangles_job, triangles_job_of, Job, JobError, BACKGROUND};
