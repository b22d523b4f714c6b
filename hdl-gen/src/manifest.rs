//! `manifest.json` and the FuseSoC CAPI2 core: machine-readable descriptions of what
//! `generate` wrote, derived from the same module descriptions that print the Verilog.
//!
//! [`Manifest`] is the file's one schema: `generate` serializes it, and every reader
//! (`hdl-gen synth-wrapper`, the harness's build script for `COSIM_RTL_DIR`, the tests)
//! deserializes it with [`Manifest::parse`], so a field renamed here is renamed for all of them.

use crate::specular::SpecNames;
use crate::verilog::{Dir, Module};
use crate::{BfpiArch, Names, Options, VERSION};
use golden::bfpi::{Adder, BfpiPlan};
use golden::rom::{Rom, BRDF_HEX, NK_HEX};
use golden::specular::{SpecularGeometry, SpecularUnit};
use serde::{Deserialize, Serialize};

pub const CORE_FILE: &str = "segshade.core";
/// The manifest's file name in a folder `generate` wrote.
pub const MANIFEST_FILE: &str = "manifest.json";

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    pub generator: Generator,
    pub parameters: Parameters,
    pub formats: Formats,
    pub modules: Vec<ModuleEntry>,
    /// The shift-and-add graph; absent for the comparison forms (`--bfpi-arch naive|tree`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bfpi: Option<Bfpi>,
    pub specular: Specular,
    /// SPEC §6's front-end; absent when the configuration cannot host the screen.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frontend: Option<Frontend>,
    /// SPEC §7's segment writer and block memory; present with the front-end.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub writer: Option<WriterEntry>,
    /// `--bus axis`: each AXI4-Stream wrapper and where it packs every port; absent for native.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub axis: Vec<crate::axis::Wrapper>,
}

/// What a module is in the chain; readers find modules by role, not by name (names take a prefix).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "snake_case")]
pub enum Role {
    Bfpi,
    SegmentShader,
    Frontend,
    /// A part of the front-end (`tri_fe_div`, `tri_fe_edge`): no model of its own; its file is
    /// among the front-end's sources.
    FrontendPart,
    TriangleShader,
    Writer,
    TriangleWriter,
    SpecularUnit,
    Rom,
    /// `<module>_axis`: an AXI4-Stream wrapper (`--bus axis`); the manifest's `axis` section says
    /// which module it wraps.
    Axis,
}

/// The block memory the writer addresses, and its timing.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WriterEntry {
    pub module: String,
    pub top: String,
    pub screen: golden::setup::Screen,
    pub blocks_per_row: u32,
    pub blocks: u32,
    pub addr_bits: u32,
    pub address: String,
    /// Clocks from a segment's transfer to its write.
    pub latency: u32,
    pub writes: String,
}

/// The front-end's screen, guard band, widths and timing.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Frontend {
    pub module: String,
    pub top: String,
    pub screen: golden::setup::Screen,
    pub guard_band: String,
    pub widths: golden::frontend::Widths,
    /// Quotient bits per clock of the set-up dividers (`--fe-div-bits`).
    pub div_bits: u32,
    /// Where `dI` comes from (`--fe-di`): `triangle` (once per triangle) or `scanline`.
    pub di: golden::frontend::DiMode,
    /// How `I0` is formed (`--fe-i0`); left out for the default, `reciprocal`.
    #[serde(default, skip_serializing_if = "golden::frontend::I0Form::is_default")]
    pub i0: golden::frontend::I0Form,
    /// Incremental I0 only: clocks of a start on the shared engine (`Hw::start_clocks`).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub start_clocks: u32,
    /// How the set-up is built (`--fe-setup`); left out for the default, `parallel`.
    #[serde(default, skip_serializing_if = "golden::frontend::engine::SetupForm::is_default")]
    pub setup: golden::frontend::engine::SetupForm,
    /// How the span path forms a row's products (`--fe-span`); left out for the default,
    /// `parallel`.
    #[serde(default, skip_serializing_if = "golden::frontend::SpanForm::is_default")]
    pub span: golden::frontend::SpanForm,
    /// The shared set-up engine's plan and schedule (`--fe-setup` not `parallel`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub engine: Option<Engine>,
    /// Per-scanline dI only: clocks the span divider runs for a span of two pixels or more.
    pub span_div_clocks: u32,
    /// Clocks from a triangle's transfer to its first span when the walker is idle.
    pub latency: u32,
    /// Set-up clocks per walked triangle (its rate limit) and per dropped triangle.
    pub setup_clocks_walked: u32,
    pub setup_clocks_dropped: u32,
    /// Walker clocks per triangle: one per row from its first to its last covered row.
    pub walker: String,
}

