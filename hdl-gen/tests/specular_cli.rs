//! The specular unit's commands: ROM images that read back to exactly golden's words,
//! `--brdf-k` and `--max-rel-error` refused with one message and exit status 2, and
//! `report accuracy` with SPEC's figures and its PNG.

mod common;
use common::{hdl_gen, scratch_dir as scratch};
use golden::rom::{Rom, RomFormat};
use golden::specular::{best_reachable, SpecularPlan, SpecularUnit, MAX_AUTO_TABLES};
use std::path::PathBuf;

fn entries(dir: &PathBuf) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    names
}

fn succeeds(args: &[&str]) -> String {
    let out = hdl_gen(args);
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).unwrap()
}

/// Runs a command that must fail: exit 2, one `error:` message naming `needle`, no output.
fn fails(args: &[&str], needle: &str) -> String {
    let out = hdl_gen(args);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert_eq!(err.matches("error:").count(), 1, "{args:?}: one message: {err}");
    assert!(err.contains(needle), "{args:?}: message should name '{needle}': {err}");
    assert!(out.stdout.is_empty(), "{args:?} printed {}", String::from_utf8_lossy(&out.stdout));
    err
}

#[test]
fn rom_images_read_back_to_golden_words() {
    let unit = SpecularUnit::default();
    let dir = scratch("rom");
    for (table, rom) in [("brdf", unit.brdf_rom()), ("nk", unit.nk_rom())] {
        for format in RomFormat::ALL {
            let ext = format.extension();
            let printed = succeeds(&["rom", "--table", table, "--format", ext]);
            let path = dir.join(format!("{table}.{ext}"));
            assert!(succeeds(&["rom", "--table", table, "--format", ext, "--out", path.to_str().unwrap()]).is_empty());
            let written = std::fs::read_to_string(&path).unwrap();
            assert_eq!(written, printed, "{table} {ext}: file and standard output differ");
            let back = Rom::parse(&rom.name, rom.width, format, &written).unwrap();
            assert_eq!(back.words, rom.words, "{table} {ext}");
        }
    }
    assert_eq!(entries(&dir).len(), 6, "no temporary file left: {:?}", entries(&dir));
}

#[test]
fn brdf_k_list_selects_golden_plan() {
    for table in ["brdf", "nk"] {
        let default = succeeds(&["rom", "--table", table]);
        assert_eq!(succeeds(&["rom", "--table", table, "--brdf-k", "1,2,4,16"]), default, "{table}");
    }
    let unit = SpecularUnit::new(SpecularPlan::from_k_set(&[1, 3, 9]).unwrap());
    let text = succeeds(&["rom", "--table", "brdf", "--brdf-k", "1,3,9"]);
    assert_ne!(text, succeeds(&["rom", "--table", "brdf"]));
    let rom = unit.brdf_rom();
    assert_eq!(Rom::parse(&rom.name, rom.width, RomFormat::Hex, &text).unwrap().words, rom.words);
}

#[test]
fn unreachable_auto_target_names_the_best_reachable_figure() {
    let (best, _) = best_reachable(MAX_AUTO_TABLES);
    let dir = scratch("auto");
    let out = dir.join("brdf.hex");
    let o = out.to_str().unwrap();
    for args in [
        &["rom", "--table", "brdf", "--brdf-k", "auto", "--max-rel-error", "0.2%", "--out", o][..],
        &["report", "accuracy", "--brdf-k", "auto", "--max-rel-error", "0.2%"],
    ] {
        let err = fails(args, "best reachable");
        assert!(err.contains(&format!("{:.3}%", best * 100.0)), "{err}");
    }
    assert!(entries(&dir).is_empty());
}

#[test]
fn bad_brdf_k_exits_2_naming_the_flag() {
    let dir = scratch("bad-k");
    let out = dir.join("brdf.hex");
    for bad in ["0", "65", "4,2", "x"] {
        fails(&["rom", "--table", "brdf", "--brdf-k", bad, "--out", out.to_str().unwrap()], "--brdf-k");
        fails(&["report", "accuracy", "--brdf-k", bad], "--brdf-k");
    }
    assert!(entries(&dir).is_empty());
}

