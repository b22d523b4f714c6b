//! `hdl-gen testbench`: self-checking Verilog-2005 testbenches with vectors exported from the
//! golden model, so the generated RTL can be checked in any simulator, no Rust involved.
//!
//! For one configuration this writes everything `generate` writes, plus, per block:
//!
//! - `<tb>_in.hex`: the input spans, one `$readmemh` word per span;
//! - `<tb>_exp.hex`: every output golden expects, in order, each tagged with its span's number;
//! - `<tb>.v`: the bench. It resets the block, offers the spans with `in_valid` gaps and drives
//!   `out_ready` with backpressure and long stalls, both from a seeded xorshift register (with
//!   full-rate stretches, spans back to back and the sink always ready), checks every output
//!   transfer against the next expected word, prints each mismatch and ends with
//!   `N passed, M failed` (spans). On failure it ends with `$fatal`, so the simulator's exit
//!   status is non-zero.
//!
//! Segment-shader spans come from golden's set-up of random triangles, plus raw random spans
//! over the whole port ranges (including the last screen column and the extremes of I0 and dI)
//! and zero-length spans. Specular spans come from golden's set-up of random normals and
//! half-vectors, plus n outside 1..1000 (which the port carries: `out_err = 1`) and
//! zero-length spans. Every vector comes from `golden::stimulus`, the generators the
//! co-simulation uses, drawing from `golden::rng::SeedRng` seeded by `--seed`, so the same
//! command always writes the same bytes.

use crate::specular::SpecNames;
use crate::verilog::{bus, comment, reg, Item, Module, Param, Port, Stmt};
use crate::{generate, GeneratedFile, Names, Options};
use golden::frontend::FixedTriangle;
use golden::rng::SeedRng;
use golden::segment::segments;
use golden::specular::{SpecularSpan, N_BITS};
use golden::stimulus::{random_fixed_triangles, random_span, segment_spans};
use golden::{Config, Span};
use rand::{Rng, RngCore, SeedableRng};

/// Largest `--vectors`: keeps the expected-output files within a few hundred megabytes.
pub const MAX_VECTORS: u32 = 1_000_000;
/// Clocks without any transfer after which a bench declares the block hung.
const STALL_LIMIT: u32 = 10_000;
/// Clocks a bench keeps running after the last expected output, in which nothing may come out.
const DRAIN: u32 = 16;

/// Names of the bench modules and their files.
pub struct BenchNames {
    pub segment: String,
    pub specular: String,
    pub frontend: String,
}

impl BenchNames {
    pub fn new(opts: &Options) -> BenchNames {
        let names = Names::new(&opts.prefix, &opts.cfg);
        let spec = SpecNames::new(&opts.prefix);
        BenchNames {
            segment: format!("tb_{}", names.segment),
            specular: format!("tb_{}", spec.unit),
            frontend: format!("tb_{}", names.frontend),
        }
    }
}

/// A vector count [`testbench`] refuses: outside `1..=MAX_VECTORS`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("--vectors {0} is outside 1..{MAX_VECTORS}")]
pub struct VectorCountError(pub u32);

/// Everything `generate` writes for `opts`, then both benches and their vector files.
pub fn testbench(opts: &Options, vectors: u32, seed: u64) -> Result<Vec<GeneratedFile>, VectorCountError> {
    if !(1..=MAX_VECTORS).contains(&vectors) {
        return Err(VectorCountError(vectors));
    }
    let mut files = generate(opts);
    let bench = BenchNames::new(opts);
    let mut rng = SeedRng::seed_from_u64(seed);
    let spans = segment_spans(&mut rng, &opts.cfg, vectors as usize);
    files.extend(segment_bench(opts, &bench.segment, &spans, rng.next_u32() | 1));
    let spec = specular_spans(&mut rng, &opts.cfg, vectors as usize);
    files.extend(specular_bench(opts, &bench.specular, &spec, rng.next_u32() | 1));
    if let Ok(hw) = opts.frontend() {
        let tris = random_fixed_triangles(&mut rng, &hw.fe, vectors as usize);
        files.extend(frontend_bench(opts, &hw, &bench.frontend, &tris, rng.next_u32() | 1));
    }
    Ok(files)
}

