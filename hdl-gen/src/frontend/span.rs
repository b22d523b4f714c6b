//! The span path: I0 of each span's first pixel (and, per scanline, its last) from the walker's
//! running sums, written once as its logical stages ([`golden::pipeline::I0_STAGES`]) and
//! registered where the pipeline level asks; every register moves on `adv`, so one stall holds
//! them all. Then the output register (and, per scanline, the span's dI divider).

use super::divider::DivConns;
use super::hw::Hw;
use super::mul18::{self, MulConns};
use super::stager::Stager;
use super::walker::{self, scanline_divider};
use crate::verilog::{comment, lit, net, reg, set, wire, zext, Item, Stmt};
use crate::Names;
use golden::frontend::{DiMode, SetupForm, Widths};

/// The span's first pixel's intensity and, per scanline, its last pixel's, the edge's value
/// there: the same path twice, under these names.
struct End {
    x: &'static str,
    gx: &'static str,
    s2: &'static str,
    h: &'static str,
    lo: &'static str,
    prod: &'static str,
    qt: &'static str,
    m: &'static str,
    corr: &'static str,
    out: &'static str,
}

/// Bits a multiplier tile takes per operand, unsigned: the ECP5's MULT18X18D (and what the other
/// set-up forms are measured on), or the UP5K's SB_MAC16 for its plan, whose 16 x 16 would
/// split an 18-bit chunk into four.
fn tile_bits(hw: &Hw) -> u32 {
    match hw.fe.setup {
        SetupForm::Ice40Up5k => 16,
        _ => 18,
    }
}

/// A chunk of at most this many bits is multiplied in logic, one adder a bit after the first,
/// instead of taking tiles: a wider one costs more LUT4 than a tile is worth (Yosys 0.23 maps
/// an 8 x 8 product modulo 2^8 to 111 LUT4, docs/fpga.md).
const LOGIC_BITS: u32 = 3;

/// A piece whose shifted adds come to at most this many adder bits ([`adder_bits`]) is made in
/// logic too, whatever its narrower side: the correction's corner, `An`'s top 6 bits against the
/// 8 bits of `q~` below 2^(AW+2) at the defaults (25 adder bits), took a whole tile for 8
/// product bits. The estimate's 3-bit slice is 45; its next piece, 5 x 18 bits, 86, a tile.
const LOGIC_ADDER_BITS: u32 = 48;

/// The adder bits of an `n`-bit chunk times a wider one in logic modulo 2^need: each shifted
/// copy after the first adds the bits it has below 2^need.
fn adder_bits(n: u32, need: u32) -> u32 {
    (1..n).map(|k| need.saturating_sub(k)).sum()
}

/// `x[hi:lo]` of a value as it reads in a stage: its whole self, a slice of a name, or of a
/// slice (the walker's `hi3[..]`).
fn bits_of(x: &str, w: u32, hi: u32, lo: u32) -> String {
    if lo == 0 && hi + 1 == w {
        return x.to_string();
    }
    if let Some((name, range)) = x.strip_suffix(']').and_then(|r| r.split_once('[')) {
        if let Some(base) = range.split_once(':').and_then(|(_, l)| l.parse::<u32>().ok()) {
            return format!("{name}[{}:{}]", base + hi, base + lo);
        }
    }
    format!("{x}[{hi}:{lo}]")
}

/// A product's operand: how it reads in the product's stage, its width, and, where the tiles
/// are `tri_fe_mul18` ([`Hw::dsp_regs`]), how it reads in the stage before: the tile's own input
/// register loads that.
struct Opnd {
    now: String,
    w: u32,
    before: Option<String>,
}

impl Opnd {
    /// `name` as it reads in the stage being written, and the stage before when `dsp`.
    fn of(sp: &Stager, name: &str, w: u32, dsp: bool) -> Opnd {
        Opnd { now: sp.at(name), w, before: dsp.then(|| sp.before(name)) }
    }
}

/// How a product's tiles are made: `bits` a tile's operand ([`tile_bits`]), and the
/// `tri_fe_mul18` module when they are instances with their own registers.
#[derive(Clone, Copy)]
struct Tiles<'a> {
    bits: u32,
    dsp: Option<&'a str>,
}

/// A partial product: its name, width and weight; and for a `tri_fe_mul18` tile, its value
/// from the instance's product register, which the next stage reads in place of a register of
/// its own.
struct Term {
    name: String,
    w: u32,
    off: u32,
    held: Option<String>,
}

