//! `hdl-gen report accuracy`: the specular unit's max relative error inside the epicentre
//! (SPEC §4) per n, as a Markdown table and as a two-panel plot after the patent's figures
//! 5 and 9. Every figure comes from golden's measurements; this module only arranges them.

use golden::specular::reference::approx_error;
use golden::specular::{accuracy_table, AccuracySummary, Decoder, NAccuracy, SpecularUnit, N_MAX, N_MIN};
use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use image::{ExtendedColorType, ImageEncoder, Rgb, RgbImage};
use std::fmt::Write as _;
use std::ops::RangeInclusive;

/// The prototype (Abbas et al.) approximates `cos^n x` by `cos^2(sqrt(n/2) x)`: the
/// patent's scheme with the single table k = 2.
const PROTOTYPE_K: u32 = 2;
/// The prototype's worst case is quoted from n = 2 on, as SPEC §1 quotes its 4.7%: at n = 1
/// alone it is twice that, which the table's footnote and n = 1 row show.
const PROTOTYPE_N_MIN: u32 = 2;

/// Everything the report shows, measured once.
pub struct AccuracyReport {
    decoder: Decoder,
    /// Golden's accuracy per valid n at the largest C: `rows[n - 1]`.
    rows: Vec<NAccuracy>,
    patent: Decoder,
    /// `(name, depth, width, bits)` of the BRDF ROM and the n-table.
    roms: [(String, usize, u32, u64); 2],
}

fn pct(e: f64) -> String {
    format!("{:.3}%", e * 100.0)
}

/// The largest `f(n)` over `ns`, with the n where it occurs (the first on a tie).
fn worst(ns: RangeInclusive<u32>, f: impl Fn(u32) -> f64) -> (f64, u32) {
    ns.map(|n| (f(n), n)).fold((f64::NEG_INFINITY, 0), |a, b| if b.0 > a.0 { b } else { a })
}

fn ns_label(ns: &RangeInclusive<u32>) -> String {
    if ns.start() == ns.end() {
        ns.start().to_string()
    } else {
        format!("{}..{}", ns.start(), ns.end())
    }
}

fn ks_label(d: &Decoder) -> String {
    d.ks().iter().map(u32::to_string).collect::<Vec<_>>().join(",")
}

impl AccuracyReport {
    /// Measures `unit` at the largest C, where the output's 1/256 step weighs least against
    /// the table error (golden's [`accuracy_table`]).
    pub fn measure(unit: &SpecularUnit) -> AccuracyReport {
        let rom = |r: &golden::rom::Rom| (r.name.clone(), r.depth(), r.width, r.bits());
        AccuracyReport {
            decoder: unit.plan().decoder.clone(),
            rows: accuracy_table(unit, u16::MAX),
            patent: Decoder::patent(),
            roms: [rom(unit.brdf_rom()), rom(unit.nk_rom())],
        }
    }

    fn row(&self, n: u32) -> &NAccuracy {
        &self.rows[(n - N_MIN) as usize]
    }

    fn patent_error(&self, n: u32) -> f64 {
        self.patent.error_of(n).expect("every n of the table is valid")
    }

