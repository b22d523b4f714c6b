//! `generate --bus axis`: an AXI4-Stream wrapper `<module>_axis` around each streaming top.
//!
//! SPEC §3's modules and ports are a public interface, so the wrapper instantiates the SPEC
//! module unchanged and only renames and packs its ports: the data inputs into `s_axis_tdata`,
//! the data outputs into `m_axis_tdata`, `m_axis_tkeep` (the lane mask), `m_axis_tlast` (end of
//! the span) and `m_axis_tuser` (positions, flags). Where each port sits is [`Wrapper`], stated
//! once here: the wrapper's Verilog and its header table, `manifest.json`'s `axis` section,
//! docs/axis.md's tables and the harness's packing code (verilator-harness/build.rs) all come
//! from it.
//!
//! Packing rule: every field starts on a byte boundary and is padded to whole bytes, so every
//! packed signal is a whole number of bytes (AXI4-Stream's TDATA is) and each field sits in byte
//! lanes of its own, as video-over-AXI4-Stream components do. Input padding is ignored; output
//! padding repeats a signed field's sign and is zero for an unsigned one, so a field read as a
//! whole number of bytes has the port's value.

use crate::verilog::{assign, comment, net, sext, zext, Dir, Item, Module, Port};
use serde::{Deserialize, Serialize};
use std::fmt;

/// How `generate` presents the streams: SPEC §3's ports only, or AXI4-Stream wrappers as well.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, clap::ValueEnum, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Bus {
    /// SPEC §3's modules and ports, nothing else.
    #[default]
    Native,
    /// Also `<module>_axis`: AXI4-Stream wrappers of the streaming tops.
    Axis,
}

impl Bus {
    pub fn name(self) -> &'static str {
        match self {
            Bus::Native => "native",
            Bus::Axis => "axis",
        }
    }
}

impl fmt::Display for Bus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The control ports every streaming SPEC module has; the wrapper maps them to the handshake.
pub const CONTROL: [&str; 6] = ["clk", "rst", "in_valid", "in_ready", "out_valid", "out_ready"];

/// One SPEC port inside a packed AXI4-Stream signal.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Field {
    /// The SPEC module's port the field carries.
    pub port: String,
    /// Its first bit in the packed signal.
    pub lsb: u32,
    /// The port's width.
    pub width: u32,
    /// Bits the field occupies, padding included: `width` rounded up to whole bytes.
    pub bits: u32,
    pub signed: bool,
    /// The port's fixed-point format, as the manifest's `ports[].format`.
    pub format: String,
}

impl Field {
    /// `[msb:lsb]` of the port's own bits.
    pub fn range(&self) -> String {
        bits_range(self.lsb, self.width)
    }

    /// `[msb:lsb]` of the padding, if any.
    pub fn padding(&self) -> Option<String> {
        (self.bits > self.width).then(|| bits_range(self.lsb + self.width, self.bits - self.width))
    }
}

fn bits_range(lsb: u32, width: u32) -> String {
    if width == 1 {
        format!("[{lsb}]")
    } else {
        format!("[{}:{lsb}]", lsb + width - 1)
    }
}

/// A packed signal: its width and its fields, lowest first.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Packing {
    pub bits: u32,
    pub fields: Vec<Field>,
}

/// A packing that breaks the rule of this module (a hand-edited manifest can hold one).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum LayoutError {
    #[error("{signal}: {bits} bits is not a whole number of bytes")]
    NotBytes { signal: String, bits: u32 },
    #[error("{signal}: field {port} at bit {lsb} does not start on a byte boundary after the previous field (expected bit {expected})")]
    Misplaced { signal: String, port: String, lsb: u32, expected: u32 },
    #[error("{signal}: field {port} is {width} bits in {bits} (its width rounded up to bytes is {want})")]
    Padding { signal: String, port: String, width: u32, bits: u32, want: u32 },
    #[error("{signal}: fields end at bit {end}, the signal is {bits} bits")]
    Length { signal: String, end: u32, bits: u32 },
}

impl Packing {
    /// `ports` in order, each from the next byte boundary, padded to whole bytes.
    pub fn bytes(ports: &[&Port]) -> Packing {
        let mut lsb = 0;
        let fields = ports
            .iter()
            .map(|p| {
                let bits = p.width.div_ceil(8) * 8;
                let f = Field { port: p.name.clone(), lsb, width: p.width, bits, signed: p.signed, format: p.format.clone() };
                lsb += bits;
                f
            })
            .collect();
        Packing { bits: lsb, fields }
    }

