//! `hdl-gen report accuracy`: the specular unit's max relative error inside the epicentre
//! (SPEC §4) per n, as a Markdown table and as a two-panel SVG plot after the patent's figures
//! 5 and 9 (drawn by `plotters`). Every figure comes from golden's measurements; this module only
//! arranges them.

use golden::specular::reference::approx_error;
use golden::specular::{accuracy_table, AccuracySummary, Decoder, NAccuracy, SpecularUnit, N_MAX, N_MIN};
use plotters::prelude::*;
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
    /// error with the configured approximation under it for scale. An SVG document: its text is
    /// SVG text, set in the viewer's sans-serif, so drawing it needs no font files.
    pub fn svg(&self) -> String {
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
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, (2 * PANEL_W, IMG_H)).into_drawing_area();
            root.fill(&WHITE).expect(DRAWN);
            let root = root.titled("max relative error inside the epicentre (SPEC §4) vs n", ("sans-serif", 22)).expect(DRAWN);
            let (a, b) = root.split_horizontally(PANEL_W);
            panel(&a, "approximation of cos^n (f64)", &left);
            panel(&b, "total error of the RTL", &right);
            root.present().expect(DRAWN);
        }
        svg
    }
}

/// Drawing into a `String` has nothing that can fail.
const DRAWN: &str = "an SVG drawn into a String";

struct Curve {
    label: String,
    color: RGBColor,
    /// `ys[n - 1]`, relative error.
    ys: Vec<f64>,
}

const GREY: RGBColor = RGBColor(150, 150, 150);
const RED: RGBColor = RGBColor(210, 40, 30);
const BLUE: RGBColor = RGBColor(30, 80, 200);
const GREEN: RGBColor = RGBColor(20, 150, 60);

const PANEL_W: u32 = 700;
const IMG_H: u32 = 520;

/// One panel: error in percent against n on a log axis, a line per curve, the legend below.
fn panel(area: &DrawingArea<SVGBackend, plotters::coord::Shift>, title: &str, curves: &[Curve]) {
    let top = curves.iter().flat_map(|c| &c.ys).fold(0.0f64, |a, &y| a.max(y)) * 100.0;
    let (plot, legend) = area.split_vertically(IMG_H - 110);
    let mut chart = ChartBuilder::on(&plot)
        .caption(title, ("sans-serif", 18))
        .margin(12)
        .margin_right(28)
        .x_label_area_size(44)
        .y_label_area_size(70)
        .build_cartesian_2d((N_MIN as f64..N_MAX as f64).log_scale(), 0.0..top * 1.05)
        .expect(DRAWN);
    chart
        .configure_mesh()
        .x_desc("n (log scale)")
        .y_desc("max relative error")
        .y_label_formatter(&|v| format!("{v:.1}%"))
        .x_label_formatter(&|v| format!("{v:.0}"))
        .draw()
        .expect(DRAWN);
    for c in curves {
        let points = c.ys.iter().enumerate().map(|(j, &y)| ((j as u32 + N_MIN) as f64, y * 100.0));
        chart.draw_series(LineSeries::new(points, c.color.stroke_width(2))).expect(DRAWN);
    }
    for (i, c) in curves.iter().enumerate() {
        let y = 20 + 24 * i as i32;
        legend.draw(&PathElement::new(vec![(90, y), (130, y)], c.color.stroke_width(2))).expect(DRAWN);
        legend.draw(&Text::new(c.label.clone(), (142, y - 8), ("sans-serif", 15))).expect(DRAWN);
    }
}
