//! `manifest.json` and the FuseSoC CAPI2 core: machine-readable descriptions of what
//! `generate` wrote, derived from the same module descriptions that print the Verilog.

use crate::specular::SpecNames;
use crate::verilog::{Dir, Module};
use crate::{segment, BfpiArch, Names, Options, VERSION};
use golden::bfpi::{Adder, BfpiPlan};
use golden::rom::{Rom, BRDF_HEX, NK_HEX};
use golden::specular::{SpecularGeometry, SpecularUnit};
use serde::Serialize;

pub const CORE_FILE: &str = "segshade.core";

#[derive(Serialize)]
struct Manifest<'a> {
    generator: Generator,
    parameters: Parameters<'a>,
    formats: Formats,
    modules: Vec<ModuleEntry>,
    /// The shift-and-add graph; absent for the comparison forms (`--bfpi-arch naive|tree`).
    #[serde(skip_serializing_if = "Option::is_none")]
    bfpi: Option<Bfpi>,
    specular: Specular,
    /// SPEC §6's front-end; absent when the configuration cannot host the screen.
    #[serde(skip_serializing_if = "Option::is_none")]
    frontend: Option<Frontend>,
    /// SPEC §7's segment writer and block memory; present with the front-end.
    #[serde(skip_serializing_if = "Option::is_none")]
    writer: Option<WriterEntry>,
}

/// The block memory the writer addresses, and its timing.
#[derive(Serialize)]
struct WriterEntry {
    module: String,
    top: String,
    screen: golden::setup::Screen,
    blocks_per_row: u32,
    blocks: u32,
    addr_bits: u32,
    address: &'static str,
    /// Clocks from a segment's transfer to its write.
    latency: u32,
    writes: &'static str,
}

/// The front-end's screen, guard band, widths and timing.
#[derive(Serialize)]
struct Frontend {
    module: String,
    top: String,
    screen: golden::setup::Screen,
    guard_band: String,
    widths: golden::frontend::Widths,
    /// Quotient bits per clock of the set-up dividers (`--fe-div-bits`).
    div_bits: u32,
    /// Where `dI` comes from (`--fe-di`): `triangle` (once per triangle) or `scanline`.
    di: golden::frontend::DiMode,
    /// Per-scanline dI only: clocks the span divider runs for a span of two pixels or more.
    span_div_clocks: u32,
    /// Clocks from a triangle's transfer to its first span when the walker is idle.
    latency: u32,
    /// Set-up clocks per walked triangle (its rate limit) and per dropped triangle.
    setup_clocks_walked: u32,
    setup_clocks_dropped: u32,
    /// Walker clocks per triangle: one per row from its first to its last covered row.
    walker: &'static str,
}

/// The specular unit's configuration: k-set, n ranges, tables, ROM geometry, pipeline.
#[derive(Serialize)]
struct Specular {
    module: String,
    brdf_rom: RomEntry,
    nk_rom: RomEntry,
    #[serde(flatten)]
    geometry: SpecularGeometry,
}

#[derive(Serialize)]
struct RomEntry {
    module: String,
    file: &'static str,
    depth: usize,
    width: u32,
    bits: u64,
}

impl RomEntry {
    fn new(module: &str, file: &'static str, rom: &Rom) -> RomEntry {
        RomEntry { module: module.to_string(), file, depth: rom.depth(), width: rom.width, bits: rom.bits() }
    }
}

#[derive(Serialize)]
struct Generator {
    name: &'static str,
    version: &'static str,
}

#[derive(Serialize)]
struct Parameters<'a> {
    p: u32,
    frac: u32,
    xbits: u32,
    align: &'static str,
    prefix: &'a str,
    /// Only written for the comparison forms, so the default output stays as it was.
    #[serde(skip_serializing_if = "Option::is_none")]
    bfpi_arch: Option<&'static str>,
}

#[derive(Serialize)]
struct Formats {
    intensity: String,
    increment: String,
    pixel: &'static str,
    iw: u32,
    dw: u32,
    mw: u32,
    accumulator_bits: u32,
}

#[derive(Serialize)]
struct ModuleEntry {
    name: String,
    file: String,
    role: &'static str,
    /// Clocks from input to output; 0 for combinational blocks.
    latency: u32,
    throughput: &'static str,
    ports: Vec<PortEntry>,
}

#[derive(Serialize)]
pub struct PortEntry {
    pub name: String,
    pub direction: &'static str,
    pub width: u32,
    pub signed: bool,
    pub format: String,
    pub description: String,
}

