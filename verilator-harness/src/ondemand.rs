//! Models built when first asked for. Any configuration `generate` accepts is generated (through
//! the hdl-gen library), verilated, compiled into a shared object with the same per-model shim as
//! the compiled catalogue's, and loaded with `libloading`, the first time a binary or test asks
//! for it; a model whose circuit is one of the catalogue's (`build.rs`) is taken from there.
//!
//! The shared objects are cached under `target/<profile>/segshade-models/<tag>-<hash>/`, the hash
//! being that of everything the build depends on: the RTL, the shim, csrc/shim.h, the compiler
//! set-up and `verilator --version`. A second run finds them (a few milliseconds); a changed
//! configuration, RTL or Verilator builds anew. A build happens in a temporary folder renamed
//! into place at the end, so two processes building the same model at once (two tests under
//! nextest) each finish, and one of the two identical folders stays; nothing half-built is ever
//! found under the final name. While a model builds, a spinner on stderr says so (a plain line
//! when stderr is not a terminal: a log shows why a run took seconds longer).
//!
//! `SEGSHADE_MODEL_CACHE=DIR` puts the cache elsewhere.

use crate::ffi::{BfpiIn, BfpiOut, FeOut, ModelInfo, SegIn, SegOut, TriIn, TriSegOut, WrIn, WrOut};
use crate::models::verilator::{self, cc_build, Link, Verilator};
use crate::models::{catalogue, io, Kind, Model, ModelError};
use std::any::Any;
use std::collections::HashMap;
use std::fs;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, OnceLock};
use std::time::{Duration, Instant};

/// The cache folder: `SEGSHADE_MODEL_CACHE`, else the one build.rs compiles the catalogue in.
pub fn cache_root() -> PathBuf {
    std::env::var_os("SEGSHADE_MODEL_CACHE").map_or_else(|| PathBuf::from(env!("SEGSHADE_MODEL_CACHE")), PathBuf::from)
}

fn verilator() -> Result<&'static Verilator, ModelError> {
    static FOUND: OnceLock<Option<Verilator>> = OnceLock::new();
    FOUND.get_or_init(|| Verilator::find().ok()).as_ref().ok_or(ModelError::NoVerilator)
}

/// Whether [`shared_object`] found the model built or built it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    Cached,
    Built,
}

/// A `cc::Build` for use outside a build script: the target is the one this crate was built for.
fn compiler(v: &Verilator) -> cc::Build {
    let mut b = cc_build(v, false, Link::Shared);
    b.target(env!("SEGSHADE_TARGET")).host(env!("SEGSHADE_TARGET")).cargo_warnings(false);
    b
}

/// A fresh temporary folder under `root` for a build of `name`, private to this process.
fn temp_dir(root: &Path, name: &str) -> Result<PathBuf, ModelError> {
    static SERIAL: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = SERIAL.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = root.join(format!(".tmp-{name}-{}-{n}", std::process::id()));
    let _ = fs::remove_dir_all(&dir);
    io(&dir, fs::create_dir_all(&dir))?;
    Ok(dir)
}

/// Renames the finished build `tmp` to `dir`. When another process got there first, its build
/// (the same key: the same bytes) stays and ours goes.
fn publish(tmp: &Path, dir: &Path, product: &Path) -> Result<(), ModelError> {
    match fs::rename(tmp, dir) {
        Ok(()) => Ok(()),
        Err(_) if product.exists() => {
            let _ = fs::remove_dir_all(tmp);
            Ok(())
        }
        Err(e) => {
            let _ = fs::remove_dir_all(tmp);
            io(dir, Err(e))
        }
    }
}

