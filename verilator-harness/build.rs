//! Builds the RTL into linkable models: generate the Verilog (or take it from COSIM_RTL_DIR),
//! verilate it, read the file list from the generated `*_classes.mk`, compile with cc at -O2
//! and link statically. A model whose inputs (RTL, shim, Verilator version) are unchanged since
//! the last build is neither re-verilated nor recompiled.
//!
//! Each model is compiled as one translation unit (its class files and its shim), as
//! Verilator's own makefile compiles `V*__ALL.cpp`: the evaluation functions inline into each
//! other and into the shim's `step`, which is what a native testbench gets. Models are built on
//! as many threads as cargo gives jobs, and each records its build time in
//! `OUT_DIR/obj/<tag>/build.time` (read by the `bench` binary).
//!
//! Traced twins (`verilator --trace-fst`, symbols `<tag>_tr_*`, see `csrc/trace.h` and
//! `verilator_harness::waveform`): with COSIM_TRACE set, every streaming model gets one; without
//! it, only [`ALWAYS_TRACED`], so the suite's waveform test has one to run. The untraced models
//! are built exactly as without twins (same flags, same keys): twins are models of their own,
//! with a runtime of their own for the FST writer (`libverilated_fst_rt.a`, linked with zlib).

use golden::frontend::DiMode;
use golden::pipeline::Pipeline;
use golden::setup::Screen;
use golden::specular::{Decoder, DecoderRepr, KRange, SpecularGeometry, SpecularPlan};
use golden::{Align, Config};
use hdl_gen::manifest::{Manifest, ModuleEntry, Role, MANIFEST_FILE};
use std::fmt::Write as _;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// How a model is compiled; part of every model's key, so a change here rebuilds the models.
const LAYOUT: &str = "one translation unit per model: class files, then the shim; -O2 -fPIE";

/// Traced twins' (see the module comment) difference from [`LAYOUT`]; part of their keys.
const TRACE_LAYOUT: &str = "verilator --trace-fst; -DVM_TRACE=1 -DVM_TRACE_FST=1";
/// The model that has a traced twin in every default build (no COSIM_RTL_DIR): a small one, cheap
/// to compile, for the suite's waveform test.
const ALWAYS_TRACED: &str = "seg_p2_span";
/// The suffix of a twin's tag (and symbols) after its model's.
const TRACED_SUFFIX: &str = "_tr";

/// The segment widths built by default, each in both alignments; each p's BFPI is built too.
const BUILT_P: [u32; 7] = [1, 2, 4, 8, 16, 32, 64];
/// The triangle-to-segment chains built by default (SPEC §6), on 640x480; with
/// `SEGSHADE_ALL_CHAINS` set, every P in both alignments.
const BUILT_TRI: [(u32, Align); 4] = [(1, Align::Span), (8, Align::Span), (8, Align::Screen), (64, Align::Screen)];
/// The segment writers built by default (SPEC §7; small: the glue's corners are P = 2 and P = 8
/// and 64 in both alignments) and the chains from triangles to memory.
const BUILT_WR: [(u32, Align); 6] =
    [(1, Align::Span), (2, Align::Span), (8, Align::Span), (8, Align::Screen), (64, Align::Span), (64, Align::Screen)];
const BUILT_FB: [(u32, Align); 2] = [(8, Align::Span), (64, Align::Screen)];
/// Pipelined shaders (`--pipeline`) built by default: levels 1 and 2 at P = 8 in both alignments,
/// the deepest at P = 8 and at the smallest and largest P in one alignment each (P = 1 has no
/// lead, so its alignments are one circuit; P = 64's screen alignment has the widest lead
/// arithmetic, and its BFPI a second adder level, formed when the span starts).
const BUILT_PIPE: [(u32, u32, Option<Align>); 5] =
    [(8, 1, None), (8, 2, None), (1, 3, Some(Align::Span)), (8, 3, Some(Align::Span)), (64, 3, Some(Align::Screen))];

#[derive(Clone, Copy, PartialEq)]
enum Kind {
    Segment,
    Bfpi,
    Specular,
    /// `tri_frontend`: triangles in, spans out.
    Frontend,
    /// `tri_shader_p<P>`: triangles in, segments with y out.
    TriShader,
    /// `fb_writer_p<P>`: segments with y in, block writes out.
    Writer,
    /// `tri_fb_p<P>`: triangles in, block writes out.
    TriWriter,
}

#[derive(Clone)]
struct Model {
    /// Symbol prefix of the shim and suffix of the Verilator class (`V<tag>`).
    tag: String,
    kind: Kind,
    cfg: Config,
    /// The front-end's screen (front-end models; the default elsewhere).
    screen: Screen,
    /// Where a front-end model's dI comes from.
    di: DiMode,
    top: String,
    /// Clocks from input transfer to first output valid (0: combinational).
    latency: u32,
    /// The shader's register stages (`--pipeline`).
    pipeline: Pipeline,
    /// Verilog sources and ROM images: (file name, text).
    sources: Vec<(String, String)>,
    /// `--bus axis`: the model is the AXI4-Stream wrapper `top` of the SPEC module of its kind,
    /// driven through the kind's per-clock structs, packed as this layout says.
    axis: Option<hdl_gen::axis::Wrapper>,
}

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=csrc/shim.h");
    println!("cargo:rerun-if-changed=csrc/trace.h");
    println!("cargo:rerun-if-env-changed=COSIM_RTL_DIR");
    println!("cargo:rerun-if-env-changed=SEGSHADE_ALL_CHAINS");
    // Only whether it is set matters here (its folder is read at run time).
    println!("cargo:rerun-if-env-changed=COSIM_TRACE");
    let out = PathBuf::from(std::env::var("OUT_DIR").unwrap());
    let rtl_dir = std::env::var_os("COSIM_RTL_DIR").map(PathBuf::from);
    let manifest = rtl_dir.as_deref().map(|dir| {
        println!("cargo:rerun-if-changed={}", dir.display());
        (dir, read_manifest(dir))
    });
    let models = match &manifest {
        Some((dir, m)) => models_from_dir(dir, m),
        None => generated_models(),
    };
    let trace_all = std::env::var_os("COSIM_TRACE").is_some();
    let twins: Vec<Model> = models
        .iter()
        .filter(|m| m.kind != Kind::Bfpi && (trace_all || (rtl_dir.is_none() && m.tag == ALWAYS_TRACED)))
        .map(|m| Model { tag: format!("{}{TRACED_SUFFIX}", m.tag), ..m.clone() })
        .collect();
    let verilator = Verilator::find();
    let jobs: Vec<(&Model, bool)> = models.iter().map(|m| (m, false)).chain(twins.iter().map(|m| (m, true))).collect();
    let globals = build_models(&verilator, &out, &jobs);
    let plain: Vec<String> = union(globals.iter().filter(|(traced, _)| !traced).map(|(_, g)| g));
    build_runtime(&verilator, &out, Runtime::PLAIN, &plain);
    // The twins' runtime files beyond the plain models' (the FST writer), with their defines.
    let fst: Vec<String> = union(globals.iter().filter(|(traced, _)| *traced).map(|(_, g)| g));
    let fst: Vec<String> = fst.into_iter().filter(|g| !plain.contains(g)).collect();
    if !twins.is_empty() {
        build_runtime(&verilator, &out, Runtime::FST, &fst);
    }
    println!("cargo:rustc-link-search=native={}", out.display());
    for m in models.iter().chain(&twins) {
        println!("cargo:rustc-link-lib=static={}", m.tag);
    }
    if !twins.is_empty() {
        println!("cargo:rustc-link-lib=static={}", Runtime::FST.lib);
    }
    println!("cargo:rustc-link-lib=static={}", Runtime::PLAIN.lib);
    println!("cargo:rustc-link-lib=stdc++");
    if !twins.is_empty() {
        // The FST writer compresses its hierarchy with zlib.
        println!("cargo:rustc-link-lib=z");
    }
    println!("cargo:rustc-link-lib=pthread");
    println!("cargo:rustc-link-lib=atomic");
    let tables = match &manifest {
        Some((dir, m)) => tables_from_dir(dir, m),
        None => SpecTables::of(hdl_gen::Options::default().specular_unit().plan(), None),
    };
    fs::write(out.join("models.rs"), models_rs(&models, &twins, trace_all, rtl_dir.as_deref(), &tables)).unwrap();
    // The segment suite's random test is one test per (model, soak slice), so that nextest can
    // deal a configuration's soak out to several machines (`verilator_harness::soak`): its list
    // of models is this build's, written where tests/segment.rs includes it.
    let seg: Vec<&str> = models.iter().filter(|m| m.kind == Kind::Segment && m.axis.is_none()).map(|m| m.tag.as_str()).collect();
    fs::write(out.join("segment_slices.rs"), format!("random_triangle_slices!({});\n", seg.join(", "))).unwrap();
}

