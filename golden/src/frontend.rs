//! The triangle front-end in hardware (SPEC §6): triangles in, one span per covered scanline out.
//! This is the bit-exact definition of what the generated `tri_setup` / `edge_walker` RTL
//! computes, and the plan (every width) the generator prints.
//!
//! # Coverage: an integer edge walker
//!
//! A triangle arrives as three vertices on the 1/256-pixel grid (signed, within a guard band of
//! one screen on every side) with UQ8.F intensities. Set-up orients the edges so the interior is
//! where every edge function `e(p) = dx (py - ya) - dy (px - xa)` is positive, exactly as
//! `setup::Snapped` does, and then, per edge with `dy != 0`, sets up a DDA on
//!
//! `g(r) = floor((e(128, 256 r + 128) - t) / D)`, `D = 256 |dy|`, `t = 0` on a top-left edge, else 1,
//!
//! which is the last covered column for a right edge (`dy > 0`: `hi = g`) and minus the first
//! covered column for a left edge (`dy < 0`: `lo = -g`). From row to row the numerator grows by
//! `256 dx = Qs D + 256 Rs` (`Qs, Rs = divmod(dx, |dy|)`), so the walker adds `Qs` and `256 Rs` and
//! carries once: one add per edge per row, no division, exactly the bound `setup::Snapped`
//! solves for with one division per row.
//!
//! Each edge takes part only in the rows whose centres lie within its own y extent
//! `[yt, yb]` (its *active* rows). Outside them the other two edges imply its constraint: a row
//! strictly above `yt` cuts the wedge at the opposite vertex inside the triangle, where the
//! edge's function is positive, hence at least 1 on the integer grid. Keeping to active rows is
//! what keeps every value small: an active edge's bound lies within one pixel of the edge's own
//! x extent, so `g` fits `GW = XW + 3` signed bits, and an edge active on two rows has
//! `|dy| >= 256`, so `|Qs| <= |dx| / 256 + 1` fits too. A horizontal edge is never active: it
//! only decides whether a centre exactly on it is covered, which for a bottom edge (the only
//! kind that excludes) removes the last row when `ymax` lies on a centre.
//!
//! # Intensity: one division for dI, one reciprocal for every scanline's I0
//!
//! With vertex intensities `I_k` (integers, 2^-F units) the plane through the snapped vertices is
//! `I(p) = I_0 + (Nx (px - x0) + Ny (py - y0)) / A` (A twice the area, oriented positive).
//!
//! - `dI = round(256 Nx / A)` (half away from zero), saturated to DW bits: one sequential
//!   division per triangle. Saturation never touches a span of two or more pixels: two
//!   neighbouring covered centres have plane values in [0, 255], so then `|dI/dx| <= 255`.
//! - `I0 = round(S / A)` for the span's first pixel, `S(c, r) = I_0 A + Nx (256c + 128 - x0) +
//!   Ny (256r + 128 - y0)`, exactly (correctly rounded), with no division per scanline: set-up
//!   computes one reciprocal `Rn = floor(2^K / (2 An))` of the normalised `An = A << s`
//!   (`s` leading zeros of A in AW bits, `K = IW + 2 + AW`); per row the walker forms
//!   `S2n = ((2S + A) << s) mod 2^(K-1)` from two running sums and one multiply by the column
//!   (of `Gxn >> 8`: the per-column step `Gxn = (256 Nx) << s` ends in 8 zero bits),
//!   and the span path takes the quotient estimate from its top IW + 1 bits only,
//!   `q~ = ((S2n >> t) Rn) >> (K - t)` with `t = AW`, which is the quotient or up to two below
//!   it; one multiply by `2An`, needed only modulo 2^(AW+3), and two compares correct it.
//!   Everything is modular: the values that leave the unit are small, and the sums only need to
//!   be right modulo 2^(K-1).
//!
//! ## Why the estimate is at most two below the quotient
//!
//! At a covered pixel the plane lies in `[0, 2^IW - 1]`, so `q = floor(S2n / 2An) = I0 < 2^IW`
//! and `S2n < 2An 2^IW < 2^(K-1)`: the true `S2n` fits K - 1 bits, and its residue is itself.
//! Write `S2n = H 2^t + L` (`L < 2^t`) and `Rn = 2^K / 2An - e` (`0 <= e < 1`). Then
//!
//! `S2n / 2An - H Rn / 2^(K-t) = L / 2An + H 2^t e / 2^K`.
//!
//! Both terms are at least 0, so `q~ <= q`. The first is below `2^t / 2^AW = 1` (`2An >= 2^AW`
//! because An is normalised), the second below `2^(K-1) / 2^K = 1/2` (`H 2^t <= S2n`): the
//! estimate's argument is less than 3/2 below `S2n / 2An >= q`, so `q~ >= q - 2`. The remainder
//! `R = S2n - 2An q~` is then in `[0, 6An)`, below 2^(AW+3): modulo 2^(AW+3) it is exact, and
//! `q = q~ + (R >= 2An) + (R >= 4An)`. Neither compare needs a comparator behind the
//! subtraction: `R - 2k An` (k = 1, 2) lies in `[-2k An, (6 - 2k) An)`, within `(-2^(AW+2),
//! 2^(AW+2))` as `An < 2^AW`, so it is negative exactly when bit AW + 2 of its residue modulo
//! 2^(AW+3) is set, and that residue is `((S2n - 2k An) - 2An q~) mod 2^(AW+3)`, whose first
//! difference does not wait for the product. `H` has IW + 1 bits, so the estimate's product is
//! `(IW + 1) x RW` bits (at the defaults 21 x 23: two 18-bit tiles and a 3-bit slice in logic;
//! the full `K x RW` product took eight tiles), and the correction's, `q~ An`, is `IW x AW` bits
//! needed modulo 2^(AW+2) only, doubled to the remainder's 2^(AW+3) (the partial products wholly
//! above it are never built; at the defaults two tiles, the 2 top bits of `q~` and the corner of
//! `An`'s top 6 bits against `q~`'s low 8 in logic). With `Gxn lo`'s three (54 x 12 bits, from
//! `Gxn >> 8`: [`Widths::GXN_ZEROS`]) the span path takes 7 tiles a row; on the ECP5-25F plan
//! ([`engine::Plan::run_sums`]) `Gxn lo` comes from running sums stepped with the left edges'
//! DDAs instead ([`sums`]), and the span path takes 4. `t = AW - 1` would
//! need one compare but a 22-bit `H`, four tiles. A shift one further (`t = AW + 1`) lets the
//! estimate fall three below, and a compare dropped leaves two-below uncorrected: the tests plant
//! both.
//!
//! # Accuracy
//!
//! `I0` is the plane rounded to nearest (error <= 2^-(F+1)) and so is `dI` (per pixel), so
//! `V_j = I0 + j dI` is within `(j + 1) 2^-(F+1) <= W 2^-(F+1)` of the plane over a span, and the
//! 8-bit pixel within `1/2 + W 2^-(F+1)` of it. That is at most 1 — SPEC §6's bound — for every
//! screen with `W <= 2^F`, which [`FrontEnd::new`] requires. The plane is the one through the
//! UQ8.F intensities the hardware receives; real-valued vertex intensities add at most
//! `2^-(F+1)` more when they are rounded onto the port.

