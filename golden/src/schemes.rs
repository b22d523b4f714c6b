//! Cycle models of the parallel shading schemes the seeds compare (SPEC §1), and of the segment
//! shader itself, so a workload's pixels per clock can be set side by side.
//!
//! What is counted: clocks of the *span interpolation* hardware, from the first span's transfer
//! to the last pixel's output, for a stream of triangles that the host has already set up
//! (SPEC §5). Assumptions, the same for every scheme so that only the parallelism differs:
//!
//! * **No per-span or per-triangle overhead.** Edge walking (the seeds' "linear interpolators"
//!   forming the triangle's edges) runs ahead of and in parallel with the span interpolation,
//!   and a new span loads in the clock the last pixels of the current one leave, as in the
//!   segment shader's RTL (which shows it: a full-rate stream has no bubble). A span with `m`
//!   pixels therefore costs exactly the clocks its pixels need.
//! * **One pipeline fill per stream**, [`fill`] = 2 clocks, the segment shader's latency, charged
//!   to every scheme (it is negligible for any real workload).
//! * **Only covered pixels are visited.** Spans come from the exact set-up of `setup`, clipped
//!   to the screen; a triangle that covers no pixel centre costs nothing.
//! * **Output ports are never the bottleneck**: a scheme that makes `k` pixels per clock can
//!   write `k` pixels per clock wherever they lie (two ends of a span, even and odd columns,
//!   four sub-triangles).
//!
//! Under these assumptions the RTL's clock count for `segment_shader_p<P>` is exactly
//! `Σ segments + fill()` ([`Scheme::Segment`]); the co-simulation sweep checks it clock for clock.

use crate::format::{Align, Config, Span};
use crate::setup::{triangle_spans, Screen, SetupError, Triangle, Vertex};
use std::fmt;

/// Pipeline fill charged once per stream: the latency of the segment shader as SPEC's seed builds it
/// (two register stages; `--pipeline` only adds fill).
pub fn fill() -> u64 {
    crate::segment::latency(&Config::default(), crate::pipeline::Pipeline::NONE) as u64
}

/// A span-interpolation scheme.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Scheme {
    /// The classical code interpolator: one pixel per clock, `I += dI`. `m` clocks per span.
    Classical,
    /// Seed (a): two code interpolators working toward each other from the span's two ends
    /// (the host also supplies the last pixel's intensity). `ceil(m/2)` clocks per span.
    CounterDirectional,
    /// Seed (b): two interpolators stepping `2dI`, one for the even and one for the odd pixels
    /// of the scanline. Whether parity is taken along the span or along the screen row, one of
    /// them has `ceil(m/2)` pixels of a run of `m`: `ceil(m/2)` clocks per span.
    EvenOdd,
    /// Seed (b) extended: four interpolators stepping `4dI` (2dI, 3dI, 4dI from one shift and
    /// one add), pixel `j` to interpolator `j mod 4`. `ceil(m/4)` clocks per span.
    FourInterpolators,
    /// Seed (d): the triangle's midlines cut it into four congruent triangles. One code
    /// interpolator shades the template (a corner sub-triangle) and three adders derive the
    /// other three, with four scanline walkers in lockstep. See [`midline_clocks`].
    MidlineSplit,
    /// `segment_shader_p<P>`: one segment of `p` pixels per clock; `ceil(m/p)` segments per
    /// span aligned to the span, `ceil(((x0 mod p) + m)/p)` aligned to the screen.
    Segment { p: u32, align: Align },
}

impl Scheme {
    /// The seeds' schemes that the segment shader is measured against, in SPEC §1's order
    /// (the seed-fill "wave" (c) is not modelled: its clock count depends on the contour-drawing
    /// and wave bookkeeping the seed leaves open).
    pub const BASELINES: [Scheme; 5] =
        [Scheme::Classical, Scheme::CounterDirectional, Scheme::EvenOdd, Scheme::FourInterpolators, Scheme::MidlineSplit];

    /// Clocks of one span of `len` pixels starting at column `x0`, for the schemes that work
    /// span by span (`None` for [`Scheme::MidlineSplit`], which works on whole triangles).
    pub fn span_clocks(&self, x0: u32, len: u32) -> Option<u64> {
        let m = len as u64;
        Some(match *self {
            Scheme::Classical => m,
            Scheme::CounterDirectional | Scheme::EvenOdd => m.div_ceil(2),
            Scheme::FourInterpolators => m.div_ceil(4),
            Scheme::Segment { p, align } => {
                let lead = if align == Align::Screen { x0 % p } else { 0 } as u64;
                if m == 0 {
                    0
                } else {
                    (lead + m).div_ceil(p as u64)
                }
            }
            Scheme::MidlineSplit => return None,
        })
    }

