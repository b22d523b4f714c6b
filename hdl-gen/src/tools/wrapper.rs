//! `hdl-gen synth-wrapper`: a harness that puts a generated module between registers for FPGA
//! area and timing measurements (scripts/synth).
//!
//! Every input of the block is driven by a flip-flop and every output lands in a flip-flop, so
//! the place-and-route Fmax is the block's own register-to-register speed, not a pad delay. The
//! wide buses would not fit the package's pins (an HX8K in ct256 has 206 I/Os, and P = 16
//! already needs more), so the harness talks to the outside through three pins:
//!
//! - the input registers form one shift chain fed from `si` (flip-flops only, no logic);
//! - the output registers are folded by a pipelined XOR tree, four bits per LUT and a register
//!   after every level, into `so`, so no output bit can be optimized away and every wrapper path
//!   is one LUT long.
//!
//! [`Outputs::Folded`] leaves out the output registers: the tree's first level takes the block's
//! outputs. It saves a flip-flop per output bit, which on a full part decides whether the
//! measurement places at all (the p = 64 shader at level 3 on an HX8K: 576 output bits). It can
//! only make a figure worse, never better: an output the block drives from a flip-flop keeps a
//! one-LUT path to the tree's register, and one it drives from logic gets one LUT more.
//!
//! The ports come from the module's entry in `manifest.json`, so any module `generate` lists is
//! covered, whatever it is.

use crate::manifest::{Manifest, ManifestError};
use crate::verilog::{bit, reg, set, Dir, Item, Module, Port, Stmt};

/// One port of the wrapped block, as the manifest lists it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BlockPort {
    pub name: String,
    pub dir: Dir,
    pub width: u32,
}

/// What the harness does with the block's outputs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Outputs {
    /// Every output bit into a flip-flop, then the XOR tree (the default, and every table's harness
    /// unless the table says otherwise).
    #[default]
    Registered,
    /// The XOR tree's first register level takes the block's outputs directly.
    Folded,
}