    /// Whether this is the packing [`Packing::bytes`] makes of its own fields: what a reader of
    /// a manifest checks before packing words by it.
    pub fn check(&self, signal: &str) -> Result<(), LayoutError> {
        let signal = signal.to_string();
        let mut expected = 0;
        for f in &self.fields {
            if f.lsb != expected {
                return Err(LayoutError::Misplaced { signal, port: f.port.clone(), lsb: f.lsb, expected });
            }
            let want = f.width.div_ceil(8) * 8;
            if f.width == 0 || f.bits != want {
                return Err(LayoutError::Padding { signal, port: f.port.clone(), width: f.width, bits: f.bits, want });
            }
            expected += f.bits;
        }
        if self.bits % 8 != 0 || self.bits == 0 {
            return Err(LayoutError::NotBytes { signal, bits: self.bits });
        }
        if expected != self.bits {
            return Err(LayoutError::Length { signal, end: expected, bits: self.bits });
        }
        Ok(())
    }

    /// The packed word from nets named as the ports, each padded as this module's rule says.
    fn pack_expr(&self) -> String {
        let parts: Vec<String> = self
            .fields
            .iter()
            .rev()
            .map(|f| if f.signed { sext(&f.port, f.width, f.bits) } else { zext(&f.port, f.width, f.bits) })
            .collect();
        match parts.as_slice() {
            [one] => one.clone(),
            _ => format!("{{{}}}", parts.join(", ")),
        }
    }

    /// One line per field: bits, port, format, padding (`input`: padding the wrapper ignores;
    /// else padding it drives).
    pub fn rows(&self, input: bool) -> Vec<[String; 4]> {
        self.fields
            .iter()
            .map(|f| {
                let pad = match f.padding() {
                    None => "none".to_string(),
                    Some(r) if input => format!("{r}: ignored"),
                    Some(r) if f.signed => format!("{r}: sign"),
                    Some(r) => format!("{r}: zero"),
                };
                let format = if f.format.is_empty() { "flag".to_string() } else { f.format.clone() };
                [f.range(), f.port.clone(), format, pad]
            })
            .collect()
    }
}

/// One side of a wrapper: what its TDATA, TUSER, TKEEP and TLAST carry.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Stream {
    pub tdata: Packing,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tuser: Option<Packing>,
    /// The port whose bit `i` is TKEEP[i], byte `i` of TDATA (the shader's lane mask).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tkeep: Option<String>,
    /// The port TLAST is (the final segment or pixel of a span).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tlast: Option<String>,
}

/// The AXI4-Stream wrapper of one SPEC module: where every port went.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Wrapper {
    /// The wrapper, `<wraps>_axis`.
    pub module: String,
    /// The SPEC module inside, unchanged.
    pub wraps: String,
    /// What one input beat is, in words.
    pub beat_in: String,
    /// What one output beat is, in words.
    pub beat_out: String,
    pub s_axis: Stream,
    pub m_axis: Stream,
    /// Outputs that are no part of a beat, passed through under their own names (`err`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub sideband: Vec<String>,
}

/// What one block's wrapper puts where: its beats and its output ports by AXI4-Stream signal.
struct Plan<'a> {
    beat_in: &'a str,
    beat_out: &'a str,
    tdata: &'a [&'a str],
    tuser: &'a [&'a str],
    tkeep: Option<&'a str>,
    tlast: Option<&'a str>,
}

impl Wrapper {
    /// The wrapper of `core`: every input but the control ports packed into `s_axis_tdata`; the
    /// outputs as `plan` says, any other output a sideband port.
    fn new(core: &Module, plan: Plan) -> Wrapper {
        let find = |name: &str| core.ports.iter().find(|p| p.name == name).unwrap_or_else(|| panic!("{} has no port {name}", core.name));
        let pack = |names: &[&str]| Packing::bytes(&names.iter().map(|n| find(n)).collect::<Vec<_>>());
        let data_in: Vec<&Port> = core.ports.iter().filter(|p| p.dir == Dir::Input && !CONTROL.contains(&p.name.as_str())).collect();
        let taken: Vec<&str> = plan.tdata.iter().chain(plan.tuser).chain(plan.tkeep.iter()).chain(plan.tlast.iter()).copied().collect();
        let sideband = core
            .ports
            .iter()
            .filter(|p| p.dir == Dir::Output && !CONTROL.contains(&p.name.as_str()) && !taken.contains(&p.name.as_str()))
            .map(|p| p.name.clone())
            .collect();
        Wrapper {
            module: format!("{}_axis", core.name),
            wraps: core.name.clone(),
            beat_in: plan.beat_in.into(),
            beat_out: plan.beat_out.into(),
            s_axis: Stream { tdata: Packing::bytes(&data_in), tuser: None, tkeep: None, tlast: None },
            m_axis: Stream {
                tdata: pack(plan.tdata),
                tuser: (!plan.tuser.is_empty()).then(|| pack(plan.tuser)),
                tkeep: plan.tkeep.map(|k| find(k).name.clone()),
                tlast: plan.tlast.map(|l| find(l).name.clone()),
            },
            sideband,
        }
    }

