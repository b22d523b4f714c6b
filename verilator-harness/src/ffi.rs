//! The verilated models, as safe Rust values. Every model has three C symbols (new, step,
//! free); `step` takes every input of one clock in one struct and returns every output in
//! another, so a clock costs one FFI call whatever the port count.

use crate::waveform::TraceError;
use golden::specular::{Decoder, DecoderRepr, KRange, PlanError, SpecularPlan};
use golden::{Align, Config};
use std::ffi::{c_char, c_int, c_void, CString};
use std::path::{Path, PathBuf};

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
    /// The circuit's identity (`Model::identity`): a model asked for at run time is this one
    /// when its identity is.
    identity: u64,
    /// The catalogue's models: the configuration they were generated from
    /// (`catalogue::options_key`).
    options: Option<&'static str>,
}

// Function pointers, names and plain values: copied whatever I and O are (a derive would ask
// I, O: Copy). The registry hands out copies of the catalogue's entries.
impl<I, O> Clone for ModelInfo<I, O> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<I, O> Copy for ModelInfo<I, O> {}

/// A model's traced twin (`verilator --trace-fst`, `csrc/trace.h`): the same RTL and the same
/// per-clock structs, and an FST file it dumps every clock into while one is open. Built, like a
/// model of a configuration outside the catalogue, the first time it is asked for
/// ([`ModelInfo::twin`], `crate::ondemand`), and cached.
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

impl<I, O> TracedModel<I, O> {
    /// A twin loaded at run time (`crate::ondemand::twin`), from its shim's symbols.
    ///
    /// # Safety
    /// The functions are the traced shim's `<tag>_new`, `_free`, `_step`, `_trace_open` and
    /// `_trace_close` (csrc/trace.h) of a model driven through `I` and `O`.
    pub(crate) unsafe fn from_symbols(
        tag: &'static str,
        new: unsafe extern "C" fn(u64) -> *mut c_void,
        free: unsafe extern "C" fn(*mut c_void),
        step: StepFn<I, O>,
        trace_open: unsafe extern "C" fn(*mut c_void, *const c_char, u64) -> c_int,
        trace_close: unsafe extern "C" fn(*mut c_void) -> c_int,
    ) -> Self {
        TracedModel { tag, new, free, step, trace_open, trace_close }
    }
}

// Function pointers and a name: copied whatever I and O are (a derive would ask I, O: Copy).
impl<I, O> Clone for TracedModel<I, O> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<I, O> Copy for TracedModel<I, O> {}

/// The table set a specular model was generated with (`--brdf-k`): the generator's default for
/// the compiled catalogue, or a COSIM_RTL_DIR folder's manifest's (`crate::registry`, which
/// checks that golden rebuilds from it the very plan the manifest states).
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

/// The traced twins this process has, by their circuit's identity ([`ModelInfo::built_twin`]).
fn twins() -> &'static std::sync::Mutex<std::collections::HashMap<u64, &'static (dyn std::any::Any + Send + Sync)>> {
    static TWINS: std::sync::OnceLock<std::sync::Mutex<std::collections::HashMap<u64, &'static (dyn std::any::Any + Send + Sync)>>> =
        std::sync::OnceLock::new();
    TWINS.get_or_init(Default::default)
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
        ModelInfo { tag, top, latency, pipeline, cfg, screen, di, new, free, step, identity, options: None }
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

    /// This model with `step` as its clock (its traced twin the model's own): a test's mutant, whose
    /// step calls [`ModelInfo::step_fn`]'s and then changes an output.
    ///
    /// # Safety
    /// `step` is called with this model's handles, inputs and outputs: it must be safe to call
    /// wherever the model's own step is.
    pub unsafe fn with_step(&self, step: StepFn<I, O>) -> ModelInfo<I, O> {
        ModelInfo { step, ..*self }
    }

    /// The model's traced twin, if this process has built (or loaded) it: `crate::ondemand::twin`
    /// builds it, the first time, and enters it here.
    pub fn built_twin(&self) -> Option<&'static TracedModel<I, O>> {
        let twins = twins().lock().unwrap_or_else(|e| e.into_inner());
        twins.get(&self.identity).and_then(|t| t.downcast_ref::<TracedModel<I, O>>())
    }

    /// Enters `twin` as this model's traced twin (its circuit's: a mutant made with
    /// [`ModelInfo::with_step`] shares it).
    pub(crate) fn enter_twin(&self, twin: TracedModel<I, O>) -> &'static TracedModel<I, O> {
        let mut twins = twins().lock().unwrap_or_else(|e| e.into_inner());
        let entry = twins.entry(self.identity).or_insert_with(|| Box::leak(Box::new(twin)));
        entry.downcast_ref::<TracedModel<I, O>>().expect("one circuit, one kind of structs")
    }

    /// Golden's front-end for a front-end model (`tri_frontend`, `tri_shader_p<P>`, `tri_fb_p<P>`).
    pub fn frontend(&self) -> golden::frontend::FrontEnd {
        golden::frontend::FrontEnd::new(self.cfg, self.screen).expect("the model's front-end").with_di(self.di)
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
    /// a file of its own in DIR open from its first clock; it panics when the twin is not built
    /// (the binaries build it first, `crate::ondemand::require_traced`).
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
        let Some(twin) = info.built_twin() else {
            return Err(TraceError::NoTwin { tag: info.tag, why: "not built in this process (crate::ondemand::twin builds it)".into() });
        };
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