/// The runtime files the lists ask for, each once, in the order first asked.
fn union<'a>(lists: impl Iterator<Item = &'a Vec<String>>) -> Vec<String> {
    let mut all: Vec<String> = Vec::new();
    for g in lists.flatten() {
        if !all.contains(g) {
            all.push(g.clone());
        }
    }
    all
}

/// The specular unit's table set, as models.rs hands it to the checkers (`ffi::SPECULAR_TABLES`),
/// which rebuild golden's plan from it: `SpecularPlan::build(decoder, word_bits)`.
struct SpecTables {
    ks: Vec<u32>,
    ranges: Vec<KRange>,
    /// `None`: the builder picks the BRDF word width, as for every plan hdl-gen makes but some
    /// `--brdf-k auto` ones (see `golden::specular::auto_plan`).
    word_bits: Option<u32>,
}

impl SpecTables {
    fn of(plan: &SpecularPlan, word_bits: Option<u32>) -> SpecTables {
        SpecTables { ks: plan.decoder.ks().to_vec(), ranges: plan.decoder.ranges(), word_bits }
    }
}

/// `DIR/manifest.json`, read as the generator's own schema (`hdl_gen::manifest::Manifest`), or
/// the build stops saying why.
fn read_manifest(dir: &Path) -> Manifest {
    let path = dir.join(MANIFEST_FILE);
    let text = fs::read_to_string(&path).unwrap_or_else(|e| panic!("COSIM_RTL_DIR={}: cannot read {MANIFEST_FILE}: {e}", dir.display()));
    Manifest::parse(&text).unwrap_or_else(|e| panic!("COSIM_RTL_DIR={}: {e}", dir.display()))
}

/// The table set of COSIM_RTL_DIR's manifest (its `specular` section, golden's typed
/// `SpecularGeometry`), checked to rebuild in golden the very plan the section states (tables,
/// widths, and the pipeline of `parameters.pipeline`), so the checkers compare the RTL with the
/// unit it was generated as. The default set when the folder has no specular unit (no checker
/// then uses it).
fn tables_from_dir(dir: &Path, m: &Manifest) -> SpecTables {
    let fail = |what: String| -> ! { panic!("COSIM_RTL_DIR={}: {MANIFEST_FILE}: specular: {what}", dir.display()) };
    if m.by_role(Role::SpecularUnit).is_none() {
        return SpecTables::of(&SpecularPlan::patent(), None);
    }
    let stated = &m.specular.geometry;
    let decoder =
        Decoder::try_from(DecoderRepr { ks: stated.ks.clone(), ranges: stated.k_ranges.clone() }).unwrap_or_else(|e| fail(e.to_string()));
    // hdl-gen builds with the builder's word width, or for some `auto` sets the search's.
    let mut last = String::new();
    for w in [None, Some(stated.brdf_word_bits)] {
        match SpecularPlan::build(decoder.clone(), w) {
            Ok(plan) => {
                let plan = plan.with_pipeline(m.parameters.pipeline);
                let mut built = plan.geometry();
                // f64::powi rounds differently at different opt-levels (hdl-gen's against this
                // build script's): the approximation error may differ in its last digits.
                let (a, b) = (built.approx_error.0, stated.approx_error.0);
                if (a - b).abs() <= 1e-9 * a.abs().max(b.abs()) {
                    built.approx_error.0 = b;
                }
                if built == *stated {
                    return SpecTables::of(&plan, w);
                }
                last = format!("with word_bits {w:?}, {}", geometry_diff(stated, &built));
            }
            Err(e) => last = e.to_string(),
        }
    }
    fail(format!("golden's plan for k = {:?} and these k_ranges is not the one the manifest states: {last}", stated.ks))
}

/// The fields of two geometries that differ, as `field: manifest X, golden Y`.
fn geometry_diff(stated: &SpecularGeometry, built: &SpecularGeometry) -> String {
    let fields = |g: &SpecularGeometry| match serde_json::to_value(g).expect("a geometry serializes") {
        serde_json::Value::Object(map) => map,
        _ => unreachable!("a struct serializes as an object"),
    };
    let (stated, built) = (fields(stated), fields(built));
    built
        .iter()
        .filter(|(k, v)| stated.get(k.as_str()) != Some(*v))
        .map(|(k, v)| format!("{k}: manifest {}, golden {v}", stated.get(k.as_str()).unwrap_or(&serde_json::Value::Null)))
        .collect::<Vec<_>>()
        .join("; ")
}