/// Verilator's runtime (the files `globals` lists), compiled position-independent once for
/// every shared object: a static archive each links a private copy of.
fn pic_runtime(v: &Verilator, root: &Path, globals: &[String]) -> Result<PathBuf, ModelError> {
    let key = format!("{}\n{}\n{}\n", v.version, Link::Shared.layout(), globals.join(" "));
    let dir = verilator::cache_dir(root, "runtime-pic", &key);
    let lib = dir.join("libverilated_rt_pic.a");
    if lib.exists() {
        return Ok(lib);
    }
    let tmp = temp_dir(root, "runtime-pic")?;
    let mut b = compiler(v);
    b.out_dir(&tmp);
    for g in globals {
        b.file(v.root.join("include").join(format!("{g}.cpp")));
    }
    b.try_compile("verilated_rt_pic").map_err(|e| ModelError::Compile {
        tag: "Verilator's runtime".into(),
        dir: tmp.clone(),
        log: e.to_string(),
    })?;
    io(tmp.join("build.key"), fs::write(tmp.join("build.key"), &key))?;
    publish(&tmp, &dir, &lib)?;
    Ok(lib)
}

/// The spinner (or line) shown while a model builds.
struct Progress(Option<indicatif::ProgressBar>);

impl Progress {
    fn start(m: &Model, dir: &Path) -> Progress {
        let what = format!("building model {} ({}): first use, verilator and the C++ compiler; cached in {}", m.tag, m.top, dir.display());
        if !std::io::stderr().is_terminal() {
            use std::io::Write;
            let _ = writeln!(std::io::stderr().lock(), "{what}");
            return Progress(None);
        }
        let bar = indicatif::ProgressBar::new_spinner()
            .with_style(indicatif::ProgressStyle::with_template("{spinner} {msg} {elapsed}").expect("a valid template"))
            .with_message(what);
        bar.enable_steady_tick(Duration::from_millis(120));
        Progress(Some(bar))
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        if let Some(bar) = &self.0 {
            bar.finish_and_clear();
        }
    }
}

/// The folder of `m`'s shared object in the cache: `<cache>/<tag>-<hash of its key>`.
pub fn cache_entry(m: &Model) -> Result<PathBuf, ModelError> {
    Ok(verilator::cache_dir(&cache_root(), &m.tag, &verilator::key(verilator()?, m, false, Link::Shared)))
}

/// The shared object of `m` (`<cache entry>/lib<tag>.so`), built unless the cache has it.
pub fn shared_object(m: &Model) -> Result<(PathBuf, Outcome), ModelError> {
    let v = verilator()?;
    let root = cache_root();
    let key = verilator::key(v, m, false, Link::Shared);
    let dir = verilator::cache_dir(&root, &m.tag, &key);
    let name = format!("lib{}.so", m.tag);
    if dir.join(&name).exists() {
        return Ok((dir.join(name), Outcome::Cached));
    }
    io(&root, fs::create_dir_all(&root))?;
    let _progress = Progress::start(m, &dir);
    let start = Instant::now();
    let tmp = temp_dir(&root, &m.tag)?;
    let (all, globals) = verilator::verilate(m, false, &tmp.join("obj"), &tmp.join("rtl"), &dir.join("rtl"))?;
    let verilated = start.elapsed().as_secs_f64();
    let runtime = pic_runtime(v, &root, &globals)?;
    let mut b = compiler(v);
    b.include(tmp.join("obj")).include(Path::new(env!("CARGO_MANIFEST_DIR")).join("csrc"));
    let tool = b.try_get_compiler().map_err(|e| ModelError::Compile { tag: m.tag.clone(), dir: tmp.clone(), log: e.to_string() })?;
    // One compile and link: the model's translation unit and a private copy of the runtime, whose
    // symbols stay inside (`--exclude-libs`), every reference bound within the object (`-Bsymbolic`).
    let out = tool
        .to_command()
        .arg("-shared")
        .arg("-o")
        .arg(tmp.join(&name))
        .arg(&all)
        .arg(&runtime)
        .args(["-Wl,-Bsymbolic", "-Wl,--exclude-libs,ALL", "-lpthread", "-latomic"])
        .output();
    let out = io(tool.path(), out)?;
    if !out.status.success() {
        let log = String::from_utf8_lossy(&out.stderr).into_owned();
        return Err(ModelError::Compile { tag: m.tag.clone(), dir: tmp, log });
    }
    let total = start.elapsed().as_secs_f64();
    let time = format!("verilate {verilated:.3}\ncompile {:.3}\ntotal {total:.3}\n", total - verilated);
    io(tmp.join("build.time"), fs::write(tmp.join("build.time"), time))?;
    io(tmp.join("build.key"), fs::write(tmp.join("build.key"), &key))?;
    publish(&tmp, &dir, &dir.join(&name))?;
    Ok((dir.join(name), Outcome::Built))
}

