//! The one registry of the models a run has, decided when the run starts, not when the crate is
//! built: the compiled catalogue (`build.rs`), or, with `COSIM_RTL_DIR=DIR` set, DIR's models.
//! A folder's models are described from its manifest (`catalogue::models_of_manifest`, its own
//! files as they are), each taken from the catalogue when it is one of its circuits and otherwise
//! built through the one on-demand builder ([`crate::ondemand`]: cached by the hash of the
//! folder's RTL, the shim and Verilator's version). Any other configuration a binary asks for
//! comes from `ondemand` too. So the crate is the same whatever COSIM_RTL_DIR says: checking a
//! folder, or another one, recompiles nothing.
//!
//! Each list ([`SEGMENT_MODELS`], ...) is made the first time it is asked for, so a test that
//! needs one kind builds (or loads) that kind's models only. The suites' rule for a model they
//! need is [`require`]: a default run must have every model; a COSIM_RTL_DIR run checks the
//! folder's models and says which tests it skipped.

use crate::ffi::{
    BfpiIn, BfpiOut, FeOut, ModelInfo, SegIn, SegOut, SpecIn, SpecOut, SpecularTables, StepFn, TriIn, TriSegOut, WrIn, WrOut,
};
use crate::ffi::{
    COMPILED_AXIS_FRONTEND_MODELS, COMPILED_AXIS_SEGMENT_MISPACKED, COMPILED_AXIS_SEGMENT_MODELS, COMPILED_AXIS_SPECULAR_MODELS,
    COMPILED_AXIS_TRISHADER_MODELS, COMPILED_BFPI_MODELS, COMPILED_FRONTEND_MODELS, COMPILED_SEGMENT_MODELS, COMPILED_SPECULAR_MODELS,
    COMPILED_SPECULAR_TABLES, COMPILED_TRISHADER_MODELS, COMPILED_TRIWRITER_MODELS, COMPILED_WRITER_MODELS,
};
use crate::models::catalogue::{self, SpecTables};
use crate::models::{Kind, Model, ModelError};
use crate::ondemand;
use golden::specular::SpecularUnit;
use golden::Align;
use std::path::{Path, PathBuf};
use std::sync::{LazyLock, OnceLock};

/// `COSIM_RTL_DIR` as this process reads it (once): a relative path from the process's folder
/// when it exists there, else from the workspace's root (`catalogue::resolve_rtl_dir`: cargo runs
/// tests in the package's folder, so `COSIM_RTL_DIR=rtl` typed at the root means `<root>/rtl`).
/// `None` when unset: the compiled catalogue.
pub fn rtl_dir() -> Option<&'static Path> {
    static DIR: OnceLock<Option<PathBuf>> = OnceLock::new();
    DIR.get_or_init(|| {
        let d = std::env::var_os("COSIM_RTL_DIR").filter(|d| !d.is_empty())?;
        let cwd = std::env::current_dir().unwrap_or_default();
        let dir = catalogue::resolve_rtl_dir(Path::new(&d), &cwd, Path::new(env!("CARGO_MANIFEST_DIR")));
        Some(dir.canonicalize().unwrap_or(dir))
    })
    .as_deref()
}

/// A COSIM_RTL_DIR folder as its manifest describes it: its models (not built yet) and the table
/// set of its specular unit.
struct Folder {
    models: Vec<Model>,
    tables: SpecTables,
}