/// The partial products of `out = (a * b) mod 2^m` (`a` and `b` read as they are in the stage,
/// unsigned), which [`sum_partials`] joins (a stage later from `--pipeline 1`): the products of
/// `tile`-bit chunks ([`tile_bits`]), only those with a bit below 2^m, each cut to the bits it
/// adds there, each its own wire `<out>_<n>`. A plain `*` would take every tile of the full
/// product: synthesis keeps a tile as long as one of its bits is read. A chunk of at most
/// [`LOGIC_BITS`] bits (the narrower operand's top, say) is multiplied in logic instead, as
/// shifted adds against the whole other operand, and so is a piece of at most
/// [`LOGIC_ADDER_BITS`] adder bits. With `tri_fe_mul18` ([`Tiles::dsp`]) a tile is an instance
/// whose input registers load the operands' chunks from the stage before and whose product
/// register is the product's register into the next stage, all on `adv` as the stage registers.
fn partial_products(sp: &mut Stager, tiles: Tiles, out: &str, a: &Opnd, b: &Opnd, m: u32) -> Vec<Term> {
    let (a, b) = if a.w >= b.w { (a, b) } else { (b, a) };
    let tile = tiles.bits;
    let chunks = |w: u32| (0..w.div_ceil(tile)).map(move |i| (i * tile, (w - i * tile).min(tile)));
    let mut terms: Vec<Term> = Vec::new();
    let mut piece = |sp: &mut Stager, (x, xo, xw): (&Opnd, u32, u32), (y, yo, yw): (&Opnd, u32, u32)| {
        let off = xo + yo;
        if off >= m {
            return;
        }
        let need = m - off;
        let (nx, ny) = (xw.min(need), yw.min(need));
        let (sx, sy) = (bits_of(&x.now, x.w, xo + nx - 1, xo), bits_of(&y.now, y.w, yo + ny - 1, yo));
        let name = format!("{out}_{}", terms.len());
        if nx.min(ny) <= LOGIC_BITS || adder_bits(nx.min(ny), need) <= LOGIC_ADDER_BITS {
            let ((n, nw), (v, vw)) = if nx <= ny { ((sx, nx), (sy, ny)) } else { ((sy, ny), (sx, nx)) };
            let v = zext(&v, vw, need);
            let value = (0..nw)
                .map(|k| {
                    let shifted = if k == 0 { v.clone() } else { format!("({v} << {k})") };
                    format!("({{{need}{{{}}}}} & {shifted})", bits_of(&n, nw, k, k))
                })
                .collect::<Vec<_>>()
                .join(" + ");
            sp.def(&name, need, false, value);
        } else if let (Some(module), Some(bx), Some(by)) = (tiles.dsp, &x.before, &y.before) {
            let (ax, ay) = (bits_of(bx, x.w, xo + nx - 1, xo), bits_of(by, y.w, yo + ny - 1, yo));
            let p = format!("{name}_p");
            // The product's bits above 2^need are not read; nor, perhaps, the operands' bits as
            // this stage holds them (the tile took them a clock earlier): `<name>_in` names them.
            sp.note(comment("verilator lint_off UNUSEDSIGNAL"));
            sp.note(net(&p, mul18::P_BITS));
            sp.note(wire(&format!("{name}_in"), nx + ny, format!("{{{sx}, {sy}}}")));
            sp.note(comment("verilator lint_on UNUSEDSIGNAL"));
            let (ea, eb) = (zext(&ax, nx, mul18::BITS), zext(&ay, ny, mul18::BITS));
            let conns = MulConns { a: &ea, b: &eb, cea: "adv", ceb: "adv", cep: "adv", p: &p, signed: (false, false) };
            sp.note(mul18::instance(module, &format!("u_{name}"), &conns));
            let held = if need >= mul18::P_BITS { zext(&p, mul18::P_BITS, need) } else { format!("{p}[{}:0]", need - 1) };
            terms.push(Term { name, w: need, off, held: Some(held) });
            return;
        } else {
            sp.def(&name, need, false, format!("{} * {}", zext(&sx, nx, need), zext(&sy, ny, need)));
        }
        terms.push(Term { name, w: need, off, held: None });
    };
    for (bo, bc) in chunks(b.w) {
        if bc <= LOGIC_BITS {
            piece(sp, (b, bo, bc), (a, 0, a.w));
            continue;
        }
        for (ao, ac) in chunks(a.w) {
            piece(sp, (a, ao, ac), (b, bo, bc));
        }
    }
    terms
}