fn generated_models() -> Vec<Model> {
    let mut models = Vec::new();
    let spec_names = hdl_gen::specular::SpecNames::new("");
    // The specular unit as SPEC's seed builds it, then split for clock rate (`--pipeline 1`;
    // level 2 adds nothing to the unit).
    for pipeline in [Pipeline::NONE, Pipeline::at(1)] {
        let opts = hdl_gen::Options { pipeline, ..Default::default() };
        let tag = if pipeline == Pipeline::NONE { "spec".to_string() } else { format!("spec_pl{pipeline}") };
        models.push(Model {
            tag,
            kind: Kind::Specular,
            cfg: Config::default(),
            di: DiMode::Triangle,
            screen: Screen::default(),
            top: spec_names.unit.clone(),
            latency: opts.specular_unit().plan().latency(),
            pipeline,
            axis: None,
            sources: hdl_gen::generate(&opts)
                .into_iter()
                .filter(|f| f.name.ends_with(".hex") || f.name.starts_with("specular_"))
                .map(|f| (f.name, f.contents))
                .collect(),
        });
    }
    for p in BUILT_P {
        for align in Align::ALL {
            let cfg = Config { p, align, ..Config::default() };
            let files = hdl_gen::generate(&hdl_gen::Options { cfg, ..Default::default() });
            let sources: Vec<(String, String)> =
                files.into_iter().filter(|f| f.name.ends_with(".v")).map(|f| (f.name, f.contents)).collect();
            let names = hdl_gen::Names::new("", &cfg);
            if align == Align::Span {
                let bfpi = sources.iter().filter(|(n, _)| *n == format!("{}.v", names.bfpi)).cloned().collect();
                models.push(Model {
                    tag: format!("bfpi_p{p}"),
                    kind: Kind::Bfpi,
                    cfg,
                    di: DiMode::Triangle,
                    screen: Screen::default(),
                    top: names.bfpi.clone(),
                    latency: 0,
                    pipeline: Pipeline::NONE,
                    axis: None,
                    sources: bfpi,
                });
            }
            let latency = golden::segment::latency(&cfg, Pipeline::NONE);
            // The chain at every P and alignment only on request (`sweep`'s front-end table):
            // each is a few seconds of compiling that the test suite does not need.
            if BUILT_TRI.contains(&(p, align)) || std::env::var_os("SEGSHADE_ALL_CHAINS").is_some() {
                let opts = hdl_gen::Options { cfg, screen: Some(Screen::default()), ..Default::default() };
                let hw = opts.frontend().expect("640x480 front-end");
                let fe = hw.fe;
                let (fe_lat, top_lat) = (hw.latency(), hw.latency() + latency);
                if p == 8 && align == Align::Span {
                    let src = sources.iter().filter(|(n, _)| *n == format!("{}.v", names.frontend)).cloned().collect();
                    models.push(Model {
                        tag: "fe".into(),
                        kind: Kind::Frontend,
                        cfg,
                        di: DiMode::Triangle,
                        screen: fe.screen,
                        top: names.frontend.clone(),
                        latency: fe_lat,
                        pipeline: Pipeline::NONE,
                        axis: None,
                        sources: src,
                    });
                    // The classical per-scanline dI (`--fe-di scanline`), the comparison option.
                    let scan = hdl_gen::frontend::Hw { fe: fe.with_di(DiMode::Scanline), ..hw };
                    let m = hdl_gen::frontend::module(&scan, &names);
                    models.push(Model {
                        tag: "fe_scan".into(),
                        kind: Kind::Frontend,
                        cfg,
                        di: DiMode::Scanline,
                        screen: fe.screen,
                        top: m.name.clone(),
                        latency: scan.latency(),
                        pipeline: Pipeline::NONE,
                        axis: None,
                        sources: vec![(format!("{}.v", m.name), m.render())],
                    });
                    // The set-up and the span path in stages (`--pipeline 1` and above: one
                    // front-end for them all); with the per-scanline dI too on request (a
                    // comparison option's, as `sweep`'s chains; `scripts/check-rtl-dir` also
                    // checks one such folder through COSIM_RTL_DIR).
                    let staged_di: &[(&str, DiMode)] = if std::env::var_os("SEGSHADE_ALL_CHAINS").is_some() {
                        &[("fe_pl1", DiMode::Triangle), ("fe_scan_pl1", DiMode::Scanline)]
                    } else {
                        &[("fe_pl1", DiMode::Triangle)]
                    };
                    for &(tag, di) in staged_di {
                        let staged = hdl_gen::frontend::Hw { fe: fe.with_di(di), pipeline: Pipeline::at(1), ..hw };
                        let m = hdl_gen::frontend::module(&staged, &names);
                        models.push(Model {
                            tag: tag.into(),
                            kind: Kind::Frontend,
                            cfg,
                            di,
                            screen: fe.screen,
                            top: m.name.clone(),
                            latency: staged.latency(),
                            pipeline: staged.pipeline,
                            axis: None,
                            sources: vec![(format!("{}.v", m.name), m.render())],
                        });
                    }
                    // The other divider rates (`--fe-div-bits`), so co-simulation covers every option.
                    for div_bits in hdl_gen::frontend::DIV_BITS.into_iter().filter(|&b| b != hw.div_bits) {
                        let hw = hdl_gen::frontend::Hw { div_bits, ..hw };
                        let m = hdl_gen::frontend::module(&hw, &names);
                        let src = vec![(format!("{}.v", m.name), m.render())];
                        models.push(Model {
                            tag: format!("fe_div{div_bits}"),
                            kind: Kind::Frontend,
                            cfg,
                            di: DiMode::Triangle,
                            screen: fe.screen,
                            top: m.name,
                            latency: hw.latency(),
                            pipeline: Pipeline::NONE,
                            axis: None,
                            sources: src,
                        });
                    }
                }
                let chain = [&names.bfpi, &names.segment, &names.frontend, &names.top].map(|n| format!("{n}.v"));
                let src: Vec<(String, String)> = sources.iter().filter(|(n, _)| chain.contains(n)).cloned().collect();
                if BUILT_TRI.contains(&(p, align)) && std::env::var_os("SEGSHADE_ALL_CHAINS").is_some() {
                    // The chain with the per-scanline dI, for `sweep`'s comparison.
                    let scan = hdl_gen::frontend::Hw { fe: fe.with_di(DiMode::Scanline), ..hw };
                    let m = hdl_gen::frontend::module(&scan, &names);
                    let mut src = src.clone();
                    src.retain(|(n, _)| *n != format!("{}.v", names.frontend));
                    src.push((format!("{}.v", m.name), m.render()));
                    models.push(Model {
                        tag: format!("tris_p{p}_{align}_scan"),
                        kind: Kind::TriShader,
                        cfg,
                        di: DiMode::Scanline,
                        screen: fe.screen,
                        top: names.top.clone(),
                        latency: scan.latency() + latency,
                        pipeline: Pipeline::NONE,
                        axis: None,
                        sources: src,
                    });
                }
                models.push(Model {
                    tag: format!("tris_p{p}_{align}"),
                    kind: Kind::TriShader,
                    cfg,
                    di: DiMode::Triangle,
                    screen: fe.screen,
                    top: names.top.clone(),
                    latency: top_lat,
                    pipeline: Pipeline::NONE,
                    axis: None,
                    sources: src,
                });
            }
            let all_chains = std::env::var_os("SEGSHADE_ALL_CHAINS").is_some();
            if BUILT_WR.contains(&(p, align)) || all_chains {
                let src = sources.iter().filter(|(n, _)| *n == format!("{}.v", names.writer)).cloned().collect();
                let (tag, top) = (format!("wr_p{p}_{align}"), names.writer.clone());
                let latency = golden::writer::LATENCY;
                models.push(Model {
                    tag,
                    kind: Kind::Writer,
                    cfg,
                    di: DiMode::Triangle,
                    screen: Screen::default(),
                    top,
                    latency,
                    pipeline: Pipeline::NONE,
                    axis: None,
                    sources: src,
                });
            }
            if BUILT_FB.contains(&(p, align)) || all_chains {
                let opts = hdl_gen::Options { cfg, screen: Some(Screen::default()), ..Default::default() };
                let chain =
                    [&names.bfpi, &names.segment, &names.frontend, &names.top, &names.writer, &names.fb_top].map(|n| format!("{n}.v"));
                let src = sources.iter().filter(|(n, _)| chain.contains(n)).cloned().collect();
                let latency = opts.frontend().expect("640x480 front-end").latency() + latency + golden::writer::LATENCY;
                let (tag, top) = (format!("trw_p{p}_{align}"), names.fb_top.clone());
                models.push(Model {
                    tag,
                    kind: Kind::TriWriter,
                    cfg,
                    di: DiMode::Triangle,
                    screen: Screen::default(),
                    top,
                    latency,
                    pipeline: Pipeline::NONE,
                    axis: None,
                    sources: src,
                });
            }
            let sources: Vec<(String, String)> =
                sources.into_iter().filter(|(n, _)| *n == format!("{}.v", names.segment) || *n == format!("{}.v", names.bfpi)).collect();
            for level in BUILT_PIPE.iter().filter(|(bp, _, a)| *bp == p && a.is_none_or(|a| a == align)).map(|&(_, l, _)| l) {
                let pipeline = Pipeline::new(level).expect("a built level exists");
                let m = hdl_gen::segment::module_with(&cfg, &names, hdl_gen::BfpiArch::ShiftAdd, pipeline);
                let mut src: Vec<(String, String)> =
                    sources.iter().filter(|(n, _)| *n != format!("{}.v", names.segment)).cloned().collect();
                src.push((format!("{}.v", m.name), m.render()));
                models.push(Model {
                    tag: format!("seg_p{p}_{align}_pl{level}"),
                    kind: Kind::Segment,
                    cfg,
                    di: DiMode::Triangle,
                    screen: Screen::default(),
                    top: names.segment.clone(),
                    latency: golden::segment::latency(&cfg, pipeline),
                    pipeline,
                    axis: None,
                    sources: src,
                });
            }
            models.push(Model {
                tag: format!("seg_p{p}_{align}"),
                kind: Kind::Segment,
                cfg,
                di: DiMode::Triangle,
                screen: Screen::default(),
                top: names.segment,
                latency,
                pipeline: Pipeline::NONE,
                axis: None,
                sources,
            });
        }
    }
    // The AXI4-Stream wrappers (`--bus axis`) of the default shader and specular unit, driven
    // through their cores' structs: two models, so the default suite stays quick; COSIM_RTL_DIR
    // builds every wrapper its folder has.
    let files = hdl_gen::generate(&hdl_gen::Options { bus: hdl_gen::Bus::Axis, ..Default::default() });
    let text = |name: &str| files.iter().find(|f| f.name == name).map(|f| f.contents.clone()).expect("a generated file");
    let manifest = Manifest::parse(&text(MANIFEST_FILE)).expect("the generated manifest reads back");
    let names = hdl_gen::Names::new("", &Config::default());
    let wanted = |w: &hdl_gen::axis::Wrapper| w.wraps == names.segment || w.wraps == spec_names.unit;
    models.extend(axis_models(&models, &manifest, wanted, |file| (file.to_string(), text(file))).expect("the default wrappers"));
    models
}

