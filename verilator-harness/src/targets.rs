//! `sweep --targets` (issue 27): each `--target`'s chain next to the defaults', on the sweep's
//! sized triangles: triangles per 1000 clocks measured in RTL (`tri_shader_p<P>`, both ends
//! always ready, every segment checked), the share of the spans-fed shader's rate that keeps, and
//! triangles a second at the clock the front-end of those options measured.
//!
//! The clocks are measurements, not models: [`measured_mhz`] holds the front-end's placed-and-
//! routed Fmax for the option sets measured (docs/fpga.md, "The triangle front-end"), and a form
//! without one reports clocks only.

use crate::frontend::{drain_clocks, run_chain};
use crate::models::ModelError;
use crate::registry;
use crate::traffic::Traffic;
use golden::frontend::{FixedTriangle, I0Form, SetupForm, SpanForm};
use golden::schemes::{workload_count, Scheme};
use golden::setup::{Screen, Triangle};
use golden::Align;
use hdl_gen::cli::VariantArgs;
use hdl_gen::Target;
use std::fmt::Write as _;

/// The widths swept per form: the iCE40s' p = 4 up to p = 16, the widest for ~100 px,
/// and p = 32, so that "the largest p keeping 95 %" is found, not capped by the sweep.
pub const WIDTHS: [u32; 4] = [4, 8, 16, 32];

/// `tri_frontend`'s Fmax on an ECP5 (speed 6, nextpnr, docs/fpga.md's tables: the 85F unless
/// said) for the options that decide it (set-up form, pipeline level, quotient bits a clock, `I0`
/// form), where it was measured.
pub fn measured_mhz(opts: &hdl_gen::Options) -> Option<(f64, &'static str)> {
    let div = opts.fe_div_bits.unwrap_or(hdl_gen::frontend::DEFAULT_DIV_BITS);
    match (opts.fe_setup, opts.pipeline.level(), div, opts.fe_i0) {
        (SetupForm::Parallel, 0, 4, I0Form::Reciprocal) => Some((18.2, "level 0, one seed")),
        (SetupForm::Parallel, 1, 4, I0Form::Reciprocal) => Some((29.6, "median of 3 seeds")),
        (SetupForm::Parallel, 1, 2, I0Form::Reciprocal) => Some((47.5, "one seed")),
        (SetupForm::Parallel, 1, 1, I0Form::Reciprocal) => Some((48.3, "one seed")),
        // The engine has no parallel dividers: their rate does not matter.
        (SetupForm::Ecp5_25f, 1, _, I0Form::Reciprocal) => Some((104.0, "LFE5U-25F, median of 3 seeds")),
        // The HX8K's target, its sequential span path: the whole `tri_fb_p4` placed (issue 27, stop 36:
        // the engine reading the triangle from its ports, seeds 3-5, seeds 1 and 2 stopped in the
        // router's livelock and replaced as scripts/synth does; stop 35 65.7).
        (SetupForm::Ice40Hx8k, 0, _, I0Form::Reciprocal) if opts.fe_span == SpanForm::Sequential => {
            Some((66.3, "iCE40 HX8K, tri_fb_p4, median of 3 seeds"))
        }
        // The UP5K's target, its sequential span path: the whole `tri_fb_p4` placed (issue 27, stop 37:
        // 5,245 of 5,280 logic cells; the walker's row its critical path).
        (SetupForm::Ice40Up5k, 0, _, I0Form::Reciprocal) if opts.fe_span == SpanForm::Sequential => {
            Some((21.6, "iCE40 UP5K, tri_fb_p4, median of 3 seeds"))
        }
        _ => None,
    }
}