    /// Every packing of the wrapper with its signal name.
    pub fn packings(&self) -> Vec<(&'static str, &Packing)> {
        let mut v = vec![("s_axis_tdata", &self.s_axis.tdata), ("m_axis_tdata", &self.m_axis.tdata)];
        v.extend(self.m_axis.tuser.as_ref().map(|u| ("m_axis_tuser", u)));
        v
    }

    /// Every packing checked against the rule (see [`Packing::check`]).
    pub fn check(&self) -> Result<(), LayoutError> {
        self.packings().into_iter().try_for_each(|(signal, p)| p.check(&format!("{}.{signal}", self.module)))
    }
}

/// The wrappers of the streaming tops among `modules` (those `generate` wrote), in their order:
/// the segment shader, the front-end and its chain with the shader, the specular unit. The
/// writers' memory ports are block writes, not streams, and get none.
pub fn wrappers(modules: &[Module], names: &crate::Names, spec: &crate::specular::SpecNames) -> Vec<Wrapper> {
    let plan = |m: &Module| -> Option<Plan<'static>> {
        Some(if m.name == names.segment {
            Plan {
                beat_in: "one span",
                beat_out: "one segment",
                tdata: &["out_pix"],
                tuser: &["out_x"],
                tkeep: Some("out_mask"),
                tlast: Some("out_last"),
            }
        } else if m.name == names.frontend {
            Plan {
                beat_in: "one triangle",
                beat_out: "one span",
                tdata: &["out_x", "out_len", "out_i0", "out_di"],
                tuser: &["out_y"],
                tkeep: None,
                tlast: None,
            }
        } else if m.name == names.top {
            Plan {
                beat_in: "one triangle",
                beat_out: "one segment",
                tdata: &["out_pix"],
                tuser: &["out_x", "out_y"],
                tkeep: Some("out_mask"),
                tlast: Some("out_last"),
            }
        } else if m.name == spec.unit {
            Plan {
                beat_in: "one span",
                beat_out: "one pixel",
                tdata: &["out_spec"],
                tuser: &["out_err"],
                tkeep: None,
                tlast: Some("out_last"),
            }
        } else {
            return None;
        })
    };
    modules.iter().filter_map(|m| plan(m).map(|p| Wrapper::new(m, p))).collect()
}

const AXIS: &str = "xilinx.com:interface:axis:1.0";

/// Vivado's interface attribute of AXI4-Stream signal `sig` (TDATA, ...) of bus `bus`.
fn axis_port(port: Port, bus: &str, sig: &str) -> Port {
    port.attr(format!("X_INTERFACE_INFO = \"{AXIS} {bus} {sig}\""))
}

