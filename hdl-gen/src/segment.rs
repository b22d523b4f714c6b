//! `segment_shader_p<P>`: P Gouraud pixels per clock from a span `(x0, m, I0, dI)`.
//!
//! Two register stages. The *current* stage holds the span being cut: its increment, the
//! accumulator (lane 0's intensity plus the rounding half), the segment's x, the pixels left
//! and, in screen mode, the masked leading lanes. Each clock the BFPI forms 1..P multiples of
//! the increment; lanes add them to the accumulator, round, clamp and land in the *output*
//! registers, while the accumulator steps by P*dI (BFPI lane P-1) to the next segment. The next
//! span loads in the same clock the last segment of the current one leaves, so spans follow
//! each other with no bubble.
//!
//! With `--bfpi-arch tree` (a comparison form) there is no BFPI: lane `j + 2^k` is lane `j` plus
//! `dI << k`, a doubling tree of P - 1 accumulator-wide adders, and the step is `dI << log2 P`.

use crate::bfpi::BfpiArch;
mod properties;

use crate::verilog::{assign, bit, comment, gather, lit, net, reg, set, sext, sreg, swire, wire, zext, Item, Module, Port, Stmt};
use crate::Names;
use golden::pipeline::Pipeline;
use golden::segment::{latency, rem_bits};
use golden::{Align, Config};

/// Why `--pipeline` above 0 refuses the tree: its lanes chain behind the accumulator, so there
/// are no increments to register when a span starts.
pub const TREE_UNPIPELINED: &str = "--pipeline above 0 needs increments formed from dI alone (--bfpi-arch shift-add or naive): \
     the tree's lanes chain behind the accumulator";

pub fn ports(cfg: &Config) -> Vec<Port> {
    let (p, xw, f) = (cfg.p, cfg.xbits, cfg.frac);
    vec![
        Port::input("clk", 1, "", "rising edge"),
        Port::input("rst", 1, "", "synchronous, active high; drops work in progress"),
        Port::input("in_valid", 1, "", "span valid"),
        Port::output("in_ready", 1, "", "span accepted when in_valid && in_ready"),
        Port::input("in_x", xw, "unsigned integer", "x0, first pixel of the span"),
        Port::input("in_len", xw + 1, "unsigned integer", "m, pixels in the span (0: no output)"),
        Port::input("in_i0", cfg.iw(), &format!("UQ8.{f}"), "intensity of the first pixel"),
        Port::input("in_di", cfg.dw(), &format!("signed Q8.{f}"), "intensity increment per pixel").signed(),
        Port::output("out_valid", 1, "", "segment valid").reg(),
        Port::input("out_ready", 1, "", "segment taken when out_valid && out_ready"),
        Port::output("out_x", xw, "unsigned integer", "screen x of lane 0").reg(),
        Port::output("out_pix", 8 * p, &format!("{p} lanes of UQ8.0"), "lane i = pixel at out_x + i").reg(),
        Port::output("out_mask", p, "bit per lane", "lane i lies inside the span").reg().vector(),
        Port::output("out_last", 1, "", "final segment of the span").reg(),
    ]
}

/// The shader, its increments formed by `arch` (SPEC §3's BFPI by default), with the register
/// stages of `pipe` (`golden::segment::stages`). Level 0 is SPEC's seed structure.
///
/// Panics on the tree at a level above 0 ([`TREE_UNPIPELINED`]; the CLI refuses it first).
pub fn module_with(cfg: &Config, names: &Names, arch: BfpiArch, pipe: Pipeline) -> Module {
    assert!(!(pipe.span_stage() && arch == BfpiArch::Tree), "{TREE_UNPIPELINED}");
    let seg = Seg::new(cfg, names, arch, pipe);
    let mut body = Vec::new();
    seg.registers(&mut body);
    seg.start(&mut body);
    seg.increments(&mut body);
    seg.lanes(&mut body);
    seg.control(&mut body);
    seg.output(&mut body);
    if pipe.span_stage() {
        body.push(properties::segment_pipelined_properties(cfg, seg.rw, pipe));
    } else {
        body.push(properties::segment_properties(cfg, seg.rw));
    }
    Module { name: names.segment.clone(), header: seg.header(), params: vec![], ports: ports(cfg), body }
}