/// The folder of [`rtl_dir`], read once; its error names the folder.
fn folder(dir: &'static Path) -> Result<&'static Folder, ModelError> {
    static FOLDER: OnceLock<Result<Folder, ModelError>> = OnceLock::new();
    let read = || -> Result<Folder, String> {
        if !dir.is_dir() {
            return Err("no such folder".into());
        }
        let manifest = catalogue::read_manifest(dir)?;
        let models = catalogue::models_from_dir(dir, &manifest)?;
        Ok(Folder { models, tables: catalogue::tables_from_dir(&manifest)? })
    };
    let folder = FOLDER.get_or_init(|| read().map_err(|what| ModelError::RtlDir { dir: dir.to_path_buf(), what }));
    folder.as_ref().map_err(Clone::clone)
}

/// For a binary, before it asks for a model: the COSIM_RTL_DIR folder (if set) read and
/// described (nothing built), or why it cannot be (the binary prints it and exits 2).
pub fn check_folder() -> Result<(), ModelError> {
    rtl_dir().map_or(Ok(()), |dir| folder(dir).map(|_| ()))
}

/// One kind's models, the compiled catalogue's or a COSIM_RTL_DIR folder's (made when first
/// asked for). It dereferences to the list, panicking with the reason when a folder's model
/// cannot be had (what a test wants); a binary asks [`Models::get`] and exits with the error.
pub struct Models<I: 'static, O: 'static> {
    compiled: fn() -> &'static [ModelInfo<I, O>],
    kind: Kind,
    /// The AXI4-Stream wrappers of the kind (`--bus axis`), or its native models.
    axis: bool,
    folder: OnceLock<Result<&'static [ModelInfo<I, O>], ModelError>>,
}

impl<I: 'static, O: 'static> Models<I, O> {
    pub const fn new(compiled: fn() -> &'static [ModelInfo<I, O>], kind: Kind, axis: bool) -> Self {
        Models { compiled, kind, axis, folder: OnceLock::new() }
    }

    /// The compiled catalogue's models of the kind, whatever COSIM_RTL_DIR says.
    pub fn compiled(&self) -> &'static [ModelInfo<I, O>] {
        (self.compiled)()
    }

    /// The models of this run: the catalogue's, or the COSIM_RTL_DIR folder's (each built, or
    /// found in the cache, the first time).
    pub fn get(&self) -> Result<&'static [ModelInfo<I, O>], ModelError> {
        let Some(dir) = rtl_dir() else { return Ok(self.compiled()) };
        let list = self.folder.get_or_init(|| {
            let compiled = self.compiled();
            let mine = folder(dir)?.models.iter().filter(|m| m.kind == self.kind && m.axis.is_some() == self.axis);
            let infos = mine.map(|m| ondemand::find_or_load(compiled, m).copied()).collect::<Result<Vec<_>, _>>()?;
            Ok(&*Box::leak(infos.into_boxed_slice()))
        });
        list.clone()
    }
}

impl<I: 'static, O: 'static> std::ops::Deref for Models<I, O> {
    type Target = [ModelInfo<I, O>];

    fn deref(&self) -> &[ModelInfo<I, O>] {
        self.get().unwrap_or_else(|e| panic!("{e}"))
    }
}

pub static SEGMENT_MODELS: Models<SegIn, SegOut> = Models::new(|| COMPILED_SEGMENT_MODELS, Kind::Segment, false);
pub static BFPI_MODELS: Models<BfpiIn, BfpiOut> = Models::new(|| COMPILED_BFPI_MODELS, Kind::Bfpi, false);
pub static SPECULAR_MODELS: Models<SpecIn, SpecOut> = Models::new(|| COMPILED_SPECULAR_MODELS, Kind::Specular, false);
pub static FRONTEND_MODELS: Models<TriIn, FeOut> = Models::new(|| COMPILED_FRONTEND_MODELS, Kind::Frontend, false);
pub static TRISHADER_MODELS: Models<TriIn, TriSegOut> = Models::new(|| COMPILED_TRISHADER_MODELS, Kind::TriShader, false);
pub static WRITER_MODELS: Models<WrIn, WrOut> = Models::new(|| COMPILED_WRITER_MODELS, Kind::Writer, false);
pub static TRIWRITER_MODELS: Models<TriIn, WrOut> = Models::new(|| COMPILED_TRIWRITER_MODELS, Kind::TriWriter, false);
/// AXI4-Stream wrappers (`--bus axis`), on their cores' structs.
pub static AXIS_SEGMENT_MODELS: Models<SegIn, SegOut> = Models::new(|| COMPILED_AXIS_SEGMENT_MODELS, Kind::Segment, true);
pub static AXIS_SPECULAR_MODELS: Models<SpecIn, SpecOut> = Models::new(|| COMPILED_AXIS_SPECULAR_MODELS, Kind::Specular, true);
pub static AXIS_FRONTEND_MODELS: Models<TriIn, FeOut> = Models::new(|| COMPILED_AXIS_FRONTEND_MODELS, Kind::Frontend, true);
pub static AXIS_TRISHADER_MODELS: Models<TriIn, TriSegOut> = Models::new(|| COMPILED_AXIS_TRISHADER_MODELS, Kind::TriShader, true);