fn frontend_bench(opts: &Options, hw: &crate::frontend::Hw, name: &str, tris: &[FixedTriangle], seed: u32) -> Vec<GeneratedFile> {
    let (fe, cfg) = (&hw.fe, &opts.cfg);
    let wd = fe.widths();
    let (xw, iw, dw, yw) = (cfg.xbits, cfg.iw(), cfg.dw(), wd.yw);
    let in_width = 3 * (wd.cx + wd.cy + iw);
    let mask = |v: i64, b: u32| (v as u64) & ((1u64 << b) - 1);
    let inputs = tris.iter().map(|t| {
        let mut w = Word::default();
        for k in 0..3 {
            w.field(mask(t.x[k], wd.cx), wd.cx).field(mask(t.y[k], wd.cy), wd.cy).field(t.i[k] as u64, iw);
        }
        w.hex()
    });
    let mut expected = Vec::new();
    for (k, t) in tris.iter().enumerate() {
        fe.spans(t, |y, s| {
            let mut w = Word::default();
            w.field(k as u64, 32).field(y as u64, yw).field(s.x0 as u64, xw).field(s.len as u64, xw + 1);
            w.field(s.i0 as u64, iw).field(mask(s.di as i64, dw), dw);
            expected.push(w.hex());
        });
    }
    let exp_width = 32 + yw + xw + (xw + 1) + iw + dw;
    let (di, i0, len, x, y, span) = (
        format!("want[{}:0]", dw - 1),
        format!("want[{} +: {iw}]", dw),
        format!("want[{} +: {}]", dw + iw, xw + 1),
        format!("want[{} +: {xw}]", dw + iw + xw + 1),
        format!("want[{} +: {yw}]", dw + iw + 2 * xw + 1),
        format!("want[{} +: 32]", dw + iw + 2 * xw + 1 + yw),
    );
    let names = Names::new(&opts.prefix, cfg);
    let header = vec![
        format!("{name} — self-checking testbench of {}, vectors from the segshade golden model.", names.frontend),
        "Generated by segshade hdl-gen testbench; do not edit.".into(),
        String::new(),
        format!(
            "Configuration: screen {}x{}, F = {}, XW = {xw}, divider bits {}.",
            fe.screen.width, fe.screen.height, cfg.frac, hw.div_bits
        ),
        format!("{name}_in.hex: {} triangles, one word each: {{in_x0, in_y0, in_i0, in_x1, .., in_i2}} ({in_width} bits).", tris.len()),
        format!("{name}_exp.hex: {} spans in output order: {{triangle, y, x0, len, i0, di}} ({exp_width} bits).", expected.len()),
        "Every span that leaves the block is compared; in_valid gaps, out_ready backpressure, stalls of up to".into(),
        "255 clocks and full-rate stretches come from an xorshift register. `N passed` counts triangles.".into(),
    ];
    let mut ports = crate::frontend::ports(fe, &wd);
    ports.extend(crate::frontend::span_ports(fe, &wd));
    let in_fields: Vec<&'static str> = vec!["in_x0", "in_y0", "in_i0", "in_x1", "in_y1", "in_i1", "in_x2", "in_y2", "in_i2"];
    let spec = BenchSpec {
        name,
        dut: names.frontend.clone(),
        ports,
        header,
        n_in: tris.len(),
        n_exp: expected.len(),
        in_width,
        exp_width,
        in_fields,
        extra: vec![],
        mismatch: format!("out_y !== {y} || out_x !== {x} || out_len !== {len} || out_i0 !== {i0} || out_di !== {di}"),
        describe: (
            "expected y %0d x %0d len %0d i0 %0d di %0d, got y %0d x %0d len %0d i0 %0d di %0d".into(),
            format!("{y}, {x}, {len}, {i0}, $signed({di}), out_y, out_x, out_len, out_i0, out_di"),
        ),
        span_field: span,
        seed,
    };
    let module = bench_module(&spec);
    vec![
        GeneratedFile { name: format!("{name}.v"), contents: module.render() },
        GeneratedFile { name: format!("{name}_in.hex"), contents: hex_file(&format!("{name}: {} triangles", tris.len()), inputs) },
        GeneratedFile {
            name: format!("{name}_exp.hex"),
            contents: hex_file(&format!("{name}: {} spans", expected.len()), expected.into_iter()),
        },
    ]
}