#[test]
fn max_rel_error_needs_brdf_k_auto() {
    for cmd in [&["rom", "--table", "nk"][..], &["report", "accuracy"]] {
        let with = |extra: &[&'static str]| [cmd, extra].concat();
        fails(&with(&["--max-rel-error", "1%"]), "--brdf-k");
        fails(&with(&["--brdf-k", "1,2,4,16", "--max-rel-error", "1%"]), "--max-rel-error");
    }
}

/// The leading percentage of a table cell such as `1.089% (n=3)`, as a percentage.
fn percent(cell: &str) -> f64 {
    cell.split('%').next().unwrap().trim().parse().unwrap_or_else(|_| panic!("no percentage in '{cell}'"))
}

#[test]
fn report_accuracy_prints_spec_figures() {
    let text = succeeds(&["report", "accuracy"]);
    let rows: Vec<Vec<&str>> = text
        .lines()
        .filter(|l| l.starts_with('|') && !l.starts_with("|---"))
        .map(|l| l.trim_matches('|').split('|').map(str::trim).collect())
        .collect();
    let col = |name: &str| rows[0].iter().position(|h| h.contains(name)).unwrap_or_else(|| panic!("no column '{name}'"));
    let firsts: Vec<&str> = rows[1..].iter().map(|r| r[0]).collect();
    assert_eq!(firsts, ["1", "2", "3..6", "7..1000", "**1..1000, worst**"], "{text}");
    let worst = rows.last().unwrap();
    let patent = worst[col("patent")];
    assert!((1.08..=1.10).contains(&percent(patent)) && patent.contains("(n=3)"), "{patent}");
    let proto = percent(worst[col("cos^2")]);
    assert!((4.6..=4.8).contains(&proto), "{proto}");
    // The RTL's total error contains the approximation's and adds at most SPEC §4's 0.25%.
    let (approx, total) = (percent(worst[col("approx., k =")]), percent(worst[col("RTL total")]));
    assert!(approx <= total && total <= approx + 0.25 + 1e-3, "{approx} {total}");
    let unit = SpecularUnit::default();
    for rom in [unit.brdf_rom(), unit.nk_rom()] {
        assert!(text.contains(&format!("{}: {} x {} = {} bits", rom.name, rom.depth(), rom.width, rom.bits())), "{text}");
    }
}

/// The plot is an SVG with one line of a point per n for each curve, each curve named in the
/// legend, the same bytes for the same command.
#[test]
fn report_accuracy_draws_an_svg() {
    let dir = scratch("svg");
    let path = dir.join("accuracy.svg");
    let p = path.to_str().unwrap();
    let table = succeeds(&["report", "accuracy", "--svg", p]);
    assert_eq!(table, succeeds(&["report", "accuracy"]), "the plot does not change the table");
    let first = std::fs::read_to_string(&path).unwrap();
    assert!(first.starts_with("<svg width=\"1400\"") && first.trim_end().ends_with("</svg>"), "{}", &first[..200]);
    let points = |l: &str| l.split("points=\"").nth(1).and_then(|p| p.split('"').next()).map_or(0, |p| p.split_whitespace().count());
    let lines: Vec<usize> = first.split("<polyline").skip(1).map(points).collect();
    let curves = lines.iter().filter(|&&points| points == 1000).count();
    assert_eq!(curves, 4, "two curves a panel, a point per n: {lines:?}");
    for label in ["cos^2(sqrt(n/2) x), prototype", "cos^k(sqrt(n/k) x), k = 1,2,4,16", "RTL (= golden) vs exact C cos^n, C max"] {
        assert!(first.contains(label), "legend: {label}");
    }
    succeeds(&["report", "accuracy", "--svg", p]);
    assert_eq!(std::fs::read_to_string(&path).unwrap(), first, "same command, same bytes");
    assert_eq!(entries(&dir), ["accuracy.svg"]);
    // Another table set adds the patent's curve for comparison.
    succeeds(&["report", "accuracy", "--brdf-k", "1,2,3,9", "--svg", p]);
    let other = std::fs::read_to_string(&path).unwrap();
    assert!(other.contains("patent, k = 1,2,4,16") && !first.contains("patent, k ="));
}

#[test]
fn report_accuracy_bad_svg_path_exits_2_and_writes_nothing() {
    let dir = scratch("bad-svg");
    let missing = dir.join("no-such-folder").join("accuracy.svg");
    fails(&["report", "accuracy", "--svg", missing.to_str().unwrap()], missing.to_str().unwrap());
    // A folder in the way: the file is staged, then cannot replace it.
    let folder = dir.join("taken");
    std::fs::create_dir(&folder).unwrap();
    fails(&["report", "accuracy", "--svg", folder.to_str().unwrap()], folder.to_str().unwrap());
    assert_eq!(entries(&dir), ["taken"]);
    assert!(entries(&folder).is_empty());
}
