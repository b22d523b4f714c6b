//! `manifest.json` against what it describes: every module it lists is a file that `generate`
//! wrote, holding that module with exactly those ports (name, direction, width, signedness,
//! order), read back from the Verilog text; every file it names exists; and every field it
//! has is documented in docs/manifest.md.

use golden::{Align, Config};
use hdl_gen::{generate, BfpiArch, Bus, GeneratedFile, Options};
use serde_json::Value;
use std::collections::BTreeSet;

fn configs() -> Vec<Options> {
    let mut v = Vec::new();
    for (p, align) in [(1, Align::Span), (8, Align::Screen), (8, Align::Span), (256, Align::Screen)] {
        for bfpi_arch in BfpiArch::ALL {
            v.push(Options { cfg: Config { p, align, ..Config::default() }, bfpi_arch, ..Default::default() });
        }
    }
    v.push(Options { cfg: Config::new(16, 4, 4, Align::Screen).unwrap(), prefix: "acme_".into(), ..Default::default() });
    v.push(Options { cfg: Config::new(2, 20, 16, Align::Span).unwrap(), ..Default::default() });
    for level in 1..=golden::pipeline::Pipeline::MAX {
        let pipeline = golden::pipeline::Pipeline::new(level).unwrap();
        v.push(Options { cfg: Config { p: 8, align: Align::Screen, ..Config::default() }, pipeline, ..Default::default() });
    }
    // `--fe-setup`: the set-up engine and its queue are listed with their ports, and the
    // engine's fields are documented.
    v.push(Options {
        cfg: Config { p: 8, ..Config::default() },
        screen: Some(golden::setup::Screen { width: 37, height: 23 }),
        fe_setup: golden::frontend::engine::SetupForm::Ecp5_25f,
        ..Default::default()
    });
    // `--bus axis`: the wrappers are listed with their ports like every module, and the `axis`
    // section's fields are documented.
    v.push(Options { cfg: Config { p: 8, ..Config::default() }, bus: Bus::Axis, ..Default::default() });
    v.push(Options {
        cfg: Config::new(1, 4, 4, Align::Screen).unwrap(),
        prefix: "acme_".into(),
        bus: Bus::Axis,
        pipeline: golden::pipeline::Pipeline::new(2).unwrap(),
        ..Default::default()
    });
    // `--target`: recorded with the choices it made.
    v.push(Options {
        target: Some(hdl_gen::Target::Ice40Up5k),
        pipeline: golden::pipeline::Pipeline::new(1).unwrap(),
        ..Default::default()
    });
    v
}

#[derive(Debug, PartialEq, Eq)]
struct PortDecl {
    name: String,
    direction: String,
    width: u32,
    signed: bool,
}

/// The ports of `module` as its ANSI header in `text` declares them; a width given by a parameter
/// (`[PW-1:0]`) at the parameter's default, as the manifest states it.
fn verilog_ports(text: &str, module: &str) -> Vec<PortDecl> {
    let mut lines = text.lines().skip_while(|l| {
        let mut t = l.split_whitespace();
        !(t.next() == Some("module") && t.next().map(|n| n.trim_end_matches(['(', '#'])) == Some(module))
    });
    assert!(lines.next().is_some(), "no `module {module}` in its file");
    let mut ports = Vec::new();
    let mut params = std::collections::HashMap::new();
    for line in lines {
        let code = line.split("//").next().unwrap().trim().trim_end_matches(',').trim();
        if code == ");" {
            return ports;
        }
        if let Some((name, value)) = code.strip_prefix("parameter ").and_then(|p| p.split_once(" = ")) {
            if let Ok(v) = value.trim().parse::<u32>() {
                params.insert(name.trim().to_string(), v);
            }
            continue;
        }
        let tokens: Vec<&str> = code.split_whitespace().collect();
        let direction = match tokens.first() {
            Some(&d @ ("input" | "output" | "inout")) => d.to_string(),
            _ => continue,
        };
        let mut rest = &tokens[1..];
        if let Some(&("wire" | "reg")) = rest.first() {
            rest = &rest[1..];
        }
        let signed = rest.first() == Some(&"signed");
        if signed {
            rest = &rest[1..];
        }
        let width = match rest.first() {
            Some(r) if r.starts_with('[') => {
                let (hi, lo) = r.trim_matches(['[', ']']).split_once(':').unwrap_or_else(|| panic!("range {r}"));
                rest = &rest[1..];
                let hi = hi.parse::<u32>().unwrap_or_else(|_| {
                    let (p, minus) = hi.split_once('-').unwrap_or_else(|| panic!("{module}: range {r}"));
                    params.get(p).unwrap_or_else(|| panic!("{module}: {r}: no parameter {p}")) - minus.parse::<u32>().unwrap()
                });
                hi - lo.parse::<u32>().unwrap() + 1
            }
            _ => 1,
        };
        assert_eq!(rest.len(), 1, "{module}: cannot read port line `{line}`");
        ports.push(PortDecl { name: rest[0].to_string(), direction, width, signed });
    }
    panic!("{module}: header has no closing `);`")
}