/// `out`, the sum of [`partial_products`]' terms modulo 2^m, read where the stage is; a
/// `tri_fe_mul18` tile's term is its product register, named here.
fn sum_partials(sp: &mut Stager, out: &str, terms: &[Term], m: u32) {
    for t in terms {
        if let Some(held) = &t.held {
            sp.def(&t.name, t.w, false, held.clone());
        }
    }
    let sum = terms.iter().map(|t| {
        let x = zext(&sp.at(&t.name), t.w, m);
        if t.off == 0 {
            x
        } else {
            format!("({x} << {})", t.off)
        }
    });
    let sum = sum.collect::<Vec<_>>().join(" + ");
    sp.def(out, m, false, sum);
}

/// The walker's sums are modulo 2^K; the span path reads their residues modulo 2^(K-2), and
/// Gxn's low bits are zero (golden's `Widths::GXN_ZEROS`): the bits it leaves, for the linter.
fn unused_sums(hw: &Hw, sum_w: u32, body: &mut Vec<Item>) {
    let zeros = Widths::GXN_ZEROS;
    body.push(comment("verilator lint_off UNUSEDSIGNAL"));
    if walker::reads_gxn(hw) {
        body.push(wire("unused_sums_top", 4, format!("{{w_tn[{0}:{1}], w_gxn[{0}:{1}]}}", sum_w - 1, sum_w - 2)));
        let gxn_low = format!("{}[{}:0]", walker::row(hw, "w_gxn"), zeros - 1);
        body.push(wire("unused_gxn_low", zeros, gxn_low));
    } else {
        body.push(wire("unused_sums_top", 2, format!("w_tn[{}:{}]", sum_w - 1, sum_w - 2)));
    }
    body.push(comment("verilator lint_on UNUSEDSIGNAL"));
}

/// `Tn + Gxn lo` with `Gxn lo = -(sum << 8)` from the running sums (`gxs`), subtracted a step
/// before S2n, modulo 2^(K-2) as S2n doubles it: the subtract then S2n's add, two carry chains in
/// one clock into the estimate tile's input, were a 25F critical path (`p3_gxs -> S2n`,
/// docs/fpga.md).
fn tn_less_sum(sp: &mut Stager, e: &End, s2_w: u32) {
    let gx = format!("{{{}, {}}}", sp.at("gxs"), lit(Widths::GXN_ZEROS, 0));
    sp.def(&format!("{}_t", e.s2), s2_w - 1, false, format!("{} - {gx}", sp.at("tn")));
}

/// S2n before its doubling, `Tn + Gxn lo` in S2n's width: `Gxn lo` by the product by the column,
/// or from the running sums [`tn_less_sum`]'s.
fn s2n_sum(sp: &Stager, e: &End, by_product: bool, s2_w: u32) -> String {
    if !by_product {
        return zext(&sp.at(&format!("{}_t", e.s2)), s2_w - 1, s2_w);
    }
    let gx = format!("{{{}, {}}}", sp.at(e.gx), lit(Widths::GXN_ZEROS, 0));
    format!("{} + {}", zext(&sp.at("tn"), s2_w - 1, s2_w), zext(&gx, s2_w - 1, s2_w))
}

/// Span stage j's valid bit.
pub(super) fn valid(j: usize) -> String {
    format!("p{j}_v")
}

