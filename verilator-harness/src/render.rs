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

use crate::cosim::{Report, SegView, SegmentCosim, Stim, Stress, Traffic, DRAIN_CLOCKS};
use crate::ffi::{specular_unit, ModelInfo, SegIn, SegOut, SpecIn, SpecOut, TriIn, TriSegOut, WrIn, WrOut};
use crate::frontend::{stream_chain, Expected};
use crate::specular::SpecularCosim;
use crate::writer::{run_segments, stream_fb, SegStim};
use golden::frontend::{FixedTriangle, FrontEnd};
use golden::setup::{parse_triangles, triangle_spans, Screen, Triangle, Vertex};
use golden::specular::setup::{cross, dot, normalize, setup_span, SpanEnds, Vec3};
use golden::specular::{SpecularSpan, C_FRAC};
use golden::writer::Writer;
use golden::{Config, Span};
use std::f64::consts::{PI, TAU};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

/// `owner` of a pixel no triangle covers.
pub const BACKGROUND: u32 = u32::MAX;

/// A triangle mesh. Faces are wound counter-clockwise seen from outside; `normals` are the
/// smooth vertex normals (unit).
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub faces: Vec<[u32; 3]>,
}

impl Mesh {
    /// Adds face `[a, b, c]`, flipped if needed so its winding agrees with its vertex normals.
    fn face(&mut self, f: [u32; 3]) {
        let p = f.map(|k| self.positions[k as usize]);
        let n = cross(sub(p[1], p[0]), sub(p[2], p[0]));
        let avg = add(add(self.normals[f[0] as usize], self.normals[f[1] as usize]), self.normals[f[2] as usize]);
        self.faces.push(if dot(n, avg) >= 0.0 { f } else { [f[0], f[2], f[1]] });
    }

    fn vertex(&mut self, p: Vec3, n: Vec3) -> u32 {
        self.positions.push(p);
        self.normals.push(normalize(n).unwrap_or([0.0, 0.0, 1.0]));
        (self.positions.len() - 1) as u32
    }
}

/// A unit sphere: `stacks` rings of latitude, `slices` of longitude; fans at the poles, so no
/// face is degenerate. `2 * slices * (stacks - 1)` triangles.
pub fn sphere(stacks: u32, slices: u32) -> Mesh {
    let mut m = Mesh::default();
    let north = m.vertex([0.0, 1.0, 0.0], [0.0, 1.0, 0.0]);
    for i in 1..stacks {
        let phi = PI * i as f64 / stacks as f64;
        for j in 0..slices {
            let th = TAU * j as f64 / slices as f64;
            let p = [phi.sin() * th.cos(), phi.cos(), -phi.sin() * th.sin()];
            m.vertex(p, p);
        }
    }
    let south = m.vertex([0.0, -1.0, 0.0], [0.0, -1.0, 0.0]);
    let ring = |i: u32, j: u32| 1 + (i - 1) * slices + j % slices;
    for j in 0..slices {
        m.face([north, ring(1, j), ring(1, j + 1)]);
        m.face([south, ring(stacks - 1, j + 1), ring(stacks - 1, j)]);
    }
    for i in 1..stacks - 1 {
        for j in 0..slices {
            let (a, b, c, d) = (ring(i, j), ring(i, j + 1), ring(i + 1, j + 1), ring(i + 1, j));
            m.face([a, d, c]);
            m.face([a, c, b]);
        }
    }
    m
}

/// A torus around the y axis: tube centre radius `big`, tube radius `small`; `2 * around *
/// tube` triangles.
pub fn torus(around: u32, tube: u32, big: f64, small: f64) -> Mesh {
    let mut m = Mesh::default();
    for i in 0..around {
        let u = TAU * i as f64 / around as f64;
        for j in 0..tube {
            let v = TAU * j as f64 / tube as f64;
            let n = [v.cos() * u.cos(), v.sin(), v.cos() * u.sin()];
            let p = [(big + small * v.cos()) * u.cos(), small * v.sin(), (big + small * v.cos()) * u.sin()];
            m.vertex(p, n);
        }
    }
    let at = |i: u32, j: u32| (i % around) * tube + j % tube;
    for i in 0..around {
        for j in 0..tube {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            m.face([a, b, c]);
            m.face([a, c, d]);
        }
    }
    m
}

fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn scale(a: Vec3, s: f64) -> Vec3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
/// Rotation about x by `ax`, then about y by `ay`.
fn rotate_xy(p: Vec3, ax: f64, ay: f64) -> Vec3 {
    let (s, c) = ax.sin_cos();
    let p = [p[0], c * p[1] - s * p[2], s * p[1] + c * p[2]];
    let (s, c) = ay.sin_cos();
    [c * p[0] + s * p[2], p[1], -s * p[0] + c * p[2]]
}