pub mod engine;
pub mod incremental;
pub mod span_seq;
pub mod sums;
mod walk;

use crate::format::{Config, Span};
use crate::setup::{is_top_left, snap, Screen, Snapped, Triangle, SUBPIXEL};
use serde::{Deserialize, Serialize};

const HALF: i64 = SUBPIXEL / 2;

/// Why a front-end configuration is refused.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum FrontEndError {
    /// The screen is wider than the `in_x` / `in_len` ports of the configuration.
    #[error("screen width {width} is outside 1..={max} (2^XW of the configuration)")]
    Width { width: u32, max: u32 },
    /// The F-bit `dI` cannot keep every pixel within 1 of the plane on so wide a screen.
    #[error(
        "screen width {width} exceeds 2^F = {}: with F = {frac} fraction bits a pixel could \
         end up more than 1 from the plane (bound 1/2 + W 2^-(F+1)); raise --frac",
        1u64 << frac
    )]
    Accuracy { width: u32, frac: u32 },
    /// Height outside 1..=65536.
    #[error("screen height {height} is outside 1..=65536")]
    Height { height: u32 },
}

/// Where a span's `dI` comes from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum DiMode {
    /// The constant-increment theorem: `dI = round(256 Nx / A)`, once per triangle.
    #[default]
    Triangle,
    /// Classical Gouraud, for comparison: per scanline, from the intensities at the span's first
    /// and last pixel (the edge intensities, exactly rounded like `I0`) by the same divider,
    /// `dI = round((I_last - I0) / (m - 1))` half away from zero, 0 for `m = 1`. Each pixel stays
    /// within `1/2 + (m - 1) 2^-(F+1)` of the plane: the same bound as the per-triangle `dI`.
    Scanline,
}