fn manifest_of(files: &[GeneratedFile]) -> Value {
    serde_json::from_str(&files.iter().find(|f| f.name == "manifest.json").expect("manifest.json written").contents).unwrap()
}

/// Every string under a key named `file`, anywhere in the manifest.
fn named_files(v: &Value, out: &mut Vec<String>) {
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                match (k.as_str(), x) {
                    ("file", Value::String(s)) => out.push(s.clone()),
                    _ => named_files(x, out),
                }
            }
        }
        Value::Array(a) => a.iter().for_each(|x| named_files(x, out)),
        _ => {}
    }
}

#[test]
fn every_listed_port_exists_in_the_verilog_with_that_width() {
    for opts in configs() {
        let what = format!("{:?}, prefix '{}', --bfpi-arch {}", opts.cfg, opts.prefix, opts.bfpi_arch);
        let files = generate(&opts);
        let m = manifest_of(&files);
        let modules = m["modules"].as_array().expect("modules list");
        let mut listed = BTreeSet::new();
        for entry in modules {
            let name = entry["name"].as_str().unwrap();
            let file = entry["file"].as_str().unwrap();
            listed.insert(file.to_string());
            let text = &files.iter().find(|f| f.name == file).unwrap_or_else(|| panic!("{what}: {file} not written")).contents;
            let declared = verilog_ports(text, name);
            let in_manifest: Vec<PortDecl> = entry["ports"]
                .as_array()
                .unwrap()
                .iter()
                .map(|p| PortDecl {
                    name: p["name"].as_str().unwrap().into(),
                    direction: p["direction"].as_str().unwrap().into(),
                    width: p["width"].as_u64().unwrap() as u32,
                    signed: p["signed"].as_bool().unwrap(),
                })
                .collect();
            assert_eq!(in_manifest, declared, "{what}: manifest ports of {name} differ from {file}");
        }
        let written: BTreeSet<String> = files.iter().filter(|f| f.name.ends_with(".v")).map(|f| f.name.clone()).collect();
        assert_eq!(listed, written, "{what}: the manifest lists other Verilog files than generate wrote");
        let mut named = Vec::new();
        named_files(&m, &mut named);
        for f in named {
            assert!(files.iter().any(|g| g.name == f), "{what}: manifest names {f}, which generate did not write");
        }
        let arch = m["parameters"]["bfpi_arch"].as_str().unwrap_or("shift-add");
        assert_eq!(arch, opts.bfpi_arch.name(), "{what}");
        assert_eq!(m["bfpi"].is_object(), opts.bfpi_arch == BfpiArch::ShiftAdd, "{what}: the bfpi graph is written for shift-add only");
    }
}

fn key_paths(v: &Value, path: &str, out: &mut BTreeSet<String>) {
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                let p = if path.is_empty() { k.clone() } else { format!("{path}.{k}") };
                out.insert(p.clone());
                key_paths(x, &p, out);
            }
        }
        Value::Array(a) => a.iter().for_each(|x| key_paths(x, &format!("{path}[]"), out)),
        _ => {}
    }
}

#[test]
fn every_manifest_field_is_documented() {
    let doc_path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/manifest.md");
    let doc = std::fs::read_to_string(&doc_path).expect("docs/manifest.md exists");
    let mut paths = BTreeSet::new();
    for opts in configs() {
        key_paths(&manifest_of(&generate(&opts)), "", &mut paths);
    }
    let missing: Vec<&String> = paths.iter().filter(|p| !doc.contains(&format!("`{p}`"))).collect();
    assert!(missing.is_empty(), "docs/manifest.md does not document (as `path`) these manifest fields: {missing:?}");
}

/// Where the layout tables lie between docs/axis.md's markers, or `None` without the markers.
fn axis_span(doc: &str) -> Option<std::ops::Range<usize>> {
    let start = doc.find(AXIS_BEGIN)? + AXIS_BEGIN.len() + 1;
    let end = start + doc[start..].find(AXIS_END)?;
    Some(start..end)
}

fn axis_tables(doc: &str) -> Option<&str> {
    axis_span(doc).map(|r| &doc[r])
}

const AXIS_BEGIN: &str =
    "<!-- generated: hdl-gen generate --p 8 --bus axis; refresh with SEGSHADE_BLESS=1 cargo test -p hdl-gen --test manifest -->";
const AXIS_END: &str = "<!-- end of generated tables -->";