    /// The table, Markdown: one row per n range of the configured decoder and one for the
    /// worst case over every n, then the ROM sizes.
    pub fn table(&self) -> String {
        let set = ks_label(&self.decoder);
        let mut s = format!(
            "Max relative error inside the epicentre (SPEC §4); RTL at C = 65535/256.\n\n\
             BRDF set k = {set}: {}\n\n\
             | n | k | approx., k = {set} | approx., patent k = {} | approx., cos^2 prototype | \
             RTL vs approx. | RTL total vs exact cos^n |\n|---|---|---|---|---|---|---|\n",
            self.decoder,
            ks_label(&self.patent)
        );
        let at = |(e, n): (f64, u32)| format!("{} (n={n})", pct(e));
        let proto = |ns: RangeInclusive<u32>| worst(ns, |n| approx_error(n, PROTOTYPE_K));
        for r in self.decoder.ranges() {
            let ns = r.n_lo..=r.n_hi;
            let sum = AccuracySummary::of(&self.rows[(r.n_lo - N_MIN) as usize..=(r.n_hi - N_MIN) as usize]);
            let cells = [
                sum.approx_vs_exact,
                worst(ns.clone(), |n| self.patent_error(n)),
                proto(ns.clone()),
                sum.model_vs_approx,
                sum.model_vs_exact,
            ];
            let show = |c: (f64, u32)| if r.n_lo == r.n_hi { pct(c.0) } else { at(c) };
            let cells: Vec<String> = cells.into_iter().map(show).collect();
            let _ = writeln!(s, "| {} | {} | {} |", ns_label(&ns), r.k, cells.join(" | "));
        }
        let sum = AccuracySummary::of(&self.rows);
        let _ = writeln!(
            s,
            "| **{}, worst** | | {} | {} | {} ¹ | {} | {} |",
            ns_label(&(N_MIN..=N_MAX)),
            at(sum.approx_vs_exact),
            at(self.patent.max_error()),
            at(proto(PROTOTYPE_N_MIN..=N_MAX)),
            at(sum.model_vs_approx),
            at(sum.model_vs_exact)
        );
        let _ = writeln!(
            s,
            "\n¹ over n = {PROTOTYPE_N_MIN}..{N_MAX}, as SPEC §1 quotes it; n = 1 alone: {}.\n",
            pct(approx_error(1, PROTOTYPE_K))
        );
        for (name, depth, width, bits) in &self.roms {
            let _ = writeln!(s, "- ROM {name}: {depth} x {width} = {bits} bits");
        }
        let _ = writeln!(s, "- ROM total: {} bits", self.roms.iter().map(|r| r.3).sum::<u64>());
        s
    }

    /// Max relative error against n in two panels: the approximations (the prototype's cos^2
    /// against the configured set, after the patent's figures 5 and 9), and the RTL's total
    /// error with the configured approximation under it for scale.
    pub fn png(&self) -> Result<Vec<u8>, String> {
        let set = ks_label(&self.decoder);
        let series = |f: &dyn Fn(u32) -> f64| (N_MIN..=N_MAX).map(f).collect::<Vec<f64>>();
        let approx = series(&|n| self.row(n).approx_vs_exact);
        let mut left = vec![
            Curve { label: "cos^2(sqrt(n/2) x), prototype".into(), color: RED, ys: series(&|n| approx_error(n, PROTOTYPE_K)) },
            Curve { label: format!("cos^k(sqrt(n/k) x), k = {set}"), color: BLUE, ys: approx.clone() },
        ];
        if self.decoder != self.patent {
            let label = format!("patent, k = {}", ks_label(&self.patent));
            // Under the configured set's curve, which is the one the reader came for.
            left.insert(1, Curve { label, color: GREEN, ys: series(&|n| self.patent_error(n)) });
        }
        let right = [
            Curve { label: "RTL (= golden) vs exact C cos^n, C max".into(), color: BLACK, ys: series(&|n| self.row(n).model_vs_exact) },
            Curve { label: format!("approximation alone, k = {set}"), color: GREY, ys: approx },
        ];
        let mut img = RgbImage::from_pixel(2 * PANEL_W, IMG_H, WHITE);
        centred(&mut img, PANEL_W, 12, "max relative error inside the epicentre (SPEC 4) vs n", BLACK);
        panel(&mut img, 0, "approximation of cos^n (f64)", &left);
        panel(&mut img, PANEL_W, "total error of the RTL", &right);
        let mut png = Vec::new();
        PngEncoder::new_with_quality(&mut png, CompressionType::Best, FilterType::Adaptive)
            .write_image(img.as_raw(), img.width(), img.height(), ExtendedColorType::Rgb8)
            .map_err(|e| format!("cannot encode the PNG: {e}"))?;
        Ok(png)
    }
}

struct Curve {
    label: String,
    color: Rgb<u8>,
    /// `ys[n - 1]`, relative error.
    ys: Vec<f64>,
}

const WHITE: Rgb<u8> = Rgb([255, 255, 255]);
const BLACK: Rgb<u8> = Rgb([0, 0, 0]);
const GRID: Rgb<u8> = Rgb([225, 225, 225]);
const GREY: Rgb<u8> = Rgb([150, 150, 150]);
const RED: Rgb<u8> = Rgb([210, 40, 30]);
const BLUE: Rgb<u8> = Rgb([30, 80, 200]);
const GREEN: Rgb<u8> = Rgb([20, 150, 60]);