/// Each AXI4-Stream shader model's step with its first two input fields packed at each other's
/// bits: the negative control of the packing (the shim's `<tag>_step_mispacked`).
pub static AXIS_SEGMENT_MISPACKED: LazyLock<Vec<(&'static str, StepFn<SegIn, SegOut>)>> = LazyLock::new(|| {
    let mut all = COMPILED_AXIS_SEGMENT_MISPACKED.to_vec();
    if let Some(dir) = rtl_dir() {
        let built = folder(dir).map(|f| f.models.as_slice()).unwrap_or_default();
        for m in built.iter().filter(|m| m.kind == Kind::Segment && m.axis.is_some()) {
            if let Some(info) = AXIS_SEGMENT_MODELS.iter().find(|i| i.identity() == m.identity()) {
                if !all.iter().any(|(t, _)| *t == info.tag) {
                    all.push((info.tag, ondemand::mispacked(m).unwrap_or_else(|e| panic!("{e}"))));
                }
            }
        }
    }
    all
});

/// The model of `kind` for `opts`: the compiled catalogue's when it has this very circuit, else
/// built (once; cached) and loaded. Under `COSIM_RTL_DIR` only the folder's models exist: the
/// one matching `opts`' P and alignment, or an error naming what there is.
fn model<I: 'static, O: 'static>(
    list: &'static Models<I, O>,
    opts: &hdl_gen::Options,
    kind: Kind,
) -> Result<&'static ModelInfo<I, O>, ModelError> {
    if let Some(dir) = rtl_dir() {
        let (p, align) = (opts.cfg.p, opts.cfg.align);
        let models = list.get()?;
        // A block whose circuit P and the alignment do not change may be the catalogue's model
        // of another P (the folder's circuit is the same): any of the folder's will do.
        let any = matches!(kind, Kind::Specular | Kind::Frontend);
        return models.iter().find(|m| any || (m.cfg.p, m.cfg.align) == (p, align)).ok_or_else(|| {
            let built: Vec<&str> = models.iter().map(|m| m.tag).collect();
            ModelError::Config(format!(
                "--p {p} --align {align}: COSIM_RTL_DIR={} has no such {kind:?} model (it has: {})",
                dir.display(),
                if built.is_empty() { "none".to_string() } else { built.join(", ") }
            ))
        });
    }
    // The catalogue's model of these very options, found without generating them (the binaries
    // ask once per run, and generating every block of a configuration takes a noticeable part of
    // a second).
    let compiled = list.compiled();
    let key = catalogue::options_key(opts);
    if let Some(m) = compiled.iter().find(|m| m.options() == Some(key.as_str())) {
        return Ok(m);
    }
    ondemand::find_or_load(compiled, &ondemand::describe(opts, kind)?)
}

/// `segment_shader_p<P>` (or its AXI4-Stream wrapper) of `opts`.
pub fn segment(opts: &hdl_gen::Options) -> Result<&'static ModelInfo<SegIn, SegOut>, ModelError> {
    let list = if opts.bus == hdl_gen::Bus::Axis { &AXIS_SEGMENT_MODELS } else { &SEGMENT_MODELS };
    model(list, opts, Kind::Segment)
}

/// `bfpi_p<P>` of `opts`.
pub fn bfpi(opts: &hdl_gen::Options) -> Result<&'static ModelInfo<BfpiIn, BfpiOut>, ModelError> {
    model(&BFPI_MODELS, opts, Kind::Bfpi)
}

/// `tri_frontend` of `opts` (its screen, dividers, dI mode and pipeline level).
pub fn frontend(opts: &hdl_gen::Options) -> Result<&'static ModelInfo<TriIn, FeOut>, ModelError> {
    model(&FRONTEND_MODELS, opts, Kind::Frontend)
}

/// `tri_shader_p<P>` of `opts`: triangles in, segments out.
pub fn tri_shader(opts: &hdl_gen::Options) -> Result<&'static ModelInfo<TriIn, TriSegOut>, ModelError> {
    model(&TRISHADER_MODELS, opts, Kind::TriShader)
}

/// `fb_writer_p<P>` of `opts`.
pub fn writer(opts: &hdl_gen::Options) -> Result<&'static ModelInfo<WrIn, WrOut>, ModelError> {
    model(&WRITER_MODELS, opts, Kind::Writer)
}

