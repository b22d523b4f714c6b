//! The verilated models, as safe Rust values. Every model has three C symbols (new, step,
//! free); `step` takes every input of one clock in one struct and returns every output in
//! another, so a clock costs one FFI call whatever the port count.

use crate::waveform::TraceError;
use golden::specular::{Decoder, DecoderRepr, KRange, PlanError, SpecularPlan, SpecularUnit};
use golden::{Align, Config};
use std::ffi::{c_char, c_int, c_void, CString};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// Inputs of `segment_shader_p<P>` for one clock.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct SegIn {
    pub in_x: u32,
    pub in_len: u32,
    pub in_i0: u32,
    /// Two's complement, masked to DW bits (Verilator requires unused bits to be zero).
    pub in_di: u32,
    pub rst: u8,
    pub in_valid: u8,
    pub out_ready: u8,
    /// 1: the data ports still hold what the last step wrote, so the shim leaves them alone
    /// (the driver's clocks between spans); 0 (the default): write them.
    pub keep: u8,
}

/// Outputs of `segment_shader_p<P>`, sampled just before the rising edge.
#[repr(C)]
#[derive(Clone, Copy)]
pub struct SegOut {
    pub out_x: u32,
    pub in_ready: u8,
    pub out_valid: u8,
    pub out_last: u8,
    /// Lane i in byte i.
    pub pix: [u8; 256],
    /// Lane i in bit i % 8 of byte i / 8.
    pub mask: [u8; 32],
}

impl Default for SegOut {
    fn default() -> Self {
        SegOut { out_x: 0, in_ready: 0, out_valid: 0, out_last: 0, pix: [0; 256], mask: [0; 32] }
    }
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct BfpiIn {
    pub di: u32,
}

#[repr(C)]
#[derive(Clone, Copy)]
pub struct BfpiOut {
    /// The packed `inc` bus, little-endian.
    pub inc: [u8; 1024],
}

impl Default for BfpiOut {
    fn default() -> Self {
        BfpiOut { inc: [0; 1024] }
    }
}

impl BfpiOut {
    /// Lane `i` of `width` bits (at most 56), sign-extended.
    pub fn lane(&self, i: u32, width: u32) -> i64 {
        let lo = (i * width) as usize;
        let mut word = [0u8; 8];
        let bytes = &self.inc[lo / 8..(lo / 8 + 8).min(self.inc.len())];
        word[..bytes.len()].copy_from_slice(bytes);
        let v = u64::from_le_bytes(word) >> (lo % 8);
        ((v << (64 - width)) as i64) >> (64 - width)
    }
}

/// Inputs of `specular_unit` for one clock.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct SpecIn {
    pub in_c: u32,
    pub in_n: u32,
    /// Two's complement bits of the signed Q3.28 ports.
    pub in_theta0: u32,
    pub in_dtheta: u32,
    pub in_len: u32,
    pub rst: u8,
    pub in_valid: u8,
    pub out_ready: u8,
    /// 1: the data ports still hold what the last step wrote, so the shim leaves them alone
    /// (the driver's clocks between spans); 0 (the default): write them.
    pub keep: u8,
}

/// Outputs of `specular_unit`, sampled just before the rising edge.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct SpecOut {
    pub out_spec: u16,
    pub in_ready: u8,
    pub out_valid: u8,
    pub out_last: u8,
    pub out_err: u8,
}

/// Inputs of `tri_frontend` and `tri_shader_p<P>` for one clock: the three vertices, each
/// value two's complement masked to its port's width.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct TriIn {
    pub x: [u32; 3],
    pub y: [u32; 3],
    pub i: [u32; 3],
    pub rst: u8,
    pub in_valid: u8,
    pub out_ready: u8,
    pub keep: u8,
}

/// Outputs of `tri_frontend`: one span, and the guard-band error pulse.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct FeOut {
    pub out_x: u32,
    pub out_len: u32,
    pub out_i0: u32,
    /// Two's complement in DW bits.
    pub out_di: u32,
    pub out_y: u32,
    pub in_ready: u8,
    pub out_valid: u8,
    pub err: u8,
    pub pad: u8,
}