/// The built-in scenes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum SceneKind {
    Sphere,
    Torus,
}

impl SceneKind {
    pub fn name(self) -> &'static str {
        match self {
            SceneKind::Sphere => "sphere",
            SceneKind::Torus => "torus",
        }
    }
}

/// Lighting and camera of a scene; everything in world units, the object centred at the origin.
#[derive(Clone, Debug)]
pub struct Lighting {
    pub eye: Vec3,
    pub light: Vec3,
    /// Object colour per channel (0..1).
    pub colour: [f64; 3],
    pub ambient: f64,
    pub diffuse: f64,
    /// `Il * ks`: the highlight's peak, in 8-bit levels, added to every channel (white).
    pub specular: f64,
    /// Blinn–Phong exponent n, 1..=1000.
    pub shininess: u16,
}

/// Every scene's camera, light and material, in its own colour.
fn lighting(colour: [f64; 3], shininess: u16) -> Lighting {
    Lighting { eye: [0.0, 0.0, 4.5], light: [-4.0, 4.5, 6.0], colour, ambient: 0.07, diffuse: 0.93, specular: 235.0, shininess }
}

/// A Wavefront OBJ mesh (`tobj`: polygons triangulated, every object of the file), moved and
/// scaled into the unit sphere the camera frames. Normals: the file's where every vertex has
/// one, else smooth normals from the faces (area-weighted), the faces' winding taken as given
/// (counter-clockwise seen from outside, OBJ's convention). Materials are ignored.
pub fn obj_mesh(text: &str) -> Result<Mesh, String> {
    let opts = tobj::LoadOptions { triangulate: true, single_index: true, ..Default::default() };
    let (models, _) = tobj::load_obj_buf(&mut text.as_bytes(), &opts, |_| Err(tobj::LoadError::OpenFileFailed))
        .map_err(|e| format!("not a Wavefront OBJ mesh: {e}"))?;
    let mut mesh = Mesh::default();
    let mut given = Vec::new();
    for m in &models {
        let base = mesh.positions.len() as u32;
        let mm = &m.mesh;
        for k in 0..mm.positions.len() / 3 {
            mesh.positions.push([0, 1, 2].map(|c| mm.positions[3 * k + c] as f64));
            given.push((mm.normals.len() == mm.positions.len()).then(|| [0, 1, 2].map(|c| mm.normals[3 * k + c] as f64)));
        }
        for f in mm.indices.chunks_exact(3) {
            mesh.faces.push([f[0] + base, f[1] + base, f[2] + base]);
        }
    }
    if mesh.faces.is_empty() {
        return Err("the OBJ file has no faces".into());
    }
    if mesh.positions.iter().flatten().any(|v| !v.is_finite()) {
        return Err("the OBJ file has a vertex that is not a finite number".into());
    }
    // Into the unit sphere: the bounding box's centre to the origin, the farthest vertex at 1.
    let lo = mesh.positions.iter().fold([f64::INFINITY; 3], |a, p| [0, 1, 2].map(|c| a[c].min(p[c])));
    let hi = mesh.positions.iter().fold([f64::NEG_INFINITY; 3], |a, p| [0, 1, 2].map(|c| a[c].max(p[c])));
    let centre = [0, 1, 2].map(|c| (lo[c] + hi[c]) / 2.0);
    let r = mesh.positions.iter().map(|p| dot(sub(*p, centre), sub(*p, centre)).sqrt()).fold(0.0, f64::max);
    if r <= 0.0 {
        return Err("the OBJ mesh has no extent".into());
    }
    for p in mesh.positions.iter_mut() {
        *p = scale(sub(*p, centre), 1.0 / r);
    }
    let mut normals = vec![[0.0; 3]; mesh.positions.len()];
    for f in &mesh.faces {
        let p = f.map(|k| mesh.positions[k as usize]);
        let n = cross(sub(p[1], p[0]), sub(p[2], p[0]));
        for &k in f {
            normals[k as usize] = add(normals[k as usize], n);
        }
    }
    mesh.normals =
        normals.iter().zip(&given).map(|(n, g)| g.and_then(normalize).or_else(|| normalize(*n)).unwrap_or([0.0, 0.0, 1.0])).collect();
    Ok(mesh)
}