impl DiMode {
    pub const ALL: [DiMode; 2] = [DiMode::Triangle, DiMode::Scanline];
    pub fn name(self) -> &'static str {
        match self {
            DiMode::Triangle => "triangle",
            DiMode::Scanline => "scanline",
        }
    }
}

/// How the walker forms each span's `I0` (issue 27). The spans are the same bit for bit; the
/// forms differ in hardware: a reciprocal evaluation a row, or adds a row and an evaluation per
/// *start* ([`incremental`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum I0Form {
    /// Per row `S2n = 2 (Tn + Gxn lo) + An`, `q~ = ((S2n >> t) Rn) >> (K - t)` and its
    /// correction: three products a row in the span path.
    #[default]
    Reciprocal,
    /// Per source of the span's left end, quotient and remainder over `2A` stepped by adds; the
    /// reciprocal formula only at a source's first covered row, on a shared multi-cycle unit.
    Incremental,
}

impl I0Form {
    pub const ALL: [I0Form; 2] = [I0Form::Reciprocal, I0Form::Incremental];
    pub fn name(self) -> &'static str {
        match self {
            I0Form::Reciprocal => "reciprocal",
            I0Form::Incremental => "incremental",
        }
    }
    /// Whether this is the default (serialised plans leave it out, so theirs stay as they were).
    pub fn is_default(&self) -> bool {
        *self == I0Form::default()
    }
}

/// How `tri_frontend` sets a triangle up (`generate --fe-setup`): today's one-clock CALC and
/// eight parallel dividers, or the shared engine on one of the named plans. The spans are the
/// same bit for bit in every form; the hardware, its set-up rate and its latency differ.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum SetupForm {
    /// CALC (every product in one clock) and eight dividers in parallel.
    #[default]
    Parallel,
    /// The engine on `Plan::ECP5_25F` (the `engine` module).
    #[cfg_attr(feature = "clap", value(name = "ecp5-25f"))]
    #[serde(rename = "ecp5-25f")]
    Ecp5_25f,
    /// The engine on `Plan::ICE40_UP5K`.
    #[cfg_attr(feature = "clap", value(name = "ice40-up5k"))]
    #[serde(rename = "ice40-up5k")]
    Ice40Up5k,
    /// The engine on `Plan::ICE40_HX8K`.
    #[cfg_attr(feature = "clap", value(name = "ice40-hx8k"))]
    #[serde(rename = "ice40-hx8k")]
    Ice40Hx8k,
}

impl SetupForm {
    pub const ALL: [SetupForm; 4] = [SetupForm::Parallel, SetupForm::Ecp5_25f, SetupForm::Ice40Up5k, SetupForm::Ice40Hx8k];

    pub fn name(self) -> &'static str {
        match self {
            SetupForm::Parallel => "parallel",
            SetupForm::Ecp5_25f => "ecp5-25f",
            SetupForm::Ice40Up5k => "ice40-up5k",
            SetupForm::Ice40Hx8k => "ice40-hx8k",
        }
    }

    /// Whether this is the default (serialised plans leave it out, so theirs stay as they were).
    pub fn is_default(&self) -> bool {
        *self == SetupForm::default()
    }
}

/// How the span path forms a covered row's `I0` (`generate --fe-span`): the products in
/// parallel logic or tiles, a row a clock (the default), or one after another on one shift-add
/// unit ([`span_seq::SpanSeq`]). The spans are the same bit for bit; the walker's rate and the latency
/// differ.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum SpanForm {
    #[default]
    Parallel,
    Sequential,
}

impl SpanForm {
    pub const ALL: [SpanForm; 2] = [SpanForm::Parallel, SpanForm::Sequential];