/// The models described by `DIR/manifest.json` (`m`), as `hdl-gen generate` writes it: the
/// Verilog is read from DIR as it is, so hand-edited or third-party RTL is checked against golden.
/// Modules are found by their role; each model's top, file and latency are the manifest's.
fn models_from_dir(dir: &Path, m: &Manifest) -> Vec<Model> {
    let fail = |what: String| -> ! { panic!("COSIM_RTL_DIR={}: {what}", dir.display()) };
    let params = &m.parameters;
    let cfg = Config::new(params.p, params.frac, params.xbits, params.align).unwrap_or_else(|e| fail(format!("{MANIFEST_FILE}: {e}")));
    let pipeline = params.pipeline;
    let read = |file: &str| {
        let text = fs::read_to_string(dir.join(file)).unwrap_or_else(|e| fail(format!("cannot read {file}: {e}")));
        (file.to_string(), text)
    };
    let files_of =
        |roles: &[Role]| -> Vec<(String, String)> { m.modules.iter().filter(|x| roles.contains(&x.role)).map(|x| read(&x.file)).collect() };
    // A model of one module: its kind, tag and role's entry, its sources.
    let model = |kind: Kind, tag: String, entry: &ModuleEntry, screen: Screen, di: DiMode, pipeline: Pipeline, sources| Model {
        tag,
        kind,
        cfg,
        di,
        screen,
        top: entry.name.clone(),
        latency: entry.latency,
        pipeline,
        axis: None,
        sources,
    };
    let (none, screen0, di0) = (Pipeline::NONE, Screen::default(), DiMode::Triangle);
    let sources = files_of(&[Role::Bfpi, Role::SegmentShader]);
    let mut models = Vec::new();
    if let Some(bfpi) = m.by_role(Role::Bfpi) {
        let src = vec![read(&bfpi.file)];
        models.push(model(Kind::Bfpi, format!("bfpi_p{}", cfg.p), bfpi, screen0, di0, none, src));
    }
    if let Some(seg) = m.by_role(Role::SegmentShader) {
        models.push(model(Kind::Segment, format!("seg_p{}_{}", cfg.p, cfg.align), seg, screen0, di0, pipeline, sources.clone()));
    }
    if let (Some(fe_mod), Some(tri)) = (m.by_role(Role::Frontend), m.by_role(Role::TriangleShader)) {
        let fe = m.frontend.as_ref().unwrap_or_else(|| fail(format!("{MANIFEST_FILE} lists a front-end module but no frontend section")));
        let (screen, di) = (fe.screen, fe.di);
        let fe_src = files_of(&[Role::Frontend]);
        let mut all = sources.clone();
        all.extend(fe_src.iter().cloned());
        all.extend(files_of(&[Role::TriangleShader]));
        models.push(model(Kind::Frontend, "fe".into(), fe_mod, screen, di, pipeline, fe_src));
        models.push(model(Kind::TriShader, format!("tris_p{}_{}", cfg.p, cfg.align), tri, screen, di, pipeline, all.clone()));
        if let (Some(wr), Some(fb)) = (m.by_role(Role::Writer), m.by_role(Role::TriangleWriter)) {
            let wr_src = files_of(&[Role::Writer]);
            models.push(model(Kind::Writer, format!("wr_p{}_{}", cfg.p, cfg.align), wr, screen, di, none, wr_src.clone()));
            all.extend(wr_src);
            all.extend(files_of(&[Role::TriangleWriter]));
            models.push(model(Kind::TriWriter, format!("trw_p{}_{}", cfg.p, cfg.align), fb, screen, di, pipeline, all));
        }
    }
    if let Some(unit) = m.by_role(Role::SpecularUnit) {
        let mut src = files_of(&[Role::SpecularUnit, Role::Rom]);
        src.push(read(&m.specular.brdf_rom.file));
        src.push(read(&m.specular.nk_rom.file));
        models.push(model(Kind::Specular, "spec".into(), unit, screen0, di0, pipeline, src));
    }
    if models.is_empty() {
        fail(format!("{MANIFEST_FILE} lists no bfpi, segment_shader or specular_unit module"));
    }
    let axis = axis_models(&models, m, |_| true, read).unwrap_or_else(|e| fail(e));
    models.extend(axis);
    models
}