/// The models this process has loaded, by their shared object: each is loaded once and lives as
/// long as the process (its `ModelInfo` is `'static`, as the compiled catalogue's are).
fn loaded() -> &'static Mutex<HashMap<PathBuf, &'static (dyn Any + Send + Sync)>> {
    static LOADED: OnceLock<Mutex<HashMap<PathBuf, &'static (dyn Any + Send + Sync)>>> = OnceLock::new();
    LOADED.get_or_init(Default::default)
}

/// `m` built (or found) and loaded: its symbols behind a `ModelInfo` like the catalogue's.
/// `I` and `O` must be its kind's per-clock structs.
pub fn load<I: 'static, O: 'static>(m: &Model) -> Result<&'static ModelInfo<I, O>, ModelError> {
    let (inp, outp) = m.kind.ports();
    let named = |t: &str, want: &str| t.rsplit("::").next() == Some(want);
    assert!(
        named(std::any::type_name::<I>(), inp) && named(std::any::type_name::<O>(), outp),
        "model {} ({:?}) is driven through {inp} and {outp}",
        m.tag,
        m.kind
    );
    let (so, _) = shared_object(m)?;
    let mut map = loaded().lock().unwrap_or_else(|e| e.into_inner());
    if let Some(info) = map.get(&so).and_then(|a| a.downcast_ref::<ModelInfo<I, O>>()) {
        return Ok(info);
    }
    // SAFETY: our own shared object, built above from the shim; its initialisers are
    // Verilator's runtime's and the model's static data.
    let lib = unsafe { libloading::Library::new(&so) }
        .map_err(|e| ModelError::Io { path: so.clone(), error: std::io::Error::other(e.to_string()) })?;
    let lib: &'static libloading::Library = Box::leak(Box::new(lib));
    let symbol = |name: &str| -> Result<*const (), ModelError> {
        let full = format!("{}_{name}", m.tag);
        // SAFETY: only the symbol's address is read here; its type is the shim's (below).
        unsafe { lib.get::<*const ()>(full.as_bytes()) }
            .map(|s| *s)
            .map_err(|e| ModelError::Io { path: so.clone(), error: std::io::Error::other(e.to_string()) })
    };
    let (new, free, step) = (symbol("new")?, symbol("free")?, symbol("step")?);
    // SAFETY: the shim defines `<tag>_new`, `_free` and `_step` with exactly these signatures
    // (csrc/shim.h), on the kind's structs, which the assertion above checked I and O are.
    let info = unsafe {
        ModelInfo::from_symbols(
            leak(&m.tag),
            leak(&m.top),
            m.latency,
            m.pipeline,
            m.cfg,
            m.screen,
            m.di,
            std::mem::transmute::<*const (), unsafe extern "C" fn(u64) -> *mut std::ffi::c_void>(new),
            std::mem::transmute::<*const (), unsafe extern "C" fn(*mut std::ffi::c_void)>(free),
            std::mem::transmute::<*const (), unsafe extern "C" fn(*mut std::ffi::c_void, *const I, *mut O)>(step),
            m.identity(),
        )
    };
    let info: &'static ModelInfo<I, O> = Box::leak(Box::new(info));
    map.insert(so, info);
    Ok(info)
}