/// The job of an OBJ mesh ([`obj_mesh`]), lit like the built-in scenes in a warm grey and
/// turned like the torus, so a box shows three faces.
pub fn obj_job(text: &str, shininess: u16, cfg: &Config, screen: &Screen) -> Result<Job, String> {
    let mut mesh = obj_mesh(text)?;
    for v in mesh.positions.iter_mut().chain(mesh.normals.iter_mut()) {
        *v = rotate_xy(*v, 0.5, 0.35);
    }
    mesh_job(&mesh, &lighting([0.85, 0.78, 0.62], shininess), 1.0, cfg, screen)
}

/// The mesh and lighting of a scene (shininess as given).
pub fn scene(kind: SceneKind, shininess: u16) -> (Mesh, Lighting, f64) {
    let lighting = |colour| lighting(colour, shininess);
    match kind {
        SceneKind::Sphere => {
            // 64 x 96: 12,096 triangles, about half of them facing the camera.
            (sphere(64, 96), lighting([0.92, 0.32, 0.22]), 1.0)
        }
        SceneKind::Torus => {
            let mut m = torus(128, 48, 1.0, 0.42);
            // Tilted toward the camera so the hole shows and the near side hides the far one.
            for p in m.positions.iter_mut() {
                *p = rotate_xy(*p, 0.5, 0.35);
            }
            for n in m.normals.iter_mut() {
                *n = rotate_xy(*n, 0.5, 0.35);
            }
            (m, lighting([0.24, 0.58, 0.95]), 1.42)
        }
    }
}

/// Everything a render streams, and who owns every pixel.
#[derive(Clone, Debug)]
pub struct Job {
    pub screen: Screen,
    /// Per colour channel (1 or 3), the spans in stream order. Every channel has the same
    /// spans (same triangles, rows, x and length), only the intensities differ.
    pub stims: Vec<Vec<Stim>>,
    /// The specular span of each stim (same order), or empty: diffuse only.
    pub specular: Vec<SpecularSpan>,
    /// Per pixel (row-major), the triangle whose pixel is visible, or [`BACKGROUND`].
    pub owner: Vec<u32>,
    /// Per colour channel, the drawn triangles as they stand on the front-end's ports (the
    /// triangle ids of `stims` index them): what `--frontend rtl` streams.
    pub tris: Vec<Vec<FixedTriangle>>,
    /// Triangles in the input (tessellated or read).
    pub triangles: usize,
    /// Triangles streamed (after back-face culling).
    pub drawn: usize,
}

impl Job {
    pub fn channels(&self) -> usize {
        self.stims.len()
    }
    pub fn spans(&self) -> usize {
        self.stims.first().map_or(0, Vec::len)
    }
    /// Pixels the shader makes per channel (covered by some streamed span).
    pub fn shaded_pixels(&self) -> u64 {
        self.stims.first().map_or(0, |s| s.iter().map(|s| s.span.len as u64).sum())
    }
    pub fn visible_pixels(&self) -> u64 {
        self.owner.iter().filter(|&&o| o != BACKGROUND).count() as u64
    }
}

/// The job of a scene: tessellate, light the vertices, cull back faces, set up the spans of
/// every channel and the specular span of each, resolve the z-buffer.
pub fn scene_job(kind: SceneKind, shininess: u16, cfg: &Config, screen: &Screen) -> Result<Job, String> {
    let (mesh, light, radius) = scene(kind, shininess);
    mesh_job(&mesh, &light, radius, cfg, screen)
}