    pub fn name(self) -> &'static str {
        match self {
            SpanForm::Parallel => "parallel",
            SpanForm::Sequential => "sequential",
        }
    }

    /// Whether this is the default (serialised plans leave it out, so theirs stay as they were).
    pub fn is_default(&self) -> bool {
        *self == SpanForm::default()
    }
}

/// A front-end configuration: the shader's formats, the screen it draws on, where `dI` comes
/// from and how `I0` is formed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct FrontEnd {
    pub cfg: Config,
    pub screen: Screen,
    #[serde(default)]
    pub di: DiMode,
    #[serde(default, skip_serializing_if = "I0Form::is_default")]
    pub i0: I0Form,
    /// How the set-up is built (issue 27): the spans do not depend on it, its clocks do.
    #[serde(default, skip_serializing_if = "SetupForm::is_default")]
    pub setup: SetupForm,
    /// How the span path forms a row's `I0` (issue 27, the iCE40s): its rate and latency.
    #[serde(default, skip_serializing_if = "SpanForm::is_default")]
    pub span: SpanForm,
}

/// Every width of the front-end, derived once from the configuration: the generator declares
/// the RTL's registers with these and golden checks its values fit them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Widths {
    /// Row index `out_y`: holds `height - 1`.
    pub yw: u32,
    /// Vertex x, signed Q(XW+2).8: the guard band [-W, 2W) and then some.
    pub cx: u32,
    /// Vertex y, signed Q(YW+2).8.
    pub cy: u32,
    /// |A|, twice the area in sub-pixel units squared, unsigned.
    pub aw: u32,
    /// Edge bound `g` and step `Qs`, signed.
    pub gw: u32,
    /// Edge divisor `D = 256 |dy|` and the DDA remainder, unsigned.
    pub dw_edge: u32,
    /// Modulus bits of the normalised intensity sums: `K = IW + 2 + AW`.
    pub k: u32,
    /// The reciprocal `Rn`.
    pub rw: u32,
    /// Leading-zero count `s` of A.
    pub sw: u32,
}

impl Widths {
    /// The bits of `S2n` the quotient estimate drops, `t = AW`: its top IW + 1 bits are all it
    /// reads, and the estimate is the quotient or up to two below it (module documentation).
    pub fn i0_shift(&self) -> u32 {
        self.aw
    }

    /// Compares the correction makes: one per unit the estimate may fall short.
    pub const I0_COMPARES: u32 = 2;

    /// Trailing zeros of `Gxn = (256 Nx << s) mod 2^K`: the 8 of the sub-pixel grid's 256. The
    /// span path multiplies `Gxn >> 8` by the column and appends them, so its product is 8 bits
    /// narrower (at 640x480 52 x 10 bits, three tiles instead of four).
    pub const GXN_ZEROS: u32 = SUBPIXEL.trailing_zeros();

    /// Bits of the running sums of `Gxn g` ([`TriSetup::sums`]): `Gxn lo` modulo 2^(K-2) without
    /// its [`Widths::GXN_ZEROS`] zero bits.
    pub fn sum_bits(&self) -> u32 {
        self.k - 2 - Self::GXN_ZEROS
    }

    /// `Gxn c` modulo 2^(K-2) as the span path forms it: `((Gxn >> z) c) << z` with `z` =
    /// [`Widths::GXN_ZEROS`]; the bits of `Gxn` below 2^z are not read (the tests plant z + 1).
    pub fn gx_lo(&self, gxn: u128, c: u32, zeros: u32) -> u128 {
        (((gxn >> zeros) * c as u128) << zeros) & mask(self.k - 2)
    }

    /// The span path's arithmetic from `S2n` (its residue modulo 2^(K-1)), `An` and `Rn`, as
    /// wide as the RTL's registers (IW bits out): [`Widths::quotient_estimate`], then
    /// [`Widths::I0_COMPARES`] compares of the remainder.
    pub fn reciprocal_quotient(&self, s2n: u128, an: u128, rn: u128) -> u32 {
        self.corrected_quotient(s2n, an, rn, self.i0_shift(), Self::I0_COMPARES)
    }

    /// The quotient estimate `q~ = ((S2n >> t) Rn) >> (K - t)`, before its correction.
    pub fn quotient_estimate(&self, s2n: u128, rn: u128, t: u32) -> u128 {
        ((s2n >> t) * rn) >> (self.k - t)
    }