    /// Pixels this scheme produces per clock at best (its number of interpolators or lanes).
    pub fn width(&self) -> u32 {
        match *self {
            Scheme::Classical => 1,
            Scheme::CounterDirectional | Scheme::EvenOdd => 2,
            Scheme::FourInterpolators | Scheme::MidlineSplit => 4,
            Scheme::Segment { p, .. } => p,
        }
    }
}

impl fmt::Display for Scheme {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Scheme::Classical => f.write_str("classical one-pixel interpolator"),
            Scheme::CounterDirectional => f.write_str("two counter-directional interpolators"),
            Scheme::EvenOdd => f.write_str("even/odd pixels, two interpolators"),
            Scheme::FourInterpolators => f.write_str("four interpolators"),
            Scheme::MidlineSplit => f.write_str("midline split into four triangles"),
            Scheme::Segment { p, align } => write!(f, "segment shader p = {p}, {align}-aligned"),
        }
    }
}

/// A workload's totals under one scheme.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Count {
    pub triangles: u64,
    /// Spans of the original triangles (the set-up's output).
    pub spans: u64,
    /// Pixels of the original triangles: the same for every scheme.
    pub pixels: u64,
    /// Clocks, without the pipeline fill.
    pub clocks: u64,
}

impl Count {
    /// Clocks with the one pipeline fill of a stream ([`fill`]); 0 for an empty workload.
    pub fn total_clocks(&self) -> u64 {
        if self.clocks == 0 {
            0
        } else {
            self.clocks + fill()
        }
    }

    pub fn pixels_per_clock(&self) -> f64 {
        self.pixels as f64 / self.total_clocks().max(1) as f64
    }

    pub fn add(&mut self, o: &Count) {
        self.triangles += o.triangles;
        self.spans += o.spans;
        self.pixels += o.pixels;
        self.clocks += o.clocks;
    }
}

/// One triangle's count under `scheme`. `cfg` gives the formats of the set-up (its `p` and
/// `align` are ignored: the scheme says how spans are cut). Errors are the set-up's.
pub fn triangle_count(scheme: Scheme, cfg: &Config, screen: &Screen, tri: &Triangle) -> Result<Count, SetupError> {
    let mut c = Count { triangles: 1, ..Count::default() };
    let mut spans: Vec<Span> = Vec::new();
    triangle_spans(cfg, screen, tri, |_, s| spans.push(s))?;
    c.spans = spans.len() as u64;
    c.pixels = spans.iter().map(|s| s.len as u64).sum();
    c.clocks = match scheme {
        Scheme::MidlineSplit => midline_clocks(cfg, screen, tri)?,
        _ => spans.iter().filter_map(|s| scheme.span_clocks(s.x0, s.len)).sum(),
    };
    Ok(c)
}

/// The first triangle of a workload the set-up refuses, numbered from 0.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[error("triangle {triangle}: {error}")]
pub struct WorkloadError {
    pub triangle: usize,
    pub error: SetupError,
}

/// A workload's count under `scheme`: the triangles in order, one stream.
pub fn workload_count(scheme: Scheme, cfg: &Config, screen: &Screen, tris: &[Triangle]) -> Result<Count, WorkloadError> {
    let mut total = Count::default();
    for (triangle, t) in tris.iter().enumerate() {
        total.add(&triangle_count(scheme, cfg, screen, t).map_err(|error| WorkloadError { triangle, error })?);
    }
    Ok(total)
}

/// The four sub-triangles of `tri` cut by its midlines: three corner triangles, translates of
/// each other, and the middle one, a point reflection of them. The midpoints carry the mean
/// intensity of their edge's ends. Midpoints are exact in f64; they land on the set-up's
/// 1/256-pixel grid (so the four tile the original exactly, pixel for pixel) whenever the
/// vertices lie on the 1/128-pixel grid.
pub fn midline_split(tri: &Triangle) -> [Triangle; 4] {
    let [a, b, c] = tri.v;
    let mid = |p: Vertex, q: Vertex| Vertex { x: (p.x + q.x) / 2.0, y: (p.y + q.y) / 2.0, i: (p.i + q.i) / 2.0 };
    let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
    [Triangle { v: [a, ab, ca] }, Triangle { v: [ab, b, bc] }, Triangle { v: [ca, bc, c] }, Triangle { v: [ab, bc, ca] }]
}

