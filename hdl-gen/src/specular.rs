//! `specular_unit`: the specular term of patent UA 71489, one pixel per clock, printed from
//! golden's [`SpecularPlan`] (widths, tables, pipeline) and ROM images.
//!
//! Five register stages (ten with `--pipeline`, which splits both multiplies into registered
//! partial products and their sum, registers the BRDF address, and takes both ROMs' words into
//! plain registers before any arithmetic: a block RAM's clock-to-out is long) with one stall signal: every
//! stage moves when the output register is free (`adv`), so the latency is fixed and a stalled
//! pipe keeps every pixel. The ROMs read on the same `adv`, which makes them ordinary
//! enable-gated block RAM reads.

mod properties;

use crate::rom;
use crate::verilog::{assign, comment, lit, reg, set, wire, zext, Item, Module, Param, Port, Stmt};
use golden::rom::{BRDF_HEX, NK_HEX};
use golden::specular::{SpecularPlan, SpecularUnit, C_FRAC, N_BITS, THETA_FRAC};
use golden::Config;

pub const THETA_BITS: u32 = 32;
pub const C_BITS: u32 = 16;

/// Module names of the unit and its ROMs, with the user's prefix.
pub struct SpecNames {
    pub unit: String,
    pub brdf: String,
    pub nk: String,
}

impl SpecNames {
    pub fn new(prefix: &str) -> SpecNames {
        SpecNames {
            unit: format!("{prefix}specular_unit"),
            brdf: format!("{prefix}specular_brdf_rom"),
            nk: format!("{prefix}specular_nk_rom"),
        }
    }
}

pub fn ports(cfg: &Config) -> Vec<Port> {
    let q = format!("signed Q3.{THETA_FRAC} rad");
    vec![
        Port::input("clk", 1, "", "rising edge"),
        Port::input("rst", 1, "", "synchronous, active high; drops work in progress"),
        Port::input("in_valid", 1, "", "span valid"),
        Port::output("in_ready", 1, "", "span accepted when in_valid && in_ready"),
        Port::input("in_c", C_BITS, &format!("UQ8.{C_FRAC}"), "C = Il * ks * A^n"),
        Port::input("in_n", N_BITS, "unsigned integer", "shininess n, valid 1..1000"),
        Port::input("in_theta0", THETA_BITS, &q, "theta of the first pixel, -lambda").signed(),
        Port::input("in_dtheta", THETA_BITS, &format!("{q} per pixel"), "gamma / l").signed(),
        Port::input("in_len", cfg.xbits + 1, "unsigned integer", "pixels in the span (0: no output)"),
        Port::output("out_valid", 1, "", "pixel valid").reg(),
        Port::input("out_ready", 1, "", "pixel taken when out_valid && out_ready"),
        Port::output("out_spec", C_BITS, &format!("UQ8.{C_FRAC}"), "C * cos^k(sqrt(n/k) * |theta|)").reg(),
        Port::output("out_last", 1, "", "final pixel of the span").reg(),
        Port::output("out_err", 1, "", "n outside 1..1000 (out_spec is 0)").reg(),
    ]
}

/// A ROM read that moves with the pipeline: enabled by `adv`, image named by `file_param`.
fn rom_read(module: &str, name: &str, file_param: &str, addr: &str, data: &str) -> Item {
    let conn = |port: &str, sig: &str| (port.to_string(), sig.to_string());
    Item::Instance {
        module: module.into(),
        name: name.into(),
        params: vec![conn("INIT_FILE", file_param)],
        conns: vec![conn("clk", "clk"), conn("en", "adv"), conn("addr", addr), conn("data", data)],
    }
}

/// `a + b + ...` as a balanced tree of two-input adds, so a sum of partial products is log2(n)
/// adders deep however Yosys maps it (the writer's row stride uses it too).
pub(crate) fn tree(terms: &[String]) -> String {
    match terms {
        [] => "0".into(),
        [one] => one.clone(),
        _ => {
            let (l, r) = terms.split_at(terms.len().div_ceil(2));
            let paren = |t: &[String]| if t.len() > 1 { format!("({})", tree(t)) } else { tree(t) };
            format!("{} + {}", paren(l), paren(r))
        }
    }
}