/// The job of a mesh inside a sphere of `radius` around the origin, lit by `light`.
pub fn mesh_job(mesh: &Mesh, light: &Lighting, radius: f64, cfg: &Config, screen: &Screen) -> Result<Job, String> {
    let (w, h) = (screen.width as f64, screen.height as f64);
    let d = light.eye[2];
    // Focal length in pixels: the object's bounding sphere fills 84% of the shorter side.
    let focal = 0.42 * w.min(h) * (d * d - radius * radius).sqrt() / radius;
    // Screen position and 1/depth of every vertex (the camera looks down -z from `eye`).
    let proj: Vec<(f64, f64, f64)> = mesh
        .positions
        .iter()
        .map(|p| {
            let depth = d - p[2];
            (w / 2.0 + focal * p[0] / depth, h / 2.0 - focal * p[1] / depth, 1.0 / depth)
        })
        .collect();
    // Per-vertex diffuse intensity of each channel (Gouraud: lit at the vertices only).
    let lit: Vec<[f64; 3]> = mesh
        .positions
        .iter()
        .zip(&mesh.normals)
        .map(|(p, n)| {
            let l = normalize(sub(light.light, *p)).unwrap_or([0.0, 0.0, 1.0]);
            let k = light.ambient + light.diffuse * dot(*n, l).max(0.0);
            light.colour.map(|c| (255.0 * c * k).clamp(0.0, 255.0))
        })
        .collect();

    let npix = (screen.width * screen.height) as usize;
    let mut job = Job {
        screen: *screen,
        stims: vec![Vec::new(); 3],
        specular: Vec::new(),
        owner: vec![BACKGROUND; npix],
        tris: vec![Vec::new(); 3],
        triangles: mesh.faces.len(),
        drawn: 0,
    };
    let mut zbuf = vec![f64::NEG_INFINITY; npix];
    for f in &mesh.faces {
        let p = f.map(|k| mesh.positions[k as usize]);
        let normal = cross(sub(p[1], p[0]), sub(p[2], p[0]));
        if dot(normal, sub(light.eye, p[0])) <= 0.0 {
            continue; // back face
        }
        let tri = job.drawn as u32;
        job.drawn += 1;
        let v = f.map(|k| proj[k as usize]);
        let first = job.stims[0].len();
        for (c, stims) in job.stims.iter_mut().enumerate() {
            let t = Triangle { v: [0, 1, 2].map(|k| Vertex { x: v[k].0, y: v[k].1, i: lit[f[k] as usize][c] }) };
            triangle_spans(cfg, screen, &t, |y, span| stims.push(Stim { triangle: tri as usize, y, span })).map_err(|e| e.to_string())?;
            job.tris[c].push(FixedTriangle::from_triangle(&t, cfg.frac));
        }
        let interp = Interp::new(v);
        for s in &job.stims[0][first..] {
            // Depth pre-pass: nearest wins, the first drawn on a tie.
            let py = s.y as f64 + 0.5;
            for x in s.span.x0..s.span.x0 + s.span.len {
                let idx = (s.y * screen.width + x) as usize;
                let z = interp.inv_depth(x as f64 + 0.5, py);
                if z > zbuf[idx] {
                    zbuf[idx] = z;
                    job.owner[idx] = tri;
                }
            }
            // Specular set-up of the span: N and H at its first and last pixel.
            let end = |x: u32| {
                let mu = interp.weights(x as f64 + 0.5, py);
                let blend = |a: &dyn Fn(usize) -> Vec3| add(add(scale(a(0), mu[0]), scale(a(1), mu[1])), scale(a(2), mu[2]));
                let n = blend(&|k| mesh.normals[f[k] as usize]);
                let pos = blend(&|k| mesh.positions[f[k] as usize]);
                let l = normalize(sub(light.light, pos)).unwrap_or([0.0, 0.0, 1.0]);
                let e = normalize(sub(light.eye, pos)).unwrap_or([0.0, 0.0, 1.0]);
                (n, add(l, e))
            };
            let (n1, h1) = end(s.span.x0);
            let (n2, h2) = end(s.span.x0 + s.span.len - 1);
            let ends = SpanEnds { n1, h1, n2, h2 };
            job.specular.push(setup_span(&ends, light.specular, 1.0, light.shininess, s.span.len - 1).port);
        }
    }
    for c in 1..3 {
        debug_assert!(job.stims[c].iter().zip(&job.stims[0]).all(|(a, b)| (a.y, a.span.x0, a.span.len) == (b.y, b.span.x0, b.span.len)));
    }
    Ok(job)
}

/// Screen-space interpolation over a projected triangle: 1/depth (affine in screen space) and
/// perspective-correct barycentric weights.
struct Interp {
    v: [(f64, f64, f64); 3],
    area: f64,
}

impl Interp {
    fn new(v: [(f64, f64, f64); 3]) -> Interp {
        let area = (v[1].0 - v[0].0) * (v[2].1 - v[0].1) - (v[1].1 - v[0].1) * (v[2].0 - v[0].0);
        Interp { v, area }
    }

    /// Screen-space barycentric weights of (x, y); equal weights for a degenerate triangle.
    fn screen_weights(&self, x: f64, y: f64) -> [f64; 3] {
        if self.area.abs() < 1e-12 {
            return [1.0 / 3.0; 3];
        }
        let v = &self.v;
        let e = |a: usize, b: usize| ((v[b].0 - v[a].0) * (y - v[a].1) - (v[b].1 - v[a].1) * (x - v[a].0)) / self.area;
        [e(1, 2), e(2, 0), e(0, 1)]
    }

    fn inv_depth(&self, x: f64, y: f64) -> f64 {
        let l = self.screen_weights(x, y);
        l[0] * self.v[0].2 + l[1] * self.v[1].2 + l[2] * self.v[2].2
    }

