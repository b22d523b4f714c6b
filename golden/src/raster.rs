//! Frame buffers, the exact f64 reference rasterizer and the SPEC §5 comparison.
//!
//! The reference shares only the snapping and the top-left classification with
//! `setup` (both are definitions, not computations). It finds coverage by evaluating the three
//! edge functions in `f64` at every pixel centre of the bounding box — exact, because the
//! snapped coordinates are multiples of 1/256 small enough that every product and difference
//! fits the 53-bit mantissa (see `setup`'s module documentation) — and keeps the exact plane
//! intensity so errors can be measured, not just bounded.

use crate::format::Span;
use crate::setup::{Screen, SetupError, Snapped, Triangle};
use std::fmt;

/// What the hardware (or the golden model standing in for it) wrote: 8-bit pixels and which
/// pixels were written at all.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Frame {
    width: u32,
    height: u32,
    pixels: Vec<u8>,
    covered: Vec<bool>,
}

impl Frame {
    pub fn new(width: u32, height: u32) -> Frame {
        let n = width as usize * height as usize;
        Frame { width, height, pixels: vec![0; n], covered: vec![false; n] }
    }

    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    fn index(&self, x: u32, y: u32) -> usize {
        assert!(x < self.width && y < self.height, "pixel ({x}, {y}) outside the {}x{} frame", self.width, self.height);
        y as usize * self.width as usize + x as usize
    }

    /// The pixel, or `None` if nothing wrote it.
    pub fn get(&self, x: u32, y: u32) -> Option<u8> {
        let k = self.index(x, y);
        self.covered[k].then_some(self.pixels[k])
    }

    /// Writes one pixel; later writes overwrite earlier ones, like a painter.
    pub fn set(&mut self, x: u32, y: u32, value: u8) {
        let k = self.index(x, y);
        self.pixels[k] = value;
        self.covered[k] = true;
    }

    /// Writes the golden pixels of a span (SPEC §2's pixel rule). Panics if the span leaves the
    /// frame: set-up never produces such a span, so it is a caller's bug.
    pub fn write_span(&mut self, y: u32, span: &Span, frac: u32) {
        if span.len == 0 {
            return;
        }
        let start = self.index(span.x0, y);
        assert!(
            span.x0 as u64 + span.len as u64 <= self.width as u64,
            "span x0 = {} len = {} leaves the {}-pixel row",
            span.x0,
            span.len,
            self.width
        );
        let end = start + span.len as usize;
        for (j, (p, c)) in self.pixels[start..end].iter_mut().zip(&mut self.covered[start..end]).enumerate() {
            *p = span.pixel(j as u32, frac);
            *c = true;
        }
    }

    pub fn clear(&mut self) {
        self.pixels.fill(0);
        self.covered.fill(false);
    }

    /// Row-major pixels; unwritten ones are 0.
    pub fn pixels(&self) -> &[u8] {
        &self.pixels
    }

    pub fn covered_count(&self) -> usize {
        self.covered.iter().filter(|&&c| c).count()
    }
}

/// The reference image: the exact plane intensity of every covered pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct RefFrame {
    width: u32,
    height: u32,
    /// NaN marks an uncovered pixel (a covered one is always a finite value in [0, 255]).
    values: Vec<f64>,
}

impl RefFrame {
    pub fn new(width: u32, height: u32) -> RefFrame {
        RefFrame { width, height, values: vec![f64::NAN; width as usize * height as usize] }
    }

    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    fn index(&self, x: u32, y: u32) -> usize {
        assert!(x < self.width && y < self.height, "pixel ({x}, {y}) outside the reference frame");
        y as usize * self.width as usize + x as usize
    }

    /// The exact intensity, or `None` if no triangle covered the pixel.
    pub fn get(&self, x: u32, y: u32) -> Option<f64> {
        let v = self.values[self.index(x, y)];
        (!v.is_nan()).then_some(v)
    }

    /// The intensity rounded as an 8-bit output pixel.
    pub fn rounded(&self, x: u32, y: u32) -> Option<u8> {
        self.get(x, y).map(round_intensity)
    }