/// The wrapper's Verilog: `core` (the SPEC module `w` wraps) instantiated unchanged.
pub fn module(w: &Wrapper, core: &Module) -> Module {
    let (s, m) = (&w.s_axis, &w.m_axis);
    let port_of = |name: &str| core.ports.iter().find(|p| p.name == name).unwrap_or_else(|| panic!("{} has no port {name}", core.name));
    let buses = "s_axis:m_axis";
    let mut ports = vec![
        Port::input("clk", 1, "", "rising edge")
            .attr("X_INTERFACE_INFO = \"xilinx.com:signal:clock:1.0 clk CLK\"")
            .attr(format!("X_INTERFACE_PARAMETER = \"ASSOCIATED_BUSIF {buses}, ASSOCIATED_RESET rst\"")),
        Port::input("rst", 1, "", "synchronous, active high")
            .attr("X_INTERFACE_INFO = \"xilinx.com:signal:reset:1.0 rst RST\"")
            .attr("X_INTERFACE_PARAMETER = \"POLARITY ACTIVE_HIGH\""),
        axis_port(Port::input("s_axis_tdata", s.tdata.bits, "", &format!("{}: {}", w.beat_in, field_list(&s.tdata))), "s_axis", "TDATA"),
        axis_port(Port::input("s_axis_tvalid", 1, "", "in_valid"), "s_axis", "TVALID"),
        axis_port(Port::output("s_axis_tready", 1, "", "in_ready"), "s_axis", "TREADY"),
        axis_port(Port::output("m_axis_tdata", m.tdata.bits, "", &format!("{}: {}", w.beat_out, field_list(&m.tdata))), "m_axis", "TDATA"),
    ];
    if let Some(k) = &m.tkeep {
        ports.push(axis_port(
            Port::output("m_axis_tkeep", m.tdata.bits / 8, "", &format!("{k}: byte i of TDATA is kept")).vector(),
            "m_axis",
            "TKEEP",
        ));
    }
    if let Some(l) = &m.tlast {
        ports.push(axis_port(Port::output("m_axis_tlast", 1, "", l), "m_axis", "TLAST"));
    }
    if let Some(u) = &m.tuser {
        ports.push(axis_port(Port::output("m_axis_tuser", u.bits, "", &field_list(u)), "m_axis", "TUSER"));
    }
    ports.push(axis_port(Port::output("m_axis_tvalid", 1, "", "out_valid"), "m_axis", "TVALID"));
    ports.push(axis_port(Port::input("m_axis_tready", 1, "", "out_ready"), "m_axis", "TREADY"));
    for name in &w.sideband {
        let mut p = port_of(name).clone();
        p.reg = false;
        ports.push(p);
    }

    let mut header = vec![
        format!("{} — AXI4-Stream wrapper of {} (generate --bus axis).", w.module, w.wraps),
        "Generated by segshade hdl-gen; do not edit.".into(),
        String::new(),
        format!("{} is instantiated unchanged; this module only renames and packs its ports.", w.wraps),
        "Every field starts on a byte boundary and is padded to whole bytes: input padding is ignored,".into(),
        "output padding is the sign of a signed field and zero otherwise (docs/axis.md).".into(),
        String::new(),
    ];
    let table = |header: &mut Vec<String>, title: String, p: &Packing, input: bool| {
        header.push(title);
        for [bits, port, format, pad] in p.rows(input) {
            header.push(format!("  {bits:<9} {port:<10} {format:<22} padding {pad}"));
        }
    };
    table(&mut header, format!("s_axis_tdata ({} bits), {} per beat:", s.tdata.bits, w.beat_in), &s.tdata, true);
    table(&mut header, format!("m_axis_tdata ({} bits), {} per beat:", m.tdata.bits, w.beat_out), &m.tdata, false);
    if let Some(u) = &m.tuser {
        table(&mut header, format!("m_axis_tuser ({} bits):", u.bits), u, false);
    }
    if let Some(k) = &m.tkeep {
        header.push(format!("m_axis_tkeep = {k}: TKEEP[i] high when lane i (TDATA byte i) lies inside the span."));
    }
    if let Some(l) = &m.tlast {
        header.push(format!("m_axis_tlast = {l}: the final beat of a span."));
    }
    header.push("No s_axis_tlast: every input beat is a whole packet. No start-of-frame in TUSER: no stream here".into());
    header.push("marks frames (the host knows where its frames start).".into());
    for sb in &w.sideband {
        header.push(format!("{sb}: passed through unchanged (not part of a beat)."));
    }

    let mut conns = vec![
        ("clk".to_string(), "clk".to_string()),
        ("rst".into(), "rst".into()),
        ("in_valid".into(), "s_axis_tvalid".into()),
        ("in_ready".into(), "s_axis_tready".into()),
    ];
    for f in &s.tdata.fields {
        conns.push((f.port.clone(), format!("s_axis_tdata[{} +: {}]", f.lsb, f.width)));
    }
    conns.push(("out_valid".into(), "m_axis_tvalid".into()));
    conns.push(("out_ready".into(), "m_axis_tready".into()));
    let mut body = Vec::new();
    let outputs: Vec<&Field> = m.tdata.fields.iter().chain(m.tuser.iter().flat_map(|u| &u.fields)).collect();
    for f in &outputs {
        body.push(if port_of(&f.port).vector { crate::verilog::bus(&f.port, f.width) } else { net(&f.port, f.width) });
        conns.push((f.port.clone(), f.port.clone()));
    }
    if let Some(k) = &m.tkeep {
        conns.push((k.clone(), "m_axis_tkeep".into()));
    }
    if let Some(l) = &m.tlast {
        conns.push((l.clone(), "m_axis_tlast".into()));
    }
    for sb in &w.sideband {
        conns.push((sb.clone(), sb.clone()));
    }
    // Keep the core's port order, so the instance reads like its declaration.
    conns.sort_by_key(|(port, _)| core.ports.iter().position(|p| &p.name == port));
    let pads: Vec<String> = s
        .tdata
        .fields
        .iter()
        .filter(|f| f.bits > f.width)
        .map(|f| format!("s_axis_tdata[{} +: {}]", f.lsb + f.width, f.bits - f.width))
        .collect();
    if !pads.is_empty() {
        body.push(comment("The input padding is ignored (Verilator's lint takes names with 'unused' as meant)."));
        body.push(crate::verilog::wire("unused_pad", 1, format!("^{{{}}}", pads.join(", "))));
    }
    body.push(Item::Blank);
    // The core's parameters (the specular unit's ROM images) are the wrapper's, passed down.
    let params = core.params.iter().map(|p| (p.name.clone(), p.name.clone())).collect();
    body.push(Item::Instance { module: w.wraps.clone(), name: "u_core".into(), params, conns });
    body.push(Item::Blank);
    body.push(assign("m_axis_tdata", m.tdata.pack_expr()));
    if let Some(u) = &m.tuser {
        body.push(assign("m_axis_tuser", u.pack_expr()));
    }
    Module { name: w.module.clone(), header, params: core.params.clone(), ports, body }
}