    /// `q~ + #{k in 1..=compares : R >= 2k An}` with the remainder `R = S2n - 2An q~` modulo
    /// 2^(AW+3): the arithmetic for any shift `t` and number of compares (the tests plant a
    /// shift one too far and a compare dropped). As the RTL forms it, each compare is the top
    /// bit of `((S2n - 2k An) - 2An q~) mod 2^(AW+3)`, the first difference formed beside the
    /// products: `R - 2k An` lies in `[-4An, 4An)`, `4An < 2^(AW+2)`, so it is negative exactly
    /// when its residue has bit AW + 2 set (module documentation).
    pub fn corrected_quotient(&self, s2n: u128, an: u128, rn: u128, t: u32, compares: u32) -> u32 {
        let iw = self.k - 2 - self.aw;
        let m = mask(self.aw + 3);
        let qt = self.quotient_estimate(s2n, rn, t) & mask(iw);
        let prod = (qt * 2 * an) & m;
        let negative = |k: u128| (((s2n.wrapping_sub(2 * k * an) & m).wrapping_sub(prod) & m) >> (self.aw + 2)) == 1;
        let up = (1..=compares as u128).filter(|&k| !negative(k));
        ((qt + up.count() as u128) & mask(iw)) as u32
    }
}

/// A triangle as it stands on the front-end's ports: sub-pixel coordinates, UQ8.F intensities.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct FixedTriangle {
    pub x: [i64; 3],
    pub y: [i64; 3],
    pub i: [u32; 3],
}

impl FixedTriangle {
    /// Snaps a triangle onto the ports (coordinates to 1/256 pixel, intensities to nearest).
    pub fn from_triangle(t: &Triangle, frac: u32) -> FixedTriangle {
        let scale = (1u64 << frac) as f64;
        let imax = ((256u64 << frac) - 1) as f64;
        FixedTriangle {
            x: t.v.map(|v| snap(v.x)),
            y: t.v.map(|v| snap(v.y)),
            i: t.v.map(|v| (v.i * scale).round().clamp(0.0, imax) as u32),
        }
    }

    /// The exact real triangle these port values stand for.
    pub fn to_triangle(&self, frac: u32) -> Triangle {
        let scale = (1u64 << frac) as f64;
        let s = SUBPIXEL as f64;
        let mut t = Triangle { v: [crate::setup::Vertex { x: 0.0, y: 0.0, i: 0.0 }; 3] };
        for k in 0..3 {
            t.v[k] = crate::setup::Vertex { x: self.x[k] as f64 / s, y: self.y[k] as f64 / s, i: self.i[k] as f64 / scale };
        }
        t
    }

    /// `setup::Snapped` of the same triangle, for coverage comparisons.
    pub fn snapped(&self, frac: u32) -> Snapped {
        let scale = (1u64 << frac) as f64;
        Snapped::from_fixed(self.x, self.y, self.i.map(|i| i as f64 / scale))
    }
}

/// What the front-end does with a triangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// A vertex lies outside the guard band: dropped, `err` raised.
    Guard,
    /// Zero area, or no pixel centre of the screen inside its bounding box: dropped by set-up.
    Culled,
    /// Walked; it may still cover no pixel (a sliver between centres).
    Walked,
}

/// One edge's walker state.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EdgeWalk {
    /// `dy > 0` (gives `hi`), `dy < 0` (gives `lo`); horizontal edges are never active.
    pub right: bool,
    pub active: bool,
    /// First and last active row (meaningful when `active`).
    pub rs: u32,
    pub re: u32,
    /// Bound and remainder at the current row.
    pub g: i64,
    pub rem: i64,
    /// `D = 256 |dy|`, and the per-row step `Qs`, `256 Rs`.
    pub d: i64,
    pub qs: i64,
    pub rs256: i64,
}

impl EdgeWalk {
    /// One DDA step; whether the remainder carried into the bound (`g` moved by `Qs + 1`).
    fn step_carry(&mut self) -> bool {
        self.rem += self.rs256;
        self.g += self.qs;
        let carry = self.rem >= self.d;
        if carry {
            self.rem -= self.d;
            self.g += 1;
        }
        carry
    }
}