/// `n` specular spans: golden's random spans (every k range and its boundaries, n outside
/// 1..1000, highlights across the span and arbitrary vectors) of up to 200 pixels, 4% of them
/// of length zero.
fn specular_spans(rng: &mut impl Rng, cfg: &Config, n: usize) -> Vec<SpecularSpan> {
    let max_len = cfg.max_len().min(200);
    (0..n)
        .map(|_| {
            let mut s = random_span(rng, max_len);
            if rng.gen_bool(0.04) {
                s.len = 0;
            }
            s
        })
        .collect()
}

/// A `$readmemh` word assembled from fields, most significant first.
#[derive(Default)]
struct Word {
    bits: Vec<bool>,
}

impl Word {
    fn field(&mut self, value: u64, width: u32) -> &mut Self {
        for b in (0..width).rev() {
            self.bits.push(b < 64 && value >> b & 1 == 1);
        }
        self
    }
    fn hex(&self) -> String {
        let pad = (4 - self.bits.len() % 4) % 4;
        let bits: Vec<bool> = std::iter::repeat_n(false, pad).chain(self.bits.iter().copied()).collect();
        bits.chunks(4)
            .map(|c| {
                let d = c.iter().fold(0u32, |a, &b| a << 1 | b as u32);
                char::from_digit(d, 16).expect("a nibble")
            })
            .collect()
    }
}

fn hex_file(header: &str, words: impl Iterator<Item = String>) -> String {
    let mut s = format!("// {header}\n");
    for w in words {
        s.push_str(&w);
        s.push('\n');
    }
    s
}

fn blocking(l: &str, r: impl Into<String>) -> Stmt {
    Stmt::Blocking(l.into(), r.into())
}
fn call(c: impl Into<String>) -> Stmt {
    Stmt::Call(c.into())
}
fn if_(c: impl Into<String>, then: Vec<Stmt>, els: Vec<Stmt>) -> Stmt {
    Stmt::If(c.into(), then, els)
}
fn scomment(c: &str) -> Stmt {
    Stmt::Comment(c.into())
}
fn set(l: &str, r: impl Into<String>) -> Stmt {
    Stmt::Set(l.into(), r.into())
}

/// A port of the block under test, declared in the bench: inputs as registers it drives.
fn bench_net(p: &Port) -> Item {
    match p.dir {
        crate::verilog::Dir::Input => Item::Reg { name: p.name.clone(), width: p.width, signed: p.signed },
        crate::verilog::Dir::Output if p.vector => bus(&p.name, p.width),
        crate::verilog::Dir::Output => Item::Wire { name: p.name.clone(), width: p.width, signed: p.signed, value: None },
    }
}

/// What differs between the two benches; the shared skeleton is [`bench_module`].
struct BenchSpec<'a> {
    name: &'a str,
    dut: String,
    ports: Vec<Port>,
    header: Vec<String>,
    n_in: usize,
    n_exp: usize,
    in_width: u32,
    exp_width: u32,
    /// The input ports loaded from a span word, most significant first.
    in_fields: Vec<&'static str>,
    /// Declarations the check needs (wires over the outputs).
    extra: Vec<Item>,
    /// The condition under which the output transfer differs from `want`.
    mismatch: String,
    /// `$display` format and arguments of a mismatch (expected, then got).
    describe: (String, String),
    /// The bit range of `want` holding the span's number.
    span_field: String,
    seed: u32,
}

fn bench_module(b: &BenchSpec) -> Module {
    let mut body = declarations(b);
    let run = clock(b);
    body.push(Item::Always(vec![
        blocking("cycle", "cycle + 1"),
        if_("cycle <= 4", vec![Stmt::Comment("Three clocks of reset.".into()), set("rst", "cycle < 4")], run),
    ]));

    let mut header = b.header.clone();
    header.extend([
        String::new(),
        "Run it from this folder (the ROM images and vector files are read from the current directory):".into(),
        format!("  iverilog -g2005 -s {0} -o {0}.vvp *.v && vvp -n {0}.vvp", b.name),
        "It prints every mismatch, then `N passed, M failed` (spans); on failure it ends with $fatal, so the".into(),
        "simulator exits non-zero. Other vector files: override the IN_FILE and EXP_FILE parameters.".into(),
    ]);
    Module {
        name: b.name.to_string(),
        header,
        params: vec![
            Param { name: "IN_FILE".into(), value: format!("\"{}_in.hex\"", b.name), doc: "input spans".into() },
            Param { name: "EXP_FILE".into(), value: format!("\"{}_exp.hex\"", b.name), doc: "expected outputs".into() },
        ],
        ports: vec![],
        body,
    }
}