/// Outputs of `tri_shader_p<P>`: a segment with its scanline, and the error pulse.
#[repr(C)]
#[derive(Clone, Copy)]
pub struct TriSegOut {
    pub out_x: u32,
    pub out_y: u32,
    pub in_ready: u8,
    pub out_valid: u8,
    pub out_last: u8,
    pub err: u8,
    pub pix: [u8; 256],
    pub mask: [u8; 32],
}

impl Default for TriSegOut {
    fn default() -> Self {
        TriSegOut { out_x: 0, out_y: 0, in_ready: 0, out_valid: 0, out_last: 0, err: 0, pix: [0; 256], mask: [0; 32] }
    }
}

/// Inputs of `fb_writer_p<P>` for one clock: a segment and its scanline; `out_ready` drives
/// `mem_ready`.
#[repr(C)]
#[derive(Clone, Copy)]
pub struct WrIn {
    pub in_x: u32,
    pub in_y: u32,
    pub rst: u8,
    pub in_valid: u8,
    pub out_ready: u8,
    pub keep: u8,
    pub in_last: u8,
    pub pad: [u8; 3],
    /// Lane i in byte i.
    pub pix: [u8; 256],
    /// Lane i in bit i % 8 of byte i / 8; bits past P are zero.
    pub mask: [u8; 32],
}

impl Default for WrIn {
    fn default() -> Self {
        WrIn { in_x: 0, in_y: 0, rst: 0, in_valid: 0, out_ready: 0, keep: 0, in_last: 0, pad: [0; 3], pix: [0; 256], mask: [0; 32] }
    }
}

/// The memory port of `fb_writer_p<P>` and `tri_fb_p<P>`: `out_valid` is `mem_valid`; `err`
/// the chain's guard-band pulse (0 for the writer alone).
#[repr(C)]
#[derive(Clone, Copy)]
pub struct WrOut {
    pub mem_addr: u32,
    pub in_ready: u8,
    pub out_valid: u8,
    pub err: u8,
    pub pad: u8,
    /// Lane i in byte i.
    pub data: [u8; 256],
    /// Lane i in bit i % 8 of byte i / 8.
    pub we: [u8; 32],
}

impl Default for WrOut {
    fn default() -> Self {
        WrOut { mem_addr: 0, in_ready: 0, out_valid: 0, err: 0, pad: 0, data: [0; 256], we: [0; 32] }
    }
}

// Every struct's size and field offsets are stated once, in csrc/shim.h (SEGSHADE_OFFSET,
// SEGSHADE_SIZE), where the C++ compiler checks them; build.rs turns the same lines into
// `const` asserts on these structs in models.rs, included below.

/// The control inputs of a streaming unit.
pub trait Control: Copy + Default + 'static {
    fn set_control(&mut self, rst: bool, in_valid: bool, out_ready: bool);
    /// Whether the next step may leave the data ports as the last one wrote them.
    fn keep_data(&mut self, keep: bool);
    /// What the two above set: `rst | in_valid << 1 | out_ready << 2 | keep << 3`.
    fn control(&self) -> u8;
}

/// The handshake outputs of a streaming unit.
pub trait Handshake: Copy + Default + 'static {
    fn in_ready(&self) -> bool;
    fn out_valid(&self) -> bool;
}

/// The control inputs and handshake outputs the streaming units share.
macro_rules! streaming_ports {
    ($in:ty $(, $out:ty)*) => {
        impl Control for $in {
            #[inline(always)]
            fn set_control(&mut self, rst: bool, in_valid: bool, out_ready: bool) {
                (self.rst, self.in_valid, self.out_ready) = (rst as u8, in_valid as u8, out_ready as u8);
            }
            #[inline(always)]
            fn keep_data(&mut self, keep: bool) {
                self.keep = keep as u8;
            }
            #[inline(always)]
            fn control(&self) -> u8 {
                self.rst | self.in_valid << 1 | self.out_ready << 2 | self.keep << 3
            }
        }
        $(impl Handshake for $out {
            #[inline(always)]
            fn in_ready(&self) -> bool {
                self.in_ready == 1
            }
            #[inline(always)]
            fn out_valid(&self) -> bool {
                self.out_valid == 1
            }
        })*
    };
}
streaming_ports!(SegIn, SegOut);
streaming_ports!(SpecIn, SpecOut);
streaming_ports!(TriIn, FeOut, TriSegOut, WrOut);
streaming_ports!(WrIn);