    /// Perspective-correct weights: the barycentric weights of the surface point seen at (x, y).
    fn weights(&self, x: f64, y: f64) -> [f64; 3] {
        let l = self.screen_weights(x, y).map(|l| l.max(0.0));
        let w = [l[0] * self.v[0].2, l[1] * self.v[1].2, l[2] * self.v[2].2];
        let s = w[0] + w[1] + w[2];
        if s > 0.0 {
            w.map(|w| w / s)
        } else {
            [1.0 / 3.0; 3]
        }
    }
}

/// The job of a triangle file (SPEC §5's text format): one grayscale channel, triangles drawn in
/// file order, later over earlier. Errors name the line (`line N: ...`) or the triangle.
pub fn triangles_job(text: &str, cfg: &Config, screen: &Screen) -> Result<Job, String> {
    let tris = parse_triangles(text).map_err(|e| e.to_string())?;
    triangles_job_of(&tris, cfg, screen)
}

/// As [`triangles_job`], for triangles already parsed.
pub fn triangles_job_of(tris: &[Triangle], cfg: &Config, screen: &Screen) -> Result<Job, String> {
    screen.check_for(cfg).map_err(|e| e.to_string())?;
    let mut job = Job {
        screen: *screen,
        stims: vec![Vec::new()],
        specular: Vec::new(),
        owner: vec![BACKGROUND; (screen.width * screen.height) as usize],
        tris: vec![tris.iter().map(|t| FixedTriangle::from_triangle(t, cfg.frac)).collect()],
        triangles: tris.len(),
        drawn: tris.len(),
    };
    for (k, t) in tris.iter().enumerate() {
        let stims = &mut job.stims[0];
        let owner = &mut job.owner;
        triangle_spans(cfg, screen, t, |y, span| {
            for x in span.x0..span.x0 + span.len {
                owner[(y * screen.width + x) as usize] = k as u32;
            }
            stims.push(Stim { triangle: k, y, span });
        })
        .map_err(|e| format!("triangle {}: {e}", k + 1))?;
    }
    Ok(job)
}

/// What a render produced.
#[derive(Debug)]
pub struct Outcome {
    /// Channels interleaved per pixel (1 or 3 bytes), row-major.
    pub rtl: Vec<u8>,
    pub golden: Vec<u8>,
    /// With the RTL front-end: the image of the host's set-up, to compare with.
    pub host: Option<Vec<u8>>,
    /// Per pixel, how many enabled output lanes of the (first) segment shader wrote it.
    pub coverage: Vec<u16>,
    /// One report per channel's segment shader.
    pub segment: Vec<Report>,
    pub specular: Option<Report>,
    /// With `Chain::HostToMemory`, one report per channel's segment writer.
    pub writer: Vec<Report>,
}

impl Outcome {
    /// Pixels where the RTL image differs from golden's.
    pub fn differing_pixels(&self, channels: usize) -> u64 {
        self.rtl.chunks(channels).zip(self.golden.chunks(channels)).filter(|(a, b)| a != b).count() as u64
    }
    /// Every co-simulation check passed.
    pub fn cosim_ok(&self) -> bool {
        self.segment.iter().chain(&self.writer).all(Report::ok) && self.specular.as_ref().is_none_or(Report::ok)
    }
}

/// Clocks from the first span offered to the last output, without the co-simulation's quiet
/// clocks after it ([`DRAIN_CLOCKS`]).
pub fn busy_cycles(r: &Report) -> u64 {
    r.cycles.saturating_sub(DRAIN_CLOCKS)
}

/// The highlight of a specular output pixel (UQ8.8) in 8-bit levels, rounded.
pub fn spec_level(spec: u16) -> u32 {
    (spec as u32 + (1 << (C_FRAC - 1))) >> C_FRAC
}

