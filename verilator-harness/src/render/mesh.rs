//! Meshes and scenes: the built-in sphere and torus, Wavefront OBJ files, and every scene's
//! camera, light and material. Geometry only: nothing here knows the screen or the hardware.

use golden::specular::geometry::{cross, dot, normalize, Vec3};
use std::f64::consts::{PI, TAU};

/// An OBJ text that is no mesh the renderer can frame.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    #[error("not a Wavefront OBJ mesh: {0}")]
    Obj(tobj::LoadError),
    #[error("the OBJ file has no faces")]
    NoFaces,
    #[error("the OBJ file has a vertex that is not a finite number")]
    NotFinite,
    #[error("the OBJ mesh has no extent")]
    NoExtent,
    /// A face of fewer than three vertices (the OBJ reader would drop it without a word).
    #[error("line {line}: a face needs at least 3 vertices, this one has {vertices}")]
    ShortFace { line: usize, vertices: usize },
}

/// The first `f` statement of fewer than three vertices.
fn short_face(text: &str) -> Option<MeshError> {
    text.lines().enumerate().find_map(|(n, line)| {
        let words: Vec<&str> = line.split('#').next().unwrap_or("").split_whitespace().collect();
        (words.first() == Some(&"f") && words.len() < 4).then(|| MeshError::ShortFace { line: n + 1, vertices: words.len() - 1 })
    })
}

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

pub(super) fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
pub(super) fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
pub(super) fn scale(a: Vec3, s: f64) -> Vec3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
/// Rotation about x by `ax`, then about y by `ay`.
pub(super) fn rotate_xy(p: Vec3, ax: f64, ay: f64) -> Vec3 {
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
pub(super) fn lighting(colour: [f64; 3], shininess: u16) -> Lighting {
    Lighting { eye: [0.0, 0.0, 4.5], light: [-4.0, 4.5, 6.0], colour, ambient: 0.07, diffuse: 0.93, specular: 235.0, shininess }
}

/// A Wavefront OBJ mesh (`tobj`: polygons triangulated, every object of the file), moved and
/// scaled into the unit sphere the camera frames. Normals: the file's where every vertex has
/// one, else smooth normals from the faces (area-weighted), the faces' winding taken as given
/// (counter-clockwise seen from outside, OBJ's convention). Materials are ignored.
pub fn obj_mesh(text: &str) -> Result<Mesh, MeshError> {
    if let Some(e) = short_face(text) {
        return Err(e);
    }
    let opts = tobj::LoadOptions { triangulate: true, single_index: true, ..Default::default() };
    let (models, _) = tobj::load_obj_buf(&mut text.as_bytes(), &opts, |_| Err(tobj::LoadError::OpenFileFailed)).map_err(MeshError::Obj)?;
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
        return Err(MeshError::NoFaces);
    }
    if mesh.positions.iter().flatten().any(|v| !v.is_finite()) {
        return Err(MeshError::NotFinite);
    }
    // Into the unit sphere: the bounding box's centre to the origin, the farthest vertex at 1.
    let lo = mesh.positions.iter().fold([f64::INFINITY; 3], |a, p| [0, 1, 2].map(|c| a[c].min(p[c])));
    let hi = mesh.positions.iter().fold([f64::NEG_INFINITY; 3], |a, p| [0, 1, 2].map(|c| a[c].max(p[c])));
    let centre = [0, 1, 2].map(|c| (lo[c] + hi[c]) / 2.0);
    let r = mesh.positions.iter().map(|p| dot(sub(*p, centre), sub(*p, centre)).sqrt()).fold(0.0, f64::max);
    if r <= 0.0 {
        return Err(MeshError::NoExtent);
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

#[cfg(test)]
mod tests {
    use super::*;

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
        assert!(matches!(obj_mesh("v 0 0 0\n"), Err(MeshError::NoFaces)));
        assert!(matches!(obj_mesh("v 0 0 0\nv 0 0 0\nv 0 0 0\nf 1 2 3\n"), Err(MeshError::NoExtent)));
        assert!(matches!(obj_mesh("f 1 2 3\n"), Err(MeshError::Obj(_))));
        // A face of two vertices (or one, or none) is refused by line, also after a good one.
        let short = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n# c\nf 1 2\n";
        assert!(matches!(obj_mesh(short), Err(MeshError::ShortFace { line: 6, vertices: 2 })), "{:?}", obj_mesh(short).err());
        assert!(matches!(obj_mesh("v 0 0 0\nf 1\n"), Err(MeshError::ShortFace { line: 2, vertices: 1 })));
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