/// The AXI4-Stream wrappers `m` lists (those `wanted` keeps): each the model in `models` of its
/// core (same kind, top, P, alignment and pipeline level) with the wrapper as top and its file
/// (`read`) added.
/// A layout that breaks the packing rule, or a wrapper of a module with no model, is an error.
fn axis_models(
    models: &[Model],
    m: &Manifest,
    wanted: impl Fn(&hdl_gen::axis::Wrapper) -> bool,
    read: impl Fn(&str) -> (String, String),
) -> Result<Vec<Model>, String> {
    let mut out = Vec::new();
    for w in m.axis.iter().filter(|w| wanted(w)) {
        w.check().map_err(|e| format!("{MANIFEST_FILE}: axis: {e}"))?;
        let entry = m.module(&w.module).map_err(|e| e.to_string())?;
        let kind = match m.module(&w.wraps).map_err(|e| e.to_string())?.role {
            Role::SegmentShader => Kind::Segment,
            Role::SpecularUnit => Kind::Specular,
            Role::Frontend => Kind::Frontend,
            Role::TriangleShader => Kind::TriShader,
            other => {
                return Err(format!("{MANIFEST_FILE}: axis: {} wraps {} ({other:?}), which has no streaming model", w.module, w.wraps))
            }
        };
        // The configuration's own model: a default build also has other alignments and pipeline
        // levels of a top (the front-end level 0's and level 1's, which every level above shares).
        let p = &m.parameters;
        let core = models
            .iter()
            .filter(|c| c.kind == kind && c.top == w.wraps && c.axis.is_none() && (c.cfg.p, c.cfg.align) == (p.p, p.align))
            .min_by_key(|c| c.pipeline != p.pipeline)
            .ok_or_else(|| format!("{MANIFEST_FILE}: axis: no model of {}, which {} wraps", w.wraps, w.module))?;
        let mut sources = core.sources.clone();
        sources.push(read(&entry.file));
        out.push(Model {
            tag: format!("{}_axis", core.tag),
            top: w.module.clone(),
            latency: entry.latency,
            sources,
            axis: Some(w.clone()),
            ..core.clone()
        });
    }
    Ok(out)
}

struct Verilator {
    root: PathBuf,
    version: String,
}

impl Verilator {
    fn find() -> Verilator {
        let missing = || -> ! {
            panic!(
                "\n\nverilator was not found on PATH. The co-simulation harness needs it.\n\
                 Install Debian's package:   apt-get install -y verilator\n\
                 (or run ./scripts/test, which installs it when missing)\n\n"
            )
        };
        let version = Command::new("verilator").arg("--version").output().unwrap_or_else(|_| missing());
        if !version.status.success() {
            missing();
        }
        let root = Command::new("verilator").args(["--getenv", "VERILATOR_ROOT"]).output().unwrap_or_else(|_| missing());
        Verilator {
            root: PathBuf::from(String::from_utf8_lossy(&root.stdout).trim()),
            version: String::from_utf8_lossy(&version.stdout).trim().to_string(),
        }
    }

    fn include(&self) -> [PathBuf; 2] {
        [self.root.join("include"), self.root.join("include/vltstd")]
    }
}

/// The compiler set-up Verilator's own makefile uses, at -O2 whatever the cargo profile.
/// Position-independent for an executable (`-fPIE`, as g++ builds a native testbench), not for
/// a shared library (`-fPIC`): the models only ever link into executables, and under `-fPIC`
/// every global function may be interposed, so GCC would not inline the model's evaluation
/// functions into each other.
///
/// `traced`: for a traced twin and the FST writer, `VM_TRACE` and `VM_TRACE_FST` are 1, as
/// Verilator's makefile sets them for a `--trace-fst` model; everything else is the same.
fn cc_build(v: &Verilator, traced: bool) -> cc::Build {
    let mut b = cc::Build::new();
    b.cpp(true)
        .opt_level(2)
        .pic(false)
        .flag("-fPIE")
        .debug(false)
        .warnings(false)
        .cargo_metadata(false)
        .flag("-std=gnu++17")
        .flag("-faligned-new")
        .flag("-fcf-protection=none");
    for d in ["VM_COVERAGE", "VM_SC", "VM_TRACE", "VM_TRACE_FST", "VM_TRACE_VCD"] {
        let on = traced && (d == "VM_TRACE" || d == "VM_TRACE_FST");
        b.define(d, if on { "1" } else { "0" });
    }
    for i in v.include() {
        b.include(i);
    }
    b
}

/// Builds every model, (model, traced twin or not), as many at once as cargo allows jobs (each
/// model is one verilator run and one compiler run). Returns, for each, whether it is traced and
/// the runtime files its makefile asks for.
fn build_models(v: &Verilator, out: &Path, models: &[(&Model, bool)]) -> Vec<(bool, Vec<String>)> {
    let jobs = std::env::var("NUM_JOBS").ok().and_then(|j| j.parse().ok()).unwrap_or(1usize).clamp(1, models.len().max(1));
    let next = std::sync::atomic::AtomicUsize::new(0);
    let globals = std::sync::Mutex::new(vec![(false, Vec::new()); models.len()]);
    std::thread::scope(|s| {
        for _ in 0..jobs {
            s.spawn(|| loop {
                let k = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                let Some(&(m, traced)) = models.get(k) else { break };
                let g = build_model(v, out, m, traced);
                globals.lock().unwrap()[k] = (traced, g);
            });
        }
    });
    globals.into_inner().unwrap()
}

/// Verilates and compiles one model (`traced`: a traced twin) unless its key (everything the
/// result depends on) is the one recorded by the last build. Returns the runtime files its
/// makefile asks for.
fn build_model(v: &Verilator, out: &Path, m: &Model, traced: bool) -> Vec<String> {
    let class = format!("V{}", m.tag);
    let shim = shim_cpp(m, &class, traced);
    let mut key = format!("{}\n{LAYOUT}\n{}\n{}\n{}\n", v.version, m.top, include_str!("csrc/shim.h"), shim);
    for (name, text) in &m.sources {
        write!(key, "== {name}\n{text}").unwrap();
    }
    if traced {
        write!(key, "== {TRACE_LAYOUT}\n{}", include_str!("csrc/trace.h")).unwrap();
    }
    let cache = cache_dir(out, &m.tag, &key);
    let (obj, rtl) = (cache.join("obj"), cache.join("rtl"));
    let key_file = obj.join("build.key");
    let classes_mk = obj.join(format!("{class}_classes.mk"));
    let lib = obj.join(format!("lib{}.a", m.tag));
    let fresh = fs::read_to_string(&key_file).is_ok_and(|k| k == key) && lib.exists() && classes_mk.exists();
    let start = Instant::now();
    if !fresh {
        let _ = fs::remove_dir_all(&obj);
        let _ = fs::remove_dir_all(&rtl);
        fs::create_dir_all(&obj).unwrap();
        fs::create_dir_all(&rtl).unwrap();
        let mut files = Vec::new();
        for (name, text) in &m.sources {
            fs::write(rtl.join(name), text).unwrap();
            if name.ends_with(".v") {
                files.push(rtl.join(name));
            }
        }
        // $readmemh opens its file when the model starts, from wherever the test runs: name
        // the images by absolute path.
        let images: Vec<String> = match m.kind {
            Kind::Specular => [("BRDF_FILE", golden::rom::BRDF_HEX), ("NK_FILE", golden::rom::NK_HEX)]
                .iter()
                .map(|(param, file)| format!("-G{param}=\"{}\"", rtl.join(file).display()))
                .collect(),
            _ => Vec::new(),
        };
        let status = Command::new("verilator")
            .args(["--cc", "-O3", "--x-assign", "fast", "--x-initial", "unique", "-Wno-fatal"])
            .args(traced.then_some("--trace-fst"))
            .args(["--prefix", &class, "--top-module", &m.top])
            .args(&images)
            .arg("-Mdir")
            .arg(&obj)
            .args(&files)
            .status()
            .expect("running verilator");
        assert!(status.success(), "verilator failed on {} ({})", m.top, rtl.display());
    }
    let mk = Classes::read(&classes_mk);
    if !fresh {
        let verilated = start.elapsed().as_secs_f64();
        // The model's classes and the shim in one translation unit (see the module comment).
        let mut all = String::from("// Generated by build.rs: the model and its shim, one translation unit.\n");
        for c in &mk.model {
            writeln!(all, "#include \"{c}.cpp\"").unwrap();
        }
        all.push_str(&shim);
        let all_path = obj.join(format!("{class}__all.cpp"));
        fs::write(&all_path, &all).unwrap();
        let mut b = cc_build(v, traced);
        b.include(&obj).include(Path::new(env!("CARGO_MANIFEST_DIR")).join("csrc")).out_dir(&obj).file(&all_path);
        b.compile(&m.tag);
        let total = start.elapsed().as_secs_f64();
        fs::write(obj.join("build.time"), format!("verilate {verilated:.3}\ncompile {:.3}\ntotal {total:.3}\n", total - verilated))
            .unwrap();
        fs::write(&key_file, &key).unwrap();
    }
    // Into OUT_DIR: the library to link, and what `bench info` reads (build time, sources).
    fs::copy(&lib, out.join(format!("lib{}.a", m.tag))).unwrap();
    let (out_obj, out_rtl) = (out.join("obj").join(&m.tag), out.join("rtl").join(&m.tag));
    fs::create_dir_all(&out_obj).unwrap();
    fs::create_dir_all(&out_rtl).unwrap();
    fs::copy(obj.join("build.time"), out_obj.join("build.time")).unwrap();
    for (name, text) in &m.sources {
        fs::write(out_rtl.join(name), text).unwrap();
    }
    mk.global
}