/// A linked model: its configuration and its three symbols. The symbols are private: only
/// [`Rtl`], which owns what `new` returns, calls them.
pub struct ModelInfo<I: 'static, O: 'static> {
    /// `seg_p8_span`, `bfpi_p8`, ...: also the Verilator class suffix.
    pub tag: &'static str,
    /// Verilog top-level module.
    pub top: &'static str,
    /// Clocks from an input transfer to the first output valid, as the generator states it.
    pub latency: u32,
    /// The shader's register stages (`--pipeline`); level 0 for every other kind of model.
    pub pipeline: golden::pipeline::Pipeline,
    pub cfg: Config,
    /// The screen of a front-end model (`tri_frontend`, `tri_shader_p<P>`); 640x480 elsewhere.
    pub screen: golden::setup::Screen,
    /// Where a front-end model's `dI` comes from (`--fe-di`).
    pub di: golden::frontend::DiMode,
    new: unsafe extern "C" fn(u64) -> *mut c_void,
    free: unsafe extern "C" fn(*mut c_void),
    step: unsafe extern "C" fn(*mut c_void, *const I, *mut O),
    /// Its traced twin, when this build has one (see [`crate::waveform`]).
    pub traced: Option<TracedModel<I, O>>,
    /// The circuit's identity (`Model::identity`): a model asked for at run time is this one
    /// when its identity is.
    identity: u64,
    /// The catalogue's models: the configuration they were generated from
    /// (`catalogue::options_key`).
    options: Option<&'static str>,
}

/// A model's traced twin (`verilator --trace-fst`, `csrc/trace.h`): the same RTL and the same
/// per-clock structs, and an FST file it dumps every clock into while one is open. build.rs
/// builds one for every streaming model when COSIM_TRACE is set, and for `seg_p2_span` always.
pub struct TracedModel<I: 'static, O: 'static> {
    /// `<tag>_tr`: its symbol prefix and the suffix of its Verilator class.
    pub tag: &'static str,
    new: unsafe extern "C" fn(u64) -> *mut c_void,
    free: unsafe extern "C" fn(*mut c_void),
    step: unsafe extern "C" fn(*mut c_void, *const I, *mut O),
    /// (handle, path, clock): the next step is clock `clock`; every clock from then on goes into
    /// the FST file at `path`. 0, or 1 when the file cannot be created, 2 on another error.
    trace_open: unsafe extern "C" fn(*mut c_void, *const c_char, u64) -> c_int,
    /// Flushes and closes the file (dropping the model does too). 0, or 2 on an error.
    trace_close: unsafe extern "C" fn(*mut c_void) -> c_int,
}

// Function pointers and a name: copied whatever I and O are (a derive would ask I, O: Copy).
impl<I, O> Clone for TracedModel<I, O> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<I, O> Copy for TracedModel<I, O> {}

/// The table set the specular model was generated with (`--brdf-k`): build.rs takes it from
/// the generator's default or from COSIM_RTL_DIR's manifest, where it checks that golden
/// rebuilds from it the very plan the manifest states.
pub struct SpecularTables {
    pub ks: &'static [u32],
    /// The decoder: which n uses which table.
    pub k_ranges: &'static [KRange],
    /// The BRDF word width, when not the plan builder's own choice (some `--brdf-k auto` plans).
    pub word_bits: Option<u32>,
}

impl SpecularTables {
    pub fn plan(&self) -> Result<SpecularPlan, PlanError> {
        let decoder = Decoder::try_from(DecoderRepr { ks: self.ks.to_vec(), ranges: self.k_ranges.to_vec() })?;
        SpecularPlan::build(decoder, self.word_bits)
    }
}

include!(concat!(env!("OUT_DIR"), "/models.rs"));

/// The golden specular unit the built specular model is checked against: [`SPECULAR_TABLES`]'
/// plan (built once), not `SpecularUnit::default()`, which is right only for the default set.
pub fn specular_unit() -> SpecularUnit {
    static UNIT: OnceLock<SpecularUnit> = OnceLock::new();
    UNIT.get_or_init(|| SpecularUnit::new(SPECULAR_TABLES.plan().expect("build.rs rebuilt this plan"))).clone()
}

