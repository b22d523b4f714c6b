//! Models built when first asked for. Any configuration `generate` accepts is generated (through
//! the hdl-gen library), verilated, compiled into a shared object with the same per-model shim as
//! the compiled catalogue's, and loaded with `libloading`, the first time a binary or test asks
//! for it; a model whose circuit is one of the catalogue's (`build.rs`) is taken from there.
//!
//! The shared objects are cached under `target/<profile>/segshade-models/<tag>-<hash>/`, the hash
//! being that of everything the build depends on: the RTL, the shim, csrc/shim.h, the compiler
//! set-up and `verilator --version`. A second run finds them (a few milliseconds); a changed
//! configuration, RTL or Verilator builds anew. A build happens in a temporary folder renamed
//! into place at the end, under a lock file (`<entry>.lock`): processes that want the same model
//! at once (tests under nextest) wait for the one building it, and nothing half-built is ever
//! found under the final name. While a model builds, a spinner on stderr says so (a plain line
//! when stderr is not a terminal: a log shows why a run took seconds longer).
//!
//! The same builder makes a `COSIM_RTL_DIR` folder's models (`crate::registry`) and every traced
//! twin (COSIM_TRACE, `--trace`: [`twin`]), the first time a run needs one.
//!
//! `SEGSHADE_MODEL_CACHE=DIR` puts the cache elsewhere.

use crate::ffi::{ModelInfo, SegIn, SegOut, StepFn, TracedModel};
use crate::models::model::TRACED_SUFFIX;
use crate::models::verilator::{self, cc_build, Link, Verilator, TRACE_LAYOUT};
use crate::models::{catalogue, io, Kind, Model, ModelError};
use crate::waveform::TraceError;
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
    FOUND.get_or_init(|| remembered_verilator().or_else(|| Verilator::find().ok())).as_ref().ok_or(ModelError::NoVerilator)
}

/// What `verilator --version` and `--getenv VERILATOR_ROOT` said of the `verilator` on PATH,
/// remembered in the cache by that file's path, size and time (and VERILATOR_ROOT): Verilator's
/// front end is a Perl script, a noticeable part of a second to start, and a test process that
/// only loads built models would otherwise start it twice. A changed or other Verilator is
/// another file, asked anew.
fn remembered_verilator() -> Option<Verilator> {
    let path = std::env::var_os("PATH")?;
    let exe = std::env::split_paths(&path).map(|d| d.join("verilator")).find(|f| f.is_file())?;
    let meta = fs::metadata(&exe).ok()?;
    let stamp = format!("{}\n{}\n{:?}\n{:?}\n", exe.display(), meta.len(), meta.modified().ok()?, std::env::var_os("VERILATOR_ROOT"));
    let file = cache_root().join(format!("verilator-{:016x}.txt", crate::models::model::hash(&stamp)));
    if let Some((version, root)) = fs::read_to_string(&file).ok().as_deref().and_then(|t| t.split_once('\n')) {
        return Some(Verilator { version: version.to_string(), root: PathBuf::from(root) });
    }
    let v = Verilator::find().ok()?;
    // Written whole or not at all: a temporary file renamed into place.
    let tmp = file.with_extension(format!("tmp{}", std::process::id()));
    let written = fs::create_dir_all(cache_root()).and_then(|()| fs::write(&tmp, format!("{}\n{}", v.version, v.root.display())));
    if written.and_then(|()| fs::rename(&tmp, &file)).is_err() {
        let _ = fs::remove_file(&tmp);
    }
    Some(v)
}

/// Whether [`shared_object`] found the model built or built it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    Cached,
    Built,
}

