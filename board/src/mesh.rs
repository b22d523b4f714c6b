//! The board's default picture: a Wavefront mesh (the Newell teapot, meshes/teapot.obj) turned,
//! lit (Gouraud, one grey light), back faces culled, and sorted back to front by each
//! triangle's mean depth, as a triangle file for the 320 x 240 frame buffer. The board has no
//! depth buffer: drawing in this order is the painter's algorithm.
//! `board mesh --obj FILE.obj --out FILE.txt` writes it; docs/teapot-board.txt is its output for
//! the teapot, and a test keeps the two equal.

#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    #[error("{0}")]
    Obj(#[from] tobj::LoadError),
    #[error("no faces, or a coordinate that is not finite")]
    Empty,
}

type V3 = [f64; 3];

fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// About y by `yaw`, then about x by `pitch` (the top tipped toward the viewer at +z).
fn turn(v: V3, yaw: f64, pitch: f64) -> V3 {
    let (sy, cy) = yaw.sin_cos();
    let (sp, cp) = pitch.sin_cos();
    let (x, z) = (cy * v[0] + sy * v[2], -sy * v[0] + cy * v[2]);
    [x, cp * v[1] - sp * z, sp * v[1] + cp * z]
}

/// The triangle file's text for the mesh in `obj` on a `width` x `height` screen.
pub fn painter_triangles(obj: &str, name: &str, width: f64, height: f64) -> Result<(String, usize, usize), MeshError> {
    let opts = tobj::LoadOptions { triangulate: true, single_index: true, ..Default::default() };
    let (models, _) = tobj::load_obj_buf(&mut obj.as_bytes(), &opts, |_| Err(tobj::LoadError::OpenFileFailed))?;
    let (mut pos, mut nrm, mut faces) = (Vec::new(), Vec::new(), Vec::new());
    for m in &models {
        let (mm, base) = (&m.mesh, pos.len());
        for k in 0..mm.positions.len() / 3 {
            let p = [0, 1, 2].map(|c| mm.positions[3 * k + c] as f64);
            let n = if mm.normals.len() == mm.positions.len() { [0, 1, 2].map(|c| mm.normals[3 * k + c] as f64) } else { [0.0, 0.0, 0.0] };
            pos.push(turn(p, 0.6, 0.45));
            nrm.push(turn(n, 0.6, 0.45));
        }
        faces.extend(mm.indices.chunks_exact(3).map(|f| [0, 1, 2].map(|c| base + f[c] as usize)));
    }
    if faces.is_empty() || pos.iter().flatten().any(|v| !v.is_finite()) {
        return Err(MeshError::Empty);
    }
    // Orthographic, the bounding box's centre at the screen's, 90 % of the tighter side.
    let lo = pos.iter().fold([f64::INFINITY; 3], |a, p| [0, 1, 2].map(|c| a[c].min(p[c])));
    let hi = pos.iter().fold([f64::NEG_INFINITY; 3], |a, p| [0, 1, 2].map(|c| a[c].max(p[c])));
    let s = 0.9 * (width / (hi[0] - lo[0])).min(height / (hi[1] - lo[1]));
    let (cx, cy) = ((lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0);
    let screen = |p: V3| (width / 2.0 + s * (p[0] - cx), height / 2.0 - s * (p[1] - cy));
    let light = {
        let l: V3 = [-0.45, 0.6, 0.66];
        let n = dot(l, l).sqrt();
        l.map(|c| c / n)
    };
    let grey = |n: V3| {
        let len = dot(n, n).sqrt();
        let d = if len > 0.0 { dot(n, light) / len } else { 0.0 };
        255.0 * (0.12 + 0.88 * d.max(0.0))
    };
    let mut front: Vec<(f64, [usize; 3])> = faces
        .iter()
        .filter(|f| {
            // Counter-clockwise seen from outside: facing the viewer when z of the normal > 0.
            let (a, b, c) = (pos[f[0]], pos[f[1]], pos[f[2]]);
            (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) > 0.0
        })
        .map(|f| (f.iter().map(|&k| pos[k][2]).sum::<f64>(), *f))
        .collect();
    // Farthest (smallest z) first; ties keep the file's order.
    front.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out = format!("# {name} turned, lit in grey, back faces culled, sorted back to front (the board draws in file\n");
    out.push_str(&format!("# order, the painter's algorithm): written by `board mesh --obj {name} --out FILE`.\n"));
    for (_, f) in &front {
        let v: Vec<String> = f
            .iter()
            .map(|&k| {
                let (x, y) = screen(pos[k]);
                format!("{x:.3} {y:.3} {:.2}", grey(nrm[k]))
            })
            .collect();
        out.push_str(&v.join("  "));
        out.push('\n');
    }
    Ok((out, faces.len(), front.len()))
}