/// Clocks of seed (d) for one triangle.
///
/// Hardware as the seed lays it out: four scanline walkers (one per sub-triangle), two edge
/// interpolators and one code interpolator shading the template, plus three adders that turn
/// the template's intensity into the other three's. All four advance in lockstep, one pixel
/// each per clock, so a clock can produce up to 4 pixels.
///
/// On the pixel grid the four sub-triangles are congruent but do not cover the same number of
/// pixels per row (a half-edge translation is rarely a whole number of pixels). Counted here:
/// row `r` of the lockstep takes as many clocks as the longest of the four sub-triangles' row
/// `r`, rows numbered from each sub-triangle's first covered row (from its last for the middle,
/// point-reflected one, whose scan runs the template's rows backwards). That is, the clocks are
/// `Σ_r max_k len_k(r)`, never less than a quarter of the pixels.
pub fn midline_clocks(cfg: &Config, screen: &Screen, tri: &Triangle) -> Result<u64, SetupError> {
    let subs = midline_split(tri);
    let mut rows: [Vec<u64>; 4] = Default::default();
    for (k, t) in subs.iter().enumerate() {
        triangle_spans(cfg, screen, t, |_, s| rows[k].push(s.len as u64))?;
    }
    rows[3].reverse();
    let n = rows.iter().map(Vec::len).max().unwrap_or(0);
    Ok((0..n).map(|r| rows.iter().map(|v| v.get(r).copied().unwrap_or(0)).max().unwrap_or(0)).sum())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SeedRng;
    use rand::{Rng, SeedableRng};

    fn tri(p: [[f64; 3]; 3]) -> Triangle {
        Triangle { v: p.map(|[x, y, i]| Vertex { x, y, i }) }
    }

    /// Random triangles of every size with vertices on the 1/128-pixel grid.
    fn random_tris(rng: &mut SeedRng, screen: &Screen, n: usize) -> Vec<Triangle> {
        (0..n)
            .map(|_| {
                let r: f64 = rng.gen_range(1.0f64.ln()..200.0f64.ln()).exp();
                let (cx, cy) = (rng.gen_range(0.0..screen.width as f64), rng.gen_range(0.0..screen.height as f64));
                let mut v = [[0.0; 3]; 3];
                for q in &mut v {
                    let g = |c: f64| (c * 128.0).round() / 128.0;
                    *q = [g(cx + rng.gen_range(-r..r)), g(cy + rng.gen_range(-r..r)), rng.gen_range(0.0..255.0)];
                }
                tri(v)
            })
            .collect()
    }

    fn spans(screen: &Screen, t: &Triangle) -> Vec<Span> {
        let mut v = Vec::new();
        triangle_spans(&Config::default(), screen, t, |_, s| v.push(s)).unwrap();
        v
    }

    #[test]
    fn schemes_span_counts() {
        let screen = Screen::default();
        let mut rng = SeedRng::seed_from_u64(7);
        let cfg = Config::default();
        for t in random_tris(&mut rng, &screen, 300) {
            let s = spans(&screen, &t);
            let m: Vec<u64> = s.iter().map(|s| s.len as u64).collect();
            let count = |sch| triangle_count(sch, &cfg, &screen, &t).unwrap();
            let pixels: u64 = m.iter().sum();
            assert_eq!(count(Scheme::Classical).clocks, pixels);
            assert_eq!(count(Scheme::Classical).pixels, pixels);
            let half: u64 = m.iter().map(|m| m.div_ceil(2)).sum();
            assert_eq!(count(Scheme::CounterDirectional).clocks, half);
            assert_eq!(count(Scheme::EvenOdd).clocks, half);
            assert_eq!(count(Scheme::FourInterpolators).clocks, m.iter().map(|m| m.div_ceil(4)).sum::<u64>());
            // p = 1 is the classical interpolator, p = 2 span-aligned the even/odd pair, p = 4
            // the four interpolators.
            for align in Align::ALL {
                assert_eq!(count(Scheme::Segment { p: 1, align }).clocks, pixels);
            }
            assert_eq!(count(Scheme::Segment { p: 2, align: Align::Span }).clocks, half);
            assert_eq!(count(Scheme::Segment { p: 4, align: Align::Span }).clocks, count(Scheme::FourInterpolators).clocks);
            // The segment model agrees with the configuration's own segment count.
            for p in [8, 16, 64] {
                for align in Align::ALL {
                    let c = Config { p, align, ..cfg };
                    let want: u64 = s.iter().map(|s| c.segment_count(s.x0, s.len) as u64).sum();
                    assert_eq!(count(Scheme::Segment { p, align }).clocks, want);
                }
            }
        }
    }

    #[test]
    fn schemes_worked_example() {
        // A span of 13 pixels from x = 6: 13, 7, 7, 4 clocks; p = 8 span 2, screen (6+13)/8 -> 3.
        let x = [Scheme::Classical, Scheme::CounterDirectional, Scheme::EvenOdd, Scheme::FourInterpolators];
        assert_eq!(x.map(|s| s.span_clocks(6, 13).unwrap()), [13, 7, 7, 4]);
        assert_eq!(Scheme::Segment { p: 8, align: Align::Span }.span_clocks(6, 13), Some(2));
        assert_eq!(Scheme::Segment { p: 8, align: Align::Screen }.span_clocks(6, 13), Some(3));
        assert_eq!(Scheme::Segment { p: 8, align: Align::Screen }.span_clocks(6, 0), Some(0));
        assert_eq!(Scheme::MidlineSplit.span_clocks(6, 13), None);
        // A right triangle with legs of 16 pixels on pixel corners. The centres on the
        // hypotenuse (x + y = 15) belong to the other side (it is a right edge): rows of 15..1
        // pixels, 120 in all.
        let t = tri([[0.0, 0.0, 0.0], [16.0, 0.0, 0.0], [0.0, 16.0, 0.0]]);
        let screen = Screen::default();
        let cfg = Config::default();
        let c = triangle_count(Scheme::Classical, &cfg, &screen, &t).unwrap();
        assert_eq!((c.spans, c.pixels, c.clocks), (15, 120, 120));
        // Its midline split: three corner triangles of rows 7..1 (28 pixels) and the middle one,
        // which owns the centres on its hypotenuse, of rows 1..8 (36). The lockstep runs the
        // middle one's rows backwards, 8..1 against 7..1: 36 clocks for 120 pixels.
        let m = triangle_count(Scheme::MidlineSplit, &cfg, &screen, &t).unwrap();
        let subs = midline_split(&t).map(|s| spans(&screen, &s).iter().map(|s| s.len as u64).sum::<u64>());
        assert_eq!(subs, [28, 28, 28, 36]);
        assert_eq!((m.pixels, m.clocks), (120, 36));
        assert_eq!(m.total_clocks(), 38);
    }

    #[test]
    fn schemes_midline_split_tiles_the_triangle() {
        let screen = Screen { width: 300, height: 200 };
        let mut rng = SeedRng::seed_from_u64(11);
        let cfg = Config::default();
        let (mut pixels, mut clocks) = (0u64, 0u64);
        for t in random_tris(&mut rng, &screen, 400) {
            let whole: u64 = spans(&screen, &t).iter().map(|s| s.len as u64).sum();
            let parts: u64 = midline_split(&t).iter().flat_map(|s| spans(&screen, s)).map(|s| s.len as u64).sum();
            assert_eq!(parts, whole, "{t}");
            let c = triangle_count(Scheme::MidlineSplit, &cfg, &screen, &t).unwrap();
            assert!(c.clocks * 4 >= c.pixels && c.clocks <= c.pixels, "{t}: {c:?}");
            pixels += c.pixels;
            clocks += c.clocks;
        }
        // Clipping to the screen and small triangles cost lockstep rows; still well over 2.
        let ppc = pixels as f64 / clocks as f64;
        assert!(ppc > 2.0 && ppc <= 4.0, "{ppc}");
        // Large triangles entirely on screen come close to 4 pixels per clock.
        let big = tri([[10.25, 3.5, 0.0], [290.0, 60.125, 255.0], [97.5, 190.75, 128.0]]);
        let c = triangle_count(Scheme::MidlineSplit, &cfg, &screen, &big).unwrap();
        assert!(c.pixels_per_clock() > 3.8, "{c:?}");
    }

    #[test]
    fn schemes_empty_workload_costs_nothing() {
        let screen = Screen::default();
        let off = tri([[-50.0, -50.0, 1.0], [-10.0, -40.0, 2.0], [-30.0, -5.0, 3.0]]);
        for s in Scheme::BASELINES {
            let c = workload_count(s, &Config::default(), &screen, &[off]).unwrap();
            assert_eq!((c.triangles, c.pixels, c.clocks, c.total_clocks()), (1, 0, 0, 0));
        }
        let bad = tri([[f64::NAN, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        let e = workload_count(Scheme::Classical, &Config::default(), &screen, &[off, bad]).unwrap_err();
        assert_eq!(e.triangle, 1);
        assert!(matches!(e.error, SetupError::Triangle(crate::setup::TriangleError::Coordinate { vertex: 0, axis: "x", .. })), "{e}");
        assert!(e.to_string().starts_with("triangle 1: vertex 0: x = NaN"), "{e}");
    }
}
