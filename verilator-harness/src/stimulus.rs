//! Triangles to drive the co-simulation: random ones over every size class, and directed ones
//! for the corners a random mix rarely hits.

use golden::setup::{Screen, Triangle, Vertex};
use golden::Config;
use rand::Rng;

fn vertex(x: f64, y: f64, i: f64) -> Vertex {
    Vertex { x, y, i }
}

fn tri(v: [(f64, f64, f64); 3]) -> Triangle {
    Triangle { v: v.map(|(x, y, i)| vertex(x, y, i)) }
}

/// A random triangle of about `radius` pixels around a random point of (or just beyond) the
/// screen, with random vertex intensities. Vertices are kept inside the set-up's limits.
pub fn triangle_of_radius(rng: &mut impl Rng, screen: &Screen, radius: f64) -> Triangle {
    let (w, h) = (screen.width as f64, screen.height as f64);
    let margin = radius.min(w.max(h));
    let cx = rng.gen_range(-margin * 0.5..w + margin * 0.5);
    let cy = rng.gen_range(-margin * 0.5..h + margin * 0.5);
    let limit = golden::setup::COORD_LIMIT;
    let mut corner = |_| {
        let a: f64 = rng.gen_range(0.0..std::f64::consts::TAU);
        let r = radius * rng.gen_range(0.2..1.0);
        let x = (cx + r * a.cos()).clamp(-limit, limit);
        let y = (cy + r * a.sin()).clamp(-limit, limit);
        vertex(x, y, rng.gen_range(0.0..=255.0))
    };
    Triangle { v: [0, 1, 2].map(&mut corner) }
}

/// A long thin triangle: two vertices close together, the third far away.
pub fn sliver(rng: &mut impl Rng, screen: &Screen) -> Triangle {
    let (w, h) = (screen.width as f64, screen.height as f64);
    let x = rng.gen_range(0.0..w);
    let y = rng.gen_range(0.0..h);
    let (dx, dy) = (rng.gen_range(-0.8..0.8), rng.gen_range(-0.8..0.8));
    tri([
        (x, y, rng.gen_range(0.0..=255.0)),
        (x + dx, y + dy, rng.gen_range(0.0..=255.0)),
        (rng.gen_range(0.0..w), rng.gen_range(0.0..h), rng.gen_range(0.0..=255.0)),
    ])
}

/// The random mix: 10% slivers, 3% larger than the screen, the rest log-uniform in size from
/// sub-pixel to a third of the screen (so small and large triangles are equally common, and
/// the huge ones that cost most simulation time stay few).
pub fn random_triangle(rng: &mut impl Rng, screen: &Screen) -> Triangle {
    let side = screen.width.max(screen.height) as f64;
    let class: f64 = rng.gen();
    if class < 0.10 {
        sliver(rng, screen)
    } else if class < 0.13 {
        let radius = rng.gen_range(side..2.0 * side);
        triangle_of_radius(rng, screen, radius)
    } else {
        let radius = rng.gen_range(0.3f64.ln()..(side / 3.0).ln()).exp();
        triangle_of_radius(rng, screen, radius)
    }
}

/// Directed cases for `cfg` on `screen`, each with a name for failure messages.
pub fn directed(cfg: &Config, screen: &Screen) -> Vec<(String, Triangle)> {
    let (w, h) = (screen.width as f64, screen.height as f64);
    let p = cfg.p as f64;
    let mut cases: Vec<(String, Triangle)> = vec![
        ("tiny, covers one centre".into(), tri([(10.3, 10.3, 50.0), (10.8, 10.4, 60.0), (10.5, 10.9, 70.0)])),
        ("tiny, covers no centre".into(), tri([(10.6, 10.6, 50.0), (10.9, 10.6, 60.0), (10.7, 10.9, 70.0)])),
        ("sliver".into(), tri([(0.2, 1.0, 0.0), (w - 0.5, 1.3, 255.0), (0.3, 1.2, 128.0)])),
        ("huge, covers the screen".into(), tri([(-4000.0, -4000.0, 0.0), (8000.0, -10.0, 255.0), (-10.0, 8000.0, 255.0)])),
        ("off-screen".into(), tri([(-50.0, -50.0, 10.0), (-10.0, -40.0, 20.0), (-30.0, -5.0, 30.0)])),
        ("off the right edge".into(), tri([(w - 5.0, 10.0, 255.0), (w + 50.0, 20.0, 0.0), (w - 20.0, 40.0, 100.0)])),
        ("off the bottom".into(), tri([(10.0, h - 3.0, 255.0), (60.0, h + 30.0, 0.0), (5.0, h + 10.0, 100.0)])),
        ("zero area, collinear".into(), tri([(1.0, 1.0, 0.0), (50.0, 50.0, 255.0), (100.0, 100.0, 128.0)])),
        ("zero area, repeated vertex".into(), tri([(5.0, 5.0, 0.0), (5.0, 5.0, 255.0), (40.0, 9.0, 128.0)])),
        ("one-pixel spans at a tip".into(), tri([(20.5, 2.0, 0.0), (20.6, 60.0, 255.0), (20.4, 60.0, 128.0)])),
        ("steep intensity".into(), tri([(30.0, 30.0, 0.0), (31.0, 30.0, 255.0), (30.5, 90.0, 0.0)])),
        ("saturating plane".into(), tri([(0.0, 0.0, 255.0), (w, 0.0, 255.0), (0.0, 40.0, 0.0)])),
    ];
    // Rectangles whose spans are exact multiples of P, from aligned and unaligned starts, and
    // one that reaches the last column of the screen.
    let x_last = w;
    for (k, x0) in [(1.0, 0.0), (2.0, 3.0), (4.0, p), (3.0, p + 1.0), (1.0, x_last - p), (2.0, x_last - 2.0 * p - 5.0)] {
        if x0 < 0.0 || x0 + k * p > w {
            continue;
        }
        let (x1, y0, y1) = (x0 + k * p, 100.0_f64.min(h - 8.0), 100.0_f64.min(h - 8.0) + 6.0);
        let name = format!("rectangle {} x 6 at x = {x0}", k * p);
        cases.push((format!("{name}, upper"), tri([(x0, y0, 0.0), (x1, y0, 255.0), (x0, y1, 40.0)])));
        cases.push((format!("{name}, lower"), tri([(x1, y0, 255.0), (x1, y1, 200.0), (x0, y1, 40.0)])));
    }
    cases
}