/// Everything set-up hands the walker for one triangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TriSetup {
    pub first: u32,
    pub last: u32,
    pub edges: [EdgeWalk; 3],
    pub di: i32,
    /// `An = A << s`, `s`, and the reciprocal `Rn = floor(2^K / (2 An))`.
    pub an: u128,
    pub s: u32,
    pub rn: u128,
    /// Normalised running sums, modulo 2^K: `S(0, first) << s`, and the steps per row and
    /// per column, `(256 Ny) << s` and `(256 Nx) << s`.
    pub tn: u128,
    pub dyn_: u128,
    pub gxn: u128,
    /// The running sums' start and step for the two left slots ([`sums::left_slots`]; the engine
    /// form's span path, when its plan has [`engine::Plan::run_sums`]): `(Gxn >> 8) g` and
    /// `(Gxn >> 8) Qs` of the slot's edge modulo 2^[`Widths::sum_bits`], so the walker steps
    /// `Gxn g` with that edge's DDA and the span path takes `Gxn lo` from the slot its left end
    /// comes from ([`FrontEnd::walk`]), with no product a row. 0 where the slot's edge is not an
    /// active left edge.
    pub sums: Option<[(u128, u128); 2]>,
    /// Exact plane data, for self-checks: `I_0 A`, `Nx`, `Ny`, `x0`, `y0`, `A`.
    pub plane: Plane,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Plane {
    pub i0a: i128,
    pub nx: i128,
    pub ny: i128,
    pub x0: i64,
    pub y0: i64,
    pub a: i128,
}

impl Plane {
    /// `S(c, r)`: A times the plane's value (2^-F units) at the centre of pixel (c, r).
    pub fn s(&self, c: i64, r: i64) -> i128 {
        self.i0a + self.nx * (256 * c + HALF - self.x0) as i128 + self.ny * (256 * r + HALF - self.y0) as i128
    }
    /// The plane's value at the centre of (c, r), in intensity levels.
    pub fn value(&self, c: i64, r: i64, frac: u32) -> f64 {
        self.s(c, r) as f64 / self.a as f64 / (1u64 << frac) as f64
    }
}

fn bits(v: u128) -> u32 {
    128 - v.leading_zeros()
}

fn floor_div(n: i64, d: i64) -> i64 {
    n.div_euclid(d)
}

fn ceil_div(n: i64, d: i64) -> i64 {
    -(-n).div_euclid(d)
}

fn mask(w: u32) -> u128 {
    if w >= 128 {
        u128::MAX
    } else {
        (1u128 << w) - 1
    }
}

impl FrontEnd {
    pub fn new(cfg: Config, screen: Screen) -> Result<FrontEnd, FrontEndError> {
        if screen.width == 0 || screen.width > cfg.max_len() {
            return Err(FrontEndError::Width { width: screen.width, max: cfg.max_len() });
        }
        if screen.width as u64 > 1u64 << cfg.frac {
            return Err(FrontEndError::Accuracy { width: screen.width, frac: cfg.frac });
        }
        if screen.height == 0 || screen.height > 1 << 16 {
            return Err(FrontEndError::Height { height: screen.height });
        }
        Ok(FrontEnd { cfg, screen, di: DiMode::Triangle, i0: I0Form::Reciprocal, setup: SetupForm::Parallel, span: SpanForm::Parallel })
    }

    /// The same front-end with `dI` from `di`.
    pub fn with_di(self, di: DiMode) -> FrontEnd {
        FrontEnd { di, ..self }
    }

    /// The same front-end with `I0` formed by `i0`.
    pub fn with_i0(self, i0: I0Form) -> FrontEnd {
        FrontEnd { i0, ..self }
    }

    /// The same front-end with its set-up built as `setup` says.
    pub fn with_setup(self, setup: SetupForm) -> FrontEnd {
        FrontEnd { setup, ..self }
    }

    /// The same front-end with its span path in the form `span` says.
    pub fn with_span(self, span: SpanForm) -> FrontEnd {
        FrontEnd { span, ..self }
    }

    pub fn widths(&self) -> Widths {
        let yw = self.screen.y_bits();
        let cx = self.cfg.xbits + 10;
        let cy = yw + 10;
        let aw = cx + cy + 1;
        let k = self.cfg.iw() + 2 + aw;
        Widths { yw, cx, cy, aw, gw: self.cfg.xbits + 3, dw_edge: cy + 8, k, rw: self.cfg.iw() + 3, sw: bits(aw as u128) }
    }