/// The span path's stages, from the walker's row to I0; returns them for the output and the
/// properties.
pub(super) fn path(hw: &Hw, names: &Names, body: &mut Vec<Item>) -> Stager {
    if super::incremental::on(hw) {
        return super::incremental::span_path(hw);
    }
    let fe = &hw.fe;
    let Widths { yw: row_w, aw: area_w, k: sum_w, rw: recip_w, .. } = fe.widths();
    let (xw, iw, dw) = (fe.cfg.xbits, fe.cfg.iw(), fe.cfg.dw());
    let scan = fe.di == DiMode::Scanline;
    let mut sp = Stager::new("p", golden::pipeline::i0_registers(hw.pipeline).to_vec());
    let i0_section = |sp: &mut Stager| {
        let what = golden::pipeline::I0_STAGES[sp.logical()];
        sp.note(Item::Blank);
        sp.note(comment(format!("Span path, step {} (stage p{}): {what}.", sp.logical(), sp.stage())));
    };
    // S2n is kept modulo 2^(K-1) (at a covered pixel it is below that), the quotient estimate
    // takes its top IW + 1 bits, and the correction is modulo 2^(AW+3): golden's
    // `Widths::reciprocal_quotient`, whose documentation proves the estimate two below at most.
    let s2_w = hw.s2n_bits();
    // A tile with its own registers stands for the stage registers on both sides of its stage.
    let dsp = hw.dsp_regs() && golden::pipeline::i0_registers(hw.pipeline).iter().all(|&c| c);
    let tiles = Tiles { bits: tile_bits(hw), dsp: dsp.then_some(names.fe_mul.as_str()) };
    let t = fe.widths().i0_shift();
    let h_w = s2_w - t;
    // The estimate's bits and the ones below: the product modulo 2^(K - t + IW).
    let prod_w = sum_w - t + iw;
    let corr_w = area_w + 3;
    // Gxn lo is `((Gxn >> z) lo) << z`: the product is z bits narrower (golden's `Widths::gx_lo`).
    let zeros = Widths::GXN_ZEROS;
    let gx_w = s2_w - 1 - zeros;
    let head = End { x: "x", gx: "gx", s2: "s2n", h: "h", lo: "lo", prod: "prod", qt: "qt", m: "m", corr: "corr", out: "i0" };
    let tail = End { x: "xh", gx: "gxh", s2: "s2h", h: "hh", lo: "hi", prod: "prodh", qt: "qh", m: "mh", corr: "corrh", out: "ilast" };
    let ends: Vec<&End> = if scan { vec![&head, &tail] } else { vec![&head] };
    i0_section(&mut sp);
    // The walker's row, or the row stage's ([`walker::row`]).
    let row = |n: &str| walker::row(hw, n);
    // With the running sums (`Hw::run_sums`) the left end's `Gxn lo` is minus the sum the row
    // stage chose (`gxs`, golden's `frontend::sums`): no product by the column.
    let (sums, gxn) = (hw.run_sums(), walker::reads_gxn(hw));
    for (n, ww, src) in [
        ("y", row_w, row("w_row")),
        ("x", xw, "lo_u".into()),
        ("len", xw + 1, format!("len_w[{xw}:0]")),
        ("tn", s2_w - 1, format!("{}[{}:0]", row("w_tn"), s2_w - 2)),
        ("gxn", gx_w, format!("{}[{}:{zeros}]", row("w_gxn"), s2_w - 2)),
        ("gxs", gx_w, row("w_gxs")),
        ("an", area_w, row("w_an")),
        ("rn", recip_w, row("w_rn")),
    ] {
        if (n != "gxn" || gxn) && (n != "gxs" || sums) {
            sp.input_as(n, ww, false, &src);
        }
    }
    unused_sums(hw, sum_w, body);
    let by_product = |e: &End| !sums || e.x != head.x; // `Gxn lo` by a product by the column
    if scan {
        sp.input_as("xh", xw, false, &format!("hi3[{}:0]", xw - 1));
        body.push(comment("verilator lint_off UNUSEDSIGNAL"));
        body.push(wire("unused_di", dw, "w_di"));
        body.push(comment("verilator lint_on UNUSEDSIGNAL"));
    } else {
        sp.input_as("di", dw, false, &row("w_di"));
    }
    sp.cut();
    i0_section(&mut sp);
    // Gxn lo modulo 2^(K-2): S2n's residue needs no more. Its partial products in one stage,
    // their sum in the next.
    let mut gx_partials = Vec::new();
    for e in ends.iter().filter(|e| by_product(e)) {
        let (gxn, x) = (Opnd::of(&sp, "gxn", gx_w, dsp), Opnd::of(&sp, e.x, xw, dsp));
        gx_partials.push(partial_products(&mut sp, tiles, e.gx, &gxn, &x, gx_w));
    }
    sp.cut();
    i0_section(&mut sp);
    sp.note(comment("verilator lint_off UNUSEDSIGNAL"));
    for (e, terms) in ends.iter().filter(|e| by_product(e)).zip(&gx_partials) {
        sum_partials(&mut sp, e.gx, terms, gx_w);
    }
    sp.note(comment("verilator lint_on UNUSEDSIGNAL"));
    for e in ends.iter().filter(|e| !by_product(e)) {
        tn_less_sum(&mut sp, e, s2_w);
    }
    sp.cut();
    i0_section(&mut sp);
    for e in &ends {
        let sum = s2n_sum(&sp, e, by_product(e), s2_w);
        sp.def(e.s2, s2_w, false, format!("(({sum}) << 1) + {}", zext(&sp.at("an"), area_w, s2_w)));
    }
    sp.cut();
    i0_section(&mut sp);
    let mut partials = Vec::new();
    let an = sp.at("an");
    sp.def("an2", corr_w, false, format!("{} << 1", zext(&an, area_w, corr_w)));
    sp.def("an4", corr_w, false, format!("{} << 2", zext(&an, area_w, corr_w)));
    for e in &ends {
        let s2 = sp.at(e.s2);
        sp.def(e.lo, corr_w, false, format!("{s2}[{}:0]", corr_w - 1));
        // The remainder's residue less 2An and 4An, ahead of the product (golden's
        // `Widths::corrected_quotient`): the correction then subtracts the product once.
        for k in [2, 4] {
            sp.def(&format!("{}_a{k}", e.corr), corr_w, false, format!("{} - an{k}", e.lo));
        }
        sp.def(e.h, h_w, false, format!("{s2}[{}:{t}]", s2_w - 1));
        // H is S2n's top bits: a clock earlier, those of S2n there.
        let h = Opnd { now: e.h.into(), w: h_w, before: dsp.then(|| format!("{}[{}:{t}]", sp.before(e.s2), s2_w - 1)) };
        let rn = Opnd::of(&sp, "rn", recip_w, dsp);
        partials.push(partial_products(&mut sp, tiles, e.prod, &h, &rn, prod_w));
    }
    sp.cut();
    i0_section(&mut sp);
    sp.note(comment("verilator lint_off UNUSEDSIGNAL"));
    for (e, terms) in ends.iter().zip(&partials) {
        sum_partials(&mut sp, e.prod, terms, prod_w);
    }
    sp.note(comment("verilator lint_on UNUSEDSIGNAL"));
    for e in &ends {
        sp.def(e.qt, iw, false, format!("{}[{}:{}]", e.prod, sum_w - t + iw - 1, sum_w - t));
    }
    sp.cut();
    i0_section(&mut sp);
    // q~ An modulo 2^(AW+2), doubled: the correction's modulus. Its partial products in one
    // stage, their sum in the next.
    let mut m_partials = Vec::new();
    for e in &ends {
        let (qt, an) = (sp.at(e.qt), Opnd::of(&sp, "an", area_w, dsp));
        let qto = Opnd::of(&sp, e.qt, iw, dsp);
        m_partials.push(partial_products(&mut sp, tiles, &format!("{}_an", e.m), &an, &qto, corr_w - 1));
        // The corrected quotient's other two values, beside the product.
        for k in [1, 2] {
            sp.def(&format!("{}{k}", e.qt), iw, false, format!("{qt} + {}", lit(iw, k)));
        }
    }
    sp.cut();
    i0_section(&mut sp);
    for (e, terms) in ends.iter().zip(&m_partials) {
        let half_m = format!("{}_an", e.m);
        sum_partials(&mut sp, &half_m, terms, corr_w - 1);
        sp.def(e.m, corr_w, false, format!("{{{half_m}, 1'b0}}"));
    }
    sp.cut();
    i0_section(&mut sp);
    for e in &ends {
        correction(&mut sp, e, iw, corr_w);
    }
    sp
}