/// A model's clock: `(handle, inputs, outputs)`, as `<tag>_step` in the shim.
pub type StepFn<I, O> = unsafe extern "C" fn(*mut c_void, *const I, *mut O);

impl<I, O> ModelInfo<I, O> {
    /// A model loaded at run time ([`crate::ondemand`]), from its shim's symbols.
    ///
    /// # Safety
    /// `new`, `free` and `step` are the shim's `<tag>_new`, `_free` and `_step` of a model driven
    /// through `I` and `O`.
    #[allow(clippy::too_many_arguments)]
    pub(crate) unsafe fn from_symbols(
        tag: &'static str,
        top: &'static str,
        latency: u32,
        pipeline: golden::pipeline::Pipeline,
        cfg: Config,
        screen: golden::setup::Screen,
        di: golden::frontend::DiMode,
        new: unsafe extern "C" fn(u64) -> *mut c_void,
        free: unsafe extern "C" fn(*mut c_void),
        step: StepFn<I, O>,
        identity: u64,
    ) -> Self {
        ModelInfo { tag, top, latency, pipeline, cfg, screen, di, new, free, step, traced: None, identity, options: None }
    }

    /// A catalogue model's configuration (`catalogue::options_key`); `None` for the others.
    pub fn options(&self) -> Option<&'static str> {
        self.options
    }

    /// What circuit this is (`Model::identity` of its description).
    pub fn identity(&self) -> u64 {
        self.identity
    }

    /// The model's own clock, for a fault-injecting wrapper ([`ModelInfo::with_step`]).
    pub fn step_fn(&self) -> StepFn<I, O> {
        self.step
    }

    /// This model with `step` as its clock (its traced twin unchanged): a test's mutant, whose
    /// step calls [`ModelInfo::step_fn`]'s and then changes an output.
    ///
    /// # Safety
    /// `step` is called with this model's handles, inputs and outputs: it must be safe to call
    /// wherever the model's own step is.
    pub unsafe fn with_step(&self, step: StepFn<I, O>) -> ModelInfo<I, O> {
        ModelInfo { step, ..*self }
    }

    /// For `--trace`: whether this model has a traced twin in this build.
    pub fn require_traced(&self) -> Result<(), TraceError> {
        match self.traced {
            Some(_) => Ok(()),
            None => Err(TraceError::NoTwin(self.tag)),
        }
    }

    /// Golden's front-end for a front-end model (`tri_frontend`, `tri_shader_p<P>`, `tri_fb_p<P>`).
    pub fn frontend(&self) -> golden::frontend::FrontEnd {
        golden::frontend::FrontEnd::new(self.cfg, self.screen).expect("the model's front-end").with_di(self.di)
    }
}

/// The segment-shader model built for `p` and `align` with SPEC's seed structure (or, from
/// `COSIM_RTL_DIR`, whatever pipeline level the folder has), if this build has one.
pub fn segment_model(p: u32, align: Align) -> Option<&'static ModelInfo<SegIn, SegOut>> {
    let seed = |m: &&ModelInfo<SegIn, SegOut>| m.pipeline == golden::pipeline::Pipeline::NONE;
    let matching = || SEGMENT_MODELS.iter().filter(|m| m.cfg.p == p && m.cfg.align == align);
    matching().find(seed).or_else(|| matching().next())
}

/// The segment-shader model for `p` and `align`, for a test that needs it (`what` names that
/// test); see [`require`] for what happens when this build has none.
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
/// `--p`/`--align` arguments to add. None when that model is built (a default build must have
/// it, see [`require`]); else, under COSIM_RTL_DIR, those of the folder's first segment shader.
/// `None` when there is no segment shader at all.
pub fn default_model_args(what: &str) -> Option<Vec<String>> {
    let other = SEGMENT_MODELS.first().filter(|_| RTL_DIR.is_some() && segment_model(8, Align::Span).is_none());
    let Some(m) = other else { return require_segment_model(8, Align::Span, what).map(|_| Vec::new()) };
    let args = vec!["--p".into(), m.cfg.p.to_string(), "--align".into(), m.cfg.align.to_string()];
    use std::io::Write;
    let _ = writeln!(
        std::io::stderr().lock(),
        "{what}: this build has no seg_p8_span model (the default): runs {} ({})",
        m.tag,
        args.join(" ")
    );
    Some(args)
}