    pub fn set(&mut self, x: u32, y: u32, value: f64) {
        assert!(!value.is_nan());
        let k = self.index(x, y);
        self.values[k] = value;
    }

    pub fn clear(&mut self) {
        self.values.fill(f64::NAN);
    }
}

/// An exact intensity rounded the way the pixel rule rounds: half up, clamped to 0..=255.
pub fn round_intensity(v: f64) -> u8 {
    (v + 0.5).floor().clamp(0.0, 255.0) as u8
}

/// Calls `f(x, y, I)` for every pixel of `screen` the triangle covers, `I` the exact plane
/// intensity at its centre, in row-major order. Checks its inputs like `triangle_spans`
/// (except that the screen need not fit a configuration).
pub fn reference_pixels(screen: &Screen, tri: &Triangle, mut f: impl FnMut(u32, u32, f64)) -> Result<(), SetupError> {
    screen.check()?;
    tri.check()?;
    let sn = Snapped::new(tri);
    let px = sn.x.map(|v| v as f64 / 256.0);
    let py = sn.y.map(|v| v as f64 / 256.0);
    let area = (px[1] - px[0]) * (py[2] - py[0]) - (py[1] - py[0]) * (px[2] - px[0]);
    if area == 0.0 || screen.width == 0 || screen.height == 0 {
        return Ok(());
    }
    let edges = [0, 1, 2].map(|k| {
        let (a, b) = ((k + 1) % 3, (k + 2) % 3);
        (px[a], py[a], px[b] - px[a], py[b] - py[a], sn.edge(k).top_left)
    });
    // A generous box: pixels outside it are rejected by the edge test anyway.
    let range = |c: [f64; 3], n: u32| {
        let lo = c.iter().copied().fold(f64::INFINITY, f64::min).floor() - 1.0;
        let hi = c.iter().copied().fold(f64::NEG_INFINITY, f64::max).ceil() + 1.0;
        (lo.max(0.0) as u32, hi.min(n as f64 - 1.0))
    };
    let (x_lo, x_hi) = range(px, screen.width);
    let (y_lo, y_hi) = range(py, screen.height);
    if x_hi < 0.0 || y_hi < 0.0 {
        return Ok(());
    }
    let (x_hi, y_hi) = (x_hi as u32, y_hi as u32);
    for y in y_lo..=y_hi {
        let cy = y as f64 + 0.5;
        for x in x_lo..=x_hi {
            let cx = x as f64 + 0.5;
            let mut w = [0.0; 3];
            let mut inside = true;
            for (k, &(ax, ay, dx, dy, top_left)) in edges.iter().enumerate() {
                w[k] = dx * (cy - ay) - dy * (cx - ax);
                inside &= w[k] > 0.0 || (w[k] == 0.0 && top_left);
            }
            if inside {
                f(x, y, (w[0] * sn.i[0] + w[1] * sn.i[1] + w[2] * sn.i[2]) / area);
            }
        }
    }
    Ok(())
}

/// Why [`reference_triangle`] paints nothing.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum ReferenceError {
    #[error(transparent)]
    Setup(#[from] SetupError),
    #[error("screen {}x{} and reference frame {}x{} differ", screen.width, screen.height, frame.0, frame.1)]
    FrameSize { screen: Screen, frame: (u32, u32) },
}

/// Paints the triangle's exact intensities into `frame` (later triangles overwrite earlier).
pub fn reference_triangle(screen: &Screen, tri: &Triangle, frame: &mut RefFrame) -> Result<(), ReferenceError> {
    if (screen.width, screen.height) != (frame.width, frame.height) {
        return Err(ReferenceError::FrameSize { screen: *screen, frame: (frame.width, frame.height) });
    }
    Ok(reference_pixels(screen, tri, |x, y, v| frame.set(x, y, v))?)
}