/// Where a build with this `key` lives: a folder per profile named by the key's hash, shared by
/// every `OUT_DIR` of the profile. `cargo clippy` and `cargo test` run this script in OUT_DIRs of
/// their own; with the models here, the second finds them built. (Two cargo processes building
/// the same new key at the same moment would race; scripts/test runs them one after the other.)
fn cache_dir(out: &Path, tag: &str, key: &str) -> PathBuf {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    key.hash(&mut h);
    // OUT_DIR is <target>/<profile>/build/<package>-<hash>/out.
    let root = out.ancestors().nth(3).map_or_else(|| out.join("cache"), |p| p.join("segshade-models"));
    root.join(format!("{tag}-{:016x}", h.finish()))
}

/// One of Verilator's runtime libraries.
struct Runtime {
    /// Its cache folder's tag (`cache_dir`).
    tag: &'static str,
    /// The static library's name.
    lib: &'static str,
    traced: bool,
}

impl Runtime {
    /// Verilator's runtime (`verilated.cpp`, `verilated_threads.cpp`, as the makefile lists them),
    /// compiled once for every model.
    const PLAIN: Runtime = Runtime { tag: "runtime", lib: "verilated_rt", traced: false };
    /// What traced twins need beyond it: the FST writer (`verilated_fst_c.cpp`, which includes
    /// GTKWave's `fstapi.c` and its compressors).
    const FST: Runtime = Runtime { tag: "fst-runtime", lib: "verilated_fst_rt", traced: true };
}

/// Compiles `globals`, runtime files the models' makefiles ask for, into `rt`'s library, once for
/// every model.
fn build_runtime(v: &Verilator, out: &Path, rt: Runtime, globals: &[String]) {
    let mut key = format!("{}\n{LAYOUT}\n{}\n", v.version, globals.join(" "));
    if rt.traced {
        key.push_str(TRACE_LAYOUT);
    }
    let obj = cache_dir(out, rt.tag, &key);
    let lib = obj.join(format!("lib{}.a", rt.lib));
    let linked = out.join(format!("lib{}.a", rt.lib));
    if fs::read_to_string(obj.join("build.key")).is_ok_and(|k| k == key) && lib.exists() {
        fs::copy(&lib, &linked).unwrap();
        return;
    }
    fs::create_dir_all(&obj).unwrap();
    let start = Instant::now();
    let mut b = cc_build(v, rt.traced);
    b.out_dir(&obj);
    if rt.traced {
        require_zlib(v, &obj);
    }
    for g in globals {
        b.file(v.root.join("include").join(format!("{g}.cpp")));
    }
    b.compile(rt.lib);
    fs::copy(&lib, &linked).unwrap();
    fs::write(
        obj.join("build.time"),
        format!("compile {:.3}\ntotal {:.3}\n", start.elapsed().as_secs_f64(), start.elapsed().as_secs_f64()),
    )
    .unwrap();
    fs::write(obj.join("build.key"), key).unwrap();
}

/// The file lists of a `V*_classes.mk`.
struct Classes {
    model: Vec<String>,
    global: Vec<String>,
}