/// The shared set-up engine: golden's plan, and its schedule's clocks.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Engine {
    pub module: String,
    pub plan: golden::frontend::engine::Plan,
    /// Clocks between two triangles entering the engine: the sustained set-up rate.
    pub ii: u32,
    /// Clocks from a triangle's entry to its set-up result at the queue.
    pub latency: u32,
    /// Triangles after which the units' binding repeats (an operation busier than II
    /// alternates between units).
    pub epochs: u32,
    pub queue_depth: u32,
}

/// The specular unit's configuration: k-set, n ranges, tables, ROM geometry, pipeline.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Specular {
    pub module: String,
    pub brdf_rom: RomEntry,
    pub nk_rom: RomEntry,
    #[serde(flatten)]
    pub geometry: SpecularGeometry,
}

#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct RomEntry {
    pub module: String,
    pub file: String,
    pub depth: usize,
    pub width: u32,
    pub bits: u64,
}

impl RomEntry {
    fn new(module: &str, file: &str, rom: &Rom) -> RomEntry {
        RomEntry { module: module.to_string(), file: file.to_string(), depth: rom.depth(), width: rom.width, bits: rom.bits() }
    }
}

#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Generator {
    pub name: String,
    pub version: String,
}

#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Parameters {
    pub p: u32,
    pub frac: u32,
    pub xbits: u32,
    pub align: golden::Align,
    pub prefix: String,
    /// Only written for the comparison forms, so the default output stays as it was.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bfpi_arch: Option<String>,
    /// `--pipeline`; only written above level 0, so the default output stays as it was.
    #[serde(default, skip_serializing_if = "is_seed_pipeline")]
    pub pipeline: golden::pipeline::Pipeline,
    /// `--bus`; only written for `axis`, so the default output stays as it was.
    #[serde(default, skip_serializing_if = "is_native")]
    pub bus: crate::Bus,
    /// `--target`, when given: the device the other options were chosen for.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target: Option<crate::Target>,
}

fn is_native(b: &crate::Bus) -> bool {
    *b == crate::Bus::Native
}

fn is_seed_pipeline(p: &golden::pipeline::Pipeline) -> bool {
    *p == golden::pipeline::Pipeline::NONE
}

#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Formats {
    pub intensity: String,
    pub increment: String,
    pub pixel: String,
    pub iw: u32,
    pub dw: u32,
    pub mw: u32,
    pub accumulator_bits: u32,
}

#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct ModuleEntry {
    pub name: String,
    pub file: String,
    pub role: Role,
    /// Clocks from input to output; 0 for combinational blocks.
    pub latency: u32,
    pub throughput: String,
    pub ports: Vec<PortEntry>,
    /// The register stages of a pipelined segment shader (`golden::segment::stages`) or of the
    /// front-end (`frontend::stages`: its CALC and span path); absent at level 0, whose stages SPEC's seed
    /// fixes (the specular unit's are in `specular`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub stages: Vec<golden::pipeline::PipeStage>,
    /// A front-end part's parameters (the divider's widths and rate): `ports` are at their
    /// defaults.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub parameters: Vec<ParamEntry>,
}

#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct ParamEntry {
    pub name: String,
    pub default: String,
    pub description: String,
}

#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct PortEntry {
    pub name: String,
    pub direction: Dir,
    pub width: u32,
    pub signed: bool,
    pub format: String,
    pub description: String,
}

#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Bfpi {
    pub module: String,
    pub adder_count: usize,
    pub depth: u32,
    pub lower_bound: u32,
    pub adders: Vec<Adder>,
}