/// One form's row at one P: per class, triangles per 1000 clocks and the spans-fed share.
struct Row {
    form: String,
    p: u32,
    cells: Vec<(f64, f64)>,
    mhz: Option<(f64, &'static str)>,
}

/// Runs every form (the defaults, then each target) at each of [`WIDTHS`], span-aligned, on
/// `workloads` (one per size class, `names` their labels); mismatches go to `failures`.
pub fn sweep(
    variant: &VariantArgs,
    screen: Screen,
    workloads: &[Vec<Triangle>],
    names: &[&str],
    seed: u64,
    failures: &mut Vec<String>,
) -> Result<String, ModelError> {
    let forms = std::iter::once(None).chain([Target::Ecp5_25f, Target::Ice40Hx8k, Target::Ice40Up5k].map(Some));
    let mut rows = Vec::new();
    for target in forms {
        let v = VariantArgs { target, ..variant.clone() };
        for p in WIDTHS {
            let opts = v.options(p, Align::Span, Some(screen)).map_err(|e| ModelError::Config(e.to_string()))?;
            let info = registry::tri_shader(&opts)?;
            let mut cells = Vec::new();
            for (k, tris) in workloads.iter().enumerate() {
                let fixed: Vec<_> = tris.iter().map(|t| FixedTriangle::from_triangle(t, info.cfg.frac)).collect();
                let run = run_chain(info, seed, Traffic::FULL, &fixed);
                if !run.report.ok() {
                    failures.push(format!("{}: class {k}: {} mismatches", info.tag, run.report.mismatch_count));
                }
                let busy = run.report.cycles.saturating_sub(drain_clocks(info.latency, &info.frontend())).max(1);
                let fed = workload_count(Scheme::Segment { p, align: Align::Span }, &info.cfg, &screen, tris)
                    .map_err(|e| ModelError::Config(e.to_string()))?
                    .pixels_per_clock();
                let ppc = run.report.pixels as f64 / busy as f64;
                cells.push((1000.0 * tris.len() as f64 / busy as f64, ppc / fed));
            }
            let form = target.map_or("defaults".to_string(), |t| format!("--target {t}"));
            rows.push(Row { form, p, cells, mhz: measured_mhz(&opts) });
        }
    }
    Ok(table(&rows, names))
}

fn table(rows: &[Row], names: &[&str]) -> String {
    let mut md = String::from(
        "Each form's chain (`tri_shader_p<P>`, span-aligned), both ends always ready, every segment checked. \
         Each cell: triangles per 1000 clocks (in brackets: the share of the spans-fed shader's pixels per clock), \
         then millions of triangles a second at the front-end's measured ECP5 clock (85F unless said).\n\n| form | p | clock |",
    );
    for n in names {
        let _ = write!(md, " {n} |");
    }
    md += "\n|---|--:|---|";
    md += &"--:|".repeat(names.len());
    md += "\n";
    for r in rows {
        let clock = r.mhz.map_or("not measured".to_string(), |(f, how)| format!("{f} MHz ({how})"));
        let _ = write!(md, "| {} | {} | {clock} |", r.form, r.p);
        for &(tpk, share) in &r.cells {
            let rate = r.mhz.map_or(String::new(), |(f, _)| format!(", {:.2} M/s", tpk * f / 1000.0));
            let _ = write!(md, " {tpk:.1} ({:.1}%){rate} |", 100.0 * share);
        }
        md += "\n";
    }
    md += "\nLargest p keeping 95 % of the spans-fed rate at each class:\n\n";
    let mut forms: Vec<&str> = rows.iter().map(|r| r.form.as_str()).collect();
    forms.dedup();
    for f in forms {
        let best: Vec<String> = (0..names.len())
            .map(|k| {
                let p = rows.iter().filter(|r| r.form == f && r.cells[k].1 >= 0.95).map(|r| r.p).max();
                format!("{} {}", names[k], p.map_or("none".to_string(), |p| format!("p = {p}")))
            })
            .collect();
        let _ = writeln!(md, "- {f}: {}", best.join(", "));
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        variant: VariantArgs,
    }

    /// The defaults and every target, whose front-ends were placed and routed,
    /// have a measured clock; an unmeasured form has none (the negative controls: the
    /// incremental I0, the HX8K's engine without its sequential span path).
    #[test]
    fn every_target_chooses_a_measured_front_end() {
        let base = Cli::parse_from(["t"]).variant;
        for target in [None, Some(Target::Ecp5_25f), Some(Target::Ice40Hx8k), Some(Target::Ice40Up5k)] {
            let opts = VariantArgs { target, ..base.clone() }.options(8, Align::Span, None).expect("valid");
            assert!(measured_mhz(&opts).is_some(), "{target:?}");
        }
        let hx = VariantArgs { target: Some(Target::Ice40Hx8k), fe_span: Some(SpanForm::Parallel), ..base.clone() };
        assert_eq!(measured_mhz(&hx.options(8, Align::Span, None).expect("valid")), None);
        let inc = VariantArgs { fe_i0: Some(I0Form::Incremental), ..base }.options(8, Align::Span, None).expect("valid");
        assert_eq!(measured_mhz(&inc), None);
    }
}