/// The one rule every suite follows for a model it needs. A default build (no COSIM_RTL_DIR)
/// builds every model, so a missing one is a bug: panic. A build against COSIM_RTL_DIR has only
/// what that folder provides: say on stderr what is skipped and why, and return `None`.
///
/// The note goes to stderr directly, not through `eprintln!`, which the test harness captures
/// and shows only for failing tests: a skip must be visible when everything passes.
pub fn require<T>(found: Option<T>, model: &str, what: &str) -> Option<T> {
    if found.is_some() {
        return found;
    }
    let built: Vec<&str> = SEGMENT_MODELS
        .iter()
        .map(|m| m.tag)
        .chain(BFPI_MODELS.iter().map(|m| m.tag))
        .chain(SPECULAR_MODELS.iter().map(|m| m.tag))
        .chain(FRONTEND_MODELS.iter().map(|m| m.tag))
        .chain(TRISHADER_MODELS.iter().map(|m| m.tag))
        .chain(WRITER_MODELS.iter().map(|m| m.tag))
        .chain(TRIWRITER_MODELS.iter().map(|m| m.tag))
        .chain(AXIS_SEGMENT_MODELS.iter().map(|m| m.tag))
        .chain(AXIS_SPECULAR_MODELS.iter().map(|m| m.tag))
        .chain(AXIS_FRONTEND_MODELS.iter().map(|m| m.tag))
        .chain(AXIS_TRISHADER_MODELS.iter().map(|m| m.tag))
        .collect();
    let built = if built.is_empty() { "nothing".to_string() } else { built.join(", ") };
    match RTL_DIR {
        None => {
            panic!("{what}: this build has no {model} model, and a default build (no COSIM_RTL_DIR) must have every model (built: {built})")
        }
        Some(dir) => {
            use std::io::Write;
            let _ = writeln!(
                std::io::stderr().lock(),
                "{what}: skipped: this build has no {model} model (COSIM_RTL_DIR={dir} provides {built} only)"
            );
            None
        }
    }
}

/// One instance of a verilated model with its own VerilatedContext: the model, or its traced
/// twin ([`Rtl::traced`]).
pub struct Rtl<I: 'static, O: 'static> {
    handle: *mut c_void,
    info: &'static ModelInfo<I, O>,
    /// The model's or the twin's.
    step: unsafe extern "C" fn(*mut c_void, *const I, *mut O),
    free: unsafe extern "C" fn(*mut c_void),
    seed: u64,
    /// The twin's functions, when this is the twin.
    twin: Option<&'static TracedModel<I, O>>,
    /// The FST file open on the twin.
    waves: Option<PathBuf>,
}

// Each instance owns its context and is only touched through &mut self.
unsafe impl<I, O> Send for Rtl<I, O> {}

impl<I, O: Default> Rtl<I, O> {
    /// `seed` randomizes the registers' power-up values, so only a real reset makes them known.
    ///
    /// Under [`crate::waveform::trace_everything`] (`--trace DIR`) this is the traced twin with
    /// a file of its own in DIR open from its first clock; it panics when the build has no twin
    /// (the binaries check first, [`crate::waveform::require_traced`]).
    pub fn new(info: &'static ModelInfo<I, O>, seed: u64) -> Self {
        let Some(dir) = crate::waveform::everything() else {
            let handle = unsafe { (info.new)(seed) };
            assert!(!handle.is_null(), "model {} failed to construct", info.tag);
            return Rtl { handle, info, step: info.step, free: info.free, seed, twin: None, waves: None };
        };
        let mut rtl = Rtl::traced(info, seed).unwrap_or_else(|e| panic!("--trace: {e}"));
        let path = crate::waveform::full_trace_path(dir, info.tag, seed);
        rtl.open_waves(&path, 0).unwrap_or_else(|e| panic!("--trace: {e}"));
        rtl
    }

    /// The traced twin of `info` (no file open yet), or why there is none.
    pub fn traced(info: &'static ModelInfo<I, O>, seed: u64) -> Result<Self, TraceError> {
        let Some(twin) = &info.traced else { return Err(TraceError::NoTwin(info.tag)) };
        // SAFETY: the twin's constructor; a null handle (it caught an exception) is refused.
        let handle = unsafe { (twin.new)(seed) };
        if handle.is_null() {
            return Err(TraceError::Construct(twin.tag));
        }
        Ok(Rtl { handle, info, step: twin.step, free: twin.free, seed, twin: Some(twin), waves: None })
    }