const PANEL_W: u32 = 700;
const IMG_H: u32 = 540;
/// Plot box inside a panel: left, top, right, bottom.
const BOX: (i32, i32, i32, i32) = (90, 70, 660, 400);
/// Text is the 5x7 font doubled: 10x14 pixels a glyph, 12 a character cell.
const SCALE: i32 = 2;
const CELL: i32 = 6 * SCALE;

fn panel(img: &mut RgbImage, x0: u32, title: &str, curves: &[Curve]) {
    let (l, t, r, b) = (BOX.0 + x0 as i32, BOX.1, BOX.2 + x0 as i32, BOX.3);
    centred(img, x0 + PANEL_W / 2, t - 30, title, BLACK);
    let x_of = |n: f64| l as f64 + n.log10() / (N_MAX as f64).log10() * (r - l) as f64;
    // y: a 1-2-5 step giving four to eight gridlines, in percent.
    let top = curves.iter().flat_map(|c| &c.ys).fold(0.0f64, |a, &y| a.max(y)) * 100.0;
    let raw = top.max(1e-6) / 6.0;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0].iter().map(|m| m * mag).find(|&s| s >= raw).unwrap_or(10.0 * mag);
    let ticks = (top / step).ceil().max(1.0) as i32;
    let y_of = |pct: f64| b as f64 - pct / (step * ticks as f64) * (b - t) as f64;
    let decimals = (-step.log10().floor()).max(0.0) as usize;
    for i in 0..=ticks {
        let v = step * i as f64;
        let y = y_of(v).round() as i32;
        rect(img, l, y, r, y, GRID);
        let label = format!("{v:.decimals$}%");
        text(img, l - 8 - CELL * label.len() as i32, y - 7, &label, BLACK);
    }
    for decade in [1u32, 10, 100] {
        for m in 2..10 {
            let x = x_of((decade * m) as f64).round() as i32;
            rect(img, x, t, x, b, GRID);
            rect(img, x, b, x, b + 4, BLACK);
        }
    }
    for n in [1u32, 10, 100, 1000] {
        let x = x_of(n as f64).round() as i32;
        rect(img, x, t, x, b, GREY);
        rect(img, x, b, x, b + 8, BLACK);
        centred(img, x as u32, b + 14, &n.to_string(), BLACK);
    }
    centred(img, x0 + PANEL_W / 2, b + 38, "n (log scale)", BLACK);
    rect(img, l, t, l, b, BLACK);
    rect(img, l, b, r, b, BLACK);
    for (i, c) in curves.iter().enumerate() {
        let pts: Vec<(f64, f64)> = c.ys.iter().enumerate().map(|(j, &y)| (x_of((j as u32 + N_MIN) as f64), y_of(y * 100.0))).collect();
        for w in pts.windows(2) {
            line(img, w[0], w[1], c.color);
        }
        let y = b + 70 + 22 * i as i32;
        line(img, (l as f64, y as f64), ((l + 40) as f64, y as f64), c.color);
        text(img, l + 52, y - 7, &c.label, BLACK);
    }
}

/// Filled rectangle, corners inclusive, clipped to the image.
fn rect(img: &mut RgbImage, x0: i32, y0: i32, x1: i32, y1: i32, c: Rgb<u8>) {
    for y in y0.max(0)..=y1.min(img.height() as i32 - 1) {
        for x in x0.max(0)..=x1.min(img.width() as i32 - 1) {
            img.put_pixel(x as u32, y as u32, c);
        }
    }
}

/// A 2-pixel line, stamped every half pixel (steep jumps between n stay continuous).
fn line(img: &mut RgbImage, a: (f64, f64), b: (f64, f64), c: Rgb<u8>) {
    let steps = ((b.0 - a.0).abs().max((b.1 - a.1).abs()) * 2.0).ceil().max(1.0) as i32;
    for i in 0..=steps {
        let f = i as f64 / steps as f64;
        let (x, y) = ((a.0 + f * (b.0 - a.0)).round() as i32, (a.1 + f * (b.1 - a.1)).round() as i32);
        rect(img, x, y, x + 1, y + 1, c);
    }
}

fn centred(img: &mut RgbImage, cx: u32, y: i32, s: &str, c: Rgb<u8>) {
    text(img, cx as i32 - CELL * s.chars().count() as i32 / 2, y, s, c);
}