/// How a frame compares with the reference.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Comparison {
    /// Pixels covered by both.
    pub covered: u64,
    /// Pixels covered by the frame only, and by the reference only.
    pub only_frame: u64,
    pub only_reference: u64,
    /// First coverage mismatch in row-major order, (x, y).
    pub first_mismatch: Option<(u32, u32)>,
    /// Largest |frame - exact reference| over pixels covered by both, and where.
    pub max_error: f64,
    pub max_error_at: Option<(u32, u32)>,
    /// Largest |frame - reference rounded to 8 bits|, and where.
    pub max_diff: u32,
    pub max_diff_at: Option<(u32, u32)>,
}

impl Comparison {
    /// SPEC §5: the same pixels covered and no pixel more than 1 from the rounded reference.
    pub fn passed(&self) -> bool {
        self.only_frame == 0 && self.only_reference == 0 && self.max_diff <= 1
    }
}

impl fmt::Display for Comparison {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} covered pixels, {} only in frame, {} only in reference", self.covered, self.only_frame, self.only_reference)?;
        if let Some((x, y)) = self.first_mismatch {
            write!(f, " (first at ({x}, {y}))")?;
        }
        write!(f, ", max error {:.4}", self.max_error)?;
        if let Some((x, y)) = self.max_error_at {
            write!(f, " at ({x}, {y})")?;
        }
        write!(f, ", max rounded difference {}", self.max_diff)?;
        if let Some((x, y)) = self.max_diff_at {
            write!(f, " at ({x}, {y})")?;
        }
        f.write_str(if self.passed() { ": pass" } else { ": FAIL" })
    }
}