/// The last stage: `I0` from `q~`, `q~ + 1`, `q~ + 2` by the signs of `R - 2An` and `R - 4An`.
/// `R - 2k An = ((S2n - 2k An) - 2An q~) mod 2^(AW+3)` is negative exactly when its top bit is
/// set (golden's `Widths::corrected_quotient`), and R >= 4An implies R >= 2An: one subtraction
/// and a select (a compare after the subtraction and an add after it were the 25F's critical
/// path, docs/fpga.md).
fn correction(sp: &mut Stager, e: &End, iw: u32, corr_w: u32) {
    let m = sp.at(e.m);
    sp.note(comment("verilator lint_off UNUSEDSIGNAL"));
    for k in [2, 4] {
        let a = sp.at(&format!("{}_a{k}", e.corr));
        sp.def(&format!("{}{k}", e.corr), corr_w, false, format!("{a} - {m}"));
    }
    sp.note(comment("verilator lint_on UNUSEDSIGNAL"));
    for k in [2, 4] {
        sp.def(&format!("{}_ge{k}", e.out), 1, false, format!("!{}{k}[{}]", e.corr, corr_w - 1));
    }
    let (qt, qt1, qt2) = (sp.at(e.qt), sp.at(&format!("{}1", e.qt)), sp.at(&format!("{}2", e.qt)));
    sp.def(e.out, iw, false, format!("{0}_ge4 ? {qt2} : {0}_ge2 ? {qt1} : {qt}", e.out));
}