/// Why no harness is written for a module.
#[derive(Debug, thiserror::Error)]
pub enum WrapperError {
    #[error(transparent)]
    Manifest(#[from] ManifestError),
    #[error("module '{0}' has no one-bit input clk")]
    NoClock(String),
    #[error("module '{0}' needs at least one input besides clk and one output")]
    NoData(String),
    /// A module or port name that is no plain Verilog identifier (it would be pasted into
    /// the harness's text).
    #[error("'{0}' is not a Verilog identifier")]
    Name(String),
    #[error("module '{0}' is named twice")]
    DuplicateModule(String),
    #[error("no module to wrap")]
    NoModule,
    #[error("module '{block}' lists port '{port}' twice")]
    DuplicatePort { block: String, port: String },
    /// A port, or all inputs or outputs together (the harness's shift chain and output
    /// register are one vector each), outside 1..=[`MAX_VECTOR_BITS`].
    #[error("module '{block}': {what} is {width} bits, outside 1..={MAX_VECTOR_BITS} (the vector length every Verilog tool must support)")]
    Width { block: String, what: String, width: u64 },
}

/// IEEE 1364-2005 §4.3.1: a tool may limit a vector's length, but to no fewer than 2^16 bits.
/// The widest port `generate` writes (the p = 256 shader's 2,048 pixel bits) is far below; a
/// manifest asking for more is not one `generate` wrote.
pub const MAX_VECTOR_BITS: u64 = 1 << 16;

/// Every name an identifier, no port twice, every width and the inputs' and outputs' totals
/// within [`MAX_VECTOR_BITS`]: checked before anything is built from a manifest's values.
fn check_ports(block: &str, ports: &[BlockPort]) -> Result<(), WrapperError> {
    let ident = |s: &str| !s.is_empty() && crate::check_prefix(s).is_ok();
    if !ident(block) {
        return Err(WrapperError::Name(block.into()));
    }
    let width_err = |what: String, width: u64| WrapperError::Width { block: block.into(), what, width };
    for (k, p) in ports.iter().enumerate() {
        if !ident(&p.name) {
            return Err(WrapperError::Name(p.name.clone()));
        }
        if ports[..k].iter().any(|q| q.name == p.name) {
            return Err(WrapperError::DuplicatePort { block: block.into(), port: p.name.clone() });
        }
        if p.width == 0 || p.width as u64 > MAX_VECTOR_BITS {
            return Err(width_err(format!("port '{}'", p.name), p.width as u64));
        }
    }
    for (dir, what) in [(Dir::Input, "the inputs together"), (Dir::Output, "the outputs together")] {
        let total: u64 = ports.iter().filter(|p| p.dir == dir && p.name != "clk").map(|p| p.width as u64).sum();
        if total > MAX_VECTOR_BITS {
            return Err(width_err(what.into(), total));
        }
    }
    Ok(())
}

/// The ports of `module` in a `manifest.json` text.
/// The ports of `module` in a `manifest.json` text, checked as [`module`] checks them.
pub fn ports_from_manifest(manifest: &str, module: &str) -> Result<Vec<BlockPort>, WrapperError> {
    let m = Manifest::parse(manifest)?;
    let entry = m.module(module)?;
    let ports: Vec<BlockPort> = entry.ports.iter().map(|p| BlockPort { name: p.name.clone(), dir: p.direction, width: p.width }).collect();
    check_ports(module, &ports)?;
    Ok(ports)
}

/// The harness module `<block>_synth` around `block`, which must have an input `clk`.
pub fn module(block: &str, ports: &[BlockPort], outputs: Outputs) -> Result<Module, WrapperError> {
    modules(&[(block.to_string(), ports.to_vec())], outputs)
}

/// One harness around several blocks side by side (`synth-wrapper --module A --module B`): one
/// design to place, as a device must hold them together (issue 27: the chain and the specular
/// unit on one LFE5U-25F). Their inputs share the shift chain and their outputs the XOR tree;
/// the harness is `<A>_<B>_synth`. One block is [`module`]'s harness, byte for byte.
pub fn modules(blocks: &[(String, Vec<BlockPort>)], outputs: Outputs) -> Result<Module, WrapperError> {
    for (k, (block, ports)) in blocks.iter().enumerate() {
        check_ports(block, ports)?;
        if blocks[..k].iter().any(|(b, _)| b == block) {
            return Err(WrapperError::DuplicateModule(block.clone()));
        }
        if !ports.iter().any(|p| p.name == "clk" && p.dir == Dir::Input && p.width == 1) {
            return Err(WrapperError::NoClock(block.clone()));
        }
    }
    let Some((first, _)) = blocks.first() else { return Err(WrapperError::NoModule) };
    let several = blocks.len() > 1;
    // Per block: its data inputs and outputs, and the names its wires take in the harness.
    let ins = |ports: &[BlockPort]| ports.iter().filter(|p| p.dir == Dir::Input && p.name != "clk").cloned().collect::<Vec<_>>();
    let outs = |ports: &[BlockPort]| ports.iter().filter(|p| p.dir == Dir::Output).cloned().collect::<Vec<_>>();
    let n_in: u32 = blocks.iter().map(|(_, p)| ins(p).iter().map(|p| p.width).sum::<u32>()).sum();
    let n_out: u32 = blocks.iter().map(|(_, p)| outs(p).iter().map(|p| p.width).sum::<u32>()).sum();
    for (block, ports) in blocks {
        if ins(ports).is_empty() || outs(ports).is_empty() {
            return Err(WrapperError::NoData(block.clone()));
        }
    }
    if n_in as u64 > MAX_VECTOR_BITS || n_out as u64 > MAX_VECTOR_BITS {
        let (what, width) = if n_in as u64 > MAX_VECTOR_BITS { ("the inputs together", n_in) } else { ("the outputs together", n_out) };
        return Err(WrapperError::Width { block: first.clone(), what: what.into(), width: width as u64 });
    }

    let mut body = vec![Item::Comment("Input registers: one shift chain from si.".into()), reg("in_q", n_in)];
    let shift_in = if n_in == 1 { "si".to_string() } else { format!("{{in_q[{}:0], si}}", n_in - 2) };
    body.push(Item::Always(vec![set("in_q", shift_in)]));
    body.push(Item::Blank);

    let mut off = 0;
    let mut outs_concat = Vec::new();
    for (block, ports) in blocks {
        let mut conns = vec![("clk".to_string(), "clk".to_string())];
        for p in ins(ports) {
            let sel = if n_in == 1 {
                "in_q".to_string()
            } else if p.width == 1 {
                format!("in_q[{off}]")
            } else {
                format!("in_q[{off} +: {}]", p.width)
            };
            conns.push((p.name.clone(), sel));
            off += p.width;
        }
        let prefix = if several { format!("o_{block}_") } else { "o_".to_string() };
        for p in outs(ports) {
            let wire = format!("{prefix}{}", p.name);
            body.push(Item::Wire { name: wire.clone(), width: p.width, signed: false, value: None });
            conns.push((p.name.clone(), wire.clone()));
            outs_concat.push(wire);
        }
        let name = if several { format!("u_{block}") } else { "u_block".into() };
        body.push(Item::Instance { module: block.clone(), name, params: vec![], conns });
    }
    body.push(Item::Blank);

    let all = if outs_concat.len() == 1 { outs_concat[0].clone() } else { format!("{{{}}}", outs_concat.join(", ")) };
    // What the XOR tree folds, how the header names the outputs, and the clocks before the tree.
    let (first, kept, out_clocks) = match outputs {
        Outputs::Registered => {
            body.push(Item::Comment("Output registers.".into()));
            body.push(reg("out_q", n_out));
            body.push(Item::Always(vec![set("out_q", all)]));
            body.push(Item::Blank);
            body.push(Item::Comment("Pipelined XOR fold of the output registers into so, four bits per level and LUT.".into()));
            ("out_q", "registered", 1)
        }
        Outputs::Folded => {
            body.push(Item::Comment("The block's outputs, folded without registers of their own.".into()));
            body.push(Item::Wire { name: "out_w".into(), width: n_out, signed: false, value: Some(all) });
            body.push(Item::Blank);
            body.push(Item::Comment("Pipelined XOR fold of the outputs into so, four bits per level and LUT.".into()));
            ("out_w", "not registered", 0)
        }
    };
    let (mut name, mut width) = (first.to_string(), n_out);
    let mut level = 0;
    while width > 1 {
        level += 1;
        let next = width.div_ceil(4);
        let next_name = format!("fold{level}");
        body.push(reg(&next_name, next));
        let mut stmts = Vec::new();
        for b in 0..next {
            let lo = 4 * b;
            let n = (width - lo).min(4);
            let rhs = if n == 1 { bit(&name, width, lo) } else { format!("^{name}[{lo} +: {n}]") };
            stmts.push(Stmt::Set(bit(&next_name, next, b), rhs));
        }
        body.push(Item::Always(stmts));
        (name, width) = (next_name, next);
    }
    body.push(Item::Assign("so".into(), name));

    let names: Vec<&str> = blocks.iter().map(|(b, _)| b.as_str()).collect();
    let harness = format!("{}_synth", names.join("_"));
    Ok(Module {
        header: vec![
            format!("{harness} — synthesis harness: {} between registers, for area and timing reports.", names.join(" and ")),
            "Generated by segshade hdl-gen synth-wrapper; do not edit.".into(),
            String::new(),
            format!("{n_in} input bits arrive through a shift chain from si; {n_out} output bits are {kept} and"),
            "folded by a pipelined XOR tree into so. Every path outside the block is at most one LUT long.".into(),
            format!("Clocks from si to the block input MSB: {n_in}; from the block's outputs to so: {}.", level + out_clocks),
        ],
        params: vec![],
        ports: vec![
            Port::input("clk", 1, "", "rising edge"),
            Port::input("si", 1, "", "serial input into the input registers"),
            Port::output("so", 1, "", "XOR of every output register, pipelined"),
        ],
        name: harness,
        body,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn port(name: &str, dir: Dir, width: u32) -> BlockPort {
        BlockPort { name: name.into(), dir, width }
    }

    #[test]
    fn wraps_every_port() {
        let ports = [
            port("clk", Dir::Input, 1),
            port("rst", Dir::Input, 1),
            port("a", Dir::Input, 5),
            port("y", Dir::Output, 9),
            port("z", Dir::Output, 1),
        ];
        let text = module("blk", &ports, Outputs::Registered).unwrap().render();
        assert!(text.contains("module blk_synth ("), "{text}");
        assert!(text.contains(".rst(in_q[0])") && text.contains(".a(in_q[1 +: 5])"), "{text}");
        assert!(text.contains("out_q <= {o_y, o_z};"), "{text}");
        // 10 output bits: 3, then 1.
        assert!(text.contains("fold1[2] <= ^out_q[8 +: 2];") && text.contains("fold2 <= ^fold1[0 +: 3];"), "{text}");
    }

    #[test]
    fn folded_outputs_have_no_register_of_their_own() {
        let ports = [port("clk", Dir::Input, 1), port("a", Dir::Input, 5), port("y", Dir::Output, 9), port("z", Dir::Output, 1)];
        let text = module("blk", &ports, Outputs::Folded).unwrap().render();
        assert!(!text.contains("out_q"), "{text}");
        assert!(text.contains("fold1[2] <= ^out_w[8 +: 2];") && text.contains("fold2 <= ^fold1[0 +: 3];"), "{text}");
        assert!(text.contains("from the block's outputs to so: 2."), "{text}");
    }

    #[test]
    fn needs_a_clock() {
        let e = module("blk", &[port("a", Dir::Input, 2), port("y", Dir::Output, 2)], Outputs::Registered).unwrap_err();
        assert!(matches!(&e, WrapperError::NoClock(b) if b == "blk"), "{e}");
        let e = module("blk", &[port("clk", Dir::Input, 1), port("y", Dir::Output, 2)], Outputs::Folded).unwrap_err();
        assert!(matches!(&e, WrapperError::NoData(b) if b == "blk"), "{e}");
    }

    /// Two blocks in one harness: one shift chain and one fold for both, each its own instance;
    /// a module named twice is refused.
    #[test]
    fn wraps_several_blocks_side_by_side() {
        let a = vec![port("clk", Dir::Input, 1), port("x", Dir::Input, 3), port("y", Dir::Output, 2)];
        let b = vec![port("clk", Dir::Input, 1), port("x", Dir::Input, 2), port("y", Dir::Output, 5)];
        let text = modules(&[("ba".into(), a.clone()), ("bb".into(), b)], Outputs::Registered).unwrap().render();
        assert!(text.contains("module ba_bb_synth ("), "{text}");
        assert!(text.contains("ba u_ba (") && text.contains("bb u_bb ("), "{text}");
        assert!(text.contains(".x(in_q[0 +: 3])") && text.contains(".x(in_q[3 +: 2])"), "{text}");
        assert!(text.contains("out_q <= {o_ba_y, o_bb_y};"), "{text}");
        // One block through `modules` is `module`'s harness.
        let one = modules(&[("ba".into(), a.clone())], Outputs::Folded).unwrap().render();
        assert_eq!(one, module("ba", &a, Outputs::Folded).unwrap().render());
        let e = modules(&[("ba".into(), a.clone()), ("ba".into(), a)], Outputs::Registered).unwrap_err();
        assert!(matches!(&e, WrapperError::DuplicateModule(b) if b == "ba"), "{e}");
        assert!(matches!(modules(&[], Outputs::Registered).unwrap_err(), WrapperError::NoModule));
    }

    /// Values no generated manifest holds are refused before any text is built.
    #[test]
    fn refuses_names_and_widths_out_of_bounds() {
        let ok = [port("clk", Dir::Input, 1), port("a", Dir::Input, 5), port("y", Dir::Output, 9)];
        assert!(module("blk", &ok, Outputs::Registered).is_ok());
        let with = |extra: BlockPort| [ok[0].clone(), ok[1].clone(), ok[2].clone(), extra];
        let max = MAX_VECTOR_BITS as u32;
        for (ports, want) in [
            (with(port("z", Dir::Output, 99_999_999)), "port 'z' is 99999999 bits"),
            (with(port("z", Dir::Output, 0)), "port 'z' is 0 bits"),
            (with(port("z", Dir::Output, max)), "the outputs together is 65545 bits"),
            (with(port("b", Dir::Input, max)), "the inputs together is 65541 bits"),
            (with(port("a", Dir::Output, 1)), "port 'a' twice"),
            (with(port("y; end", Dir::Output, 1)), "'y; end' is not a Verilog identifier"),
        ] {
            let e = module("blk", &ports, Outputs::Registered).unwrap_err().to_string();
            assert!(e.contains(want), "{e}");
        }
        assert!(module("blk", &with(port("z", Dir::Output, max - 9)), Outputs::Folded).is_ok());
        let e = module("1blk", &ok, Outputs::Registered).unwrap_err().to_string();
        assert!(e.contains("'1blk' is not"), "{e}");
    }
}