/// Text in the built-in font, upper case (the font has no lower case).
fn text(img: &mut RgbImage, x: i32, y: i32, s: &str, c: Rgb<u8>) {
    for (i, ch) in s.chars().enumerate() {
        let rows = FONT.iter().find(|g| g.0 == ch.to_ascii_uppercase()).map_or(UNKNOWN, |g| g.1);
        for (dy, bits) in rows.iter().enumerate() {
            for dx in 0..5 {
                if bits >> (4 - dx) & 1 == 1 {
                    let (px, py) = (x + i as i32 * CELL + dx * SCALE, y + dy as i32 * SCALE);
                    rect(img, px, py, px + SCALE - 1, py + SCALE - 1, c);
                }
            }
        }
    }
}

/// A filled box marks a character the font lacks, so a new label cannot lose one unseen.
const UNKNOWN: [u8; 7] = [0x1f; 7];
/// 5x7 glyphs, one row a byte, bit 4 leftmost.
#[rustfmt::skip]
const FONT: &[(char, [u8; 7])] = &[
    (' ', [0, 0, 0, 0, 0, 0, 0]), ('.', [0, 0, 0, 0, 0, 0x0c, 0x0c]), (',', [0, 0, 0, 0, 0x0c, 0x04, 0x08]),
    ('%', [0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03]), ('=', [0, 0, 0x1f, 0, 0x1f, 0, 0]), ('-', [0, 0, 0, 0x1f, 0, 0, 0]),
    ('(', [0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02]), (')', [0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08]),
    ('/', [0, 0x01, 0x02, 0x04, 0x08, 0x10, 0]), ('^', [0x04, 0x0a, 0x11, 0, 0, 0, 0]), (':', [0, 0x0c, 0x0c, 0, 0x0c, 0x0c, 0]),
    ('0', [0x0e, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0e]), ('1', [0x04, 0x0c, 0x04, 0x04, 0x04, 0x04, 0x0e]),
    ('2', [0x0e, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1f]), ('3', [0x1f, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0e]),
    ('4', [0x02, 0x06, 0x0a, 0x12, 0x1f, 0x02, 0x02]), ('5', [0x1f, 0x10, 0x1e, 0x01, 0x01, 0x11, 0x0e]),
    ('6', [0x06, 0x08, 0x10, 0x1e, 0x11, 0x11, 0x0e]), ('7', [0x1f, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08]),
    ('8', [0x0e, 0x11, 0x11, 0x0e, 0x11, 0x11, 0x0e]), ('9', [0x0e, 0x11, 0x11, 0x0f, 0x01, 0x02, 0x0c]),
    ('A', [0x0e, 0x11, 0x11, 0x1f, 0x11, 0x11, 0x11]), ('B', [0x1e, 0x11, 0x11, 0x1e, 0x11, 0x11, 0x1e]),
    ('C', [0x0e, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0e]), ('D', [0x1c, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1c]),
    ('E', [0x1f, 0x10, 0x10, 0x1e, 0x10, 0x10, 0x1f]), ('F', [0x1f, 0x10, 0x10, 0x1e, 0x10, 0x10, 0x10]),
    ('G', [0x0e, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0f]), ('H', [0x11, 0x11, 0x11, 0x1f, 0x11, 0x11, 0x11]),
    ('I', [0x0e, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0e]), ('J', [0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0c]),
    ('K', [0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11]), ('L', [0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1f]),
    ('M', [0x11, 0x1b, 0x15, 0x15, 0x11, 0x11, 0x11]), ('N', [0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11]),
    ('O', [0x0e, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0e]), ('P', [0x1e, 0x11, 0x11, 0x1e, 0x10, 0x10, 0x10]),
    ('Q', [0x0e, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0d]), ('R', [0x1e, 0x11, 0x11, 0x1e, 0x14, 0x12, 0x11]),
    ('S', [0x0f, 0x10, 0x10, 0x0e, 0x01, 0x01, 0x1e]), ('T', [0x1f, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04]),
    ('U', [0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0e]), ('V', [0x11, 0x11, 0x11, 0x11, 0x11, 0x0a, 0x04]),
    ('W', [0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0a]), ('X', [0x11, 0x11, 0x0a, 0x04, 0x0a, 0x11, 0x11]),
    ('Y', [0x11, 0x11, 0x11, 0x0a, 0x04, 0x04, 0x04]), ('Z', [0x1f, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1f]),
];