/// The bench's nets, the DUT, the vector memories, its state and the clock and reset.
fn declarations(b: &BenchSpec) -> Vec<Item> {
    let mut body = vec![
        Item::Localparam { name: "N_SPANS".into(), width: 32, value: b.n_in.to_string() },
        Item::Localparam { name: "N_OUT".into(), width: 32, value: b.n_exp.to_string() },
        Item::Localparam { name: "STALL_LIMIT".into(), width: 32, value: STALL_LIMIT.to_string() },
        Item::Blank,
    ];
    body.extend(b.ports.iter().map(bench_net));
    body.push(Item::Blank);
    body.push(Item::Instance {
        module: b.dut.clone(),
        name: "dut".into(),
        params: vec![],
        conns: b.ports.iter().map(|p| (p.name.clone(), p.name.clone())).collect(),
    });
    body.push(Item::Blank);
    body.push(comment("Vectors exported from the golden model."));
    body.push(Item::Memory { name: "span_mem".into(), width: b.in_width, depth: b.n_in.max(1) as u32, no_rw_check: false });
    body.push(Item::Memory { name: "out_mem".into(), width: b.exp_width, depth: b.n_exp.max(1) as u32, no_rw_check: false });
    body.push(Item::ReadMemH { file: "IN_FILE".into(), mem: "span_mem".into() });
    body.push(Item::ReadMemH { file: "EXP_FILE".into(), mem: "out_mem".into() });
    body.push(Item::Blank);
    body.extend(b.extra.iter().cloned());
    body.push(comment("Bench state; all of it is updated with blocking assignments in the one always block."));
    for r in ["rnd", "cycle", "n_in", "n_out", "idle", "failed", "last_failed", "stall", "drain", "first_open"] {
        body.push(reg(r, 32));
    }
    body.push(reg("progress", 1));
    body.push(reg("extra", 1));
    body.push(reg("want", b.exp_width));
    body.push(reg("full", 1));
    body.push(Item::Blank);
    body.push(Item::Initial(vec![blocking("clk", "1'b0"), Stmt::Forever(vec![Stmt::Delay(5), blocking("clk", "!clk")])]));
    let mut init = vec![blocking("rst", "1'b1"), blocking("in_valid", "1'b0"), blocking("out_ready", "1'b0")];
    init.extend(
        ["rnd", "cycle", "n_in", "n_out", "idle", "failed", "stall", "drain", "first_open"]
            .iter()
            .map(|r| blocking(r, if *r == "rnd" { format!("32'd{}", b.seed) } else { "32'd0".into() })),
    );
    init.push(blocking("last_failed", "32'hffffffff"));
    init.push(blocking("extra", "1'b0"));
    body.push(Item::Initial(init));
    body.push(Item::Blank);
    body
}

/// The end of a run: the tally line, then `$finish` if nothing failed (`passed_msg`), else
/// `$fatal`, so the simulator's exit status tells.
fn finish(b: &BenchSpec, passed_msg: bool) -> Vec<Stmt> {
    let mut v = vec![
        if_("failed > N_SPANS", vec![blocking("failed", "N_SPANS")], vec![]),
        call("$display(\"%0d passed, %0d failed\", N_SPANS - failed, failed)".to_string()),
    ];
    if passed_msg {
        v.push(if_("failed != 0", vec![call(format!("$fatal(1, \"{}: FAILED\")", b.name))], vec![call("$finish")]));
    } else {
        v.push(call(format!("$fatal(1, \"{}: FAILED\")", b.name)));
    }
    v
}

