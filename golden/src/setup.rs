//! Host-side triangle set-up (SPEC §5): parse triangles, snap them, decide coverage exactly and
//! turn every covered scanline into one `Span` for the segment shader.
//!
//! Coordinates are snapped to 1/256 pixel and every coverage decision is made in exact `i64`
//! arithmetic on the snapped integers, so the answer never depends on rounding. Each scanline's
//! covered run is found by solving the three edge inequalities for `x` (one floor or ceil
//! division per edge), not by testing pixels: this is the path that feeds the hardware.
//!
//! Numeric limits. `|x|, |y| <= COORD_LIMIT = 2^15` pixels (2^23 sub-pixel units) and a screen
//! of at most 2^16 x 2^16 pixels keep every edge function value below 2^51 in units of
//! 1/65536 pixel^2. That fits `i64` with a wide margin and, more importantly, is exact in `f64`
//! (53-bit mantissa), which is what lets `raster::reference_pixels` evaluate the same edge
//! functions in floating point with no error at all.
//!
//! Accuracy. `I0` is rounded to nearest (error <= 2^-(F+1)) and so is `dI` (error <= 2^-(F+1)
//! per step), so pixel `j` of a span is off the exact plane by at most `(j+1) * 2^-(F+1)`
//! before the final rounding to 8 bits. SPEC §5's "within 1 of the exact rasterizer" therefore
//! holds whenever that bound stays below 1 for the widest span, i.e. `width < 2^(F+1)`
//! (8192 pixels at the default F = 12); see [`max_span_error`]. Narrower formats on wider
//! screens drift further, which is a property of the formats, not of this set-up.

use crate::format::{Config, Span};
use serde::{Deserialize, Serialize};
use std::fmt;

/// Sub-pixel resolution: positions are snapped to multiples of 1/SUBPIXEL pixel.
pub const SUBPIXEL: i64 = 256;
const HALF: i64 = SUBPIXEL / 2;
/// Largest accepted |x| or |y| of a vertex, in pixels (see the module documentation).
pub const COORD_LIMIT: f64 = 32768.0;
/// Largest accepted screen width or height, in pixels (the widest XW = 16 screen).
pub const SCREEN_LIMIT: u32 = 1 << 16;

/// A vertex: position in pixels, intensity in 0..=255.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Vertex {
    pub x: f64,
    pub y: f64,
    pub i: f64,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Triangle {
    pub v: [Vertex; 3],
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Screen {
    pub width: u32,
    pub height: u32,
}

impl Default for Screen {
    fn default() -> Self {
        Screen { width: 640, height: 480 }
    }
}

/// A screen the set-up cannot serve ([`Screen::check`], [`Screen::check_for`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ScreenError {
    #[error("screen {width}x{height} exceeds {SCREEN_LIMIT}x{SCREEN_LIMIT}")]
    TooLarge { width: u32, height: u32 },
    #[error("screen width {width} exceeds 2^XW = {max} pixels of the configuration")]
    WiderThanPorts { width: u32, max: u32 },
}