    /// Whether every vertex lies in the guard band: `-W <= x < 2W`, `-H <= y < 2H` pixels.
    pub fn in_guard_band(&self, t: &FixedTriangle) -> bool {
        let (w, h) = (self.screen.width as i64 * SUBPIXEL, self.screen.height as i64 * SUBPIXEL);
        (0..3).all(|k| (-w..2 * w).contains(&t.x[k]) && (-h..2 * h).contains(&t.y[k]))
    }

    /// Whether the triangle's port values fit the ports (any value the RTL can be given).
    pub fn fits_ports(&self, t: &FixedTriangle) -> bool {
        let w = self.widths();
        let fits = |v: i64, bw: u32| v >= -(1i64 << (bw - 1)) && v < 1i64 << (bw - 1);
        (0..3).all(|k| fits(t.x[k], w.cx) && fits(t.y[k], w.cy) && t.i[k] < 1 << self.cfg.iw())
    }

    /// Set-up of one triangle: the outcome, and for a walked triangle everything the walker needs.
    pub fn setup(&self, t: &FixedTriangle) -> (Outcome, Option<TriSetup>) {
        assert!(self.fits_ports(t), "triangle does not fit the ports: {t:?}");
        if !self.in_guard_band(t) {
            return (Outcome::Guard, None);
        }
        let wd = self.widths();
        let (x, y) = (t.x, t.y);
        let a = ((x[1] - x[0]) as i128) * ((y[2] - y[0]) as i128) - ((y[1] - y[0]) as i128) * ((x[2] - x[0]) as i128);
        if a == 0 {
            return (Outcome::Culled, None);
        }
        let o: i64 = if a > 0 { 1 } else { -1 };
        let aabs = a.unsigned_abs();
        debug_assert!(bits(aabs) <= wd.aw);
        let (w, h) = (self.screen.width as i64, self.screen.height as i64);
        let (ymin, ymax) = (*y.iter().min().unwrap(), *y.iter().max().unwrap());
        let (xmin, xmax) = (*x.iter().min().unwrap(), *x.iter().max().unwrap());
        let mut edges = [EdgeWalk { right: false, active: false, rs: 0, re: 0, g: 0, rem: 0, d: 1, qs: 0, rs256: 0 }; 3];
        let mut kill = 0;
        // (dx, dy) oriented, anchor a, the edge's y extent, top-left.
        let mut dirs = [(0i64, 0i64, 0i64, 0i64, (0i64, 0i64), false); 3];
        for (k, dir) in dirs.iter_mut().enumerate() {
            let (ea, eb) = ((k + 1) % 3, (k + 2) % 3);
            let (dx, dy) = (o * (x[eb] - x[ea]), o * (y[eb] - y[ea]));
            let tl = is_top_left(dx, dy);
            if dy == 0 && !tl {
                kill = 1;
            }
            *dir = (dx, dy, x[ea], y[ea], (y[ea].min(y[eb]), y[ea].max(y[eb])), tl);
        }
        let first = ceil_div(ymin - HALF, SUBPIXEL).max(0);
        let last = floor_div(ymax - HALF - kill, SUBPIXEL).min(h - 1);
        let cfirst = ceil_div(xmin - HALF, SUBPIXEL);
        let clast = floor_div(xmax - HALF, SUBPIXEL);
        if first > last || cfirst > clast || cfirst > w - 1 || clast < 0 {
            return (Outcome::Culled, None);
        }
        let b = 1i64 << (wd.gw - 1);
        for (k, &(dx, dy, xa, ya, (yt, yb), tl)) in dirs.iter().enumerate() {
            if dy == 0 {
                continue;
            }
            let rs = ceil_div(yt - HALF, SUBPIXEL).max(first);
            let re = floor_div(yb - HALF, SUBPIXEL).min(last);
            let d = SUBPIXEL * dy.abs();
            let t = if tl { 0 } else { 1 };
            let e = &mut edges[k];
            e.right = dy > 0;
            e.d = d;
            e.qs = floor_div(dx, dy.abs());
            e.rs256 = SUBPIXEL * (dx - e.qs * dy.abs());
            if rs > re {
                continue;
            }
            e.active = true;
            (e.rs, e.re) = (rs as u32, re as u32);
            let n = dx * (SUBPIXEL * rs + HALF - ya) - dy * (HALF - xa) - t;
            e.g = floor_div(n, d);
            e.rem = n - e.g * d;
            // The widths the RTL's dividers have (module documentation).
            debug_assert!((-b..b).contains(&e.g), "edge bound {} outside GW = {} bits", e.g, wd.gw);
            debug_assert!(re == rs || (-b..b).contains(&e.qs), "edge step {} outside GW bits", e.qs);
            debug_assert!(bits(d as u128) <= wd.dw_edge);
        }
        // The plane, oriented like the edges.
        let (i0, i1, i2) = (t.i[0] as i128, t.i[1] as i128, t.i[2] as i128);
        let (dx1, dy1, dx2, dy2) = ((x[1] - x[0]) as i128, (y[1] - y[0]) as i128, (x[2] - x[0]) as i128, (y[2] - y[0]) as i128);
        let nx = o as i128 * ((i1 - i0) * dy2 - (i2 - i0) * dy1);
        let ny = o as i128 * ((i2 - i0) * dx1 - (i1 - i0) * dx2);
        let plane = Plane { i0a: i0 * aabs as i128, nx, ny, x0: x[0], y0: y[0], a: aabs as i128 };
        let di = self.di(256 * nx, aabs);
        let s = wd.aw - bits(aabs);
        let an = aabs << s;
        let rn = (1u128 << wd.k) / (2 * an);
        debug_assert!(bits(rn) <= wd.rw);
        let km = mask(wd.k);
        let norm = |v: i128| ((v as u128) << s) & km;
        let setup = TriSetup {
            first: first as u32,
            last: last as u32,
            edges,
            di,
            an,
            s,
            rn,
            tn: norm(plane.s(0, first)),
            dyn_: norm(256 * ny),
            gxn: norm(256 * nx),
            sums: None,
            plane,
        };
        let sums = self.setup.plan().is_some_and(|p| p.run_sums).then(|| self.running_sums(&setup));
        (Outcome::Walked, Some(TriSetup { sums, ..setup }))
    }