/// One clock of the bench: the traffic pattern, the output check, the input side, the sink's
/// stalls, and the end (done, or a hang).
fn clock(b: &BenchSpec) -> Vec<Stmt> {
    let fields = format!("{{{}}}", b.in_fields.join(", "));
    let mut run = vec![
        Stmt::Comment("Full rate one stretch of 1024 clocks in eight: spans back to back, the sink always ready.".into()),
        blocking("full", "cycle[12:10] == 3'd0"),
        blocking("progress", "1'b0"),
        if_(
            "out_valid !== 1'b0 && out_valid !== 1'b1",
            [vec![call("$display(\"FAIL: out_valid is %b after reset\", out_valid)"), blocking("failed", "N_SPANS")], finish(b, false)].concat(),
            vec![],
        ),
        scomment("Output side: the transfer at this edge must be the next expected word."),
        if_(
            "out_valid && out_ready",
            vec![
                blocking("progress", "1'b1"),
                if_(
                    "n_out == N_OUT",
                    vec![
                        if_("!extra", vec![blocking("failed", "failed + 1")], vec![]),
                        blocking("extra", "1'b1"),
                        call("$display(\"FAIL: output after the last expected one (clock %0d)\", cycle)"),
                    ],
                    vec![
                        blocking("want", "out_mem[n_out]"),
                        if_(
                            b.mismatch.clone(),
                            vec![
                                call(format!("$display(\"FAIL span %0d, output %0d: {}\", {}, n_out, {})", b.describe.0, b.span_field, b.describe.1)),
                                if_(
                                    format!("{} != last_failed", b.span_field),
                                    vec![blocking("failed", "failed + 1"), blocking("last_failed", b.span_field.clone())],
                                    vec![],
                                ),
                            ],
                            vec![],
                        ),
                        blocking("n_out", "n_out + 1"),
                    ],
                ),
            ],
            vec![],
        ),
        scomment("Input side: the span taken at this edge; offer the next one or hold the current."),
        if_(
            "in_valid !== 1'b0 && in_ready !== 1'b0 && in_ready !== 1'b1",
            [vec![call("$display(\"FAIL: in_ready is %b\", in_ready)"), blocking("failed", "N_SPANS")], finish(b, false)].concat(),
            vec![],
        ),
        if_("in_valid && in_ready", vec![blocking("progress", "1'b1"), blocking("n_in", "n_in + 1")], vec![]),
        if_(
            "!in_valid || in_ready",
            vec![if_(
                "n_in < N_SPANS && (full || rnd[1:0] != 2'd0)",
                vec![set("in_valid", "1'b1"), set(&fields, "span_mem[n_in]")],
                vec![set("in_valid", "1'b0")],
            )],
            vec![],
        ),
        scomment("Sink: ready 3/4 of the clocks; with probability 1/256 per clock a stall of up to 255 clocks."),
        if_("stall != 0", vec![blocking("stall", "stall - 1")], vec![if_("!full && rnd[15:8] == 8'd0", vec![blocking("stall", "rnd[23:16]")], vec![])]),
        set("out_ready", "full || (stall == 0 && rnd[3:2] != 2'd0)"),
        scomment("The end: everything in and out, then a few quiet clocks; or a hang."),
        blocking("idle", "progress ? 32'd0 : idle + 1"),
        if_(
            "n_in == N_SPANS && n_out == N_OUT",
            vec![blocking("drain", "drain + 1"), if_(format!("drain == {DRAIN}"), finish(b, true), vec![])],
            vec![if_(
                "idle == STALL_LIMIT",
                [
                    vec![
                        call("$display(\"FAIL: no transfer for %0d clocks: %0d of %0d spans in, %0d of %0d outputs out\", STALL_LIMIT, n_in, N_SPANS, n_out, N_OUT)"),
                        if_(
                            "n_out < N_OUT",
                            vec![blocking("want", "out_mem[n_out]"), blocking("first_open", b.span_field.clone())],
                            vec![blocking("first_open", "n_in")],
                        ),
                        blocking("failed", "failed + N_SPANS - first_open - (last_failed == first_open ? 32'd1 : 32'd0)"),
                    ],
                    finish(b, false),
                ]
                .concat(),
                vec![],
            )],
        ),
    ];
    run.insert(0, scomment("xorshift32: the traffic pattern."));
    run.insert(1, blocking("rnd", "rnd ^ (rnd << 13)"));
    run.insert(2, blocking("rnd", "rnd ^ (rnd >> 17)"));
    run.insert(3, blocking("rnd", "rnd ^ (rnd << 5)"));
    run
}

