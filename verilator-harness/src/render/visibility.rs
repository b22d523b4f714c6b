//! The job of a render: every span of every channel, the specular span of each, and who owns
//! every pixel. Visibility is decided here, on the host, before any shading: back-face culling
//! and a depth pre-pass for meshes, file order for triangle files (see [`super`]).

use super::mesh::{add, lighting, obj_mesh, rotate_xy, scale, scene, sub, Lighting, Mesh, MeshError, SceneKind};
use crate::segment::Stim;
use golden::frontend::FixedTriangle;
use golden::setup::{parse_triangles, triangle_spans, ParseError, Screen, ScreenError, SetupError, Triangle, Vertex};
use golden::specular::geometry::{cross, dot, normalize, SpanEnds, Vec3};
use golden::specular::setup::setup_span;
use golden::specular::SpecularSpan;
use golden::Config;

/// `owner` of a pixel no triangle covers.
pub const BACKGROUND: u32 = u32::MAX;

/// Why no job is made of a scene, mesh or triangle file.
#[derive(Debug, thiserror::Error)]
pub enum JobError {
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// A triangle file's line (`line N: ...`).
    #[error(transparent)]
    Parse(#[from] ParseError),
    #[error(transparent)]
    Screen(#[from] ScreenError),
    /// The set-up refuses a triangle, numbered from 1 in input order.
    #[error("triangle {triangle}: {error}")]
    Triangle { triangle: usize, error: SetupError },
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
pub fn scene_job(kind: SceneKind, shininess: u16, cfg: &Config, screen: &Screen) -> Result<Job, JobError> {
    let (mesh, light, radius) = scene(kind, shininess);
    mesh_job(&mesh, &light, radius, cfg, screen)
}

/// The job of an OBJ mesh ([`obj_mesh`]), lit like the built-in scenes in a warm grey and
/// turned like the torus, so a box shows three faces.
pub fn obj_job(text: &str, shininess: u16, cfg: &Config, screen: &Screen) -> Result<Job, JobError> {
    let mut mesh = obj_mesh(text)?;
    for v in mesh.positions.iter_mut().chain(mesh.normals.iter_mut()) {
        *v = rotate_xy(*v, 0.5, 0.35);
    }
    mesh_job(&mesh, &lighting([0.85, 0.78, 0.62], shininess), 1.0, cfg, screen)
}

/// The job of a mesh inside a sphere of `radius` around the origin, lit by `light`.
pub fn mesh_job(mesh: &Mesh, light: &Lighting, radius: f64, cfg: &Config, screen: &Screen) -> Result<Job, JobError> {
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
            triangle_spans(cfg, screen, &t, |y, span| stims.push(Stim { triangle: tri as usize, y, span }))
                .map_err(|error| JobError::Triangle { triangle: tri as usize + 1, error })?;
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
pub fn triangles_job(text: &str, cfg: &Config, screen: &Screen) -> Result<Job, JobError> {
    let tris = parse_triangles(text)?;
    triangles_job_of(&tris, cfg, screen)
}

/// As [`triangles_job`], for triangles already parsed.
pub fn triangles_job_of(tris: &[Triangle], cfg: &Config, screen: &Screen) -> Result<Job, JobError> {
    screen.check_for(cfg)?;
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
        .map_err(|error| JobError::Triangle { triangle: k + 1, error })?;
    }
    Ok(job)
}