/// A `manifest.json` that does not read as [`Manifest`].
///
/// Like every error of the workspace's libraries, its message is complete on its own (the JSON
/// error's text is in it, and not repeated as `source()`): the CLIs print it on one line.
#[derive(Debug, thiserror::Error)]
pub enum ManifestError {
    #[error("manifest.json: {0}")]
    Json(serde_json::Error),
    #[error("manifest.json lists no module '{module}' (it lists {listed})")]
    NoModule { module: String, listed: String },
}

impl Manifest {
    /// Reads a `manifest.json` text.
    pub fn parse(text: &str) -> Result<Manifest, ManifestError> {
        serde_json::from_str(text).map_err(ManifestError::Json)
    }

    /// The entry of the module named `name`.
    pub fn module(&self, name: &str) -> Result<&ModuleEntry, ManifestError> {
        self.modules.iter().find(|m| m.name == name).ok_or_else(|| ManifestError::NoModule {
            module: name.to_string(),
            listed: self.modules.iter().map(|m| m.name.as_str()).collect::<Vec<_>>().join(", "),
        })
    }

    /// The first module with `role`, if the configuration has one.
    pub fn by_role(&self, role: Role) -> Option<&ModuleEntry> {
        self.modules.iter().find(|m| m.role == role)
    }
}

fn ports(m: &Module) -> Vec<PortEntry> {
    m.ports
        .iter()
        .map(|p| PortEntry {
            name: p.name.clone(),
            direction: p.dir,
            width: p.width,
            signed: p.signed,
            format: p.format.clone(),
            description: p.doc.clone(),
        })
        .collect()
}