impl Classes {
    fn read(path: &Path) -> Classes {
        let text = fs::read_to_string(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
        let mut model = Vec::new();
        let mut global = Vec::new();
        let mut current: Option<&mut Vec<String>> = None;
        for line in text.lines() {
            let line = line.trim();
            if let Some((var, _)) = line.split_once("+=") {
                current = match var.trim() {
                    "VM_CLASSES_FAST" | "VM_CLASSES_SLOW" | "VM_SUPPORT_FAST" | "VM_SUPPORT_SLOW" => Some(&mut model),
                    "VM_GLOBAL_FAST" | "VM_GLOBAL_SLOW" => Some(&mut global),
                    _ => None,
                };
            } else if line.is_empty() || line.starts_with('#') {
                current = None;
            } else if let Some(list) = current.as_deref_mut() {
                list.extend(line.trim_end_matches('\\').split_whitespace().map(str::to_string));
            }
        }
        assert!(!model.is_empty(), "{} lists no model files", path.display());
        Classes { model, global }
    }
}

/// The model's shim: shim.h's macro for its kind. A traced twin expands it on the traced class
/// under the symbol prefix `<tag>_raw`, and `trace.h`'s wrappers give the `<tag>_*` symbols.
fn shim_cpp(m: &Model, class: &str, traced: bool) -> String {
    let (model, sym) = match traced {
        false => (class.to_string(), m.tag.clone()),
        true => (format!("SegshadeTraced<{class}>"), format!("{}_raw", m.tag)),
    };
    let expand = match (&m.axis, m.kind) {
        (Some(w), _) => axis_step_cpp(m.kind, w, &model, &sym),
        (None, kind) => native_expand(kind, m, &model, &sym),
    };
    if !traced {
        return format!("// Generated by build.rs.\n#include \"{class}.h\"\n#include \"shim.h\"\n{expand}\n");
    }
    let (inp, outp) = ports(m.kind);
    format!(
        "// Generated by build.rs: a traced twin.\n#include \"{class}.h\"\n#include \"shim.h\"\n#include \"trace.h\"\n{expand}\n\
         SEGSHADE_TRACE_SHIM({class}, {}, {inp}, {outp})\n",
        m.tag
    )
}

/// shim.h's macro for a native model of `kind`.
fn native_expand(kind: Kind, m: &Model, model: &str, sym: &str) -> String {
    match kind {
        Kind::Segment => format!("SEGSHADE_SEGMENT_SHIM({model}, {sym}, {})", m.cfg.p),
        Kind::Bfpi => format!("SEGSHADE_BFPI_SHIM({model}, {sym}, {})", (m.cfg.p * m.cfg.mw()).div_ceil(8)),
        Kind::Specular => format!("SEGSHADE_SPECULAR_SHIM({model}, {sym})"),
        Kind::Frontend => format!("SEGSHADE_FRONTEND_SHIM({model}, {sym})"),
        Kind::TriShader => format!("SEGSHADE_TRISHADER_SHIM({model}, {sym}, {})", m.cfg.p),
        Kind::Writer => format!("SEGSHADE_WRITER_SHIM({model}, {sym}, {})", m.cfg.p),
        Kind::TriWriter => format!("SEGSHADE_TRIWRITER_SHIM({model}, {sym}, {})", m.cfg.p),
    }
}

/// The ports whose struct members are byte arrays (lane `i` in byte `i`, or in bit `i`).
const LANE_BUSES: [&str; 2] = ["out_pix", "out_mask"];

/// The struct member (of the kind's per-clock structs) a SPEC port's value lives in: the same
/// name, but for lane buses (arrays of bytes) and the triangle structs' vertex arrays.
fn member(kind: Kind, port: &str) -> String {
    let vertex = matches!(kind, Kind::Frontend | Kind::TriShader | Kind::TriWriter);
    match port {
        "out_pix" => "pix".into(),
        "out_mask" => "mask".into(),
        _ if vertex && port.len() == 5 && ["in_x", "in_y", "in_i"].contains(&&port[..4]) => format!("{}[{}]", &port[3..4], &port[4..]),
        _ => port.into(),
    }
}

/// The C++ step of an AXI4-Stream wrapper's model, printed from its typed layout `w`: the kind's
/// structs in and out, packed into and out of the wrapper's ports. Also `SYM_step_mispacked`,
/// the negative control of the packing: the same, with the first two input fields at each
/// other's bits (what a wrapper and a driver that disagree on the layout do).
fn axis_step_cpp(kind: Kind, w: &hdl_gen::axis::Wrapper, model: &str, sym: &str) -> String {
    let (inp, outp) = ports(kind);
    let (s, o) = (&w.s_axis.tdata, &w.m_axis);
    let pack = |swap: bool| {
        let mut c = format!("uint8_t b[{}] = {{}}; ", s.bits / 8 + 8);
        for (k, f) in s.fields.iter().enumerate() {
            let at = match (swap, k) {
                (true, 0) => s.fields[1].lsb,
                (true, 1) => s.fields[0].lsb,
                _ => f.lsb,
            };
            write!(c, "segshade_put_bits(b, {at}, {}, in->{}); ", f.width, member(kind, &f.port)).unwrap();
        }
        write!(c, "segshade_load(m->s_axis_tdata, b, {});", s.bits / 8).unwrap();
        c
    };
    let mut sample = String::new();
    for (signal, p) in [("m_axis_tdata", Some(&o.tdata)), ("m_axis_tuser", o.tuser.as_ref())] {
        let Some(p) = p else { continue };
        write!(sample, "{{ uint8_t d[{}] = {{}}; segshade_copy(d, m->{signal}, {}); ", p.bits / 8 + 8, p.bits / 8).unwrap();
        for f in &p.fields {
            let to = member(kind, &f.port);
            if LANE_BUSES.contains(&f.port.as_str()) {
                // A lane bus, byte i lane i: copied whole.
                write!(sample, "std::memcpy(out->{to}, d + {}, {}); ", f.lsb / 8, f.width.div_ceil(8)).unwrap();
            } else {
                write!(sample, "out->{to} = segshade_get_bits(d, {}, {}); ", f.lsb, f.width).unwrap();
            }
        }
        sample.push_str("} ");
    }
    if let Some(k) = &o.tkeep {
        write!(sample, "segshade_copy(out->{}, m->m_axis_tkeep, {}); ", member(kind, k), o.tdata.bits.div_ceil(64)).unwrap();
    }
    if let Some(l) = &o.tlast {
        write!(sample, "out->{} = m->m_axis_tlast; ", member(kind, l)).unwrap();
    }
    for sb in &w.sideband {
        write!(sample, "out->{} = m->{sb}; ", member(kind, sb)).unwrap();
    }
    let step = |name: &str, swap: bool| {
        format!(
            "extern \"C\" void {sym}_{name}(void* h, const {inp}* in, {outp}* out) noexcept {{\n    \
             {model}* m = static_cast<SegshadeModel<{model}>*>(h)->top;\n    \
             segshade_axis_clock(m, in, out, [&] {{ {} }}, [&] {{ {sample}}});\n}}\n",
            pack(swap)
        )
    };
    format!("SEGSHADE_LIFETIME({model}, {sym})\n{}{}", step("step", false), step("step_mispacked", true))
}

/// The per-clock input and output structs of a kind's shim (the same names in shim.h and ffi.rs).
fn ports(kind: Kind) -> (&'static str, &'static str) {
    match kind {
        Kind::Segment => ("SegIn", "SegOut"),
        Kind::Bfpi => ("BfpiIn", "BfpiOut"),
        Kind::Specular => ("SpecIn", "SpecOut"),
        Kind::Frontend => ("TriIn", "FeOut"),
        Kind::TriShader => ("TriIn", "TriSegOut"),
        Kind::Writer => ("WrIn", "WrOut"),
        Kind::TriWriter => ("TriIn", "WrOut"),
    }
}

/// Stops the build with the package to install when the compiler finds no `zlib.h` (the FST
/// writer's), rather than with a compiler error deep in GTKWave's code.
fn require_zlib(v: &Verilator, obj: &Path) {
    let probe = obj.join("zlib-probe.cpp");
    fs::write(&probe, "#include <zlib.h>\n").unwrap();
    if cc_build(v, true).file(&probe).try_expand().is_err() {
        panic!(
            "\n\nzlib's header (zlib.h) was not found. The traced models' FST writer needs it.\n\
             Install Debian's package:   apt-get install -y zlib1g-dev\n\
             (or run ./scripts/test, which installs it when missing)\n\n"
        );
    }
}

/// The layout csrc/shim.h states (`SEGSHADE_OFFSET(S, F, N);`, `SEGSHADE_SIZE(S, N);`, checked
/// there by the C++ compiler) as Rust `const` asserts on ffi.rs's structs: one statement of the
/// layout, checked by both compilers.
fn layout_asserts(shim: &str) -> String {
    let mut s = String::from("// csrc/shim.h's layout of the per-clock structs, checked on ffi.rs's.\n");
    let args = |line: &str, macro_: &str| -> Option<Vec<String>> {
        let inner = line.trim().strip_prefix(macro_)?.strip_prefix('(')?.strip_suffix(");")?;
        Some(inner.split(',').map(|a| a.trim().to_string()).collect())
    };
    let (mut offsets, mut sizes) = (0, 0);
    for line in shim.lines() {
        if let Some(a) = args(line, "SEGSHADE_OFFSET").filter(|a| a.len() == 3) {
            writeln!(
                s,
                "const _: () = assert!(std::mem::offset_of!({}, {}) == {}, \"{}.{} (csrc/shim.h)\");",
                a[0], a[1], a[2], a[0], a[1]
            )
            .unwrap();
            offsets += 1;
        } else if let Some(a) = args(line, "SEGSHADE_SIZE").filter(|a| a.len() == 2) {
            writeln!(s, "const _: () = assert!(std::mem::size_of::<{}>() == {}, \"size of {} (csrc/shim.h)\");", a[0], a[1], a[0]).unwrap();
            sizes += 1;
        }
    }
    assert!(offsets > 0 && sizes > 0, "csrc/shim.h states no layout (SEGSHADE_OFFSET/SEGSHADE_SIZE lines)");
    s
}

fn models_rs(models: &[Model], twins: &[Model], trace_all: bool, rtl_dir: Option<&Path>, tables: &SpecTables) -> String {
    let mut s = String::from("// Generated by build.rs: the models linked into this crate.\n");
    s.push_str(&layout_asserts(include_str!("csrc/shim.h")));
    let dir = rtl_dir.map_or("None".to_string(), |d| format!("Some({:?})", d.display().to_string()));
    writeln!(s, "/// The COSIM_RTL_DIR the models came from; `None`: all generated.\npub const RTL_DIR: Option<&str> = {dir};").unwrap();
    writeln!(s, "/// Whether COSIM_TRACE was set when these models were built (every streaming model traced).\npub const TRACED_BUILD: bool = {trace_all};")
        .unwrap();
    let mut seg = String::new();
    let mut bfpi = String::new();
    let mut spec = String::new();
    let mut fe = String::new();
    let mut tris = String::new();
    let mut wr = String::new();
    let mut trw = String::new();
    let (mut axis_seg, mut axis_spec, mut axis_fe, mut axis_tris) = (String::new(), String::new(), String::new(), String::new());
    let mut mispacked = String::new();
    for m in models {
        let (inp, outp) = ports(m.kind);
        let list = match (m.kind, m.axis.is_some()) {
            (Kind::Segment, true) => {
                writeln!(s, "extern \"C\" {{\n    fn {t}_step_mispacked(h: *mut c_void, i: *const SegIn, o: *mut SegOut);\n}}", t = m.tag)
                    .unwrap();
                writeln!(mispacked, "    (\"{t}\", {t}_step_mispacked),", t = m.tag).unwrap();
                &mut axis_seg
            }
            (Kind::Specular, true) => &mut axis_spec,
            (Kind::Frontend, true) => &mut axis_fe,
            (Kind::TriShader, true) => &mut axis_tris,
            (kind, true) => panic!("an AXI4-Stream model of kind {} has no list", ports(kind).0),
            (kind, false) => match kind {
                Kind::Segment => &mut seg,
                Kind::Bfpi => &mut bfpi,
                Kind::Specular => &mut spec,
                Kind::Frontend => &mut fe,
                Kind::TriShader => &mut tris,
                Kind::Writer => &mut wr,
                Kind::TriWriter => &mut trw,
            },
        };
        let t = &m.tag;
        writeln!(
            s,
            "extern \"C\" {{\n    fn {t}_new(seed: u64) -> *mut c_void;\n    fn {t}_free(h: *mut c_void);\n    \
             fn {t}_step(h: *mut c_void, i: *const {inp}, o: *mut {outp});\n}}"
        )
        .unwrap();
        let traced = match twins.iter().find(|w| w.tag == format!("{t}{TRACED_SUFFIX}")) {
            None => "None".to_string(),
            Some(w) => {
                let w = &w.tag;
                writeln!(
                    s,
                    "extern \"C\" {{\n    fn {w}_new(seed: u64) -> *mut c_void;\n    fn {w}_free(h: *mut c_void);\n    \
                     fn {w}_step(h: *mut c_void, i: *const {inp}, o: *mut {outp});\n    \
                     fn {w}_trace_open(h: *mut c_void, path: *const c_char, clock: u64) -> c_int;\n    \
                     fn {w}_trace_close(h: *mut c_void) -> c_int;\n}}"
                )
                .unwrap();
                format!(
                    "Some(TracedModel {{ tag: \"{w}\", new: {w}_new, free: {w}_free, step: {w}_step, \
                     trace_open: {w}_trace_open, trace_close: {w}_trace_close }})"
                )
            }
        };
        let c = &m.cfg;
        let align = match c.align {
            Align::Span => "Span",
            Align::Screen => "Screen",
        };
        writeln!(
            list,
            "    ModelInfo {{ tag: \"{t}\", top: \"{}\", latency: {}, pipeline: golden::pipeline::Pipeline::at({}), cfg: Config {{ p: {}, frac: {}, xbits: {}, align: Align::{align} }}, \
             screen: golden::setup::Screen {{ width: {}, height: {} }}, di: golden::frontend::DiMode::{:?}, \
             new: {t}_new, free: {t}_free, step: {t}_step, traced: {traced} }},",
            m.top, m.latency, m.pipeline, c.p, c.frac, c.xbits, m.screen.width, m.screen.height, m.di
        )
        .unwrap();
    }
    write!(
        s,
        "pub static SEGMENT_MODELS: &[ModelInfo<SegIn, SegOut>] = &[\n{seg}];\n\
         pub static BFPI_MODELS: &[ModelInfo<BfpiIn, BfpiOut>] = &[\n{bfpi}];\n\
         pub static SPECULAR_MODELS: &[ModelInfo<SpecIn, SpecOut>] = &[\n{spec}];\n\
         pub static FRONTEND_MODELS: &[ModelInfo<TriIn, FeOut>] = &[\n{fe}];\n\
         pub static TRISHADER_MODELS: &[ModelInfo<TriIn, TriSegOut>] = &[\n{tris}];\n\
         pub static WRITER_MODELS: &[ModelInfo<WrIn, WrOut>] = &[\n{wr}];\n\
         pub static TRIWRITER_MODELS: &[ModelInfo<TriIn, WrOut>] = &[\n{trw}];\n\
         /// AXI4-Stream wrappers (`--bus axis`), on their cores' structs.\n\
         pub static AXIS_SEGMENT_MODELS: &[ModelInfo<SegIn, SegOut>] = &[\n{axis_seg}];\n\
         pub static AXIS_SPECULAR_MODELS: &[ModelInfo<SpecIn, SpecOut>] = &[\n{axis_spec}];\n\
         pub static AXIS_FRONTEND_MODELS: &[ModelInfo<TriIn, FeOut>] = &[\n{axis_fe}];\n\
         pub static AXIS_TRISHADER_MODELS: &[ModelInfo<TriIn, TriSegOut>] = &[\n{axis_tris}];\n\
         /// Each AXI4-Stream shader model's step with its first two input fields packed at each other's\n\
         /// bits: the negative control of the packing.\n\
         pub static AXIS_SEGMENT_MISPACKED: &[(&str, StepFn<SegIn, SegOut>)] = &[\n{mispacked}];\n"
    )
    .unwrap();
    let ranges: String = tables
        .ranges
        .iter()
        .map(|r| format!("        KRange {{ table: {}, k: {}, n_lo: {}, n_hi: {} }},\n", r.table, r.k, r.n_lo, r.n_hi))
        .collect();
    write!(
        s,
        "/// The specular model's table set: golden's unit is rebuilt from it (`specular_unit`).\n\
         pub static SPECULAR_TABLES: SpecularTables = SpecularTables {{\n    ks: &{:?},\n    k_ranges: &[\n{ranges}    ],\n    word_bits: {:?},\n}};\n",
        tables.ks, tables.word_bits
    )
    .unwrap();
    s
}