/// The output register, loaded from the span path's last stage (per scanline, after the span's
/// dI divider).
pub(super) fn output(hw: &Hw, names: &Names, mut sp: Stager, body: &mut Vec<Item>) -> Stager {
    let fe = &hw.fe;
    let (xw, iw, dw) = (fe.cfg.xbits, fe.cfg.iw(), fe.cfg.dw());
    let scan = fe.di == DiMode::Scanline;
    let (sdv, sd_cnt_w) = scanline_divider(hw);
    let sd_qbits = sdv.qb;
    let (oy, ox, olen) = (sp.at("y"), sp.at("x"), sp.at("len"));
    let odi = if scan { lit(dw, 0) } else { sp.at("di") };
    let nsp = sp.stage();
    let pv = valid;
    for j in 1..=nsp {
        body.push(reg(&pv(j), 1));
    }
    let mut p_scan = Vec::new();
    let mut ostall = vec![];
    if scan {
        sp.note(comment("dI = round(|I_last - I0| / (m - 1)), its sign apart: (2 |N| + D) / 2D, D = m - 1."));
        sp.def("p_div", 1, false, format!("{olen} > {}", lit(xw + 1, 1)));
        sp.def("nabs", iw, false, "ilast >= i0 ? ilast - i0 : i0 - ilast");
        sp.def("dm1", xw + 1, false, format!("{olen} - {}", lit(xw + 1, 1)));
        sp.note(Item::Blank);
        let start_div = format!("!rst && adv && {} && p_div", pv(nsp));
        let dividend = format!("({} << 1) + {}", zext("nabs", iw, sdv.pw), zext("dm1", xw + 1, sdv.pw));
        let divisor = format!("{} << {sd_qbits}", zext("dm1", xw + 1, sdv.pw));
        let conns = DivConns { cnt: "sd_cnt", load: &start_div, run: "!rst && sd_busy", dividend: &dividend, divisor: &divisor };
        for item in sdv.instance(&names.fe_div, hw.div_bits, sd_cnt_w, &conns, &["q_next"]) {
            sp.note(item);
        }
        sp.def("sd_fin", 1, false, format!("sd_cnt < {}", lit(sd_cnt_w, hw.div_bits as u64)));
        let q = sdv.out("q_next");
        sp.def("sd_di", dw, false, format!("sd_neg ? -{} : {}", zext(&q, iw, dw), zext(&q, iw, dw)));
        let start = vec![set("sd_busy", "1'b1"), set("sd_cnt", lit(sd_cnt_w, (sd_qbits - 1) as u64)), set("sd_neg", "ilast < i0")];
        let run = vec![Stmt::If(
            "sd_fin".into(),
            vec![set("sd_busy", "1'b0")],
            vec![set("sd_cnt", format!("sd_cnt - {}", lit(sd_cnt_w, hw.div_bits as u64)))],
        )];
        p_scan.push(Item::Always(vec![Stmt::If(
            "rst".into(),
            vec![set("sd_busy", "1'b0")],
            vec![Stmt::If(format!("adv && {} && p_div", pv(nsp)), start, vec![Stmt::If("sd_busy".into(), run, vec![])])],
        )]));
        ostall = vec![Stmt::If("sd_busy && sd_fin".into(), vec![set("out_valid", "1'b1"), set("out_di", "sd_di")], vec![])];
    }
    body.extend(sp.items());
    body.extend(p_scan);
    let mut moves: Vec<Stmt> = vec![set(pv(1), "emit")];
    moves.extend((2..=nsp).map(|j| set(pv(j), pv(j - 1))));
    for j in 0..nsp {
        moves.extend(sp.loads(j));
    }
    moves.extend([
        set("out_valid", if scan { format!("{} && !p_div", pv(nsp)) } else { pv(nsp) }),
        set("out_y", oy.clone()),
        set("out_x", ox.clone()),
        set("out_len", olen.clone()),
        set("out_i0", "i0"),
        set("out_di", odi.clone()),
    ]);
    let mut resets: Vec<Stmt> = (1..=nsp).map(|j| set(pv(j), "1'b0")).collect();
    resets.push(set("out_valid", "1'b0"));
    body.push(Item::Always(vec![Stmt::If("rst".into(), resets, vec![Stmt::If("adv".into(), moves, ostall)])]));
    sp
}