/// A `cc::Build` for use outside a build script: the target is the one this crate was built for
/// (`traced`: a traced twin's, `cc_build`).
fn compiler(v: &Verilator, traced: bool) -> cc::Build {
    let mut b = cc_build(v, traced, Link::Shared);
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

/// An exclusive lock on `path` (created if missing), held until dropped: one process (or
/// thread) builds a cache entry while the others that want it wait, then find it built, rather
/// than each compiling it (nextest runs every test in a process of its own).
struct Lock(#[allow(dead_code)] fs::File);

fn lock(path: &Path) -> Result<Lock, ModelError> {
    use std::os::fd::AsRawFd;
    let file = io(path, fs::OpenOptions::new().create(true).truncate(false).write(true).open(path))?;
    // SAFETY: flock on the descriptor of a file this function opened and keeps open.
    while unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX) } != 0 {
        let e = std::io::Error::last_os_error();
        if e.kind() != std::io::ErrorKind::Interrupted {
            return io(path, Err(e));
        }
    }
    Ok(Lock(file))
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
/// every shared object: a static archive each links a private copy of. `traced`: the traced
/// twins' (with the FST writer, `VM_TRACE` on). The untraced one is usually there already:
/// build.rs compiles the same entry for the crate's models.
fn pic_runtime(v: &Verilator, root: &Path, globals: &[String], traced: bool) -> Result<PathBuf, ModelError> {
    let (key, dir, lib) = verilator::runtime_entry(v, root, globals, traced);
    if lib.exists() {
        return Ok(lib);
    }
    let _lock = lock(&dir.with_extension("lock"))?;
    if lib.exists() {
        return Ok(lib);
    }
    let tmp = temp_dir(root, if traced { "fst-runtime-pic" } else { "runtime-pic" })?;
    if traced {
        verilator::require_zlib(compiler(v, true), &tmp).map_err(ModelError::Config)?;
    }
    let mut b = compiler(v, traced);
    b.out_dir(&tmp);
    for g in globals {
        b.file(v.root.join("include").join(format!("{g}.cpp")));
    }
    b.try_compile(verilator::RUNTIME_PIC).map_err(|e| ModelError::Compile {
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
    build(m, false)
}

/// [`shared_object`] of `m`, or (`traced`) of `m` as a traced twin: `verilator --trace-fst`, the
/// shim of `csrc/trace.h`, the FST writer in its runtime and zlib linked.
fn build(m: &Model, traced: bool) -> Result<(PathBuf, Outcome), ModelError> {
    let v = verilator()?;
    let root = cache_root();
    let key = verilator::key(v, m, traced, Link::Shared);
    let dir = verilator::cache_dir(&root, &m.tag, &key);
    let name = format!("lib{}.so", m.tag);
    if dir.join(&name).exists() {
        return Ok((dir.join(name), Outcome::Cached));
    }
    io(&root, fs::create_dir_all(&root))?;
    let _lock = lock(&dir.with_extension("lock"))?;
    // Another process may have built it while this one waited.
    if dir.join(&name).exists() {
        return Ok((dir.join(name), Outcome::Cached));
    }
    let _progress = Progress::start(m, &dir);
    let start = Instant::now();
    let tmp = temp_dir(&root, &m.tag)?;
    let (all, globals) = verilator::verilate(m, traced, &tmp.join("obj"), &tmp.join("rtl"), &dir.join("rtl"))?;
    let verilated = start.elapsed().as_secs_f64();
    // Verilator's runtime as every model has it, and for a twin the FST writer's files beside it
    // in an archive of their own (as build.rs linked twins): the plain runtime is compiled once.
    let (fst, plain): (Vec<String>, Vec<String>) = globals.into_iter().partition(|g| traced && g.contains("fst"));
    let mut runtime = vec![pic_runtime(v, &root, &plain, false)?];
    if !fst.is_empty() {
        runtime.insert(0, pic_runtime(v, &root, &fst, true)?);
    }
    let mut b = compiler(v, traced);
    verilator::use_precompiled_header(v, &mut b, &root);
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
        .args(&runtime)
        .args(["-Wl,-Bsymbolic", "-Wl,--exclude-libs,ALL", "-lpthread", "-latomic"])
        // The FST writer compresses its hierarchy with zlib.
        .args(traced.then_some("-lz"))
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

/// The shared object `so`, loaded once per process and never unloaded (the models' `ModelInfo`s
/// are `'static`, as the compiled catalogue's are).
fn open(so: &Path) -> Result<&'static libloading::Library, ModelError> {
    static OPEN: OnceLock<Mutex<HashMap<PathBuf, &'static libloading::Library>>> = OnceLock::new();
    let mut open = OPEN.get_or_init(Default::default).lock().unwrap_or_else(|e| e.into_inner());
    if let Some(lib) = open.get(so) {
        return Ok(lib);
    }
    // SAFETY: our own shared object, built from the shim; its initialisers are Verilator's
    // runtime's and the model's static data.
    let lib = unsafe { libloading::Library::new(so) }.map_err(|e| loading(so, e))?;
    let lib: &'static libloading::Library = Box::leak(Box::new(lib));
    open.insert(so.to_path_buf(), lib);
    Ok(lib)
}

fn loading(so: &Path, e: libloading::Error) -> ModelError {
    ModelError::Io { path: so.to_path_buf(), error: std::sync::Arc::new(std::io::Error::other(e.to_string())) }
}

/// The address of `<tag>_<name>` in `lib` (the shared object `so`); its type is the shim's.
fn symbol(lib: &'static libloading::Library, so: &Path, tag: &str, name: &str) -> Result<*const (), ModelError> {
    let full = format!("{tag}_{name}");
    // SAFETY: only the symbol's address is read here; the callers give it the shim's type.
    unsafe { lib.get::<*const ()>(full.as_bytes()) }.map(|s| *s).map_err(|e| loading(so, e))
}

/// The descriptions of the models this process loaded, by identity: what their traced twins
/// are built from.
fn described() -> &'static Mutex<HashMap<u64, &'static Model>> {
    static DESCRIBED: OnceLock<Mutex<HashMap<u64, &'static Model>>> = OnceLock::new();
    DESCRIBED.get_or_init(Default::default)
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
    let lib = open(&so)?;
    let (new, free, step) = (symbol(lib, &so, &m.tag, "new")?, symbol(lib, &so, &m.tag, "free")?, symbol(lib, &so, &m.tag, "step")?);
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
            std::mem::transmute::<*const (), StepFn<I, O>>(step),
            m.identity(),
        )
    };
    let info: &'static ModelInfo<I, O> = Box::leak(Box::new(info));
    map.insert(so, info);
    described().lock().unwrap_or_else(|e| e.into_inner()).entry(m.identity()).or_insert_with(|| Box::leak(Box::new(m.clone())));
    Ok(info)
}

/// The traced twin of `info` (a model of the catalogue, or one loaded at run time), built (or
/// found in the cache) and loaded the first time this process asks, and entered in `info`'s
/// table ([`ModelInfo::built_twin`]): the same description under the tag `<tag>_tr`, verilated
/// with `--trace-fst` (a few seconds, once).
pub fn twin<I: 'static, O: 'static>(info: &ModelInfo<I, O>) -> Result<&'static TracedModel<I, O>, ModelError> {
    // One twin build at a time in this process: two threads asking for one twin build it once.
    static BUILDING: Mutex<()> = Mutex::new(());
    let _one = BUILDING.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(t) = info.built_twin() {
        return Ok(t);
    }
    let id = info.identity();
    let tag = format!("{}{TRACED_SUFFIX}", info.tag);
    // The twin of this circuit built before (under this Verilator, shims and layout): its shared
    // object, found without describing the model again (generating a configuration takes a
    // good part of a second).
    let v = verilator()?;
    let stamp = format!("{id}\n{}\n{}\n{}\n{}\n{}", v.version, Link::Shared.layout(), verilator::SHIM_H, verilator::TRACE_H, TRACE_LAYOUT);
    let index = cache_root().join(format!("{tag}-{:016x}.twin", crate::models::model::hash(&stamp)));
    let known = fs::read_to_string(&index).ok().map(PathBuf::from).filter(|so| so.exists());
    let so = match known {
        Some(so) => so,
        None => {
            let so = build(&describe_again(info)?, true)?.0;
            let tmp = index.with_extension(format!("tmp{}", std::process::id()));
            if fs::write(&tmp, so.as_os_str().as_encoded_bytes()).and_then(|()| fs::rename(&tmp, &index)).is_err() {
                let _ = fs::remove_file(&tmp);
            }
            so
        }
    };
    let lib = open(&so)?;
    let sym = |name: &str| symbol(lib, &so, &tag, name);
    // SAFETY: csrc/trace.h's SEGSHADE_TRACE_SHIM defines these five with exactly these
    // signatures, on the same structs as the model's (the description is the model's own).
    let twin = unsafe {
        TracedModel::from_symbols(
            leak(&tag),
            std::mem::transmute::<*const (), unsafe extern "C" fn(u64) -> *mut std::ffi::c_void>(sym("new")?),
            std::mem::transmute::<*const (), unsafe extern "C" fn(*mut std::ffi::c_void)>(sym("free")?),
            std::mem::transmute::<*const (), StepFn<I, O>>(sym("step")?),
            std::mem::transmute::<*const (), unsafe extern "C" fn(*mut std::ffi::c_void, *const std::ffi::c_char, u64) -> std::ffi::c_int>(
                sym("trace_open")?,
            ),
            std::mem::transmute::<*const (), unsafe extern "C" fn(*mut std::ffi::c_void) -> std::ffi::c_int>(sym("trace_close")?),
        )
    };
    Ok(info.enter_twin(twin))
}