    pub fn info(&self) -> &'static ModelInfo<I, O> {
        self.info
    }

    /// The seed of the registers' power-up values.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// The FST file this instance writes, if any.
    pub fn waves(&self) -> Option<&Path> {
        self.waves.as_deref()
    }

    /// One clock: apply `input` with the clock low, sample the outputs, raise the clock.
    pub fn step_into(&mut self, input: &I, output: &mut O) {
        unsafe { (self.step)(self.handle, input, output) }
    }

    /// The twin only: from the next step on, which is clock `clock` of the run (the file's time
    /// is 10 `clock`), every clock goes into a new FST file at `path`.
    pub fn open_waves(&mut self, path: &Path, clock: u64) -> Result<(), TraceError> {
        let Some(twin) = self.twin else { return Err(TraceError::NotTraced(self.info.tag)) };
        use std::os::unix::ffi::OsStrExt;
        let c = CString::new(path.as_os_str().as_bytes()).map_err(|_| TraceError::Nul(path.to_path_buf()))?;
        // The FST writer cannot say why it fails to create a file: find out first.
        std::fs::File::create(path).map_err(|error| TraceError::Io { path: path.to_path_buf(), error })?;
        // SAFETY: our handle of the twin, and a NUL-terminated path that outlives the call.
        match unsafe { (twin.trace_open)(self.handle, c.as_ptr(), clock) } {
            0 => {
                self.waves = Some(path.to_path_buf());
                Ok(())
            }
            1 => Err(TraceError::Create(path.to_path_buf())),
            _ => Err(TraceError::Writer(path.to_path_buf())),
        }
    }

    /// Flushes and closes the FST file, if one is open.
    pub fn close_waves(&mut self) -> Result<(), TraceError> {
        let (Some(twin), Some(path)) = (self.twin, self.waves.take()) else { return Ok(()) };
        // SAFETY: our handle of the twin.
        match unsafe { (twin.trace_close)(self.handle) } {
            0 => Ok(()),
            _ => Err(TraceError::Close(path)),
        }
    }
}

impl<I, O> Drop for Rtl<I, O> {
    fn drop(&mut self) {
        // The twin's destructor closes its file.
        unsafe { (self.free)(self.handle) }
    }
}

/// A two's complement value masked to `width` bits, as Verilator stores a signed port.
pub fn to_port(v: i64, width: u32) -> u32 {
    (v as u64 & ((1u64 << width) - 1)) as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`require`]'s rule: a missing model fails a default build and is skipped (`None`) in a
    /// COSIM_RTL_DIR build; a built one is returned either way.
    #[test]
    fn a_missing_model_fails_only_a_default_build() {
        let missing = std::panic::catch_unwind(|| {
            require_segment_model(3, Align::Span, "ffi: the rule's own test (a p = 3 shader is never built)").map(|m| m.tag)
        });
        match RTL_DIR {
            None => {
                let e = missing.expect_err("a default build with a model missing must fail");
                let msg = e.downcast_ref::<String>().expect("a formatted message");
                assert!(msg.contains("this build has no seg_p3_span model"), "{msg}");
            }
            Some(_) => assert!(missing.unwrap().is_none()),
        }
        // A default build also has pipelined twins of some shaders: (p, align) names the seed's
        // structure (pipeline level 0), which a default build always has.
        for m in SEGMENT_MODELS {
            let found = require_segment_model(m.cfg.p, m.cfg.align, "ffi").expect("built");
            assert_eq!((found.cfg.p, found.cfg.align), (m.cfg.p, m.cfg.align));
            if RTL_DIR.is_none() {
                assert_eq!(found.pipeline, golden::pipeline::Pipeline::NONE, "{} for {}", found.tag, m.tag);
            }
            if m.pipeline == golden::pipeline::Pipeline::NONE {
                assert_eq!(found.tag, m.tag);
            }
        }
        assert_eq!(require_specular_model("ffi").map(|x| x.tag), SPECULAR_MODELS.first().map(|x| x.tag));
    }
}