fn leak(s: &str) -> &'static str {
    Box::leak(s.to_string().into_boxed_str())
}

/// `m` from the compiled catalogue `compiled` when one there is the same circuit, else built and
/// loaded ([`load`]).
pub fn find_or_load<I: 'static, O: 'static>(
    compiled: &'static [ModelInfo<I, O>],
    m: &Model,
) -> Result<&'static ModelInfo<I, O>, ModelError> {
    let id = m.identity();
    match compiled.iter().find(|c| c.identity() == id) {
        Some(c) => Ok(c),
        None => load(m),
    }
}

/// The tag suffix of a configuration: what it sets other than P and the alignment (which every
/// tag names), so that a model built at run time says what it is (`seg_p2_span_f10`).
pub fn tag_suffix(opts: &hdl_gen::Options) -> String {
    let d = golden::Config::default();
    let mut s = String::new();
    if opts.cfg.frac != d.frac {
        s += &format!("_f{}", opts.cfg.frac);
    }
    if opts.cfg.xbits != d.xbits {
        s += &format!("_x{}", opts.cfg.xbits);
    }
    if opts.pipeline != golden::pipeline::Pipeline::NONE {
        s += &format!("_pl{}", opts.pipeline);
    }
    if let Some(screen) = opts.screen.filter(|&s| s != hdl_gen::Options::default_screen(&opts.cfg)) {
        s += &format!("_{}x{}", screen.width, screen.height);
    }
    if let Some(b) = opts.fe_div_bits.filter(|&b| b != hdl_gen::frontend::DEFAULT_DIV_BITS) {
        s += &format!("_div{b}");
    }
    if opts.fe_di != golden::frontend::DiMode::Triangle {
        s += "_scan";
    }
    if opts.fe_i0 != golden::frontend::I0Form::Reciprocal {
        s += "_inc";
    }
    if opts.bfpi_arch != hdl_gen::BfpiArch::ShiftAdd {
        s += &format!("_{:?}", opts.bfpi_arch).to_lowercase();
    }
    if opts.brdf.is_some() {
        s += "_brdf";
    }
    if !opts.prefix.is_empty() {
        s += &format!("_{}", opts.prefix.trim_end_matches('_'));
    }
    s
}

/// The model of `kind` that `generate` makes for `opts` (its AXI4-Stream wrapper with `--bus
/// axis`), described in memory; a configuration `generate` refuses is a [`ModelError::Config`].
pub fn describe(opts: &hdl_gen::Options, kind: Kind) -> Result<Model, ModelError> {
    let chain = matches!(kind, Kind::Frontend | Kind::TriShader | Kind::Writer | Kind::TriWriter);
    if chain {
        opts.frontend().map_err(|e| ModelError::Config(format!("--width/--height: {e}")))?;
        opts.writer().map_err(|e| ModelError::Config(format!("--width/--height: {e}")))?;
    }
    catalogue::model_of(opts, kind, &tag_suffix(opts)).map_err(ModelError::Config)
}

/// The model of `kind` for `opts`: the compiled catalogue's when it has this very circuit, else
/// built (once; cached) and loaded. Under a `COSIM_RTL_DIR` build only the folder's models
/// exist: the one matching `opts`' P and alignment, or an error naming what there is.
fn model<I: 'static, O: 'static>(
    compiled: &'static [ModelInfo<I, O>],
    opts: &hdl_gen::Options,
    kind: Kind,
) -> Result<&'static ModelInfo<I, O>, ModelError> {
    if let Some(dir) = crate::ffi::RTL_DIR {
        let (p, align) = (opts.cfg.p, opts.cfg.align);
        return compiled.iter().find(|m| (m.cfg.p, m.cfg.align) == (p, align)).ok_or_else(|| {
            let built: Vec<&str> = compiled.iter().map(|m| m.tag).collect();
            ModelError::Config(format!(
                "--p {p} --align {align}: COSIM_RTL_DIR={dir} has no such {kind:?} model (it has: {})",
                if built.is_empty() { "none".to_string() } else { built.join(", ") }
            ))
        });
    }
    // The catalogue's model of these very options, found without generating them (the binaries
    // ask once per run, and generating every block of a configuration takes a noticeable part of
    // a second).
    let key = catalogue::options_key(opts);
    if let Some(m) = compiled.iter().find(|m| m.options() == Some(key.as_str())) {
        return Ok(m);
    }
    find_or_load(compiled, &describe(opts, kind)?)
}