/// Which RTL draws a render's diffuse channels, and where their pixels land.
#[derive(Clone, Copy)]
pub enum Chain {
    /// The host's set-up: spans into one `segment_shader_p<P>` per channel; the harness paints
    /// the segments.
    Host,
    /// The host's set-up, and each channel's RTL segments then stream through `fb_writer_p<P>`
    /// into a memory model: the image is read out of memory.
    HostToMemory(&'static ModelInfo<WrIn, WrOut>),
    /// The RTL front-end: triangles into `tri_shader_p<P>`.
    Rtl(&'static ModelInfo<TriIn, TriSegOut>),
    /// The whole RTL chain: triangles into `tri_fb_p<P>`, the image read out of memory.
    RtlToMemory(&'static ModelInfo<TriIn, WrOut>),
}

impl Chain {
    /// The front-end's configuration and screen, when the RTL sets up the triangles.
    fn frontend(self) -> Option<FrontEnd> {
        match self {
            Chain::Host | Chain::HostToMemory(_) => None,
            Chain::Rtl(m) => Some(m.frontend()),
            Chain::RtlToMemory(m) => Some(m.frontend()),
        }
    }
}

/// Streams `job` through one `seg` model per channel and, when the job has specular spans, the
/// `spec` model, all at full rate on their own threads; builds the RTL and golden images.
/// `progress` is called now and then on the calling thread with the fraction done.
pub fn run(
    job: &Job,
    seg: &'static ModelInfo<SegIn, SegOut>,
    spec: Option<&'static ModelInfo<SpecIn, SpecOut>>,
    progress: impl FnMut(f64),
) -> Outcome {
    run_with(job, seg, Chain::Host, spec, progress)
}

/// [`run`] through `chain`. With the RTL front-end the RTL image must equal golden's front-end
/// image, and `Outcome::host` holds the host-set-up image to compare with. Through memory,
/// hidden surfaces stay hidden by the memory model's ownership test ([`MemoryCheck::owner`]),
/// the host's depth pre-pass, and the image is what memory holds.
///
/// [`MemoryCheck::owner`]: crate::writer::MemoryCheck::owner
pub fn run_with(
    job: &Job,
    seg: &'static ModelInfo<SegIn, SegOut>,
    chain: Chain,
    spec: Option<&'static ModelInfo<SpecIn, SpecOut>>,
    mut progress: impl FnMut(f64),
) -> Outcome {
    let exps: Option<Vec<Expected>> = chain.frontend().map(|fe| job.tris.iter().map(|t| Expected::new(fe, t)).collect());
    let exps = &exps;
    let screen = job.screen;
    let (width, npix) = (screen.width, (screen.width * screen.height) as usize);
    let channels = job.channels();
    let p = seg.cfg.p;
    let with_spec = !job.specular.is_empty() && spec.is_some();
    let total = (job.shaded_pixels() * (channels as u64 + with_spec as u64)).max(1);
    let done = AtomicU64::new(0);
    let owner = &job.owner;
    const SEED: u64 = 1;

    let (diffuse, coverage, segment, writer, spec_out) = std::thread::scope(|s| {
        let seg_threads: Vec<_> = job
            .stims
            .iter()
            .enumerate()
            .map(|(c, stims)| {
                let done = &done;
                s.spawn(move || {
                    let mut img = vec![0u8; npix];
                    let mut cov = if c == 0 { vec![0u16; npix] } else { Vec::new() };
                    let mut paint = |triangle: usize, y: u32, out: &SegView| {
                        let mut n = 0;
                        for i in (0..p).filter(|&i| out.lane_enabled(i)) {
                            let x = out.out_x + i;
                            if x >= width {
                                continue;
                            }
                            let idx = (y * width + x) as usize;
                            n += 1;
                            if c == 0 {
                                cov[idx] = cov[idx].saturating_add(1);
                            }
                            if owner[idx] == triangle as u32 {
                                img[idx] = out.pix[i as usize];
                            }
                        }
                        done.fetch_add(n, Ordering::Relaxed);
                    };
                    // Through memory the paint only counts: the image is read out of memory.
                    let to_memory = matches!(chain, Chain::HostToMemory(_) | Chain::RtlToMemory(_));
                    let mut lanes: Vec<SegStim> = Vec::new();
                    let report = match (chain, exps) {
                        (Chain::Rtl(info), Some(exps)) => stream_chain(info, SEED + c as u64, Traffic::FULL, &exps[c], paint),
                        (Chain::RtlToMemory(info), Some(exps)) => {
                            let run = stream_fb(info, SEED + c as u64, Traffic::FULL, &exps[c], Some(owner.clone()));
                            done.fetch_add(run.report.pixels, Ordering::Relaxed);
                            img = memory_image(&run.frame);
                            if c == 0 {
                                cov = run.mem.screen_writes().into_iter().map(u16::from).collect();
                            }
                            run.report
                        }
                        _ => {
                            let mut sim = SegmentCosim::new(seg, SEED + c as u64, Traffic::FULL);
                            let mut report = Report { triangles: job.drawn, ..Report::default() };
                            // (span number, segment index) of the last segment; a span's
                            // segments come one after another, so a new `&Stim` is a new span.
                            let mut at: Option<(usize, usize, u32)> = None;
                            sim.stream(stims, &mut report, |stim, out| {
                                if to_memory {
                                    // The RTL's segments, as they came out, go on to the writer.
                                    let addr = stim as *const Stim as usize;
                                    let (span_index, s) = match at {
                                        Some((prev, k, s)) if prev == addr => (k, s + 1),
                                        Some((_, k, _)) => (k + 1, 0),
                                        None => (0, 0),
                                    };
                                    at = Some((addr, span_index, s));
                                    let mut l = out.pix[..p as usize].to_vec();
                                    l.extend_from_slice(&out.mask[..p.div_ceil(8) as usize]);
                                    let lanes_of = Some(l.into_boxed_slice());
                                    lanes.push(SegStim {
                                        span_index,
                                        triangle: Some(stim.triangle),
                                        y: stim.y,
                                        span: stim.span,
                                        s,
                                        lanes: lanes_of,
                                    });
                                }
                                paint(stim.triangle, stim.y, out)
                            });
                            report
                        }
                    };
                    let writer = match chain {
                        Chain::HostToMemory(info) => {
                            let w = Writer::new(info.cfg, screen).expect("the job's screen fits the writer");
                            let run = run_segments(info, SEED + c as u64, Traffic::FULL, Stress::NONE, &lanes, w, Some(owner.clone()));
                            img = memory_image(&run.mem.memory.frame());
                            Some(run.report)
                        }
                        _ => None,
                    };
                    (img, cov, report, writer)
                })
            })
            .collect();
        let spec_thread = spec.filter(|_| with_spec).map(|info| {
            let done = &done;
            s.spawn(move || {
                let mut out = vec![0u16; npix];
                let mut sim = SpecularCosim::new(info, specular_unit(), SEED, Traffic::FULL);
                let mut report = Report { triangles: job.drawn, ..Report::default() };
                let stims = &job.stims[0];
                sim.stream_with(&job.specular, &mut report, |k, j, o| {
                    let st = &stims[k];
                    let idx = (st.y * width + st.span.x0 + j) as usize;
                    if owner[idx] == st.triangle as u32 {
                        out[idx] = o.out_spec;
                    }
                    done.fetch_add(1, Ordering::Relaxed);
                });
                (out, report)
            })
        });
        while !(seg_threads.iter().all(|t| t.is_finished()) && spec_thread.as_ref().is_none_or(|t| t.is_finished())) {
            progress(done.load(Ordering::Relaxed) as f64 / total as f64);
            std::thread::sleep(Duration::from_millis(10));
        }
        progress(1.0);
        let mut diffuse = Vec::new();
        let mut coverage = Vec::new();
        let mut reports = Vec::new();
        let mut writers = Vec::new();
        for (c, t) in seg_threads.into_iter().enumerate() {
            let (img, cov, report, writer) = t.join().expect("segment co-simulation thread panicked");
            if c == 0 {
                coverage = cov;
            }
            writers.extend(writer);
            diffuse.push(img);
            reports.push(report);
        }
        let spec_out = spec_thread.map(|t| t.join().expect("specular co-simulation thread panicked"));
        (diffuse, coverage, reports, writers, spec_out)
    });

    // Golden: the same spans, the same ownership, golden's pixels (the host's spans, or with
    // the RTL front-end golden's front-end spans; then the host's image is kept beside).
    let frac = seg.cfg.frac;
    let paint_golden = |spans: &mut dyn Iterator<Item = (usize, u32, Span)>, img: &mut [u8]| {
        for (triangle, y, span) in spans {
            for j in 0..span.len {
                let idx = (y * width + span.x0 + j) as usize;
                if owner[idx] == triangle as u32 {
                    img[idx] = span.pixel(j, frac);
                }
            }
        }
    };
    let mut host_diffuse = vec![vec![0u8; npix]; channels];
    for (c, stims) in job.stims.iter().enumerate() {
        paint_golden(&mut stims.iter().map(|s| (s.triangle, s.y, s.span)), &mut host_diffuse[c]);
    }
    let gold_diffuse = match exps {
        Some(exps) => {
            let mut g = vec![vec![0u8; npix]; channels];
            for (c, exp) in exps.iter().enumerate() {
                let mut it = exp
                    .stims
                    .iter()
                    .flat_map(|st| exp.spans[st.first..st.first + st.count as usize].iter().map(move |&(y, s)| (st.triangle, y, s)));
                paint_golden(&mut it, &mut g[c]);
            }
            g
        }
        None => host_diffuse.clone(),
    };
    let gold_spec = with_spec.then(|| {
        let unit = specular_unit();
        let mut out = vec![0u16; npix];
        for (st, sp) in job.stims[0].iter().zip(&job.specular) {
            for (j, px) in unit.span(sp).enumerate() {
                let idx = (st.y * width + st.span.x0 + j as u32) as usize;
                if owner[idx] == st.triangle as u32 {
                    out[idx] = px.spec;
                }
            }
        }
        out
    });
    let (spec_img, spec_report) = match spec_out {
        Some((img, r)) => (Some(img), Some(r)),
        None => (None, None),
    };
    Outcome {
        rtl: compose(&diffuse, spec_img.as_deref(), owner),
        golden: compose(&gold_diffuse, gold_spec.as_deref(), owner),
        host: exps.is_some().then(|| compose(&host_diffuse, gold_spec.as_deref(), owner)),
        coverage,
        segment,
        specular: spec_report,
        writer,
    }
}

/// A channel of the image out of memory: background (never written) 0.
fn memory_image(frame: &golden::raster::Frame) -> Vec<u8> {
    let w = frame.width();
    (0..w * frame.height()).map(|k| frame.get(k % w, k / w).unwrap_or(0)).collect()
}

/// Diffuse channels plus the white highlight, saturated; background 0.
fn compose(diffuse: &[Vec<u8>], spec: Option<&[u16]>, owner: &[u32]) -> Vec<u8> {
    let channels = diffuse.len();
    let mut img = vec![0u8; owner.len() * channels];
    for (idx, &o) in owner.iter().enumerate() {
        if o == BACKGROUND {
            continue;
        }
        let hi = spec.map_or(0, |s| spec_level(s[idx]));
        for c in 0..channels {
            img[idx * channels + c] = (diffuse[c][idx] as u32 + hi).min(255) as u8;
        }
    }
    img
}

/// A difference image (RGB): matching pixels as a dim gray copy of golden, differing pixels
/// bright red (brighter the larger the difference).
pub fn difference_image(rtl: &[u8], golden: &[u8], channels: usize) -> Vec<u8> {
    let mut out = Vec::with_capacity(rtl.len() / channels * 3);
    for (a, b) in rtl.chunks(channels).zip(golden.chunks(channels)) {
        let diff = a.iter().zip(b).map(|(x, y)| x.abs_diff(*y)).max().unwrap_or(0);
        if diff == 0 {
            let g = (b.iter().map(|&v| v as u32).sum::<u32>() / channels as u32 / 4) as u8;
            out.extend([g, g, g]);
        } else {
            out.extend([(128 + diff as u32 / 2).min(255) as u8, 0, 0]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn difference_image_marks_differing_pixels_red() {
        let golden = [100u8, 100, 100, 40, 40, 40];
        let rtl = [100u8, 100, 100, 40, 41, 40];
        assert_eq!(difference_image(&rtl, &golden, 3), vec![25, 25, 25, 128, 0, 0]);
        assert_eq!(difference_image(&[0, 255], &[0, 0], 1), vec![0, 0, 0, 255, 0, 0]);
        assert_eq!(spec_level(0), 0);
        assert_eq!(spec_level(127), 0);
        assert_eq!(spec_level(128), 1);
        assert_eq!(spec_level(u16::MAX), 256);
    }

    /// An OBJ quad mesh: triangulated, moved into the unit sphere, smooth unit normals pointing
    /// outward; OBJ text that is not a mesh is refused with a reason.
    #[test]
    fn obj_meshes_are_read_triangulated_and_framed() {
        let cube = "v 0 0 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\nv 0 0 2\nv 2 0 2\nv 2 2 2\nv 0 2 2\n\
                    f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
        let m = obj_mesh(cube).unwrap();
        assert_eq!(m.faces.len(), 12);
        for (p, n) in m.positions.iter().zip(&m.normals) {
            assert!((dot(*p, *p).sqrt() - 1.0).abs() < 1e-9, "every corner on the unit sphere");
            assert!((dot(*n, *n) - 1.0).abs() < 1e-9 && dot(*n, *p) > 0.0, "unit normals, outward");
        }
        assert!(obj_mesh("v 0 0 0\n").unwrap_err().contains("no faces"));
        assert!(obj_mesh("f 1 2 3\n").is_err());
    }

    #[test]
    fn meshes_are_closed_and_outward() {
        for (m, want) in [(sphere(8, 12), 2 * 12 * 7), (torus(16, 8, 1.0, 0.4), 2 * 16 * 8)] {
            assert_eq!(m.faces.len(), want);
            // Closed: every directed edge has its reverse.
            let mut edges = std::collections::HashSet::new();
            for f in &m.faces {
                for k in 0..3 {
                    assert!(edges.insert((f[k], f[(k + 1) % 3])), "edge used twice in one direction");
                }
            }
            for &(a, b) in &edges {
                assert!(edges.contains(&(b, a)), "open edge");
            }
            // Outward: the face normal agrees with the vertex normals.
            for f in &m.faces {
                let p = f.map(|k| m.positions[k as usize]);
                let n = cross(sub(p[1], p[0]), sub(p[2], p[0]));
                assert!(f.iter().all(|&k| dot(n, m.normals[k as usize]) > 0.0));
            }
        }
    }
}