/// A triangle outside the set-up's numeric limits ([`Triangle::check`]).
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum TriangleError {
    /// `axis` is "x" or "y"; the value is NaN, infinite or beyond [`COORD_LIMIT`].
    #[error("vertex {vertex}: {axis} = {value} is outside -{COORD_LIMIT}..={COORD_LIMIT}")]
    Coordinate { vertex: usize, axis: &'static str, value: f64 },
    #[error("vertex {vertex}: intensity {value} is outside 0..=255")]
    Intensity { vertex: usize, value: f64 },
}

/// Why [`triangle_spans`] (or the f64 reference) refuses a triangle on a screen.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum SetupError {
    #[error(transparent)]
    Screen(#[from] ScreenError),
    #[error(transparent)]
    Triangle(#[from] TriangleError),
}

impl Screen {
    /// Both dimensions within [`SCREEN_LIMIT`] (needed for the exactness argument above).
    pub fn check(&self) -> Result<(), ScreenError> {
        if self.width > SCREEN_LIMIT || self.height > SCREEN_LIMIT {
            return Err(ScreenError::TooLarge { width: self.width, height: self.height });
        }
        Ok(())
    }

    /// Bits of a scanline number `0..H` (at least 1): the `y` ports of the front-end and writer.
    pub fn y_bits(&self) -> u32 {
        (32 - self.height.saturating_sub(1).leading_zeros()).max(1)
    }

    /// As [`Screen::check`], and every span of this screen fits `cfg`'s `in_x`/`in_len` ports.
    pub fn check_for(&self, cfg: &Config) -> Result<(), ScreenError> {
        self.check()?;
        if self.width > cfg.max_len() {
            return Err(ScreenError::WiderThanPorts { width: self.width, max: cfg.max_len() });
        }
        Ok(())
    }
}

impl Triangle {
    /// The validation `parse_triangles` applies, for triangles built in code.
    pub fn check(&self) -> Result<(), TriangleError> {
        for (vertex, v) in self.v.iter().enumerate() {
            for (axis, value) in [("x", v.x), ("y", v.y)] {
                if !value.is_finite() || value.abs() > COORD_LIMIT {
                    return Err(TriangleError::Coordinate { vertex, axis, value });
                }
            }
            if !(v.i.is_finite() && (0.0..=255.0).contains(&v.i)) {
                return Err(TriangleError::Intensity { vertex, value: v.i });
            }
        }
        Ok(())
    }
}

/// One line of the text format; `f64`'s `Display` round-trips, so this parses back exactly.
impl fmt::Display for Triangle {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (n, v) in self.v.iter().enumerate() {
            let sep = if n == 0 { "" } else { " " };
            write!(f, "{sep}{} {} {}", v.x, v.y, v.i)?;
        }
        Ok(())
    }
}

/// A line of triangle text [`parse_triangles`] refuses.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("line {line}: {kind}")]
pub struct ParseError {
    /// 1-based line number.
    pub line: usize,
    pub kind: ParseErrorKind,
}

/// What is wrong with the line.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ParseErrorKind {
    #[error("expected 9 numbers (x0 y0 i0 x1 y1 i1 x2 y2 i2), found {0}")]
    FieldCount(usize),
    /// `field` is one of x0 y0 i0 ... i2; Rust parses "inf" and "NaN", which are no coordinates.
    #[error("{field} = '{text}' is not finite")]
    NotFinite { field: &'static str, text: String },
    #[error("{field} = '{text}' is not a number")]
    NotANumber { field: &'static str, text: String },
    #[error(transparent)]
    Triangle(#[from] TriangleError),
}

const FIELD_NAMES: [&str; 9] = ["x0", "y0", "i0", "x1", "y1", "i1", "x2", "y2", "i2"];

/// Parses SPEC §5's text format: `x0 y0 i0 x1 y1 i1 x2 y2 i2` per line, `#` comments.
pub fn parse_triangles(text: &str) -> Result<Vec<Triangle>, ParseError> {
    let mut out = Vec::new();
    for (n, raw) in text.lines().enumerate() {
        let err = |kind: ParseErrorKind| ParseError { line: n + 1, kind };
        let body = raw.split('#').next().unwrap_or("");
        let fields: Vec<&str> = body.split_whitespace().collect();
        if fields.is_empty() {
            continue;
        }
        if fields.len() != 9 {
            return Err(err(ParseErrorKind::FieldCount(fields.len())));
        }
        let mut f = [0.0f64; 9];
        for (k, s) in fields.iter().enumerate() {
            // Rust also parses "inf" and "NaN"; those are numbers to it but not to us.
            let (field, text) = (FIELD_NAMES[k], s.to_string());
            f[k] = match s.parse::<f64>() {
                Ok(v) if v.is_finite() => v,
                Ok(_) => return Err(err(ParseErrorKind::NotFinite { field, text })),
                Err(_) => return Err(err(ParseErrorKind::NotANumber { field, text })),
            };
        }
        let vertex = |k: usize| Vertex { x: f[3 * k], y: f[3 * k + 1], i: f[3 * k + 2] };
        let tri = Triangle { v: [vertex(0), vertex(1), vertex(2)] };
        tri.check().map_err(|e| err(e.into()))?;
        out.push(tri);
    }
    Ok(out)
}

/// Snaps a coordinate in pixels to sub-pixel units (round to nearest, ties away from zero).
pub fn snap(c: f64) -> i64 {
    (c * SUBPIXEL as f64).round() as i64
}

/// The D3D11 top-left rule for an edge with direction `(dx, dy)` of a triangle whose interior
/// lies where the edge function is positive (y grows downward): a centre exactly on the edge
/// is covered only for a left edge (going up, `dy < 0`) or a top edge (horizontal, going right).
/// A shared edge is traversed in opposite directions by its two triangles, so exactly one of
/// them owns the centres on it. Equivalently: ties are decided by sampling at `p + (e, e^2)`.
pub fn is_top_left(dx: i64, dy: i64) -> bool {
    dy < 0 || (dy == 0 && dx > 0)
}

/// The directed edge from vertex `k+1` to vertex `k+2` of a [`Snapped`] triangle (opposite
/// vertex `k`), in sub-pixel units.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Edge {
    pub ax: i64,
    pub ay: i64,
    pub dx: i64,
    pub dy: i64,
    pub top_left: bool,
}

impl Edge {
    /// Twice the signed area of (a, b, p): positive on the interior side. Exact.
    pub fn eval(&self, px: i64, py: i64) -> i64 {
        self.dx * (py - self.ay) - self.dy * (px - self.ax)
    }
}

/// A validated triangle snapped to the sub-pixel grid and put in canonical form: vertices sorted
/// by (y, x), then the last two swapped if needed so `area2 >= 0`. Every permutation and either
/// winding of the input thus gives the same `Snapped`, and so bit-identical spans.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Snapped {
    pub x: [i64; 3],
    pub y: [i64; 3],
    /// The unrounded vertex intensities.
    pub i: [f64; 3],
    /// Twice the area in sub-pixel units^2; 0 for a degenerate triangle, which covers nothing.
    pub area2: i64,
}

impl Snapped {
    /// The triangle must pass [`Triangle::check`]; otherwise the exactness bounds do not hold.
    pub fn new(tri: &Triangle) -> Snapped {
        Snapped::from_fixed(tri.v.map(|v| snap(v.x)), tri.v.map(|v| snap(v.y)), tri.v.map(|v| v.i))
    }

    /// The same canonical form from coordinates already snapped to sub-pixel units (the
    /// hardware front-end's ports). Coverage stays exact in `i64` for any coordinates within
    /// 2^25 sub-pixel units, the widest guard band a configuration can have.
    pub fn from_fixed(x: [i64; 3], y: [i64; 3], i: [f64; 3]) -> Snapped {
        let mut v = [0, 1, 2].map(|k| (y[k], x[k], i[k]));
        v.sort_by_key(|&(y, x, _)| (y, x));
        let area2 = (v[1].1 - v[0].1) * (v[2].0 - v[0].0) - (v[1].0 - v[0].0) * (v[2].1 - v[0].1);
        if area2 < 0 {
            v.swap(1, 2);
        }
        Snapped { x: v.map(|v| v.1), y: v.map(|v| v.0), i: v.map(|v| v.2), area2: area2.abs() }
    }

    pub fn is_degenerate(&self) -> bool {
        self.area2 == 0
    }

    /// Edge `k`, opposite vertex `k`; its edge function is `area2` at vertex `k`, so
    /// `eval / area2` is vertex `k`'s barycentric weight.
    pub fn edge(&self, k: usize) -> Edge {
        let (a, b) = ((k + 1) % 3, (k + 2) % 3);
        let (dx, dy) = (self.x[b] - self.x[a], self.y[b] - self.y[a]);
        Edge { ax: self.x[a], ay: self.y[a], dx, dy, top_left: is_top_left(dx, dy) }
    }

    /// dI/dx of the plane through the snapped vertices, per pixel (0 if degenerate).
    ///
    /// Each term is an exact integer times an intensity, so the relative error is a few ulp of
    /// the terms; whenever a row holds two covered pixels, `area2 >= 256 * (y extent)` and the
    /// absolute error is below 1e-12, far under the 2^-(F+1) quantization step.
    pub fn didx(&self) -> f64 {
        if self.is_degenerate() {
            return 0.0;
        }
        let (y, i) = (&self.y, &self.i);
        let n = i[0] * (y[1] - y[2]) as f64 + i[1] * (y[2] - y[0]) as f64 + i[2] * (y[0] - y[1]) as f64;
        n * SUBPIXEL as f64 / self.area2 as f64
    }

    /// `dI` in the signed DW-bit format with F fraction bits, computed once per triangle
    /// (constant-increment theorem): nearest, saturated to [-2^(DW-1), 2^(DW-1) - 1].
    ///
    /// Saturation never changes a pixel: dI only matters in spans of >= 2 pixels, and two
    /// centres one pixel apart inside the triangle both have plane values in [0, 255] (convex
    /// combinations of the vertex intensities), so then |dI/dx| <= 255 < 256.
    pub fn di(&self, cfg: &Config) -> i32 {
        let lim = (1i64 << (cfg.dw() - 1)) as f64;
        (self.didx() * (1u64 << cfg.frac) as f64).round().clamp(-lim, lim - 1.0) as i32
    }

    /// Emits one span per covered scanline of `screen`, top to bottom. Precondition (checked by
    /// [`triangle_spans`]): `screen.check_for(cfg)`, so every span passes `Span::check(cfg)`.
    pub fn spans(&self, cfg: &Config, screen: &Screen, mut out: impl FnMut(u32, Span)) {
        if self.is_degenerate() || screen.width == 0 || screen.height == 0 {
            return;
        }
        let di = self.di(cfg);
        let scale = (1u64 << cfg.frac) as f64;
        let i0_max = ((1u64 << cfg.iw()) - 1) as f64;
        let area = self.area2 as f64;
        let edges = [self.edge(0), self.edge(1), self.edge(2)];
        // Only rows whose centre lies within the vertices' y extent can be covered.
        let ymin = self.y.iter().copied().min().unwrap_or(0);
        let ymax = self.y.iter().copied().max().unwrap_or(0);
        let first = ceil_div(ymin - HALF, SUBPIXEL).max(0);
        let last = floor_div(ymax - HALF, SUBPIXEL).min(screen.height as i64 - 1);
        for row in first..=last {
            let py = row * SUBPIXEL + HALF;
            let (mut lo, mut hi) = (0i64, screen.width as i64 - 1);
            // Edge function at the centre of column x: e0 - SUBPIXEL*dy*x, required >= t
            // (t = 0 on a top-left edge, 1 otherwise: the integer form of "> 0").
            let mut e0 = [0i64; 3];
            for (k, e) in edges.iter().enumerate() {
                e0[k] = e.eval(HALF, py);
                let t = if e.top_left { 0 } else { 1 };
                if e.dy > 0 {
                    hi = hi.min(floor_div(e0[k] - t, SUBPIXEL * e.dy));
                } else if e.dy < 0 {
                    lo = lo.max(ceil_div(t - e0[k], -SUBPIXEL * e.dy));
                } else if e0[k] < t {
                    hi = -1;
                }
            }
            if lo > hi {
                continue;
            }
            // Barycentric weights at the first pixel are exact non-negative integers, so this
            // convex combination is accurate to a few ulp even for the thinnest sliver.
            let w = |k: usize| (e0[k] - SUBPIXEL * edges[k].dy * lo) as f64;
            let v = (w(0) * self.i[0] + w(1) * self.i[1] + w(2) * self.i[2]) / area;
            let i0 = (v * scale).round().clamp(0.0, i0_max) as u32;
            out(row as u32, Span { x0: lo as u32, len: (hi - lo + 1) as u32, i0, di });
        }
    }
}

/// Validates `screen` against `cfg` and `tri`, then emits the triangle's spans (see
/// [`Snapped::spans`]). No allocation; the hot path of the co-simulation.
pub fn triangle_spans(cfg: &Config, screen: &Screen, tri: &Triangle, out: impl FnMut(u32, Span)) -> Result<(), SetupError> {
    screen.check_for(cfg)?;
    tri.check()?;
    Snapped::new(tri).spans(cfg, screen, out);
    Ok(())
}

/// Worst-case distance, in intensity levels, between `V_j / 2^F` and the exact plane over a span
/// of `len` pixels (before the 8-bit rounding). SPEC §5's ±1 holds when this is below 1 for
/// `len = screen width`.
pub fn max_span_error(cfg: &Config, len: u32) -> f64 {
    len as f64 / (1u64 << (cfg.frac + 1)) as f64
}

fn floor_div(n: i64, d: i64) -> i64 {
    debug_assert!(d > 0);
    n.div_euclid(d)
}

fn ceil_div(n: i64, d: i64) -> i64 {
    -floor_div(-n, d)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(p: [[f64; 3]; 3]) -> Triangle {
        Triangle { v: p.map(|[x, y, i]| Vertex { x, y, i }) }
    }

    fn spans_of(cfg: &Config, screen: &Screen, t: &Triangle) -> Vec<(u32, Span)> {
        let mut v = Vec::new();
        triangle_spans(cfg, screen, t, |y, s| v.push((y, s))).unwrap();
        v
    }

    /// Per-pixel coverage counts of a list of triangles, from their spans.
    fn coverage(screen: &Screen, tris: &[Triangle]) -> Vec<u32> {
        let mut c = vec![0u32; (screen.width * screen.height) as usize];
        for t in tris {
            for (y, s) in spans_of(&Config::default(), screen, t) {
                for x in s.x0..s.x0 + s.len {
                    c[(y * screen.width + x) as usize] += 1;
                }
            }
        }
        c
    }

    #[test]
    fn parses_comments_and_blank_lines() {
        let text = "# header\n\n  0 0 0  10 0 128 0 10 255 # trailing\n\t\n1.5 -2 3 4 5e1 6 7 8 255\n";
        let t = parse_triangles(text).unwrap();
        assert_eq!(t.len(), 2);
        assert_eq!(t[0].v[2], Vertex { x: 0.0, y: 10.0, i: 255.0 });
        assert_eq!(t[1].v[1], Vertex { x: 4.0, y: 50.0, i: 6.0 });
        // Display writes the format back exactly.
        let again: Vec<String> = t.iter().map(|t| t.to_string()).collect();
        assert_eq!(parse_triangles(&again.join("\n")).unwrap(), t);
        assert_eq!(parse_triangles("").unwrap(), vec![]);
    }

    #[test]
    fn parse_errors_name_the_line() {
        use ParseErrorKind::*;
        let good = "0 0 0 1 0 0 0 1 0\n";
        let text = |field: &'static str, text: &str| (field, text.to_string());
        let (coord, intensity) = (
            |vertex, axis, value| Triangle(TriangleError::Coordinate { vertex, axis, value }),
            |vertex, value| Triangle(TriangleError::Intensity { vertex, value }),
        );
        let cases = [
            ("0 0 0 1 0 0 0 1", FieldCount(8)),
            ("0 0 0 1 0 0 0 1 0 5", FieldCount(10)),
            ("0 0 0 1 zero 0 0 1 0", {
                let (field, text) = text("y1", "zero");
                NotANumber { field, text }
            }),
            ("0 0 0 1 0 0 0 1 NaN", {
                let (field, text) = text("i2", "NaN");
                NotFinite { field, text }
            }),
            ("inf 0 0 1 0 0 0 1 0", {
                let (field, text) = text("x0", "inf");
                NotFinite { field, text }
            }),
            ("0 0 0 1 0 256 0 1 0", intensity(1, 256.0)),
            ("0 0 -0.5 1 0 0 0 1 0", intensity(0, -0.5)),
            ("0 0 0 1 0 0 0 -40000 0", coord(2, "y", -40000.0)),
            ("32768.5 0 0 1 0 0 0 1 0", coord(0, "x", 32768.5)),
            ("1e300 0 0 1 0 0 0 1 0", coord(0, "x", 1e300)),
            ("0 0 0 32768.004 0 0 0 1 0", coord(1, "x", 32768.004)),
            ("0 0 0 1 0 0 0 -32769 0", coord(2, "y", -32769.0)),
            ("0 0 0 1 0 0 0 1 255.5", intensity(2, 255.5)),
            ("0 NaN 0 1 0 0 0 1 0", {
                let (field, text) = text("y0", "NaN");
                NotFinite { field, text }
            }),
            ("0 0 0 1 -inf 0 0 1 0", {
                let (field, text) = text("y1", "-inf");
                NotFinite { field, text }
            }),
            ("0 0 0 1 0 0 1e400 1 0", {
                let (field, text) = text("x2", "1e400");
                NotFinite { field, text }
            }),
            ("0 0 0 1 0 0 0 1 infinity", {
                let (field, text) = text("i2", "infinity");
                NotFinite { field, text }
            }),
            ("0 0 0 1 0 0 0 1 0x10", {
                let (field, text) = text("i2", "0x10");
                NotANumber { field, text }
            }),
            ("0,0,0 1 0 0 0 1 0", FieldCount(7)),
        ];
        for (bad, want) in cases {
            let text = format!("# c\n{good}\n{bad} # comment\n{good}");
            let e = parse_triangles(&text).unwrap_err();
            assert_eq!(e, ParseError { line: 4, kind: want }, "{bad}");
        }
        // The message the CLIs print: the line, then what is wrong with it.
        let e = parse_triangles("0 0 0 1 zero 0 0 1 0").unwrap_err().to_string();
        assert_eq!(e, "line 1: y1 = 'zero' is not a number");
        let e = parse_triangles("0 0 0 1 0 0 0 -40000 0").unwrap_err().to_string();
        assert_eq!(e, "line 1: vertex 2: y = -40000 is outside -32768..=32768");
        assert!(parse_triangles("32768 -32768 255 0 0 0 0 0 0").is_ok());
    }

    /// Lines of random tokens, numbers and junk never panic the parser, and whatever it returns
    /// passes the set-up's own validation.
    #[test]
    fn parser_fuzz_returns_only_valid_triangles() {
        use crate::rng::SeedRng;
        use rand::{Rng, SeedableRng};
        let mut rng = SeedRng::seed_from_u64(6);
        let tokens = ["0", "-1", "1e9", "nan", "inf", "-0", "255", "3.5", "#", "x", "", "1e-400", "32768", "-32768", "\t", "1e308"];
        let mut parsed = 0;
        for _ in 0..5000 {
            let line: Vec<&str> = (0..rng.gen_range(0..12)).map(|_| tokens[rng.gen_range(0..tokens.len())]).collect();
            if let Ok(tris) = parse_triangles(&line.join(" ")) {
                for t in tris {
                    t.check().expect("the parser returns only valid triangles");
                    parsed += 1;
                }
            }
        }
        assert!(parsed > 0, "the fuzz never produced a valid line: it tests nothing");
    }

    #[test]
    fn programmatic_triangles_get_the_same_validation() {
        let cfg = Config::default();
        let screen = Screen::default();
        let bad = tri([[0.0, 0.0, 0.0], [f64::NAN, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        let e = triangle_spans(&cfg, &screen, &bad, |_, _| {}).unwrap_err();
        assert!(matches!(e, SetupError::Triangle(TriangleError::Coordinate { vertex: 1, axis: "x", value }) if value.is_nan()), "{e}");
        let ok = tri([[0.0, 0.0, 0.0], [5.0, 0.0, 0.0], [0.0, 5.0, 0.0]]);
        let narrow = Config::new(8, 12, 9, crate::Align::Span).unwrap();
        let e = triangle_spans(&narrow, &screen, &ok, |_, _| {}).unwrap_err();
        assert_eq!(e, SetupError::Screen(ScreenError::WiderThanPorts { width: 640, max: 512 }));
        assert_eq!(e.to_string(), "screen width 640 exceeds 2^XW = 512 pixels of the configuration");
        // Built in code, triangles the parser would refuse are refused by the set-up: no span.
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e300, COORD_LIMIT + 0.01] {
            let t = tri([[0.0, 0.0, 0.0], [bad, 5.0, 9.0], [3.0, 9.0, 1.0]]);
            let mut spans = 0;
            let e = triangle_spans(&cfg, &screen, &t, |_, _| spans += 1).unwrap_err();
            assert!(matches!(e, SetupError::Triangle(TriangleError::Coordinate { vertex: 1, axis: "x", .. })), "{e}");
            assert_eq!(spans, 0);
        }
        let huge = Screen { width: 100, height: SCREEN_LIMIT + 1 };
        let e = triangle_spans(&cfg, &huge, &ok, |_, _| {}).unwrap_err();
        assert_eq!(e, SetupError::Screen(ScreenError::TooLarge { width: 100, height: SCREEN_LIMIT + 1 }));
    }

    #[test]
    fn square_split_on_its_diagonal_covers_each_pixel_once() {
        // Corners on pixel centres: every edge, the diagonal included, runs through centres.
        let screen = Screen { width: 16, height: 16 };
        let (a, b) = (2.5, 10.5);
        for diag in [false, true] {
            let t = if diag {
                [tri([[a, a, 0.0], [b, a, 0.0], [b, b, 0.0]]), tri([[a, a, 0.0], [b, b, 0.0], [a, b, 0.0]])]
            } else {
                [tri([[a, a, 0.0], [b, a, 0.0], [a, b, 0.0]]), tri([[b, a, 0.0], [b, b, 0.0], [a, b, 0.0]])]
            };
            let c = coverage(&screen, &t);
            for y in 0..16 {
                for x in 0..16 {
                    // Left (x = 2.5) and top (y = 2.5) sides own their centres; right and bottom do not.
                    let want = ((2..10).contains(&x) && (2..10).contains(&y)) as u32;
                    assert_eq!(c[y * 16 + x], want, "pixel ({x}, {y}), diagonal {diag}");
                }
            }
        }
    }

    #[test]
    fn shared_vertical_and_horizontal_edges() {
        let screen = Screen { width: 12, height: 12 };
        let cfg = Config::default();
        // Vertical edge x = 5.5 through centres of column 5: it is the left edge of the right
        // triangle, so column 5 belongs there.
        let left = tri([[5.5, 0.0, 0.0], [5.5, 12.0, 0.0], [0.0, 6.0, 0.0]]);
        let right = tri([[5.5, 0.0, 0.0], [11.0, 6.0, 0.0], [5.5, 12.0, 0.0]]);
        assert!(spans_of(&cfg, &screen, &left).iter().all(|(_, s)| s.x0 + s.len <= 5));
        let r = spans_of(&cfg, &screen, &right);
        assert_eq!(r.len(), 12);
        assert!(r.iter().all(|(_, s)| s.x0 == 5));
        // Horizontal edge y = 5.5: a top edge for the triangle below it.
        let above = tri([[0.0, 5.5, 0.0], [6.0, 0.0, 0.0], [12.0, 5.5, 0.0]]);
        let below = tri([[0.0, 5.5, 0.0], [12.0, 5.5, 0.0], [6.0, 11.0, 0.0]]);
        assert!(spans_of(&cfg, &screen, &above).iter().all(|&(y, _)| y < 5));
        let b = spans_of(&cfg, &screen, &below);
        assert_eq!(b[0].0, 5);
        assert_eq!((b[0].1.x0, b[0].1.len), (0, 12));
        let c = coverage(&screen, &[left, right, above, below]);
        assert_eq!(c[5 * 12 + 5], 2, "centre (5.5, 5.5) lies on both shared edges");
    }

    #[test]
    fn zero_area_triangles_cover_nothing() {
        let cfg = Config::default();
        let screen = Screen::default();
        for t in [
            tri([[1.0, 1.0, 9.0], [50.0, 50.0, 9.0], [100.5, 100.5, 9.0]]), // collinear through centres
            tri([[10.5, 3.5, 0.0], [10.5, 3.5, 0.0], [10.5, 3.5, 0.0]]),
            tri([[10.5, 3.5, 0.0], [20.5, 3.5, 0.0], [30.5, 3.5, 0.0]]), // along a row of centres
            tri([[10.0, 10.0, 0.0], [20.0, 10.0, 0.0], [15.0, 10.001, 0.0]]), // flat after snapping
        ] {
            assert!(Snapped::new(&t).is_degenerate());
            assert!(spans_of(&cfg, &screen, &t).is_empty(), "{t}");
        }
        // Barely not degenerate: one sub-pixel unit of height still covers its centres.
        let t = tri([[10.0, 10.5, 0.0], [20.0, 10.5, 0.0], [15.0, 10.5 + 1.0 / 256.0, 0.0]]);
        assert_eq!(spans_of(&cfg, &screen, &t).len(), 1);
    }

    #[test]
    fn every_order_and_winding_gives_identical_spans() {
        let cfg = Config::default();
        let screen = Screen::default();
        let base = [[3.3, 7.9, 10.0], [200.12, 50.5, 200.7], [90.0, 300.25, 77.0]];
        let want = spans_of(&cfg, &screen, &tri(base));
        assert!(want.len() > 200);
        for p in [[0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]] {
            assert_eq!(spans_of(&cfg, &screen, &tri(p.map(|k| base[k]))), want, "{p:?}");
        }
    }

    #[test]
    fn clipped_to_the_screen() {
        let cfg = Config::default();
        let screen = Screen { width: 64, height: 48 };
        let cover = tri([[-1000.0, -1000.0, 0.0], [3000.0, -1000.0, 0.0], [-1000.0, 3000.0, 0.0]]);
        let s = spans_of(&cfg, &screen, &cover);
        assert_eq!(s.len(), 48);
        assert!(s.iter().all(|(_, s)| (s.x0, s.len) == (0, 64)));
        // Partly off the left and top: rows and columns start at 0, ends are the true edges.
        let part = tri([[-10.0, -10.0, 0.0], [20.0, -10.0, 255.0], [-10.0, 20.0, 255.0]]);
        let s = spans_of(&cfg, &screen, &part);
        assert_eq!(s.iter().map(|s| s.0).collect::<Vec<_>>(), (0..9).collect::<Vec<_>>());
        for (y, sp) in &s {
            sp.check(&cfg).unwrap();
            assert_eq!(sp.x0, 0);
            // Hypotenuse x + y = 10 is a right edge: centres on it (x + y + 1 = 10) are not covered.
            assert_eq!(sp.len, 9 - y);
        }
        // Partly off the right and bottom.
        let part = tri([[60.0, 40.0, 0.0], [100.0, 40.0, 0.0], [60.0, 100.0, 0.0]]);
        let s = spans_of(&cfg, &screen, &part);
        assert_eq!(s.len(), 8);
        assert!(s.iter().all(|(_, s)| (s.x0, s.len) == (60, 4)));
        // Entirely off each side.
        for (dx, dy) in [(-200.0, 0.0), (200.0, 0.0), (0.0, -200.0), (0.0, 200.0)] {
            let t = tri([[10.0 + dx, 10.0 + dy, 0.0], [50.0 + dx, 10.0 + dy, 0.0], [10.0 + dx, 40.0 + dy, 0.0]]);
            assert!(spans_of(&cfg, &screen, &t).is_empty());
        }
    }

    #[test]
    fn di_is_the_rounded_plane_slope_and_i0_the_plane_at_the_first_centre() {
        let cfg = Config::default();
        let screen = Screen::default();
        let t = tri([[10.0, 10.0, 0.0], [110.0, 10.0, 100.0], [10.0, 60.0, 255.0]]);
        let s = spans_of(&cfg, &screen, &t);
        // dI/dx = 1 exactly: di = 2^F; I at centre (10.5, y + 0.5) = 0.5 + 5.1 * (y + 0.5 - 10).
        for (y, sp) in &s {
            assert_eq!(sp.di, 1 << 12);
            assert_eq!(sp.x0, 10);
            let exact = 0.5 + 5.1 * (*y as f64 + 0.5 - 10.0);
            assert_eq!(sp.i0, (exact * 4096.0).round() as u32, "row {y}");
        }
        // Saturation: 255 levels over 1/256 pixel cannot fit the format.
        let steep = tri([[10.0, 10.0, 0.0], [10.0 + 1.0 / 256.0, 10.0, 255.0], [10.0, 20.0, 0.0]]);
        let sn = Snapped::new(&steep);
        assert_eq!(sn.di(&cfg), (1 << 20) - 1);
        let steep = tri([[10.0, 10.0, 255.0], [10.0 + 1.0 / 256.0, 10.0, 0.0], [10.0, 20.0, 0.0]]);
        assert_eq!(Snapped::new(&steep).di(&cfg), -(1 << 20));
        assert_eq!(max_span_error(&cfg, 640), 640.0 / 8192.0);
    }

    #[test]
    fn span_ends_match_a_per_pixel_integer_test() {
        // The division-based solver against the plain integer edge test on many small triangles.
        use rand::{Rng, SeedableRng};
        let cfg = Config::default();
        let screen = Screen { width: 40, height: 30 };
        let mut rng = crate::rng::SeedRng::seed_from_u64(7);
        for _ in 0..3000 {
            let c = |rng: &mut crate::rng::SeedRng, hi: f64| {
                let v: f64 = rng.gen_range(-5.0..hi);
                if rng.gen_bool(0.5) {
                    (v * 2.0).round() / 2.0
                } else {
                    v
                }
            };
            let t = tri([0, 1, 2].map(|_| [c(&mut rng, 45.0), c(&mut rng, 35.0), 0.0]));
            let sn = Snapped::new(&t);
            let mut want = vec![false; 1200];
            if !sn.is_degenerate() {
                for y in 0..30 {
                    for x in 0..40 {
                        let (px, py) = (x * 256 + 128, y * 256 + 128);
                        want[(y * 40 + x) as usize] = (0..3).all(|k| {
                            let e = sn.edge(k);
                            let v = e.eval(px, py);
                            v > 0 || (v == 0 && e.top_left)
                        });
                    }
                }
            }
            let mut got = vec![false; 1200];
            for (y, s) in spans_of(&cfg, &screen, &t) {
                for x in s.x0..s.x0 + s.len {
                    got[(y * 40 + x) as usize] = true;
                }
            }
            assert_eq!(got, want, "{t}");
        }
    }
}
