//! The models: the catalogue build.rs compiles into the crate (what the test suites use), and
//! the models of one `generate` configuration's files, wherever they come from (generated in
//! memory for a model asked for at run time, or read from a `COSIM_RTL_DIR` folder): modules are
//! found by their role in the manifest, and each model's top, files and latency are the
//! manifest's.

use super::model::{Kind, Model};
use golden::frontend::DiMode;
use golden::pipeline::Pipeline;
use golden::setup::Screen;
use golden::specular::{Decoder, DecoderRepr, KRange, SpecularGeometry, SpecularPlan};
use golden::{Align, Config};
use hdl_gen::manifest::{Manifest, ModuleEntry, Role, MANIFEST_FILE};
use std::fs;
use std::path::Path;

/// The segment widths built by default, each in both alignments; each p's BFPI is built too.
pub const BUILT_P: [u32; 7] = [1, 2, 4, 8, 16, 32, 64];
/// The triangle-to-segment chains built by default (SPEC §6), on 640x480; with
/// `SEGSHADE_ALL_CHAINS` set, every P in both alignments.
pub const BUILT_TRI: [(u32, Align); 4] = [(1, Align::Span), (8, Align::Span), (8, Align::Screen), (64, Align::Screen)];
/// The segment writers built by default (SPEC §7; small: the glue's corners are P = 2 and P = 8
/// and 64 in both alignments) and the chains from triangles to memory.
pub const BUILT_WR: [(u32, Align); 6] =
    [(1, Align::Span), (2, Align::Span), (8, Align::Span), (8, Align::Screen), (64, Align::Span), (64, Align::Screen)];
pub const BUILT_FB: [(u32, Align); 2] = [(8, Align::Span), (64, Align::Screen)];
/// Pipelined shaders (`--pipeline`) built by default: levels 1 and 2 at P = 8 in both alignments,
/// the deepest at P = 8 and at the smallest and largest P in one alignment each (P = 1 has no
/// lead, so its alignments are one circuit; P = 64's screen alignment has the widest lead
/// arithmetic, and its BFPI a second adder level, formed when the span starts).
pub const BUILT_PIPE: [(u32, u32, Option<Align>); 5] =
    [(8, 1, None), (8, 2, None), (1, 3, Some(Align::Span)), (8, 3, Some(Align::Span)), (64, 3, Some(Align::Screen))];

/// The specular unit's table set, as models.rs hands it to the checkers (`ffi::SPECULAR_TABLES`),
/// which rebuild golden's plan from it: `SpecularPlan::build(decoder, word_bits)`.
pub struct SpecTables {
    pub ks: Vec<u32>,
    pub ranges: Vec<KRange>,
    /// `None`: the builder picks the BRDF word width, as for every plan hdl-gen makes but some
    /// `--brdf-k auto` ones (see `golden::specular::auto_plan`).
    pub word_bits: Option<u32>,
}

impl SpecTables {
    pub fn of(plan: &SpecularPlan, word_bits: Option<u32>) -> SpecTables {
        SpecTables { ks: plan.decoder.ks().to_vec(), ranges: plan.decoder.ranges(), word_bits }
    }
}

/// COSIM_RTL_DIR as a folder to read, `cwd` being the folder of the process that reads it. A
/// relative path is taken from the folder the user typed the command in, which neither a build
/// script nor a test is told: cargo runs both in the package's folder (`verilator-harness/`). So a
/// relative path that does not exist from `cwd` is taken from the workspace's root, the package's
/// parent (`COSIM_RTL_DIR=rtl cargo test -p verilator-harness`, typed at the root, reads
/// `<root>/rtl`). An absolute path is itself.
pub fn resolve_rtl_dir(dir: &Path, cwd: &Path, package: &Path) -> std::path::PathBuf {
    match dir.is_relative() && !cwd.join(dir).exists() {
        true => package.parent().unwrap_or(package).join(dir),
        false => cwd.join(dir),
    }
}