/// Compares two frames of the same size pixel by pixel.
pub fn compare(frame: &Frame, reference: &RefFrame) -> Comparison {
    assert_eq!((frame.width, frame.height), (reference.width, reference.height), "frame and reference sizes differ");
    let mut c = Comparison::default();
    for y in 0..frame.height {
        for x in 0..frame.width {
            match (frame.get(x, y), reference.get(x, y)) {
                (None, None) => {}
                (Some(_), None) | (None, Some(_)) => {
                    if frame.get(x, y).is_some() {
                        c.only_frame += 1;
                    } else {
                        c.only_reference += 1;
                    }
                    c.first_mismatch.get_or_insert((x, y));
                }
                (Some(p), Some(v)) => {
                    c.covered += 1;
                    let err = (p as f64 - v).abs();
                    if err > c.max_error || c.max_error_at.is_none() {
                        c.max_error = err;
                        c.max_error_at = Some((x, y));
                    }
                    let diff = (p as i32 - round_intensity(v) as i32).unsigned_abs();
                    if diff > c.max_diff || c.max_diff_at.is_none() {
                        c.max_diff = diff;
                        c.max_diff_at = Some((x, y));
                    }
                }
            }
        }
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::format::Config;
    use crate::rng::SeedRng;
    use crate::setup::{max_span_error, triangle_spans, Vertex, COORD_LIMIT};
    use rand::{Rng, SeedableRng};

    fn tri(p: [[f64; 3]; 3]) -> Triangle {
        Triangle { v: p.map(|[x, y, i]| Vertex { x, y, i }) }
    }

    /// Quantizes some coordinates onto pixel centres/corners or the sub-pixel grid, so edges
    /// through centres and axis-aligned edges are common.
    fn coord(rng: &mut SeedRng, v: f64) -> f64 {
        match rng.gen_range(0..4) {
            0 => (v * 2.0).round() / 2.0,
            1 => (v * 256.0).round() / 256.0,
            _ => v,
        }
        .clamp(-COORD_LIMIT, COORD_LIMIT)
    }

    fn intensity(rng: &mut SeedRng) -> f64 {
        match rng.gen_range(0..5) {
            0 => 0.0,
            1 => 255.0,
            2 => rng.gen_range(0..=255) as f64,
            _ => rng.gen_range(0.0..=255.0),
        }
    }

    fn random_triangle(rng: &mut SeedRng, screen: &Screen) -> Triangle {
        let (w, h) = (screen.width as f64, screen.height as f64);
        let mut p = [[0.0; 2]; 3];
        let anchor = [rng.gen_range(-20.0..w + 20.0), rng.gen_range(-20.0..h + 20.0)];
        match rng.gen_range(0..6) {
            // Tiny: a few pixels or less.
            0 => {
                let r = if rng.gen_bool(0.5) { 2.0 } else { 0.05 };
                for q in &mut p {
                    *q = [anchor[0] + rng.gen_range(-r..r), anchor[1] + rng.gen_range(-r..r)];
                }
            }
            // Medium.
            1 | 2 => {
                for q in &mut p {
                    *q = [anchor[0] + rng.gen_range(-60.0..60.0), anchor[1] + rng.gen_range(-60.0..60.0)];
                }
            }
            // Sliver: the third vertex a hair off the line through the other two.
            3 => {
                let a = [rng.gen_range(-w..2.0 * w), rng.gen_range(-h..2.0 * h)];
                let t: f64 = rng.gen_range(0.0..1.0);
                let off = rng.gen_range(-1.5..1.5) * if rng.gen_bool(0.5) { 1.0 } else { 0.01 };
                p = [anchor, a, [anchor[0] + t * (a[0] - anchor[0]) + off, anchor[1] + t * (a[1] - anchor[1]) - off]];
            }
            // Huge: up to the coordinate limit.
            4 => {
                for q in &mut p {
                    *q = [rng.gen_range(-COORD_LIMIT..COORD_LIMIT), rng.gen_range(-COORD_LIMIT..COORD_LIMIT)];
                }
            }
            // Large, around the screen, with an axis-aligned edge.
            _ => {
                for q in &mut p {
                    *q = [rng.gen_range(-w..2.0 * w), rng.gen_range(-h..2.0 * h)];
                }
                let k = rng.gen_range(0..2);
                p[1][k] = p[0][k];
            }
        }
        let mut v = [[0.0; 3]; 3];
        for (vk, q) in v.iter_mut().zip(p) {
            *vk = [coord(rng, q[0]), coord(rng, q[1]), intensity(rng)];
        }
        tri(v)
    }

    /// Spans against the reference, triangle by triangle (exact coverage, pixels within 1, one
    /// di per triangle equal to the rounded slope), and painter frames compared in batches.
    fn property(cfg: &Config, screen: &Screen, count: usize, rng: &mut SeedRng) -> f64 {
        assert!(max_span_error(cfg, screen.width) < 1.0, "test set-up: ±1 not guaranteed");
        let mut frame = Frame::new(screen.width, screen.height);
        let mut reference = RefFrame::new(screen.width, screen.height);
        let mut spans: Vec<(u32, Span)> = Vec::new();
        let mut worst = 0.0f64;
        for n in 0..count {
            let t = random_triangle(rng, screen);
            spans.clear();
            triangle_spans(cfg, screen, &t, |y, s| spans.push((y, s))).unwrap();
            let sn = Snapped::new(&t);
            let di = sn.di(cfg);
            let mut last_y = None;
            for (y, s) in &spans {
                s.check(cfg).unwrap();
                assert!(*y < screen.height && s.len > 0 && s.x0 + s.len <= screen.width, "{t}");
                assert!(last_y < Some(*y), "rows out of order: {t}");
                last_y = Some(*y);
                assert_eq!(s.di, di, "{t}");
                frame.write_span(*y, s, cfg.frac);
            }
            if spans.iter().any(|(_, s)| s.len >= 2) {
                // The slope from the plane equation in pixels, independent of Snapped::didx.
                let (x, y, i) = (sn.x.map(|v| v as f64 / 256.0), sn.y.map(|v| v as f64 / 256.0), sn.i);
                let slope = ((i[1] - i[0]) * (y[2] - y[0]) - (i[2] - i[0]) * (y[1] - y[0]))
                    / ((x[1] - x[0]) * (y[2] - y[0]) - (y[1] - y[0]) * (x[2] - x[0]));
                let scaled = slope * (1u64 << cfg.frac) as f64;
                assert!((di as f64 - scaled).abs() <= 0.5 + 1e-6, "di {di} vs {scaled}: {t}");
            }
            let mut covered = 0u64;
            reference_pixels(screen, &t, |x, y, v| {
                covered += 1;
                let k = spans.binary_search_by_key(&y, |s| s.0).unwrap_or_else(|_| panic!("({x}, {y}) in no span: {t}"));
                let s = spans[k].1;
                assert!(x >= s.x0 && x < s.x0 + s.len, "({x}, {y}) outside span {s:?}: {t}");
                let p = s.pixel(x - s.x0, cfg.frac);
                worst = worst.max((p as f64 - v).abs());
                assert!(p.abs_diff(round_intensity(v)) <= 1, "({x}, {y}): {p} vs {v}: {t}");
                reference.set(x, y, v);
            })
            .unwrap();
            let total: u64 = spans.iter().map(|(_, s)| s.len as u64).sum();
            assert_eq!(covered, total, "spans cover pixels the reference does not: {t}");
            if n % 32 == 31 {
                let c = compare(&frame, &reference);
                assert!(c.passed(), "{c}");
                frame.clear();
                reference.clear();
            }
        }
        worst
    }

    #[test]
    fn random_triangles_match_the_reference() {
        let mut rng = SeedRng::seed_from_u64(crate::rng::test_seed("random_triangles_match_the_reference"));
        let align = crate::Align::Span;
        let runs = [
            (Config::default(), Screen { width: 400, height: 300 }, 3000),
            (Config::new(8, 6, 7, align).unwrap(), Screen { width: 100, height: 60 }, 1500),
            (Config::new(4, 4, 5, align).unwrap(), Screen { width: 30, height: 20 }, 1500),
            (Config::new(16, 20, 16, align).unwrap(), Screen { width: 1000, height: 8 }, 300),
        ];
        for (cfg, screen, count) in runs {
            let worst = property(&cfg, &screen, count, &mut rng);
            println!("F = {}, {}x{}: max |pixel - exact| = {worst:.4}", cfg.frac, screen.width, screen.height);
        }
    }

    /// Coverage counts of a list of triangles, from spans and from the reference.
    fn counts(screen: &Screen, tris: &[Triangle]) -> (Vec<u32>, Vec<u32>) {
        let n = (screen.width * screen.height) as usize;
        let (mut a, mut b) = (vec![0u32; n], vec![0u32; n]);
        for t in tris {
            triangle_spans(&Config::default(), screen, t, |y, s| {
                for x in s.x0..s.x0 + s.len {
                    a[(y * screen.width + x) as usize] += 1;
                }
            })
            .unwrap();
            reference_pixels(screen, t, |x, y, _| b[(y * screen.width + x) as usize] += 1).unwrap();
        }
        (a, b)
    }

    #[test]
    fn jittered_mesh_covers_every_pixel_once() {
        let mut rng = SeedRng::seed_from_u64(crate::rng::test_seed("jittered_mesh_covers_every_pixel_once"));
        let screen = Screen { width: 200, height: 150 };
        for _ in 0..4 {
            // A lattice through pixel centres, extending two cells past the screen on every
            // side; jitter below 0.2 cell keeps both triangles of every quad positively oriented.
            let cell = rng.gen_range(3..20) as f64;
            let (nx, ny) = ((200.0 / cell) as usize + 5, (150.0 / cell) as usize + 5);
            let mut grid = vec![[0.0; 3]; nx * ny];
            for j in 0..ny {
                for i in 0..nx {
                    let jit = |rng: &mut SeedRng| match rng.gen_range(0..3) {
                        0 => 0.0,
                        1 => (rng.gen_range(-0.19..0.19) * cell * 2.0).round() / 2.0,
                        _ => rng.gen_range(-0.19..0.19) * cell,
                    };
                    let x = 0.5 + (i as f64 - 2.0) * cell + jit(&mut rng);
                    let y = 0.5 + (j as f64 - 2.0) * cell + jit(&mut rng);
                    grid[j * nx + i] = [x, y, intensity(&mut rng)];
                }
            }
            let mut tris = Vec::new();
            for j in 0..ny - 1 {
                for i in 0..nx - 1 {
                    let [a, b, c, d] = [grid[j * nx + i], grid[j * nx + i + 1], grid[(j + 1) * nx + i + 1], grid[(j + 1) * nx + i]];
                    if rng.gen_bool(0.5) {
                        tris.extend([tri([a, b, c]), tri([a, c, d])]);
                    } else {
                        tris.extend([tri([a, b, d]), tri([b, c, d])]);
                    }
                }
            }
            let (spans, reference) = counts(&screen, &tris);
            assert!(spans.iter().all(|&c| c == 1), "cell {cell}: spans cover a pixel {:?} times", spans.iter().find(|&&c| c != 1));
            assert!(reference.iter().all(|&c| c == 1), "cell {cell}: reference");
        }
    }

    #[test]
    fn fan_around_a_shared_vertex_covers_every_pixel_once() {
        let screen = Screen { width: 60, height: 40 };
        for centre in [[30.5, 20.5], [30.0, 20.0], [17.3, 9.81]] {
            for spokes in [4, 7, 32] {
                let corner = |k: usize| {
                    let a = std::f64::consts::TAU * k as f64 / spokes as f64 + 0.1;
                    [centre[0] + 500.0 * a.cos(), centre[1] + 500.0 * a.sin(), 100.0]
                };
                let c = [centre[0], centre[1], 0.0];
                let tris: Vec<_> = (0..spokes).map(|k| tri([c, corner(k), corner(k + 1)])).collect();
                let (a, b) = counts(&screen, &tris);
                assert!(a.iter().chain(&b).all(|&n| n == 1), "centre {centre:?}, {spokes} spokes");
            }
        }
    }

    #[test]
    fn compare_reports_coverage_and_value_differences() {
        let screen = Screen { width: 8, height: 4 };
        let mut reference = RefFrame::new(8, 4);
        let t = tri([[0.0, 0.0, 10.0], [8.0, 0.0, 10.0], [0.0, 4.0, 10.0]]);
        reference_triangle(&screen, &t, &mut reference).unwrap();
        assert_eq!(reference.get(0, 0), Some(10.0));
        assert_eq!(reference.get(7, 3), None);
        let mut frame = Frame::new(8, 4);
        triangle_spans(&Config::default(), &screen, &t, |y, s| frame.write_span(y, &s, 12)).unwrap();
        let c = compare(&frame, &reference);
        assert!(c.passed(), "{c}");
        assert_eq!((c.covered as usize, c.max_diff, c.max_error), (frame.covered_count(), 0, 0.0));

        frame.set(1, 1, 11);
        let c = compare(&frame, &reference);
        assert!(c.passed() && c.max_diff == 1 && c.max_diff_at == Some((1, 1)), "{c}");
        frame.set(1, 1, 12);
        assert!(!compare(&frame, &reference).passed());
        frame.set(1, 1, 10);
        frame.set(7, 3, 0);
        let c = compare(&frame, &reference);
        assert_eq!((c.only_frame, c.only_reference, c.first_mismatch), (1, 0, Some((7, 3))));
        assert!(!c.passed() && c.to_string().ends_with("FAIL"));
        frame.clear();
        let c = compare(&frame, &reference);
        assert_eq!((c.only_reference, c.first_mismatch), (reference_count(&reference), Some((0, 0))));
        let e = reference_triangle(&Screen { width: 9, height: 4 }, &t, &mut reference).unwrap_err();
        assert_eq!(e, ReferenceError::FrameSize { screen: Screen { width: 9, height: 4 }, frame: (reference.width, reference.height) });
    }

    fn reference_count(r: &RefFrame) -> u64 {
        (0..r.height()).flat_map(|y| (0..r.width()).map(move |x| (x, y))).filter(|&(x, y)| r.get(x, y).is_some()).count() as u64
    }

    #[test]
    fn rounding_of_the_reference_matches_the_pixel_rule() {
        for (v, p) in [(-0.4, 0), (0.49, 0), (0.5, 1), (254.5, 255), (255.0, 255), (300.0, 255)] {
            assert_eq!(round_intensity(v), p, "{v}");
        }
    }
}