/// `segment_shader_p<P>` (or its AXI4-Stream wrapper) of `opts`.
pub fn segment(opts: &hdl_gen::Options) -> Result<&'static ModelInfo<SegIn, SegOut>, ModelError> {
    let compiled = if opts.bus == hdl_gen::Bus::Axis { crate::ffi::AXIS_SEGMENT_MODELS } else { crate::ffi::SEGMENT_MODELS };
    model(compiled, opts, Kind::Segment)
}

/// `bfpi_p<P>` of `opts`.
pub fn bfpi(opts: &hdl_gen::Options) -> Result<&'static ModelInfo<BfpiIn, BfpiOut>, ModelError> {
    model(crate::ffi::BFPI_MODELS, opts, Kind::Bfpi)
}

/// `tri_frontend` of `opts` (its screen, dividers, dI mode and pipeline level).
pub fn frontend(opts: &hdl_gen::Options) -> Result<&'static ModelInfo<TriIn, FeOut>, ModelError> {
    model(crate::ffi::FRONTEND_MODELS, opts, Kind::Frontend)
}

/// `tri_shader_p<P>` of `opts`: triangles in, segments out.
pub fn tri_shader(opts: &hdl_gen::Options) -> Result<&'static ModelInfo<TriIn, TriSegOut>, ModelError> {
    model(crate::ffi::TRISHADER_MODELS, opts, Kind::TriShader)
}

/// `fb_writer_p<P>` of `opts`.
pub fn writer(opts: &hdl_gen::Options) -> Result<&'static ModelInfo<WrIn, WrOut>, ModelError> {
    model(crate::ffi::WRITER_MODELS, opts, Kind::Writer)
}

/// `tri_fb_p<P>` of `opts`: triangles in, block writes out.
pub fn tri_writer(opts: &hdl_gen::Options) -> Result<&'static ModelInfo<TriIn, WrOut>, ModelError> {
    model(crate::ffi::TRIWRITER_MODELS, opts, Kind::TriWriter)
}

/// `generate`'s options for P and the alignment at the default formats (and, for the front-end's
/// models, `screen`); a P `generate` refuses is a [`ModelError::Config`].
pub fn options(p: u32, align: golden::Align, screen: Option<golden::setup::Screen>) -> Result<hdl_gen::Options, ModelError> {
    let d = golden::Config::default();
    let cfg = golden::Config::new(p, d.frac, d.xbits, align).map_err(|e| ModelError::Config(e.to_string()))?;
    Ok(hdl_gen::Options { cfg, screen, ..Default::default() })
}

/// A binary's exit status for `e`: 2 for a configuration it cannot have (a usage error), 1 when a
/// tool failed (Verilator, the compiler, the file system).
pub fn exit_status(e: &ModelError) -> u8 {
    match e {
        ModelError::Config(_) | ModelError::RtlDir { .. } => 2,
        _ => 1,
    }
}

/// Prints `error: {what}: {e}` and returns [`exit_status`]'s code: a binary's way out when the
/// model it needs cannot be had.
pub fn exit(what: &str, e: &ModelError) -> std::process::ExitCode {
    eprintln!("error: {what}: {e}");
    std::process::ExitCode::from(exit_status(e))
}