/// A multiply `a * b` split for clock rate (`--pipeline`): `a` times each `k`-bit slice of `b`
/// (wires `<product>_j`), registered (`<reg>_j`), and summed a stage later in a balanced tree.
/// Operands are (name, width). `logic`: each slice's product as shifts and adds
/// ([`golden::pipeline::Pipeline::logic_products`]).
struct SplitMul {
    a: (&'static str, u32),
    b: (&'static str, u32),
    k: u32,
    product: &'static str,
    reg: &'static str,
    logic: bool,
}

impl SplitMul {
    fn slices(&self) -> u32 {
        self.b.1.div_ceil(self.k)
    }

    /// Each slice's product and its register; a partial is `a`'s width plus `k` bits.
    fn items(&self) -> Vec<Item> {
        let ((a, aw), (b, bw), k) = (self.a, self.b, self.k);
        (0..self.slices())
            .flat_map(|j| {
                let bits = k.min(bw - j * k);
                let wide = zext(a, aw, aw + k);
                let product = if self.logic {
                    // Bit i of the slice selects `a << i`; the selected terms summed in a tree.
                    let terms: Vec<String> = (0..bits)
                        .map(|i| {
                            let shifted = if i == 0 { wide.clone() } else { format!("({wide} << {i})") };
                            format!("({{{}{{{b}[{}]}}}} & {shifted})", aw + k, j * k + i)
                        })
                        .collect();
                    tree(&terms)
                } else {
                    format!("{wide} * {}", zext(&format!("{b}[{}:{}]", j * k + bits - 1, j * k), bits, aw + k))
                };
                [reg(&format!("{}_{j}", self.reg), aw + k), wire(&format!("{}_{j}", self.product), aw + k, product)]
            })
            .collect()
    }

    /// The registers' loads, for the stage that holds them.
    fn loads(&self) -> Vec<Stmt> {
        (0..self.slices()).map(|j| set(format!("{}_{j}", self.reg), format!("{}_{j}", self.product))).collect()
    }

    /// The registered partials, each at its slice's weight, summed at `width` bits.
    fn sum(&self, width: u32) -> String {
        let terms: Vec<String> = (0..self.slices())
            .map(|j| {
                let t = zext(&format!("{}_{j}", self.reg), self.a.1 + self.k, width);
                if j == 0 {
                    t
                } else {
                    format!("({t} << {})", j * self.k)
                }
            })
            .collect();
        tree(&terms)
    }
}

/// The ROM modules and the unit, in file order.
pub fn modules(cfg: &Config, unit: &SpecularUnit, names: &SpecNames) -> Vec<Module> {
    vec![
        rom::module(&names.brdf, unit.brdf_rom(), BRDF_HEX, "BRDF tables cos^k, packed back to back"),
        rom::module(&names.nk, unit.nk_rom(), NK_HEX, "n-table: {table select, M} per n; M = 0 marks an invalid n"),
        module(cfg, unit, names),
    ]
}

fn module(cfg: &Config, unit: &SpecularUnit, names: &SpecNames) -> Module {
    let p = unit.plan();
    let adv = "adv";
    let mut body = issue(cfg, p, names);
    argument(p, &mut body);
    table_read(p, names, &mut body);
    scale(p, &mut body);
    let Moves { resets, stages, order } = moves(p);
    body.push(comment("Stages 1 to 4 move together; only the valid bits are reset."));
    body.push(Item::Always(vec![Stmt::If("rst".into(), resets, vec![Stmt::If(adv.into(), stages.concat(), vec![])])]));

    body.push(Item::Blank);
    body.push(properties::specular_properties(cfg.xbits + 1, &order));
    Module {
        name: names.unit.clone(),
        header: header(unit, names),
        params: vec![
            Param { name: "BRDF_FILE".into(), value: format!("\"{BRDF_HEX}\""), doc: "BRDF ROM image".into() },
            Param { name: "NK_FILE".into(), value: format!("\"{NK_HEX}\""), doc: "n-table ROM image".into() },
        ],
        ports: ports(cfg),
        body,
    }
}

/// The header: the arithmetic, both ROMs, every table and the stages.
fn header(unit: &SpecularUnit, names: &SpecNames) -> Vec<String> {
    let p = unit.plan();
    let g = p.geometry();
    let (w, mw, sb) = (p.word_bits, p.nk_mant_bits, p.sel_bits);
    let tables = &p.tables;
    let mut header = vec![
        format!("{} — specular term of patent UA 71489, one pixel per clock.", names.unit),
        "Generated by segshade hdl-gen; do not edit.".into(),
        String::new(),
        "Pixel j of a span: theta_j = theta0 + j*dtheta (32-bit accumulator), k = k(n),".into(),
        "out = C * cos^k(sqrt(n/k) * |theta_j|), 0 where the table ends (before pi/2).".into(),
        format!("k-set {:?}; n ranges: {}.", g.ks, p.decoder),
        format!(
            "BRDF ROM: {} tables packed back to back, {} words x {w} bits = {} bits (word w means (w+1)/2^{w}).",
            tables.len(),
            g.brdf_depth,
            g.brdf_bits
        ),
        format!("n-table ROM: {} words x {} bits ({sb}-bit table select, {mw}-bit M) = {} bits.", g.nk_depth, g.nk_width, g.nk_bits),
        "Tables (index = (|theta| >> drop) * M >> shift; at or past len the output is 0):".into(),
    ];
    for (t, tb) in tables.iter().enumerate() {
        header.push(format!(
            "  table {t}: k = {:2}, base {:5}, len {:4}, shift {:2}, step {:.6} rad, ends at {:.4} rad",
            tb.k,
            tb.base,
            tb.len,
            tb.shift,
            tb.step,
            tb.end_arg()
        ));
    }
    header.push(format!("Pipeline ({} clocks from the span's transfer to its first out_valid):", p.latency()));
    for s in p.stages() {
        header.push(format!("  stage {} {}: {}", s.stage, s.name, s.logic));
    }

    header
}

/// Split multiplies (`--pipeline`): |theta| * M and C * w, by k-bit slices of M and of w.
fn arg_mul(p: &SpecularPlan) -> SplitMul {
    let logic = p.pipeline.logic_products();
    SplitMul { a: ("mag1q", p.mag_bits), b: ("m1", p.nk_mant_bits), k: SpecularPlan::MUL_CHUNK, product: "pp1", reg: "pp2a", logic }
}
fn c_mul(p: &SpecularPlan) -> SplitMul {
    let logic = p.pipeline.logic_products();
    SplitMul { a: ("c3q", C_BITS), b: ("w3q", p.word_bits), k: SpecularPlan::MUL_CHUNK, product: "cp3", reg: "cp4a", logic }
}

/// Stages 0 and 1: the issue stage (the span's registers, theta of the pixel being issued),
/// then |theta| and the n-table read.
fn issue(cfg: &Config, p: &SpecularPlan, names: &SpecNames) -> Vec<Item> {
    let g = p.geometry();
    let lw = cfg.xbits + 1;
    let mag = p.mag_bits;
    let adv = "adv";
    let body = vec![
        comment("The whole pipe moves when the output register is free."),
        wire(adv, 1, "!out_valid || out_ready"),
        Item::Blank,
        comment("Stage 0, issue: the span's registers and theta of the pixel being issued."),
        reg("busy", 1),
        reg("cnt", lw),
        Item::Reg { name: "theta".into(), width: THETA_BITS, signed: true },
        Item::Reg { name: "dtheta".into(), width: THETA_BITS, signed: true },
        reg("c0", C_BITS),
        reg("n0", N_BITS),
        wire("last0", 1, format!("cnt == {}", lit(lw, 1))),
        assign("in_ready", "!busy || (adv && last0)"),
        wire("load", 1, "in_valid && in_ready"),
        Item::Always(vec![Stmt::If(
            "rst".into(),
            vec![set("busy", "1'b0")],
            vec![Stmt::If(
                "load".into(),
                vec![
                    set("busy", format!("in_len != {}", lit(lw, 0))),
                    set("cnt", "in_len"),
                    set("theta", "in_theta0"),
                    set("dtheta", "in_dtheta"),
                    set("c0", "in_c"),
                    set("n0", "in_n"),
                ],
                vec![Stmt::If(
                    "adv && busy".into(),
                    vec![Stmt::If(
                        "last0".into(),
                        vec![set("busy", "1'b0")],
                        vec![set("theta", "theta + dtheta"), set("cnt", format!("cnt - {}", lit(lw, 1)))],
                    )],
                    vec![],
                )],
            )],
        )]),
        Item::Blank,
        comment(format!(
            "Stage 1: |theta| (2^31 for -2^31, exact) without the {} bits below 2^-{} rad; n-table read.",
            p.theta_drop,
            p.mag_frac()
        )),
        comment("verilator lint_off UNUSEDSIGNAL"),
        wire("abs_theta", THETA_BITS, "theta[31] ? -theta : theta"),
        comment("verilator lint_on UNUSEDSIGNAL"),
        wire("mag0", mag, format!("abs_theta[31:{}]", p.theta_drop)),
        reg("v1", 1),
        reg("mag1", mag),
        reg("c1", C_BITS),
        reg("last1", 1),
        Item::Bus { name: "nk1".into(), width: g.nk_width },
        rom_read(&names.nk, "u_nk", "NK_FILE", "n0", "nk1"),
        Item::Blank,
    ];
    body
}

/// Stage 2: the argument |theta| * M (split in slices at `--pipeline`).
fn argument(p: &SpecularPlan, body: &mut Vec<Item>) {
    let g = p.geometry();
    let (mw, sb) = (p.nk_mant_bits, p.sel_bits);
    let (mag, prod) = (p.mag_bits, p.prod_bits());
    let tables = &p.tables;
    let lo = p.prod_drop();
    let split = p.pipeline.split_multiplies();
    let k = SpecularPlan::MUL_CHUNK;
    let arg_mul = arg_mul(p);
    if split {
        body.push(comment("Stage 1q: |theta| and the n-table word registered off the ROM's output."));
        body.extend([reg("v1q", 1), reg("mag1q", mag), reg("c1q", C_BITS), reg("last1q", 1), reg("nk1q", g.nk_width), Item::Blank]);
        body.push(comment(format!("Stage 2a: |theta| times each {k}-bit slice of M; M = 0 marks an invalid n.")));
        body.push(wire("m1", mw, format!("nk1q[{}:0]", mw - 1)));
        body.extend([reg("v2a", 1), reg("c2a", C_BITS), reg("last2a", 1), reg("err2a", 1)]);
        if sb > 0 && tables.len() > 1 {
            body.push(reg("sel2a", sb));
        }
        body.extend(arg_mul.items());
        body.push(Item::Blank);
        body.push(comment("Stage 2: the argument, the partial products summed in a balanced tree."));
    } else {
        body.push(comment("Stage 2: the argument multiplier; M = 0 marks an invalid n."));
        body.push(wire("m1", mw, format!("nk1[{}:0]", mw - 1)));
    }
    let prod_expr = if split { arg_mul.sum(prod) } else { format!("{} * {}", zext("mag1", mag, prod), zext("m1", mw, prod)) };
    body.extend([
        comment(format!("Bits below the smallest table shift ({lo}) never reach an index: not registered.")),
        comment("verilator lint_off UNUSEDSIGNAL"),
        wire("prod1", prod, prod_expr),
        comment("verilator lint_on UNUSEDSIGNAL"),
        reg("v2", 1),
        reg("prod2", prod - lo),
        reg("err2", 1),
        reg("c2", C_BITS),
        reg("last2", 1),
    ]);
    let multi_table = sb > 0 && tables.len() > 1;
    if multi_table {
        body.push(reg("sel2", sb));
    }
    body.push(Item::Blank);
}

/// Stage 3: each table's index, the select, the BRDF ROM read.
fn table_read(p: &SpecularPlan, names: &SpecNames, body: &mut Vec<Item>) {
    let (w, sb) = (p.word_bits, p.sel_bits);
    let (prod, ab, ib) = (p.prod_bits(), p.brdf_addr_bits(), p.index_bits());
    let tables = &p.tables;
    let lo = p.prod_drop();
    let split = p.pipeline.split_multiplies();
    // Stage 3: each table's index is a fixed shift of the product; the select picks one.
    if split {
        body.push(comment("Stage 3a: index = prod >> shift[sel]; past the table's end the output is 0; the BRDF address."));
    } else {
        body.push(comment("Stage 3: index = prod >> shift[sel]; past the table's end the output is 0; BRDF read."));
    }
    body.push(comment("Each table uses the product bits above its own shift; no table uses them all."));
    body.push(comment("verilator lint_off UNUSEDSIGNAL"));
    for (t, tb) in tables.iter().enumerate() {
        let iw = prod - tb.shift;
        body.push(wire(&format!("idx_t{t}"), iw, format!("prod2[{}:{}]", prod - lo - 1, tb.shift - lo)));
        body.push(wire(&format!("in_t{t}"), 1, format!("idx_t{t} < {}", lit(iw, tb.len as u64))));
        let idx = if iw >= ib { format!("idx_t{t}[{}:0]", ib - 1) } else { zext(&format!("idx_t{t}"), iw, ib) };
        body.push(wire(&format!("addr_t{t}"), ab, format!("{} + {}", lit(ab, tb.base as u64), zext(&idx, ib, ab))));
    }
    body.push(comment("verilator lint_on UNUSEDSIGNAL"));
    let pick = |what: &str| -> String {
        let last = tables.len() - 1;
        let mut e = format!("{what}_t{last}");
        for t in (0..last).rev() {
            e = format!("(sel2 == {}) ? {what}_t{t} : {e}", lit(sb, t as u64));
        }
        e
    };
    body.push(wire("in_table", 1, pick("in")));
    body.push(wire("addr2", ab, pick("addr")));
    let rom_addr = if split {
        body.extend([
            reg("v3a", 1),
            reg("cut3a", 1),
            reg("err3a", 1),
            reg("c3a", C_BITS),
            reg("last3a", 1),
            reg("addr3a", ab),
            Item::Blank,
        ]);
        body.push(comment("Stage 3: the BRDF read."));
        "addr3a"
    } else {
        "addr2"
    };
    body.extend([
        reg("v3", 1),
        reg("cut3", 1),
        reg("err3", 1),
        reg("c3", C_BITS),
        reg("last3", 1),
        Item::Bus { name: "w3".into(), width: w },
        rom_read(&names.brdf, "u_brdf", "BRDF_FILE", rom_addr, "w3"),
        Item::Blank,
    ]);
}

/// Stage 4: out = C * (w + 1) / 2^W, rounded (split in slices at `--pipeline`).
fn scale(p: &SpecularPlan, body: &mut Vec<Item>) {
    let w = p.word_bits;
    let split = p.pipeline.split_multiplies();
    let k = SpecularPlan::MUL_CHUNK;
    let c_mul = c_mul(p);
    let sw = C_BITS + w + 1;
    let wp = format!("({} + {})", zext("w3", w, w + 1), lit(w + 1, 1));
    let scaled = if split {
        // The word off the ROM into a plain register first; then C times each k-bit slice of
        // it, registered; their sum, with C (C * (w + 1) = C * w + C), is the last stage.
        body.push(comment("Stage 3q: the BRDF word registered off the ROM's output."));
        body.extend([reg("v3q", 1), reg("cut3q", 1), reg("err3q", 1), reg("c3q", C_BITS), reg("last3q", 1), reg("w3q", w), Item::Blank]);
        body.push(comment(format!("Stage 4a: C times each {k}-bit slice of w.")));
        body.extend([reg("v4a", 1), reg("cut4a", 1), reg("err4a", 1), reg("c4a", C_BITS), reg("last4a", 1)]);
        body.extend(c_mul.items());
        body.push(Item::Blank);
        body.push(comment(format!("Stage 4: out = C * (w + 1) / 2^{w}, the slices and C summed, rounded half up; never above C.")));
        format!("{} + {} + {}", c_mul.sum(sw), zext("c4a", C_BITS, sw), lit(sw, 1 << (w - 1)))
    } else {
        body.push(comment(format!("Stage 4: out = C * (w + 1) / 2^{w}, rounded half up; never above C.")));
        format!("{} * {} + {}", zext("c3", C_BITS, sw), zext(&wp, w + 1, sw), lit(sw, 1 << (w - 1)))
    };
    body.extend([
        comment("verilator lint_off UNUSEDSIGNAL"),
        wire("scaled", sw, scaled),
        comment("verilator lint_on UNUSEDSIGNAL"),
        Item::Blank,
    ]);
}

/// Every stage's register moves, the valid bits' resets, and each stage's (valid, last) in
/// order for the properties.
struct Moves {
    resets: Vec<Stmt>,
    stages: Vec<Vec<Stmt>>,
    order: Vec<(&'static str, &'static str)>,
}

fn moves(p: &SpecularPlan) -> Moves {
    let (w, mw, sb) = (p.word_bits, p.nk_mant_bits, p.sel_bits);
    let prod = p.prod_bits();
    let lo = p.prod_drop();
    let split = p.pipeline.split_multiplies();
    let multi_table = sb > 0 && p.tables.len() > 1;
    let (arg_mul, c_mul) = (arg_mul(p), c_mul(p));
    let sel_of_nk = format!("{}[{}:{mw}]", if split { "nk1q" } else { "nk1" }, mw + sb - 1);
    let err_of_m = format!("m1 == {}", lit(mw, 0));
    let mut stages: Vec<Vec<Stmt>> = vec![vec![set("v1", "busy"), set("mag1", "mag0"), set("c1", "c0"), set("last1", "last0")]];
    let mut resets = vec![set("v1", "1'b0")];
    let mut order = vec![("v1", "last1")];
    if split {
        stages.push(vec![set("v1q", "v1"), set("mag1q", "mag1"), set("c1q", "c1"), set("last1q", "last1"), set("nk1q", "nk1")]);
        resets.push(set("v1q", "1'b0"));
        order.push(("v1q", "last1q"));
        let mut part = vec![set("v2a", "v1q"), set("c2a", "c1q"), set("last2a", "last1q"), set("err2a", err_of_m.clone())];
        part.extend(arg_mul.loads());
        if multi_table {
            part.push(set("sel2a", sel_of_nk.clone()));
        }
        stages.push(part);
        resets.push(set("v2a", "1'b0"));
        order.push(("v2a", "last2a"));
    }
    let from2 = |r: &str| if split { format!("{r}2a") } else { format!("{r}1") };
    let mut stage2 = vec![
        set("v2", from2("v")),
        set("prod2", format!("prod1[{}:{lo}]", prod - 1)),
        set("err2", if split { "err2a".to_string() } else { err_of_m }),
        set("c2", from2("c")),
        set("last2", from2("last")),
    ];
    if multi_table {
        stage2.push(set("sel2", if split { "sel2a".to_string() } else { sel_of_nk }));
    }
    stages.push(stage2);
    resets.push(set("v2", "1'b0"));
    order.push(("v2", "last2"));
    if split {
        stages.push(vec![
            set("v3a", "v2"),
            set("cut3a", "err2 || !in_table"),
            set("err3a", "err2"),
            set("c3a", "c2"),
            set("last3a", "last2"),
            set("addr3a", "addr2"),
        ]);
        resets.push(set("v3a", "1'b0"));
        order.push(("v3a", "last3a"));
        stages.push(vec![set("v3", "v3a"), set("cut3", "cut3a"), set("err3", "err3a"), set("c3", "c3a"), set("last3", "last3a")]);
        stages.push(vec![
            set("v3q", "v3"),
            set("cut3q", "cut3"),
            set("err3q", "err3"),
            set("c3q", "c3"),
            set("last3q", "last3"),
            set("w3q", "w3"),
        ]);
        let mut part = vec![set("v4a", "v3q"), set("cut4a", "cut3q"), set("err4a", "err3q"), set("c4a", "c3q"), set("last4a", "last3q")];
        part.extend(c_mul.loads());
        stages.push(part);
        resets.extend([set("v3", "1'b0"), set("v3q", "1'b0"), set("v4a", "1'b0")]);
        order.extend([("v3", "last3"), ("v3q", "last3q"), ("v4a", "last4a")]);
    } else {
        stages.push(vec![set("v3", "v2"), set("cut3", "err2 || !in_table"), set("err3", "err2"), set("c3", "c2"), set("last3", "last2")]);
        resets.push(set("v3", "1'b0"));
        order.push(("v3", "last3"));
    }
    let fin = if split { "4a" } else { "3" };
    stages.push(vec![
        set("out_valid", format!("v{fin}")),
        set("out_spec", format!("cut{fin} ? {} : scaled[{}:{w}]", lit(C_BITS, 0), C_BITS + w - 1)),
        set("out_err", format!("err{fin}")),
        set("out_last", format!("last{fin}")),
    ]);
    resets.push(set("out_valid", "1'b0"));
    order.push(("out_valid", "out_last"));
    Moves { resets, stages, order }
}