    /// `round(x / a)`, half away from zero, saturated to DW signed bits: the set-up's divider.
    fn di(&self, x: i128, a: u128) -> i32 {
        let iw = self.cfg.iw();
        let x2 = 2 * x.unsigned_abs() + a;
        let q = x2 / (2 * a);
        if q >= 1 << iw {
            return if x < 0 { -(1 << iw) } else { (1 << iw) - 1 };
        }
        if x < 0 {
            -(q as i32)
        } else {
            q as i32
        }
    }

    /// The walker's intensity for row `r`, first column `c`: `S2n = ((2S + A) << s) mod 2^(K-1)`
    /// from the running sum `tn` of the row, then the reciprocal and one correction.
    pub fn i0(&self, st: &TriSetup, tn: u128, c: u32) -> u32 {
        debug_assert_eq!(st.gxn & mask(Widths::GXN_ZEROS), 0, "Gxn's low bits, {st:?}");
        self.i0_from(st, tn, self.widths().gx_lo(st.gxn, c, Widths::GXN_ZEROS))
    }

    /// [`FrontEnd::i0`] from `Gxn c` modulo 2^(K-2), however it was formed.
    pub fn i0_from(&self, st: &TriSetup, tn: u128, gx: u128) -> u32 {
        let wd = self.widths();
        let s2n = (2 * (tn + gx) + st.an) & mask(wd.k - 1);
        wd.reciprocal_quotient(s2n, st.an, st.rn)
    }

    /// Set-up and walk: the outcome, and `out(y, span)` for every span.
    pub fn spans(&self, t: &FixedTriangle, out: impl FnMut(u32, Span)) -> Outcome {
        let (outcome, st) = self.setup(t);
        if let Some(st) = st {
            match self.i0 {
                I0Form::Reciprocal => self.walk(&st, out),
                I0Form::Incremental => {
                    self.walk_incremental(&st, out);
                }
            }
        }
        outcome
    }

    /// The spans as a list (tests, tools).
    pub fn span_list(&self, t: &FixedTriangle) -> (Outcome, Vec<(u32, Span)>) {
        let mut v = Vec::new();
        let o = self.spans(t, |y, s| v.push((y, s)));
        (o, v)
    }
}

#[cfg(test)]
mod tests;