/// docs/axis.md's layout tables are the typed layout's (`hdl_gen::axis::markdown` of the
/// default configuration's manifest), so the document cannot drift from the generator.
#[test]
fn docs_axis_tables_are_the_layout() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/axis.md");
    let doc = std::fs::read_to_string(&path).expect("docs/axis.md exists");
    let files = generate(&Options { bus: Bus::Axis, ..Default::default() });
    let m = hdl_gen::manifest::Manifest::parse(&files.iter().find(|f| f.name == "manifest.json").unwrap().contents).unwrap();
    assert_eq!(m.axis.len(), 4, "the shader, the front-end, its chain and the specular unit have wrappers");
    let want = hdl_gen::axis::markdown(&m.axis);
    if std::env::var_os("SEGSHADE_BLESS").is_some() {
        let r = axis_span(&doc).expect("docs/axis.md has the generated-table markers");
        std::fs::write(&path, format!("{}{want}{}", &doc[..r.start], &doc[r.end..])).unwrap();
        return;
    }
    assert_eq!(
        axis_tables(&doc),
        Some(want.as_str()),
        "docs/axis.md's tables differ from the layout; refresh: SEGSHADE_BLESS=1 cargo test -p hdl-gen --test manifest"
    );
    // The negative control: one field's bits changed in the document is a difference.
    let broken = doc.replacen("| `[11:0]` | `in_x` |", "| `[12:0]` | `in_x` |", 1);
    assert_ne!(broken, doc, "the control edits a row the tables have");
    assert_ne!(axis_tables(&broken), Some(want.as_str()));
}

// Tests of the whole generator, kept out of its modules so that no module imports the crate root
// (scripts/import-cycles).
use hdl_gen::manifest::{Manifest, Role, MANIFEST_FILE};

/// The reader is the writer's schema: every configuration's manifest reads back into
/// [`Manifest`] and prints again byte for byte, so no field is dropped or misread.
#[test]
fn manifests_read_back_exactly() {
    let configs = [
        Options::default(),
        Options { cfg: Config { p: 64, align: Align::Screen, ..Config::default() }, prefix: "x_".into(), ..Default::default() },
        Options { cfg: Config::new(2, 20, 16, Align::Span).unwrap(), bfpi_arch: BfpiArch::Tree, ..Default::default() },
        Options { prefix: "a_".into(), bus: Bus::Axis, ..Default::default() },
    ];
    for opts in configs {
        let files = generate(&opts);
        let text = &files.iter().find(|f| f.name == MANIFEST_FILE).unwrap().contents;
        let m = Manifest::parse(text).unwrap();
        assert_eq!(&(serde_json::to_string_pretty(&m).unwrap() + "\n"), text);
        assert_eq!(m.parameters.align, opts.cfg.align);
        assert!(m.by_role(Role::SegmentShader).is_some());
        assert_eq!(m.axis.len(), if opts.bus == Bus::Axis { 4 } else { 0 });
        for w in &m.axis {
            w.check().unwrap();
            assert_eq!(m.module(&w.module).unwrap().role, Role::Axis);
            assert_eq!(m.module(&w.module).unwrap().latency, m.module(&w.wraps).unwrap().latency);
        }
    }
}

#[test]
fn a_missing_module_is_named_with_the_ones_listed() {
    let files = generate(&Options::default());
    let m = Manifest::parse(&files.iter().find(|f| f.name == MANIFEST_FILE).unwrap().contents).unwrap();
    let e = m.module("nope").unwrap_err().to_string();
    assert!(e.contains("'nope'") && e.contains("segment_shader_p8"), "{e}");
    assert!(Manifest::parse("{}").is_err());
}

/// The extreme P (a byte and 256 bytes of pixels; P = 4 has a one-word lane bus) in both
/// alignments (the default P = 8 is in the manifest tests): each wrapper's packings keep the
/// rule, every data input is in `s_axis_tdata` once, and the shader's TKEEP has a bit per
/// TDATA byte.
#[test]
fn every_configuration_packs_by_the_rule() {
    for p in [1, 4, 256] {
        for align in Align::ALL {
            let cfg = Config { p, align, ..golden::Config::default() };
            let opts = Options { cfg, bus: Bus::Axis, ..Default::default() };
            let names = hdl_gen::Names::new("", &cfg);
            let files = generate(&opts);
            let m = Manifest::parse(&files.iter().find(|f| f.name == "manifest.json").unwrap().contents).unwrap();
            assert_eq!(m.axis.len(), 4, "p = {p}");
            for w in &m.axis {
                w.check().unwrap();
                let core = m.module(&w.wraps).unwrap();
                let inputs: Vec<&str> = core
                    .ports
                    .iter()
                    .filter(|x| x.direction == hdl_gen::verilog::Dir::Input && !hdl_gen::axis::CONTROL.contains(&x.name.as_str()))
                    .map(|x| x.name.as_str())
                    .collect();
                let packed: Vec<&str> = w.s_axis.tdata.fields.iter().map(|f| f.port.as_str()).collect();
                assert_eq!(packed, inputs, "{}", w.module);
                if w.wraps == names.segment {
                    assert_eq!((w.m_axis.tdata.bits, w.m_axis.tkeep.as_deref()), (8 * p, Some("out_mask")));
                }
            }
        }
    }
}