fn segment_bench(opts: &Options, name: &str, spans: &[Span], seed: u32) -> Vec<GeneratedFile> {
    let cfg = &opts.cfg;
    let (p, xw) = (cfg.p, cfg.xbits);
    let in_width = xw + (xw + 1) + cfg.iw() + cfg.dw();
    let inputs = spans.iter().map(|s| {
        let di = (s.di as i64 as u64) & ((1u64 << cfg.dw()) - 1);
        Word::default().field(s.x0 as u64, xw).field(s.len as u64, xw + 1).field(s.i0 as u64, cfg.iw()).field(di, cfg.dw()).hex()
    });
    let mut expected = Vec::new();
    for (k, s) in spans.iter().enumerate() {
        for seg in segments(cfg, s) {
            let mut w = Word::default();
            w.field(k as u64, 32).field(seg.x as u64, xw).field(seg.last as u64, 1);
            for i in (0..p).rev() {
                w.field(seg.lane_pixel(i).is_some() as u64, 1);
            }
            for i in (0..p).rev() {
                w.field(seg.lane_pixel(i).map_or(0, |j| s.pixel(j, cfg.frac)) as u64, 8);
            }
            expected.push(w.hex());
        }
    }
    let exp_width = 32 + xw + 1 + p + 8 * p;
    let (pix, mask, last, x, span) = (
        format!("want[{}:0]", 8 * p - 1),
        format!("want[{} +: {p}]", 8 * p),
        format!("want[{}]", 9 * p),
        format!("want[{} +: {xw}]", 9 * p + 1),
        format!("want[{} +: 32]", 9 * p + 1 + xw),
    );
    let names = Names::new(&opts.prefix, cfg);
    let header = vec![
        format!("{name} — self-checking testbench of {}, vectors from the segshade golden model.", names.segment),
        "Generated by segshade hdl-gen testbench; do not edit.".into(),
        String::new(),
        format!("Configuration: P = {p}, F = {}, XW = {xw}, align = {}.", cfg.frac, cfg.align),
        format!("{}: {} spans, one word each: {{in_x, in_len, in_i0, in_di}} ({in_width} bits).", format!("{name}_in.hex"), spans.len()),
        format!(
            "{}: {} segments in output order: {{span, out_x, out_last, out_mask, out_pix}} ({exp_width} bits), masked lanes 0.",
            format!("{name}_exp.hex"),
            expected.len()
        ),
        "Every segment that leaves the block is compared (masked lanes are don't-care); in_valid gaps, out_ready".into(),
        "backpressure, stalls of up to 255 clocks and full-rate stretches come from an xorshift register.".into(),
    ];
    let lanes = vec![
        comment("Enabled lanes of the segment on the output, as a pixel mask (masked lanes are don't-care)."),
        bus("lanes", 8 * p),
        Item::ForGenerate {
            var: "i".into(),
            count: p,
            label: "lane".into(),
            body: vec![Item::Assign("lanes[i*8 +: 8]".into(), "{8{out_mask[i]}}".into())],
        },
        Item::Blank,
    ];
    let spec = BenchSpec {
        name,
        dut: names.segment.clone(),
        ports: crate::segment::ports(cfg),
        header,
        n_in: spans.len(),
        n_exp: expected.len(),
        in_width,
        exp_width,
        in_fields: vec!["in_x", "in_len", "in_i0", "in_di"],
        extra: lanes,
        mismatch: format!("out_x !== {x} || out_last !== {last} || out_mask !== {mask} || (out_pix & lanes) !== {pix}"),
        describe: (
            "expected x %0d last %0d mask %h pixels %h, got x %0d last %0d mask %h pixels %h".into(),
            format!("{x}, {last}, {mask}, {pix}, out_x, out_last, out_mask, out_pix & lanes"),
        ),
        span_field: span,
        seed,
    };
    let module = bench_module(&spec);
    vec![
        GeneratedFile { name: format!("{name}.v"), contents: module.render() },
        GeneratedFile { name: format!("{name}_in.hex"), contents: hex_file(&format!("{name}: {} spans", spans.len()), inputs) },
        GeneratedFile {
            name: format!("{name}_exp.hex"),
            contents: hex_file(&format!("{name}: {} segments", expected.len()), expected.into_iter()),
        },
    ]
}