pub fn render(opts: &Options, names: &Names, modules: &[Module], unit: &SpecularUnit, wrappers: &[crate::axis::Wrapper]) -> String {
    let cfg = &opts.cfg;
    let plan = BfpiPlan::new(cfg.p);
    let spec = SpecNames::new(&opts.prefix);
    let fe = opts.frontend().ok();
    let fe_latency = fe.as_ref().map_or(0, |hw| hw.latency());
    let seg_latency = golden::segment::latency(cfg, opts.pipeline);
    let wr = opts.writer().ok().filter(|_| fe.is_some());
    let entry = |m: &Module| {
        // A wrapper's timing is its core's: it only renames and packs ports.
        let name = wrappers.iter().find(|w| w.module == m.name).map_or(&m.name, |w| &w.wraps);
        let (role, latency, throughput) = if name == &names.bfpi {
            (Role::Bfpi, 0, "combinational")
        } else if name == &names.segment {
            (Role::SegmentShader, seg_latency, "one segment per clock")
        } else if name == &names.frontend {
            (Role::Frontend, fe_latency, "one span per clock; set-up per walked triangle as in frontend.setup_clocks")
        } else if name == &names.fe_div {
            (Role::FrontendPart, 1, "BITS quotient bits a clock; the quotient after ceil(QB / BITS) run clocks")
        } else if name == &names.fe_edge {
            (Role::FrontendPart, 1, "one row per clock")
        } else if name == &names.fe_engine {
            let s = fe.as_ref().and_then(|hw| hw.engine()).expect("the engine form writes the engine");
            (Role::FrontendPart, s.latency + 1, "one triangle every frontend.engine.ii clocks")
        } else if name == &names.fe_queue {
            (Role::FrontendPart, 1, "one entry in and one out per clock")
        } else if name == &names.fe_mul {
            (Role::FrontendPart, 2, "one product per clock")
        } else if name == &names.top {
            (Role::TriangleShader, fe_latency + seg_latency, "one segment per clock")
        } else if name == &names.writer {
            (Role::Writer, golden::writer::LATENCY, "one block write per clock")
        } else if name == &names.fb_top {
            (Role::TriangleWriter, fe_latency + seg_latency + golden::writer::LATENCY, "one block write per clock")
        } else if name == &spec.unit {
            (Role::SpecularUnit, unit.plan().latency(), "one pixel per clock")
        } else {
            (Role::Rom, 1, "one word per clock")
        };
        let role = if name == &m.name { role } else { Role::Axis };
        let stages = match (role, &fe) {
            (Role::SegmentShader, _) if opts.pipeline != golden::pipeline::Pipeline::NONE => golden::segment::stages(cfg, opts.pipeline),
            (Role::Frontend, Some(hw)) => crate::frontend::stages(hw),
            _ => Vec::new(),
        };
        ModuleEntry {
            name: m.name.clone(),
            file: format!("{}.v", m.name),
            role,
            latency,
            throughput: throughput.into(),
            ports: ports(m),
            stages,
            // The ROMs' and the specular unit's file-name parameters are not widths: only the
            // front-end's divider states its parameters (its ports are at their defaults).
            parameters: m
                .params
                .iter()
                .filter(|_| role == Role::FrontendPart)
                .map(|p| ParamEntry { name: p.name.clone(), default: p.value.clone(), description: p.doc.clone() })
                .collect(),
        }
    };
    let manifest = Manifest {
        generator: Generator { name: "segshade hdl-gen".into(), version: VERSION.into() },
        parameters: Parameters {
            p: cfg.p,
            frac: cfg.frac,
            xbits: cfg.xbits,
            align: cfg.align,
            prefix: opts.prefix.clone(),
            bfpi_arch: (opts.bfpi_arch != BfpiArch::ShiftAdd).then(|| opts.bfpi_arch.name().into()),
            pipeline: opts.pipeline,
            bus: opts.bus,
            target: opts.target,
        },
        formats: Formats {
            intensity: format!("UQ8.{}", cfg.frac),
            increment: format!("signed Q8.{}", cfg.frac),
            pixel: "UQ8.0".into(),
            iw: cfg.iw(),
            dw: cfg.dw(),
            mw: cfg.mw(),
            accumulator_bits: cfg.aw(),
        },
        modules: modules.iter().map(entry).collect(),
        bfpi: (opts.bfpi_arch == BfpiArch::ShiftAdd).then(|| Bfpi {
            module: names.bfpi.clone(),
            adder_count: plan.adder_count(),
            depth: plan.depth(),
            lower_bound: (cfg.p / 2).saturating_sub(1),
            adders: plan.adders.clone(),
        }),
        specular: Specular {
            module: spec.unit.clone(),
            brdf_rom: RomEntry::new(&spec.brdf, BRDF_HEX, unit.brdf_rom()),
            nk_rom: RomEntry::new(&spec.nk, NK_HEX, unit.nk_rom()),
            geometry: unit.plan().geometry(),
        },
        frontend: fe.map(|hw| Frontend {
            module: names.frontend.clone(),
            top: names.top.clone(),
            screen: hw.fe.screen,
            guard_band: format!(
                "-{w} <= x < {}, -{h} <= y < {} pixels",
                2 * hw.fe.screen.width,
                2 * hw.fe.screen.height,
                w = hw.fe.screen.width,
                h = hw.fe.screen.height
            ),
            widths: hw.fe.widths(),
            div_bits: hw.div_bits,
            di: hw.fe.di,
            i0: hw.fe.i0,
            start_clocks: hw.start_clocks(),
            setup: hw.fe.setup,
            engine: hw.engine().zip(hw.engine_timing()).map(|(s, (ii, latency, epochs))| Engine {
                module: names.fe_engine.clone(),
                plan: s.plan,
                ii,
                latency,
                epochs,
                queue_depth: hw.queue_depth(),
            }),
            span_div_clocks: hw.span_div_clocks(),
            latency: hw.latency(),
            setup_clocks_walked: hw.setup_clocks().0,
            setup_clocks_dropped: hw.setup_clocks().1,
            span: hw.fe.span,
            walker: walker_clocks(&hw),
        }),
        writer: wr.map(|w| WriterEntry {
            module: names.writer.clone(),
            top: names.fb_top.clone(),
            screen: w.screen,
            blocks_per_row: w.blocks_per_row(),
            blocks: w.blocks(),
            addr_bits: w.addr_bits(),
            address: "y * blocks_per_row + x div P; pixel x mod P in mem_data[8i +: 8], enable mem_we[i]".into(),
            latency: golden::writer::LATENCY,
            writes: match opts.cfg.align {
                golden::Align::Span => "ceil((x0 mod P + m) / P) per span: each block the span touches, once, ascending (glue)",
                golden::Align::Screen => "one per segment: each block the span touches, once, ascending",
            }
            .into(),
        }),
        axis: wrappers.to_vec(),
    };
    serde_json::to_string_pretty(&manifest).expect("manifest serializes") + "\n"
}