/// `tri_fb_p<P>` of `opts`: triangles in, block writes out.
pub fn tri_writer(opts: &hdl_gen::Options) -> Result<&'static ModelInfo<TriIn, WrOut>, ModelError> {
    model(&TRIWRITER_MODELS, opts, Kind::TriWriter)
}

/// `specular_unit` (or its AXI4-Stream wrapper) of `opts`; [`unit_of`] is then the golden unit
/// of its table set and pipeline.
pub fn specular(opts: &hdl_gen::Options) -> Result<&'static ModelInfo<SpecIn, SpecOut>, ModelError> {
    let list = if opts.bus == hdl_gen::Bus::Axis { &AXIS_SPECULAR_MODELS } else { &SPECULAR_MODELS };
    let info = model(list, opts, Kind::Specular)?;
    if rtl_dir().is_none() {
        units().lock().unwrap_or_else(|e| e.into_inner()).entry(info.identity()).or_insert_with(|| opts.specular_unit());
    }
    Ok(info)
}

/// The golden units of the specular models [`specular`] handed out, by circuit.
fn units() -> &'static std::sync::Mutex<std::collections::HashMap<u64, SpecularUnit>> {
    static UNITS: OnceLock<std::sync::Mutex<std::collections::HashMap<u64, SpecularUnit>>> = OnceLock::new();
    UNITS.get_or_init(Default::default)
}

/// The golden unit the specular model `info` is checked against: that of the options
/// [`specular`] built it for, else the run's table set ([`specular_unit`]).
pub fn unit_of(info: &ModelInfo<SpecIn, SpecOut>) -> SpecularUnit {
    let known = units().lock().unwrap_or_else(|e| e.into_inner()).get(&info.identity()).cloned();
    known.unwrap_or_else(specular_unit)
}

/// The golden specular unit the specular model is checked against: the plan of the run's table
/// set (the default, or the COSIM_RTL_DIR folder's manifest's, which the folder's description
/// checked golden rebuilds), built once, not `SpecularUnit::default()`, which is right only for
/// the default set.
pub fn specular_unit() -> SpecularUnit {
    static UNIT: OnceLock<SpecularUnit> = OnceLock::new();
    UNIT.get_or_init(|| {
        let plan = match rtl_dir() {
            None => COMPILED_SPECULAR_TABLES.plan(),
            Some(dir) => {
                let t = &folder(dir).unwrap_or_else(|e| panic!("{e}")).tables;
                SpecularTables { ks: &*t.ks.clone().leak(), k_ranges: &*t.ranges.clone().leak(), word_bits: t.word_bits }.plan()
            }
        };
        SpecularUnit::new(plan.expect("the table set was checked against golden's plan"))
    })
    .clone()
}

/// The segment-shader model for `p` and `align` with SPEC's seed structure (or, from
/// `COSIM_RTL_DIR`, whatever pipeline level the folder has), if this run has one.
pub fn segment_model(p: u32, align: Align) -> Option<&'static ModelInfo<SegIn, SegOut>> {
    let seed = |m: &&ModelInfo<SegIn, SegOut>| m.pipeline == golden::pipeline::Pipeline::NONE;
    let matching = || SEGMENT_MODELS.iter().filter(|m| m.cfg.p == p && m.cfg.align == align);
    matching().find(seed).or_else(|| matching().next())
}

/// The segment-shader model for `p` and `align`, for a test that needs it (`what` names that
/// test); see [`require`] for what happens when this run has none.
pub fn require_segment_model(p: u32, align: Align, what: &str) -> Option<&'static ModelInfo<SegIn, SegOut>> {
    require(segment_model(p, align), &format!("seg_p{p}_{align}"), what)
}

/// The specular unit's model, for a test that needs it; see [`require`].
pub fn require_specular_model(what: &str) -> Option<&'static ModelInfo<SpecIn, SpecOut>> {
    require(SPECULAR_MODELS.first(), "specular_unit", what)
}