fn specular_bench(opts: &Options, name: &str, spans: &[SpecularSpan], seed: u32) -> Vec<GeneratedFile> {
    let cfg = &opts.cfg;
    let unit = opts.specular_unit();
    let lw = cfg.xbits + 1;
    let in_width = 16 + N_BITS + 32 + 32 + lw;
    let inputs = spans.iter().map(|s| {
        Word::default()
            .field(s.c as u64, 16)
            .field(s.n as u64, N_BITS)
            .field(s.theta0 as u32 as u64, 32)
            .field(s.dtheta as u32 as u64, 32)
            .field(s.len as u64, lw)
            .hex()
    });
    let mut expected = Vec::new();
    for (k, s) in spans.iter().enumerate() {
        for px in unit.span(s) {
            expected
                .push(Word::default().field(k as u64, 32).field(px.spec as u64, 16).field(px.err as u64, 1).field(px.last as u64, 1).hex());
        }
    }
    let exp_width = 32 + 16 + 2;
    let spec_names = SpecNames::new(&opts.prefix);
    let header = vec![
        format!("{name} — self-checking testbench of {}, vectors from the segshade golden model.", spec_names.unit),
        "Generated by segshade hdl-gen testbench; do not edit.".into(),
        String::new(),
        format!("Configuration: XW = {}, k-set {:?}.", cfg.xbits, unit.plan().geometry().ks),
        format!("{name}_in.hex: {} spans, one word each: {{in_c, in_n, in_theta0, in_dtheta, in_len}} ({in_width} bits).", spans.len()),
        format!("{name}_exp.hex: {} pixels in output order: {{span, out_spec, out_err, out_last}} ({exp_width} bits).", expected.len()),
        "Every pixel that leaves the unit is compared bit for bit; in_valid gaps, out_ready backpressure,".into(),
        "stalls of up to 255 clocks and full-rate stretches come from an xorshift register.".into(),
    ];
    let spec = BenchSpec {
        name,
        dut: spec_names.unit.clone(),
        ports: crate::specular::ports(cfg),
        header,
        n_in: spans.len(),
        n_exp: expected.len(),
        in_width,
        exp_width,
        in_fields: vec!["in_c", "in_n", "in_theta0", "in_dtheta", "in_len"],
        extra: vec![],
        mismatch: "out_spec !== want[17:2] || out_err !== want[1] || out_last !== want[0]".into(),
        describe: (
            "expected spec %0d err %0d last %0d, got spec %0d err %0d last %0d".into(),
            "want[17:2], want[1], want[0], out_spec, out_err, out_last".into(),
        ),
        span_field: "want[49:18]".into(),
        seed,
    };
    let module = bench_module(&spec);
    vec![
        GeneratedFile { name: format!("{name}.v"), contents: module.render() },
        GeneratedFile { name: format!("{name}_in.hex"), contents: hex_file(&format!("{name}: {} spans", spans.len()), inputs) },
        GeneratedFile {
            name: format!("{name}_exp.hex"),
            contents: hex_file(&format!("{name}: {} pixels", expected.len()), expected.into_iter()),
        },
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_are_msb_first_hex() {
        let mut w = Word::default();
        w.field(1, 1).field(0xab, 8).field(3, 3);
        // 1 1010 1011 011 = 0b1_1010_1011_011 -> 12 bits: 1101 0101 1011
        assert_eq!(w.hex(), "d5b");
        let mut w = Word::default();
        w.field(5, 4);
        assert_eq!(w.hex(), "5");
    }

    #[test]
    fn same_seed_same_files() {
        let opts = Options::default();
        assert_eq!(testbench(&opts, 50, 7).unwrap(), testbench(&opts, 50, 7).unwrap());
        assert_ne!(testbench(&opts, 50, 7).unwrap(), testbench(&opts, 50, 8).unwrap());
        assert_eq!(testbench(&opts, 0, 7), Err(VectorCountError(0)));
        assert_eq!(testbench(&opts, MAX_VECTORS + 1, 7), Err(VectorCountError(MAX_VECTORS + 1)));
    }

    #[test]
    fn spans_fit_the_ports_in_narrow_configurations() {
        for (p, xw) in [(1, 4), (16, 4), (256, 8), (8, 16)] {
            let cfg = Config::new(p, 12, xw, golden::Align::Screen).unwrap();
            // Enough spans that the 4% of zero-length draws come up whatever the seed.
            let spans = segment_spans(&mut SeedRng::seed_from_u64(1), &cfg, 5000);
            assert_eq!(spans.len(), 5000);
            assert!(spans.iter().any(|s| s.len == 0));
            let spec = specular_spans(&mut SeedRng::seed_from_u64(2), &cfg, 200);
            assert!(spec.iter().all(|s| s.len <= cfg.max_len()));
        }
    }
}