/// One shader's configuration and the widths and choices every section of it reads.
#[derive(Clone)]
struct Seg<'a> {
    cfg: &'a Config,
    names: &'a Names,
    arch: BfpiArch,
    pipe: Pipeline,
    p: u32,
    xw: u32,
    f: u32,
    log2p: u32,
    iw: u32,
    dw: u32,
    mw: u32,
    aw: u32,
    rw: u32,
    /// Screen alignment with more than one lane: segments start on multiples of P.
    screen: bool,
    /// The accumulator after the rounding shift.
    qw: u32,
    lat: u32,
    /// `--pipeline 3`: the multiples the BFPI's first level makes, registered with the span.
    split: bool,
    first: Vec<u32>,
    /// A sum stage between the lanes and the output register.
    sum: bool,
}

impl<'a> Seg<'a> {
    fn new(cfg: &'a Config, names: &'a Names, arch: BfpiArch, pipe: Pipeline) -> Seg<'a> {
        let (p, f) = (cfg.p, cfg.frac);
        Seg {
            cfg,
            names,
            arch,
            pipe,
            p,
            xw: cfg.xbits,
            f,
            log2p: cfg.log2p(),
            iw: cfg.iw(),
            dw: cfg.dw(),
            mw: cfg.mw(),
            aw: cfg.aw(),
            rw: rem_bits(cfg),
            screen: cfg.align == Align::Screen && p > 1,
            qw: cfg.aw() - f,
            lat: latency(cfg, pipe),
            split: pipe.split_adds(),
            first: golden::segment::first_level(p),
            sum: pipe.sum_stage(),
        }
    }

    /// Where the span's fields come from when the current stage starts it: the input ports, or
    /// the span register in front of it.
    fn src(&self, port: &str) -> String {
        if self.pipe.span_stage() {
            port.replacen("in_", "sp_", 1)
        } else {
            port.to_string()
        }
    }

    /// The header: configuration, formats, pixel rule, latency, increments and stages.
    fn header(&self) -> Vec<String> {
        let Seg { cfg, names, arch, pipe, p, xw, f, iw, dw, aw, lat, .. } = *self;

        let mut header = vec![
            format!("{} — segment Gouraud shader, {p} pixel(s) per clock.", names.segment),
            "Generated by segshade hdl-gen; do not edit.".into(),
            String::new(),
            format!("Configuration: P = {p}, F = {f}, XW = {xw}, align = {}.", cfg.align),
            format!("Formats: I0 UQ8.{f} ({iw} bits), dI signed Q8.{f} ({dw} bits), pixels UQ8.0."),
            format!("Accumulator: signed {aw} bits (XW + DW), holds I0 + j*dI for every j < 2^XW without wrap."),
            format!("Pixel rule: out = clamp((I0 + j*dI + 2^{}) >>> {f}, 0, 255).", f - 1),
            match cfg.align {
                Align::Span => "Segments start at the span's first pixel: segment s is out_x = x0 + s*P.".into(),
                Align::Screen => "Segments start on multiples of P (whole memory blocks); lanes outside the span are masked.".into(),
            },
            format!("Latency: first segment valid {lat} clocks after the span's transfer; one segment per clock after that,"),
            "across span boundaries too, while out_ready is high.".into(),
            match arch {
                BfpiArch::ShiftAdd => format!("Increments: {} (shift-and-add, no multipliers).", names.bfpi),
                BfpiArch::Naive => format!("Increments: {} (naive comparison form: `*` by constants).", names.bfpi),
                BfpiArch::Tree => "Increments: doubling tree, lane j + 2^k = lane j + (dI << k) (comparison form, no BFPI).".into(),
            },
        ];
        if pipe.span_stage() {
            header.push(format!("Pipeline level {pipe} (--pipeline): every stage moves when the output register is free."));
            for st in golden::segment::stages(cfg, pipe) {
                header.push(format!("  stage {} {}: {}", st.stage, st.name, st.logic));
            }
        }
        header
    }

    /// The span register (levels 1 and up), the current span, the sum stage; the handshake.
    fn registers(&self, body: &mut Vec<Item>) {
        let Seg { pipe, p, xw, log2p, iw, dw, mw, aw, rw, screen, qw, split, ref first, .. } = *self;

        if pipe.span_stage() {
            body.extend([
                comment("Span register: the accepted span waits here while the BFPI forms its increments."),
                reg("sp_valid", 1),
                reg("sp_x", xw),
                reg("sp_len", xw + 1),
                reg("sp_i0", iw),
                sreg("sp_di", dw),
            ]);
            if screen {
                body.push(sreg("sp_lead_di", aw));
            }
            if split {
                body.push(comment("The BFPI's first adder level, formed from the input's dI as the span enters."));
                body.extend(first.iter().map(|c| sreg(&format!("sp_m{c}"), mw)));
            }
            body.push(Item::Blank);
        }
        body.push(comment("Current span: accumulator = lane 0's intensity + 2^(F-1), so each lane rounds with one add."));
        body.push(reg("cur_valid", 1));
        if pipe.span_stage() {
            body.push(comment("The increments 1..P times dI, formed while the span waited; the last flag, ahead."));
            body.push(reg("cur_inc", p * mw));
            body.push(reg("cur_last", 1));
        } else {
            body.push(sreg("cur_di", dw));
        }
        body.extend([sreg("cur_acc", aw), reg("cur_x", xw), reg("cur_rem", rw)]);
        if screen {
            body.push(reg("cur_lead", log2p));
        }
        if split {
            body.extend([
                Item::Blank,
                comment("Sum stage: each lane's sum cut at the binary point, joined before the clamp."),
                reg("s1_valid", 1),
                reg("s1_x", xw),
                reg("s1_hc", p * (qw + 1)),
                reg("s1_mask", p),
                reg("s1_last", 1),
            ]);
        } else if pipe.sum_stage() {
            body.extend([
                Item::Blank,
                comment("Sum stage: the lanes' integer parts, before round and clamp."),
                reg("s1_valid", 1),
                reg("s1_x", xw),
                reg("s1_q", p * qw),
                reg("s1_mask", p),
                reg("s1_last", 1),
            ]);
        }
        body.push(Item::Blank);
        if !pipe.span_stage() {
            body.push(wire("cur_last", 1, format!("cur_rem <= {}", lit(rw, p as u64))));
        }
        body.extend([wire("out_free", 1, "!out_valid || out_ready"), wire("fire", 1, "cur_valid && out_free")]);
        if pipe.span_stage() {
            body.extend([
                wire("take", 1, "!cur_valid || (fire && cur_last)"),
                assign("in_ready", "!sp_valid || take"),
                wire("load", 1, "in_valid && in_ready"),
                wire("start", 1, "sp_valid && take"),
            ]);
            if split {
                // Level 3: the current stage's enable is one LUT from out_ready, and its data select
                // comes from registers only: at its last segment it loads the span register whether
                // or not a span waits (cur_valid takes sp_valid), so out_ready reaches the stage
                // through its enable alone (the iCE40's critical path at p = 8). Registers behind a
                // clear valid bit hold don't-cares. Loading the span register on in_ready alone, the
                // same idea one stage earlier, measured no faster (docs/fpga.md).
                body.push(wire("cur_en", 1, "cur_valid ? out_free : sp_valid"));
            }
        } else {
            body.extend([assign("in_ready", "!cur_valid || (fire && cur_last)"), wire("load", 1, "in_valid && in_ready")]);
        }
        body.push(Item::Blank);
    }

    /// The first accumulator value. Screen mode starts `lead` pixels before x0, so it needs
    /// I0 - lead*dI: lead has log2 P bits, so that is log2 P shifted, gated copies of dI.
    fn start(&self, body: &mut Vec<Item>) {
        let Seg { f, log2p, iw, dw, aw, screen, .. } = *self;
        let src = |port: &str| self.src(port);
        let half = lit(aw, 1 << (f - 1));
        let i0 = zext(&src("in_i0"), iw, aw);
        let start = if screen {
            body.push(wire(&src("in_lead"), log2p, format!("{}[{}:0]", src("in_x"), log2p - 1)));
            // Behind the span register, lead * dI is formed from the input as the span enters and
            // registered with it (`sp_lead_di`), so the start is one add from registers: the
            // tree, the add and the select into `cur_acc` in one clock were the 25F chain's
            // worst path on seed 1 of stop 34 (`sp_i0 -> cur_acc`, 10.1 ns, docs/fpga.md).
            let staged = self.pipe.span_stage();
            let from = "in";
            if staged {
                body.push(wire("in_lead", log2p, format!("in_x[{}:0]", log2p - 1)));
            }
            body.push(swire(&format!("{from}_di_ext"), aw, sext(&format!("{from}_di"), dw, aw)));
            let terms: Vec<String> = (0..log2p)
                .map(|b| {
                    let ext = format!("{from}_di_ext");
                    let shifted = if b == 0 { ext } else { format!("({ext} << {b})") };
                    format!("({} ? {shifted} : {})", bit(&format!("{from}_lead"), log2p, b), lit(aw, 0))
                })
                .collect();
            // A balanced tree: log2(log2 P) adders deep, not log2 P - 1 in a row (the start
            // value into `cur_acc` was the level-2 shader's one path over 10 ns beside the
            // chain on the 25F, docs/fpga.md).
            let (tree, lead_di) = if staged { ("in_lead_di", "sp_lead_di") } else { ("lead_di", "lead_di") };
            body.push(swire(tree, aw, crate::specular::tree(&terms)));
            format!("{i0} + {half} - {lead_di}")
        } else {
            format!("{i0} + {half}")
        };
        body.push(swire("start_acc", aw, start));
        body.push(Item::Blank);
    }

    /// The multiples 1..P of dI: the BFPI (instanced, or its graph inline at level 3), or the
    /// comparison forms; and the step of P pixels.
    fn increments(&self, body: &mut Vec<Item>) {
        let Seg { names, arch, pipe, p, log2p, dw, mw, aw, split, ref first, .. } = *self;

        if arch == BfpiArch::Tree {
            body.push(comment("Doubling tree: lane j + 2^k = lane j + (dI << k)."));
            body.push(swire("cur_di_ext", aw, sext("cur_di", dw, aw)));
            body.push(swire("tv0", aw, "cur_acc"));
            for i in 1..p {
                let k = 31 - i.leading_zeros();
                let j = i - (1 << k);
                let term = if k == 0 { "cur_di_ext".to_string() } else { format!("(cur_di_ext << {k})") };
                body.push(swire(&format!("tv{i}"), aw, format!("tv{j} + {term}")));
            }
            body.push(reg("tree", p * aw));
            body.push(gather("tree", (0..p).map(|i| format!("tv{i}")).collect()));
            let step = if log2p == 0 { "cur_di_ext".to_string() } else { format!("cur_di_ext << {log2p}") };
            body.push(swire("step", aw, step));
        } else {
            if split {
                // The BFPI's graph inline, cut after its first level: the span register holds those
                // values, so the clock that starts a span has at most the deeper levels (one adder
                // for P = 16..128, two at 256) where the instance had the whole graph.
                let plan = golden::bfpi::BfpiPlan::new(p);
                let node = |v: u32| if v == 1 || first.contains(&v) { format!("sp_m{v}") } else { format!("m{v}") };
                body.push(comment("Multiples 1..P of the waiting span's increment (the BFPI's graph, its first level"));
                body.push(comment("registered with the span), registered when it starts."));
                body.push(swire("sp_m1", mw, sext("sp_di", dw, mw)));
                for a in plan.adders.iter().filter(|a| a.depth > 1) {
                    body.push(swire(&node(a.value), mw, a.describe(node)));
                }
                body.push(reg("sp_inc", p * mw));
                body.push(gather("sp_inc", crate::bfpi::lanes(p, node)));
                body.push(net("inc", p * mw));
                body.push(assign("inc", "cur_inc"));
            } else if pipe.span_stage() {
                body.push(comment("Multiples 1..P of the waiting span's increment, registered when it starts."));
                body.push(net("sp_inc", p * mw));
                body.push(Item::Instance {
                    module: names.bfpi.clone(),
                    name: "u_bfpi".into(),
                    params: vec![],
                    conns: vec![("di".into(), "sp_di".into()), ("inc".into(), "sp_inc".into())],
                });
                body.push(net("inc", p * mw));
                body.push(assign("inc", "cur_inc"));
            } else {
                body.push(comment("Multiples 1..P of the current increment."));
                body.push(net("inc", p * mw));
                body.push(Item::Instance {
                    module: names.bfpi.clone(),
                    name: "u_bfpi".into(),
                    params: vec![],
                    conns: vec![("di".into(), "cur_di".into()), ("inc".into(), "inc".into())],
                });
            }
            body.push(swire("inc_p", mw, format!("inc[{} +: {mw}]", (p - 1) * mw)));
            body.push(swire("step", aw, sext("inc_p", mw, aw)));
        }
        body.push(Item::Blank);
    }

    /// The P lanes, a `generate` loop, and the buses they are gathered into.
    fn lanes(&self, body: &mut Vec<Item>) {
        let Seg { arch, p, f, mw, aw, rw, screen, qw, split, sum, .. } = *self;

        // Each lane's results are nets of its own (`lane[i].pixel`, ...), gathered into the buses
        // below by one process each (`verilog::gather`), so that a clock costs Icarus O(P).
        if split {
            body.push(comment("Lanes: add in two parts, the fraction's carry and the high part (the half is in the"));
            body.push(comment("accumulator); join, clamp and mask a stage later."));
            body.push(reg("hcs", p * (qw + 1)));
        } else if sum {
            body.push(comment("Lanes: add (the half is in the accumulator) and mask; round and clamp a stage later."));
            body.push(reg("qs", p * qw));
        } else {
            body.push(comment("Lanes: add, round (the half is in the accumulator), clamp to 0..255, mask."));
        }
        body.push(reg("pix", 8 * p));
        body.push(reg("mask", p));
        if screen {
            body.push(wire("lead_mask", p, format!("{{{p}{{1'b1}}}} << cur_lead")));
        }
        let clamp = |q: &str| format!("{q}[{}] ? 8'd0 : (|{q}[{}:8]) ? 8'd255 : {q}[7:0]", qw - 1, qw - 2);
        let mut lane = vec![Item::Localparam { name: "LANE".into(), width: rw, value: "i".into() }];
        if split {
            lane.extend([
                Item::Wire { name: "hi".into(), width: qw, signed: true, value: None },
                net("c", 1),
                Item::IfGenerate {
                    cond: "i == 0".into(),
                    then: ("base".into(), vec![assign("hi", format!("cur_acc[{}:{f}]", aw - 1)), assign("c", "1'b0")]),
                    els: (
                        "offset".into(),
                        vec![
                            swire("d", mw, format!("inc[(i-1)*{mw} +: {mw}]")),
                            comment("verilator lint_off UNUSEDSIGNAL"),
                            swire("de", aw, sext("d", mw, aw)),
                            wire("lo", f + 1, format!("{{1'b0, cur_acc[{fm}:0]}} + {{1'b0, de[{fm}:0]}}", fm = f - 1)),
                            comment("verilator lint_on UNUSEDSIGNAL"),
                            assign("hi", format!("cur_acc[{a}:{f}] + de[{a}:{f}]", a = aw - 1)),
                            assign("c", format!("lo[{f}]")),
                        ],
                    ),
                },
                comment("Lane i's high part and carry, {hi, c}, go to hcs[i*(QW+1) +: QW+1]."),
                // clamp(h + c) without the qw-bit carry chain of the sum: h <= h + c <= h + 1, so the
                // clamp is decided by h alone (h < 0 gives 0, h >= 255 gives 255, whatever c is),
                // and in between the pixel is the 8-bit increment h[7:0] + c.
                swire("h", qw, format!("s1_hc[i*{h}+1 +: {qw}]", h = qw + 1)),
                wire("hc", 1, format!("s1_hc[i*{}]", qw + 1)),
                wire("low", 8, format!("h[7:0] + {}", zext("hc", 1, 8))),
                wire("neg", 1, format!("h[{}]", qw - 1)),
                wire("over", 1, format!("!h[{}] && ((|h[{}:8]) || (&h[7:0]))", qw - 1, qw - 2)),
                wire("pixel", 8, "neg ? 8'd0 : over ? 8'd255 : low"),
            ]);
        } else {
            lane.extend([
                comment("The fraction bits of v only carry into the sum; the pixel is its integer part."),
                comment("verilator lint_off UNUSEDSIGNAL"),
                Item::Wire { name: "v".into(), width: aw, signed: true, value: None },
                if arch == BfpiArch::Tree {
                    assign("v", format!("tree[i*{aw} +: {aw}]"))
                } else {
                    Item::IfGenerate {
                        cond: "i == 0".into(),
                        then: ("base".into(), vec![assign("v", "cur_acc")]),
                        els: (
                            "offset".into(),
                            vec![
                                swire("d", mw, format!("inc[(i-1)*{mw} +: {mw}]")),
                                assign("v", format!("cur_acc + {}", sext("d", mw, aw))),
                            ],
                        ),
                    }
                },
                swire("q", qw, format!("v[{}:{f}]", aw - 1)),
                comment("verilator lint_on UNUSEDSIGNAL"),
            ]);
            if sum {
                lane.push(comment("q goes to qs[i*QW +: QW]; the sum stage gives it back as r."));
                lane.push(swire("r", qw, format!("s1_q[i*{qw} +: {qw}]")));
                lane.push(wire("pixel", 8, clamp("r")));
            } else {
                lane.push(wire("pixel", 8, clamp("q")));
            }
        }
        if screen {
            lane.push(wire("in_span", 1, "(LANE < cur_rem) && lead_mask[i]"));
        } else {
            lane.push(wire("in_span", 1, "LANE < cur_rem"));
        }
        body.push(Item::ForGenerate { var: "i".into(), count: p, label: "lane".into(), body: lane });
        let lanes = |of: &dyn Fn(u32) -> String| (0..p).map(of).collect::<Vec<_>>();
        let (stage_bus, stage_lane) = if split { ("hcs", "{hi, c}") } else { ("qs", "q") };
        body.push(comment(if sum {
            format!("Lane i's {stage_lane}, pixel and in_span, on the buses {stage_bus}, pix and mask; one process per bus, so each changes once a clock.")
        } else {
            "Lane i's pixel and in_span, on the buses pix and mask; one process per bus, so each changes once a clock.".into()
        }));
        if split {
            body.push(gather("hcs", lanes(&|k| format!("{{lane[{k}].hi, lane[{k}].c}}"))));
        } else if sum {
            body.push(gather("qs", lanes(&|k| format!("lane[{k}].q"))));
        }
        body.push(gather("pix", lanes(&|k| format!("lane[{k}].pixel"))));
        body.push(gather("mask", lanes(&|k| format!("lane[{k}].in_span"))));
        body.push(Item::Blank);
    }

    /// The current stage's load and advance, and the span register's.
    fn control(&self, body: &mut Vec<Item>) {
        let Seg { pipe, p, xw, log2p, dw, mw, rw, screen, split, .. } = *self;
        let src = |port: &str| self.src(port);
        let x_step = lit(xw, (p as u64) % (1u64 << xw));
        let (len, x) = (src("in_len"), src("in_x"));
        let valid = if split {
            "sp_valid".to_string()
        } else if pipe.span_stage() {
            "1'b1".into()
        } else {
            format!("{len} != 0")
        };
        let mut load = vec![set("cur_valid", valid)];
        if pipe.span_stage() {
            load.push(set("cur_inc", "sp_inc"));
        } else {
            load.push(set("cur_di", "in_di"));
        }
        load.push(set("cur_acc", "start_acc"));
        let mut advance = vec![
            set("cur_acc", "cur_acc + step"),
            set("cur_x", format!("cur_x + {x_step}")),
            set("cur_rem", format!("cur_rem - {}", lit(rw, p as u64))),
        ];
        let tot = if screen {
            // Config guarantees P <= 2^XW; at equality every segment starts at x = 0.
            let block = if log2p == xw { lit(xw, 0) } else { format!("{{{x}[{}:{log2p}], {}}}", xw - 1, lit(log2p, 0)) };
            load.push(set("cur_x", block));
            let tot = format!("{} + {}", zext(&len, xw + 1, rw), zext(&src("in_lead"), log2p, rw));
            load.push(set("cur_rem", tot.clone()));
            load.push(set("cur_lead", src("in_lead")));
            advance.push(set("cur_lead", lit(log2p, 0)));
            tot
        } else {
            load.push(set("cur_x", x.clone()));
            let tot = zext(&len, xw + 1, rw);
            load.push(set("cur_rem", tot.clone()));
            tot
        };
        if pipe.span_stage() {
            // The flag the next clock needs, from this clock's count: last when at most P are left,
            // so after a step of P when at most 2P are (compared one bit wider: 2P may not fit).
            load.push(set("cur_last", format!("{} <= {}", zext(&format!("({tot})"), rw, rw + 1), lit(rw + 1, p as u64))));
            advance.push(set("cur_last", format!("{} <= {}", zext("cur_rem", rw, rw + 1), lit(rw + 1, 2 * p as u64))));
        }
        if pipe.span_stage() {
            // Level 3's first BFPI level, from the input's dI (`in_m1`, declared with the other wires).
            let plan = golden::bfpi::BfpiPlan::new(p);
            let first_level: Vec<(u32, String)> = if split {
                plan.adders.iter().filter(|a| a.depth == 1).map(|a| (a.value, a.describe(|_| "in_m1".to_string()))).collect()
            } else {
                Vec::new()
            };
            if !first_level.is_empty() {
                body.push(swire("in_m1", mw, sext("in_di", dw, mw)));
            }
            body.push(comment("A span of length 0 is consumed and dropped in the span register."));
            body.push(Item::Always(vec![Stmt::If(
                "rst".into(),
                vec![set("sp_valid", "1'b0")],
                vec![Stmt::If(
                    "load".into(),
                    [
                        set("sp_valid", "in_len != 0"),
                        set("sp_x", "in_x"),
                        set("sp_len", "in_len"),
                        set("sp_i0", "in_i0"),
                        set("sp_di", "in_di"),
                    ]
                    .into_iter()
                    .chain(first_level.iter().map(|(c, e)| set(format!("sp_m{c}"), e.as_str())))
                    .chain(screen.then(|| set("sp_lead_di", "in_lead_di")))
                    .collect(),
                    vec![Stmt::If("start".into(), vec![set("sp_valid", "1'b0")], vec![])],
                )],
            )]));
            body.push(Item::Blank);
        } else {
            body.push(comment("A span of length 0 is consumed and yields nothing."));
        }
        let moves = if split {
            Stmt::If("cur_en".into(), vec![Stmt::If("!cur_valid || cur_last".into(), load, advance)], vec![])
        } else {
            let begin = if pipe.span_stage() { "start" } else { "load" };
            Stmt::If(
                begin.into(),
                load,
                vec![Stmt::If("fire".into(), vec![Stmt::If("cur_last".into(), vec![set("cur_valid", "1'b0")], advance)], vec![])],
            )
        };
        body.push(Item::Always(vec![Stmt::If("rst".into(), vec![set("cur_valid", "1'b0")], vec![moves])]));
        body.push(Item::Blank);
    }

    /// The stages behind the current one: (valid, x, mask, last) and the lanes move together.
    fn output(&self, body: &mut Vec<Item>) {
        let Seg { split, sum, .. } = *self;

        let from = if sum {
            body.push(Item::Always(vec![Stmt::If(
                "rst".into(),
                vec![set("s1_valid", "1'b0")],
                vec![Stmt::If(
                    "out_free".into(),
                    [set("s1_valid", "cur_valid"), set("s1_x", "cur_x")]
                        .into_iter()
                        .chain(if split { vec![set("s1_hc", "hcs")] } else { vec![set("s1_q", "qs")] })
                        .chain([set("s1_mask", "mask"), set("s1_last", "cur_last")])
                        .collect(),
                    vec![],
                )],
            )]));
            body.push(Item::Blank);
            ["s1_valid", "s1_x", "s1_mask", "s1_last"]
        } else {
            ["cur_valid", "cur_x", "mask", "cur_last"]
        };
        body.push(Item::Always(vec![Stmt::If(
            "rst".into(),
            vec![set("out_valid", "1'b0")],
            vec![Stmt::If(
                "out_free".into(),
                vec![
                    set("out_valid", from[0]),
                    set("out_x", from[1]),
                    set("out_pix", "pix"),
                    set("out_mask", from[2]),
                    set("out_last", from[3]),
                ],
                vec![],
            )],
        )]));
        body.push(Item::Blank);
    }
}