/// `info`'s description as its twin is built from: the one it was loaded from, or the
/// catalogue's entry of its tag (checked to be the circuit compiled in), under the twin's tag.
fn describe_again<I, O>(info: &ModelInfo<I, O>) -> Result<Model, ModelError> {
    let id = info.identity();
    let loaded = described().lock().unwrap_or_else(|e| e.into_inner()).get(&id).copied();
    let m = match loaded {
        Some(m) => m.clone(),
        None => {
            let m = catalogue::catalogue_model(info.tag).map_err(ModelError::Config)?;
            if m.identity() != id {
                return Err(ModelError::Config(format!("{}: the catalogue describes another circuit than the one compiled in", info.tag)));
            }
            m
        }
    };
    if m.kind == Kind::Bfpi {
        return Err(ModelError::Config(format!("{}: a combinational block has no traced twin", m.tag)));
    }
    Ok(Model { tag: format!("{}{TRACED_SUFFIX}", m.tag), ..m })
}

/// For `--trace` and a failure's waveform: `info`'s traced twin built ([`twin`]), as a
/// [`TraceError`] when it cannot be. A binary asks before its run starts, so that the build's
/// progress line comes first and a failure ends the run before it begins.
pub fn require_traced<I: 'static, O: 'static>(info: &ModelInfo<I, O>) -> Result<(), TraceError> {
    twin(info).map(|_| ()).map_err(|e| TraceError::NoTwin { tag: info.tag, why: e.to_string() })
}

/// The negative control of an AXI4-Stream shader model loaded at run time: its shim's
/// `<tag>_step_mispacked` (`shim::axis_step_cpp`).
pub fn mispacked(m: &Model) -> Result<StepFn<SegIn, SegOut>, ModelError> {
    let (so, _) = shared_object(m)?;
    let step = symbol(open(&so)?, &so, &m.tag, "step_mispacked")?;
    // SAFETY: the AXI4-Stream shim defines `<tag>_step_mispacked` with the step's signature, on
    // the segment shader's structs.
    Ok(unsafe { std::mem::transmute::<*const (), StepFn<SegIn, SegOut>>(step) })
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
    if !opts.fe_setup.is_default() {
        s += &format!("_{}", opts.fe_setup.name().replace('-', ""));
    }
    if !opts.fe_span.is_default() {
        s += "_seqspan";
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