/// `DIR/manifest.json`, read as the generator's own schema (`hdl_gen::manifest::Manifest`); the
/// error says why not, in one line.
pub fn read_manifest(dir: &Path) -> Result<Manifest, String> {
    let path = dir.join(MANIFEST_FILE);
    let text = fs::read_to_string(&path).map_err(|e| format!("cannot read {MANIFEST_FILE}: {e}"))?;
    Manifest::parse(&text).map_err(|e| e.to_string())
}

/// The table set of COSIM_RTL_DIR's manifest (its `specular` section, golden's typed
/// `SpecularGeometry`), checked to rebuild in golden the very plan the section states (tables,
/// widths, and the pipeline of `parameters.pipeline`), so the checkers compare the RTL with the
/// unit it was generated as. The default set when the folder has no specular unit (no checker
/// then uses it).
pub fn tables_from_dir(m: &Manifest) -> Result<SpecTables, String> {
    let fail = |what: String| format!("{MANIFEST_FILE}: specular: {what}");
    if m.by_role(Role::SpecularUnit).is_none() {
        return Ok(SpecTables::of(&SpecularPlan::patent(), None));
    }
    let stated = &m.specular.geometry;
    let decoder =
        Decoder::try_from(DecoderRepr { ks: stated.ks.clone(), ranges: stated.k_ranges.clone() }).map_err(|e| fail(e.to_string()))?;
    // hdl-gen builds with the builder's word width, or for some `auto` sets the search's.
    let mut last = String::new();
    for w in [None, Some(stated.brdf_word_bits)] {
        match SpecularPlan::build(decoder.clone(), w) {
            Ok(plan) => {
                let plan = plan.with_pipeline(m.parameters.pipeline);
                let mut built = plan.geometry();
                // f64::powi rounds differently at different opt-levels (hdl-gen's against this
                // crate's): the approximation error may differ in its last digits.
                let (a, b) = (built.approx_error.0, stated.approx_error.0);
                if (a - b).abs() <= 1e-9 * a.abs().max(b.abs()) {
                    built.approx_error.0 = b;
                }
                if built == *stated {
                    return Ok(SpecTables::of(&plan, w));
                }
                last = format!("with word_bits {w:?}, {}", geometry_diff(stated, &built));
            }
            Err(e) => last = e.to_string(),
        }
    }
    Err(fail(format!("golden's plan for k = {:?} and these k_ranges is not the one the manifest states: {last}", stated.ks)))
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

/// The catalogue: every model build.rs compiles in, each the model of one kind that `generate`
/// makes for one configuration (described as any other configuration is, [`model_of`]), under
/// its own tag. Its order is the lists' order in `ffi`.
pub fn generated_models() -> Vec<Model> {
    let mut described: std::collections::HashMap<String, Vec<Model>> = std::collections::HashMap::new();
    entries(std::env::var_os("SEGSHADE_ALL_CHAINS").is_some())
        .into_iter()
        .map(|(tag, kind, opts)| {
            // One generation per configuration: many entries share one.
            let models = described
                .entry(format!("{opts:?}"))
                .or_insert_with(|| models_of_options(&opts, "").unwrap_or_else(|e| panic!("{tag}: {e}")));
            let axis = opts.bus == hdl_gen::Bus::Axis;
            let m = pick(models, kind, axis).unwrap_or_else(|e| panic!("{tag}: {e}"));
            Model { tag, options: Some(options_key(&opts)), ..m }
        })
        .collect()
}

/// The catalogue's entries: (tag, kind, configuration); `all_chains`: as SEGSHADE_ALL_CHAINS
/// builds it (a superset: the same tags for the same configurations, and more).
pub fn entries(all_chains: bool) -> Vec<(String, Kind, hdl_gen::Options)> {
    use hdl_gen::Options;
    let mut e: Vec<(String, Kind, Options)> = Vec::new();
    // The specular unit as SPEC's seed builds it, then split for clock rate (`--pipeline 1`;
    // level 2's partial products in shifts and adds, the same registers, are built on demand in
    // the slow tier: tests/specular.rs).
    e.push(("spec".into(), Kind::Specular, Options::default()));
    e.push(("spec_pl1".into(), Kind::Specular, Options { pipeline: Pipeline::at(1), ..Default::default() }));
    for p in BUILT_P {
        for align in Align::ALL {
            let o = Options { cfg: Config { p, align, ..Config::default() }, ..Default::default() };
            let with = |f: &dyn Fn(&mut Options)| {
                let mut o = o.clone();
                f(&mut o);
                o
            };
            if align == Align::Span {
                e.push((format!("bfpi_p{p}"), Kind::Bfpi, o.clone()));
            }
            // The chain at every P and alignment only on request (`sweep`'s front-end table):
            // each is a few seconds of compiling that the test suite does not need.
            if BUILT_TRI.contains(&(p, align)) || all_chains {
                if p == 8 && align == Align::Span {
                    e.push(("fe".into(), Kind::Frontend, o.clone()));
                    // The classical per-scanline dI (`--fe-di scanline`), the comparison option.
                    e.push(("fe_scan".into(), Kind::Frontend, with(&|o| o.fe_di = DiMode::Scanline)));
                    // The set-up and the span path in stages (`--pipeline 1` and above: one
                    // front-end for them all); with the per-scanline dI too on request (a
                    // comparison option's, as `sweep`'s chains; `scripts/check-rtl-dir` also
                    // checks one such folder through COSIM_RTL_DIR).
                    e.push(("fe_pl1".into(), Kind::Frontend, with(&|o| o.pipeline = Pipeline::at(1))));
                    if all_chains {
                        let staged = with(&|o| (o.pipeline, o.fe_di) = (Pipeline::at(1), DiMode::Scanline));
                        e.push(("fe_scan_pl1".into(), Kind::Frontend, staged));
                    }
                    // The other divider rates (`--fe-div-bits`), so co-simulation covers every option.
                    for b in hdl_gen::frontend::DIV_BITS.into_iter().filter(|&b| b != hdl_gen::frontend::DEFAULT_DIV_BITS) {
                        e.push((format!("fe_div{b}"), Kind::Frontend, with(&|o| o.fe_div_bits = Some(b))));
                    }
                }
                if BUILT_TRI.contains(&(p, align)) && all_chains {
                    // The chain with the per-scanline dI, for `sweep`'s comparison.
                    e.push((format!("tris_p{p}_{align}_scan"), Kind::TriShader, with(&|o| o.fe_di = DiMode::Scanline)));
                }
                e.push((format!("tris_p{p}_{align}"), Kind::TriShader, o.clone()));
            }
            if BUILT_WR.contains(&(p, align)) || all_chains {
                e.push((format!("wr_p{p}_{align}"), Kind::Writer, o.clone()));
            }
            if BUILT_FB.contains(&(p, align)) || all_chains {
                e.push((format!("trw_p{p}_{align}"), Kind::TriWriter, o.clone()));
            }
            for level in BUILT_PIPE.iter().filter(|(bp, _, a)| *bp == p && a.is_none_or(|a| a == align)).map(|&(_, l, _)| l) {
                let pipeline = Pipeline::new(level).expect("a built level exists");
                e.push((format!("seg_p{p}_{align}_pl{level}"), Kind::Segment, with(&|o| o.pipeline = pipeline)));
            }
            e.push((format!("seg_p{p}_{align}"), Kind::Segment, o));
        }
    }
    // The AXI4-Stream wrappers (`--bus axis`) of the default shader and specular unit, driven
    // through their cores' structs: two models, so the default suite stays quick; COSIM_RTL_DIR
    // builds every wrapper its folder has.
    let axis = Options { bus: hdl_gen::Bus::Axis, ..Default::default() };
    e.push(("seg_p8_span_axis".into(), Kind::Segment, axis.clone()));
    e.push(("spec_axis".into(), Kind::Specular, axis));
    e
}

/// The catalogue's model `tag` (whichever SEGSHADE_ALL_CHAINS built it), described again: a
/// compiled model's description, for what is built from it at run time (its traced twin).
pub fn catalogue_model(tag: &str) -> Result<Model, String> {
    let (tag, kind, opts) =
        entries(true).into_iter().find(|(t, _, _)| t == tag).ok_or_else(|| format!("{tag}: not a model of the catalogue"))?;
    Ok(Model { tag, options: Some(options_key(&opts)), ..model_of(&opts, kind, "")? })
}

/// `opts` in one text, the same for options that generate the same files: the screen and the
/// dividers' rate spelled out when left to their defaults.
pub fn options_key(opts: &hdl_gen::Options) -> String {
    let mut o = opts.clone();
    o.screen = Some(o.screen.unwrap_or_else(|| hdl_gen::Options::default_screen(&o.cfg)));
    o.fe_div_bits = Some(o.fe_div_bits.unwrap_or(hdl_gen::frontend::DEFAULT_DIV_BITS));
    // A target only names the device its choices (already in the other fields) were made for.
    o.target = None;
    format!("{o:?}")
}

/// The model of `kind` among `models` (its AXI4-Stream wrapper when `axis`).
pub fn pick(models: &[Model], kind: Kind, axis: bool) -> Result<Model, String> {
    let found = models.iter().find(|m| m.kind == kind && m.axis.is_some() == axis).cloned();
    found.ok_or_else(|| format!("this configuration has no {kind:?} model{}", if axis { " with --bus axis" } else { "" }))
}

/// The model of `kind` that `generate` makes for `opts` (its AXI4-Stream wrapper with `--bus
/// axis`), described from the files generated in memory, its tag ending in `suffix`.
pub fn model_of(opts: &hdl_gen::Options, kind: Kind, suffix: &str) -> Result<Model, String> {
    pick(&models_of_options(opts, suffix)?, kind, opts.bus == hdl_gen::Bus::Axis)
}

/// The models of one `generate` configuration, described by its manifest `m` (as `hdl-gen
/// generate` writes it), each file's text read by `read`: from a `COSIM_RTL_DIR` folder as it is
/// (so hand-edited or third-party RTL is checked against golden), or from files generated in
/// memory. Modules are found by their role; each model's top, files and latency are the
/// manifest's. Every tag ends in `suffix` (a model built at run time says which configuration it
/// is). The error is one line, without the source's name.
pub fn models_of_manifest(m: &Manifest, read: &dyn Fn(&str) -> Result<String, String>, suffix: &str) -> Result<Vec<Model>, String> {
    let params = &m.parameters;
    let cfg = Config::new(params.p, params.frac, params.xbits, params.align).map_err(|e| format!("{MANIFEST_FILE}: {e}"))?;
    let pipeline = params.pipeline;
    let read = |file: &str| -> Result<(String, String), String> { Ok((file.to_string(), read(file)?)) };
    let files_of = |roles: &[Role]| -> Result<Vec<(String, String)>, String> {
        m.modules.iter().filter(|x| roles.contains(&x.role)).map(|x| read(&x.file)).collect()
    };
    // A model of one module: its kind, tag and role's entry, its sources.
    let model = |kind: Kind, tag: String, entry: &ModuleEntry, screen: Screen, di: DiMode, pipeline: Pipeline, sources| Model {
        tag: format!("{tag}{suffix}"),
        kind,
        cfg,
        di,
        screen,
        top: entry.name.clone(),
        latency: entry.latency,
        pipeline,
        axis: None,
        sources,
        options: None,
    };
    let (none, screen0, di0) = (Pipeline::NONE, Screen::default(), DiMode::Triangle);
    let sources = files_of(&[Role::Bfpi, Role::SegmentShader])?;
    let mut models = Vec::new();
    if let Some(bfpi) = m.by_role(Role::Bfpi) {
        let src = vec![read(&bfpi.file)?];
        models.push(model(Kind::Bfpi, format!("bfpi_p{}", cfg.p), bfpi, screen0, di0, none, src));
    }
    if let Some(seg) = m.by_role(Role::SegmentShader) {
        models.push(model(Kind::Segment, format!("seg_p{}_{}", cfg.p, cfg.align), seg, screen0, di0, pipeline, sources.clone()));
    }
    if let (Some(fe_mod), Some(tri)) = (m.by_role(Role::Frontend), m.by_role(Role::TriangleShader)) {
        let fe = m.frontend.as_ref().ok_or_else(|| format!("{MANIFEST_FILE} lists a front-end module but no frontend section"))?;
        let (screen, di) = (fe.screen, fe.di);
        let fe_src = files_of(&[Role::Frontend, Role::FrontendPart])?;
        let mut all = sources.clone();
        all.extend(fe_src.iter().cloned());
        all.extend(files_of(&[Role::TriangleShader])?);
        models.push(model(Kind::Frontend, "fe".into(), fe_mod, screen, di, pipeline, fe_src));
        models.push(model(Kind::TriShader, format!("tris_p{}_{}", cfg.p, cfg.align), tri, screen, di, pipeline, all.clone()));
        if let (Some(wr), Some(fb)) = (m.by_role(Role::Writer), m.by_role(Role::TriangleWriter)) {
            let wr_src = files_of(&[Role::Writer])?;
            models.push(model(Kind::Writer, format!("wr_p{}_{}", cfg.p, cfg.align), wr, screen, di, none, wr_src.clone()));
            all.extend(wr_src);
            all.extend(files_of(&[Role::TriangleWriter])?);
            models.push(model(Kind::TriWriter, format!("trw_p{}_{}", cfg.p, cfg.align), fb, screen, di, pipeline, all));
        }
    }
    if let Some(unit) = m.by_role(Role::SpecularUnit) {
        let mut src = files_of(&[Role::SpecularUnit, Role::Rom])?;
        src.push(read(&m.specular.brdf_rom.file)?);
        src.push(read(&m.specular.nk_rom.file)?);
        models.push(model(Kind::Specular, "spec".into(), unit, screen0, di0, pipeline, src));
    }
    if models.is_empty() {
        return Err(format!("{MANIFEST_FILE} lists no bfpi, segment_shader or specular_unit module"));
    }
    let axis = axis_models(&models, m, |_| true, read)?;
    models.extend(axis);
    Ok(models)
}

/// The models of the folder `dir` (a `COSIM_RTL_DIR`), read as [`models_of_manifest`] says.
pub fn models_from_dir(dir: &Path, m: &Manifest) -> Result<Vec<Model>, String> {
    let read = |file: &str| fs::read_to_string(dir.join(file)).map_err(|e| format!("cannot read {file}: {e}"));
    models_of_manifest(m, &read, "")
}

/// The models of one `generate` configuration, generated in memory (tags ending in `suffix`).
pub fn models_of_options(opts: &hdl_gen::Options, suffix: &str) -> Result<Vec<Model>, String> {
    let files = hdl_gen::generate(opts);
    let text =
        |name: &str| files.iter().find(|f| f.name == name).map(|f| f.contents.clone()).ok_or_else(|| format!("{name}: not generated"));
    let manifest = Manifest::parse(&text(MANIFEST_FILE)?).map_err(|e| e.to_string())?;
    models_of_manifest(&manifest, &text, suffix)
}

/// The AXI4-Stream wrappers `m` lists (those `wanted` keeps): each the model in `models` of its
/// core (same kind, top, P, alignment and pipeline level) with the wrapper as top and its file
/// (`read`) added.
/// A layout that breaks the packing rule, or a wrapper of a module with no model, is an error.
fn axis_models(
    models: &[Model],
    m: &Manifest,
    wanted: impl Fn(&hdl_gen::axis::Wrapper) -> bool,
    read: impl Fn(&str) -> Result<(String, String), String>,
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
        sources.push(read(&entry.file)?);
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