/// A FuseSoC CAPI2 core for the generated files: a default target with the segment shader as
/// top level, a `specular` target with the specular unit, and a Verilator lint target. The ROM
/// images are copied into the tool's work folder, where `$readmemh` looks for them.
///
/// With `--bus axis` the wrappers are in the `rtl` fileset like every module, and each gets a
/// target of its own (`<role>_axis`: `segment_axis`, `specular_axis`, ...) with the wrapper as
/// top level, plus `lint_axis` for the shader's wrapper.
pub fn core_file(opts: &Options, names: &Names, modules: &[Module], wrappers: &[crate::axis::Wrapper]) -> String {
    let cfg = &opts.cfg;
    let mut files = String::new();
    for m in modules {
        files.push_str(&format!("      - {}.v\n", m.name));
    }
    // The chain from triangles to memory, when this configuration has one (SPEC §6, §7).
    let frame = match modules.iter().any(|m| m.name == names.fb_top) {
        true => format!("\x20 frame:\n\x20   filesets: [rtl]\n\x20   toplevel: {}\n", names.fb_top),
        false => String::new(),
    };
    let spec = SpecNames::new(&opts.prefix);
    let mut axis = String::new();
    for w in wrappers {
        let (target, filesets) = if w.wraps == names.segment {
            ("segment_axis", "[rtl]")
        } else if w.wraps == spec.unit {
            ("specular_axis", "[rtl, rom]")
        } else if w.wraps == names.frontend {
            ("frontend_axis", "[rtl]")
        } else {
            ("triangle_axis", "[rtl]")
        };
        axis.push_str(&format!("\x20 {target}:\n\x20   filesets: {filesets}\n\x20   toplevel: {}\n", w.module));
        if w.wraps == names.segment {
            axis.push_str(&format!(
                "\x20 lint_axis:\n\x20   default_tool: verilator\n\x20   filesets: [rtl]\n\x20   toplevel: {}\n\x20   tools:\n\x20     verilator:\n\x20       mode: lint-only\n\x20       verilator_options: [-Wall]\n",
                w.module
            ));
        }
    }
    format!(
        "CAPI=2:\n\
         # Generated by segshade hdl-gen {VERSION}; do not edit.\n\
         name: segshade:shading:{top}:{VERSION}\n\
         description: Segment Gouraud shader and specular unit, P = {p}, F = {f}, XW = {xw}, align = {align}\n\
         \n\
         filesets:\n\
         \x20 rtl:\n\
         \x20   files:\n{files}\
         \x20   file_type: verilogSource\n\
         \x20 rom:\n\
         \x20   files:\n\
         \x20     - {BRDF_HEX}: {{copyto: {BRDF_HEX}}}\n\
         \x20     - {NK_HEX}: {{copyto: {NK_HEX}}}\n\
         \x20   file_type: user\n\
         \n\
         targets:\n\
         \x20 default:\n\
         \x20   filesets: [rtl, rom]\n\
         \x20   toplevel: {top}\n\
         \x20 specular:\n\
         \x20   filesets: [rtl, rom]\n\
         \x20   toplevel: {spec_top}\n\
         {frame}\
         {axis}\
         \x20 lint:\n\
         \x20   default_tool: verilator\n\
         \x20   filesets: [rtl]\n\
         \x20   toplevel: {top}\n\
         \x20   tools:\n\
         \x20     verilator:\n\
         \x20       mode: lint-only\n\
         \x20       verilator_options: [-Wall]\n",
        top = names.segment,
        spec_top = spec.unit,
        p = cfg.p,
        f = cfg.frac,
        xw = cfg.xbits,
        align = cfg.align,
    )
}

fn is_zero(v: &u32) -> bool {
    *v == 0
}

/// The manifest's walker clocks: a row a clock, or with the sequential span path its clocks a
/// covered row.
fn walker_clocks(hw: &crate::frontend::Hw) -> String {
    let rows = "one clock per row from the first to the last row of the bounding box on screen";
    match hw.fe.span_seq() {
        None => rows.into(),
        Some(q) => format!("{rows}, {} per covered row (the sequential span path's)", q.row_clocks()),
    }
}