/// `in_x, in_len, ...`: a packing's ports, lowest first.
fn field_list(p: &Packing) -> String {
    p.fields.iter().map(|f| f.port.as_str()).collect::<Vec<_>>().join(", ")
}

/// docs/axis.md's layout tables for `wrappers`, as Markdown: what the document must hold.
pub fn markdown(wrappers: &[Wrapper]) -> String {
    let mut o = String::new();
    for w in wrappers {
        o.push_str(&format!("### `{}` (wraps `{}`)\n\n", w.module, w.wraps));
        o.push_str("| signal | bits | port | format | padding |\n|---|---|---|---|---|\n");
        for (signal, p) in w.packings() {
            for [bits, port, format, pad] in p.rows(signal.starts_with("s_")) {
                o.push_str(&format!("| `{signal}` | `{bits}` | `{port}` | {format} | {pad} |\n"));
            }
        }
        if let Some(k) = &w.m_axis.tkeep {
            o.push_str(&format!("| `m_axis_tkeep` | `{}` | `{k}` | bit per lane | none |\n", bits_range(0, w.m_axis.tdata.bits / 8)));
        }
        if let Some(l) = &w.m_axis.tlast {
            o.push_str(&format!("| `m_axis_tlast` | | `{l}` | | |\n"));
        }
        for sb in &w.sideband {
            o.push_str(&format!("| `{sb}` (sideband) | | `{sb}` | | |\n"));
        }
        o.push('\n');
    }
    o
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ports() -> Vec<Port> {
        vec![Port::input("a", 12, "uint", ""), Port::input("b", 21, "sQ8.12", "").signed(), Port::input("c", 8, "UQ8.0", "")]
    }

    #[test]
    fn fields_sit_on_byte_boundaries() {
        let ps = ports();
        let p = Packing::bytes(&ps.iter().collect::<Vec<_>>());
        let at: Vec<(u32, u32, u32)> = p.fields.iter().map(|f| (f.lsb, f.width, f.bits)).collect();
        assert_eq!(at, [(0, 12, 16), (16, 21, 24), (40, 8, 8)]);
        assert_eq!(p.bits, 48);
        p.check("t").unwrap();
        assert_eq!(p.pack_expr(), "{c, {{3{b[20]}}, b}, {4'd0, a}}");
        assert_eq!(p.rows(false)[0], ["[11:0]".to_string(), "a".into(), "uint".into(), "[15:12]: zero".into()]);
        assert_eq!(p.rows(false)[1][3], "[39:37]: sign");
        assert_eq!(p.rows(true)[1][3], "[39:37]: ignored");
    }

    /// The negative controls of the check a manifest's reader relies on.
    #[test]
    fn a_broken_packing_is_refused() {
        let ps = ports();
        let good = Packing::bytes(&ps.iter().collect::<Vec<_>>());
        let mut overlap = good.clone();
        overlap.fields[1].lsb = 8;
        assert!(matches!(overlap.check("t"), Err(LayoutError::Misplaced { lsb: 8, expected: 16, .. })));
        let mut unpadded = good.clone();
        unpadded.fields[0].bits = 12;
        assert!(matches!(unpadded.check("t"), Err(LayoutError::Padding { want: 16, .. })));
        let mut short = good.clone();
        short.bits = 40;
        assert!(matches!(short.check("t"), Err(LayoutError::Length { end: 48, bits: 40, .. })));
        let mut odd = good;
        odd.bits = 50;
        assert!(matches!(odd.check("t"), Err(LayoutError::NotBytes { bits: 50, .. })));
    }
}