#[derive(Serialize)]
struct Bfpi {
    module: String,
    adder_count: usize,
    depth: u32,
    lower_bound: u32,
    adders: Vec<Adder>,
}

fn ports(m: &Module) -> Vec<PortEntry> {
    m.ports
        .iter()
        .map(|p| PortEntry {
            name: p.name.clone(),
            direction: match p.dir {
                Dir::Input => "input",
                Dir::Output => "output",
            },
            width: p.width,
            signed: p.signed,
            format: p.format.clone(),
            description: p.doc.clone(),
        })
        .collect()
}

pub fn render(opts: &Options, names: &Names, modules: &[Module], unit: &SpecularUnit) -> String {
    let cfg = &opts.cfg;
    let plan = BfpiPlan::new(cfg.p);
    let spec = SpecNames::new(&opts.prefix);
    let fe = opts.frontend().ok();
    let fe_latency = fe.as_ref().map_or(0, |hw| hw.latency());
    let wr = opts.writer().ok().filter(|_| fe.is_some());
    let entry = |m: &Module| {
        let (role, latency, throughput) = if m.name == names.bfpi {
            ("bfpi", 0, "combinational")
        } else if m.name == names.segment {
            ("segment_shader", segment::LATENCY, "one segment per clock")
        } else if m.name == names.frontend {
            ("frontend", fe_latency, "one span per clock; set-up per walked triangle as in frontend.setup_clocks")
        } else if m.name == names.top {
            ("triangle_shader", fe_latency + segment::LATENCY, "one segment per clock")
        } else if m.name == names.writer {
            ("writer", golden::writer::LATENCY, "one block write per clock")
        } else if m.name == names.fb_top {
            ("triangle_writer", fe_latency + segment::LATENCY + golden::writer::LATENCY, "one block write per clock")
        } else if m.name == spec.unit {
            ("specular_unit", unit.plan().latency(), "one pixel per clock")
        } else {
            ("rom", 1, "one word per clock")
        };
        ModuleEntry { name: m.name.clone(), file: format!("{}.v", m.name), role, latency, throughput, ports: ports(m) }
    };
    let manifest = Manifest {
        generator: Generator { name: "segshade hdl-gen", version: VERSION },
        parameters: Parameters {
            p: cfg.p,
            frac: cfg.frac,
            xbits: cfg.xbits,
            align: cfg.align.name(),
            prefix: &opts.prefix,
            bfpi_arch: (opts.bfpi_arch != BfpiArch::ShiftAdd).then(|| opts.bfpi_arch.name()),
        },
        formats: Formats {
            intensity: format!("UQ8.{}", cfg.frac),
            increment: format!("signed Q8.{}", cfg.frac),
            pixel: "UQ8.0",
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
            span_div_clocks: hw.span_div_clocks(),
            latency: hw.latency(),
            setup_clocks_walked: hw.setup_clocks().0,
            setup_clocks_dropped: hw.setup_clocks().1,
            walker: "one clock per row from the first to the last row of the bounding box on screen",
        }),
        writer: wr.map(|w| WriterEntry {
            module: names.writer.clone(),
            top: names.fb_top.clone(),
            screen: w.screen,
            blocks_per_row: w.blocks_per_row(),
            blocks: w.blocks(),
            addr_bits: w.addr_bits(),
            address: "y * blocks_per_row + x div P; pixel x mod P in mem_data[8i +: 8], enable mem_we[i]",
            latency: golden::writer::LATENCY,
            writes: match opts.cfg.align {
                golden::Align::Span => "ceil((x0 mod P + m) / P) per span: each block the span touches, once, ascending (glue)",
                golden::Align::Screen => "one per segment: each block the span touches, once, ascending",
            },
        }),
    };
    serde_json::to_string_pretty(&manifest).expect("manifest serializes") + "\n"
}

/// A FuseSoC CAPI2 core for the generated files: a default target with the segment shader as
/// top level, a `specular` target with the specular unit, and a Verilator lint target. The ROM
/// images are copied into the tool's work folder, where `$readmemh` looks for them.
pub fn core_file(opts: &Options, names: &Names, modules: &[Module]) -> String {
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
         \x20 lint:\n\
         \x20   default_tool: verilator\n\
         \x20   filesets: [rtl]\n\
         \x20   toplevel: {top}\n\
         \x20   tools:\n\
         \x20     verilator:\n\
         \x20       mode: lint-only\n\
         \x20       verilator_options: [-Wall]\n",
        top = names.segment,
        spec_top = SpecNames::new(&opts.prefix).unit,
        p = cfg.p,
        f = cfg.frac,
        xw = cfg.xbits,
        align = cfg.align,
    )
}