/// Every model of one kind (`kind`: "segment shader", "bfpi"), for a test that runs them all;
/// `None` when there are none, see [`require`].
pub fn require_models<I, O>(models: &'static [ModelInfo<I, O>], kind: &str, what: &str) -> Option<&'static [ModelInfo<I, O>]> {
    require((!models.is_empty()).then_some(models), kind, what)
}

/// For a test of the `cosim` or `render` binary run with their default model (p = 8 span): the
/// `--p`/`--align` arguments to add. None when that model is in the run (a default run must have
/// it, see [`require`]); else, under COSIM_RTL_DIR, those of the folder's first segment shader.
/// `None` when there is no segment shader at all.
pub fn default_model_args(what: &str) -> Option<Vec<String>> {
    let other = SEGMENT_MODELS.first().filter(|_| rtl_dir().is_some() && segment_model(8, Align::Span).is_none());
    let Some(m) = other else { return require_segment_model(8, Align::Span, what).map(|_| Vec::new()) };
    let args = vec!["--p".into(), m.cfg.p.to_string(), "--align".into(), m.cfg.align.to_string()];
    use std::io::Write;
    let _ =
        writeln!(std::io::stderr().lock(), "{what}: this run has no seg_p8_span model (the default): runs {} ({})", m.tag, args.join(" "));
    Some(args)
}

/// The one rule every suite follows for a model it needs. A default run (no COSIM_RTL_DIR) has
/// every model of the catalogue, so a missing one is a bug: panic. A run against COSIM_RTL_DIR
/// has only what that folder provides: say on stderr what is skipped and why, and return `None`.
///
/// The note goes to stderr directly, not through `eprintln!`, which the test harness captures
/// and shows only for failing tests: a skip must be visible when everything passes.
pub fn require<T>(found: Option<T>, model: &str, what: &str) -> Option<T> {
    if found.is_some() {
        return found;
    }
    let Some(dir) = rtl_dir() else {
        let built: Vec<&str> = [
            SEGMENT_MODELS.compiled().iter().map(|m| m.tag).collect::<Vec<_>>(),
            BFPI_MODELS.compiled().iter().map(|m| m.tag).collect(),
            SPECULAR_MODELS.compiled().iter().map(|m| m.tag).collect(),
            FRONTEND_MODELS.compiled().iter().map(|m| m.tag).collect(),
            TRISHADER_MODELS.compiled().iter().map(|m| m.tag).collect(),
            WRITER_MODELS.compiled().iter().map(|m| m.tag).collect(),
            TRIWRITER_MODELS.compiled().iter().map(|m| m.tag).collect(),
        ]
        .concat();
        panic!(
            "{what}: this run has no {model} model, and a default run (no COSIM_RTL_DIR) must have every model (the catalogue: {})",
            built.join(", ")
        )
    };
    // The folder's descriptions, not its lists: naming what it has builds nothing.
    let provides = match folder(dir) {
        Ok(f) => f.models.iter().map(|m| m.tag.as_str()).collect::<Vec<_>>().join(", "),
        Err(e) => e.to_string(),
    };
    use std::io::Write;
    let _ = writeln!(
        std::io::stderr().lock(),
        "{what}: skipped: this build has no {model} model (COSIM_RTL_DIR={} provides {provides} only)",
        dir.display()
    );
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`require`]'s rule: a missing model fails a default run and is skipped (`None`) in a
    /// COSIM_RTL_DIR run; a model the run has is returned either way.
    #[test]
    fn a_missing_model_fails_only_a_default_run() {
        let missing = std::panic::catch_unwind(|| {
            require_segment_model(3, Align::Span, "registry: the rule's own test (a p = 3 shader is never built)").map(|m| m.tag)
        });
        match rtl_dir() {
            None => {
                let e = missing.expect_err("a default run with a model missing must fail");
                let msg = e.downcast_ref::<String>().expect("a formatted message");
                assert!(msg.contains("this run has no seg_p3_span model"), "{msg}");
            }
            Some(_) => assert!(missing.unwrap().is_none()),
        }
        // A default run also has pipelined twins of some shaders: (p, align) names the seed's
        // structure (pipeline level 0), which a default run always has.
        for m in SEGMENT_MODELS.iter() {
            let found = require_segment_model(m.cfg.p, m.cfg.align, "registry").expect("built");
            assert_eq!((found.cfg.p, found.cfg.align), (m.cfg.p, m.cfg.align));
            if rtl_dir().is_none() {
                assert_eq!(found.pipeline, golden::pipeline::Pipeline::NONE, "{} for {}", found.tag, m.tag);
            }
            if m.pipeline == golden::pipeline::Pipeline::NONE {
                assert_eq!(found.tag, m.tag);
            }
        }
        assert_eq!(require_specular_model("registry").map(|x| x.tag), SPECULAR_MODELS.first().map(|x| x.tag));
    }
}
