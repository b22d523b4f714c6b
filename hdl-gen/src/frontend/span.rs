//! The span path: I0 of each span's first pixel (and, per scanline, its last) from the walker's
//! running sums, written once as its logical stages ([`golden::pipeline::I0_STAGES`]) and
//! registered where the pipeline level asks; every register moves on `adv`, so one stall holds
//! them all. Then the output register (and, per scanline, the span's dI divider).

use super::divider::DivConns;
use super::hw::Hw;
use super::stager::Stager;
use super::walker::{self, scanline_divider};
use crate::verilog::{comment, lit, reg, set, wire, zext, Item, Stmt};
use crate::Names;
use golden::frontend::{DiMode, Widths};

/// The span's first pixel's intensity and, per scanline, its last pixel's, the edge's value
/// there: the same path twice, under these names.
struct End {
    x: &'static str,
    gx: &'static str,
    s2: &'static str,
    lo: &'static str,
    pl: &'static str,
    ph: &'static str,
    prod: &'static str,
    qt: &'static str,
    m: &'static str,
    corr: &'static str,
    out: &'static str,
}

/// Span stage j's valid bit.
pub(super) fn valid(j: usize) -> String {
    format!("p{j}_v")
}

/// The span path's stages, from the walker's row to I0; returns them for the output and the
/// properties.
pub(super) fn path(hw: &Hw, body: &mut Vec<Item>) -> Stager {
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
    let prod_w = sum_w + recip_w;
    let corr_w = area_w + 2;
    let half = recip_w / 2;
    // The span's first pixel's intensity and, per scanline, its last pixel's, the edge's value
    // there: the same path twice, under these names.
    let head = End { x: "x", gx: "gx", s2: "s2n", lo: "lo", pl: "pl", ph: "ph", prod: "prod", qt: "qt", m: "m", corr: "corr", out: "i0" };
    let tail = End {
        x: "xh",
        gx: "gxh",
        s2: "s2h",
        lo: "hi",
        pl: "plh",
        ph: "phh",
        prod: "prodh",
        qt: "qh",
        m: "mh",
        corr: "corrh",
        out: "ilast",
    };
    let ends: Vec<&End> = if scan { vec![&head, &tail] } else { vec![&head] };
    i0_section(&mut sp);
    // The walker's row, or the row stage's ([`walker::row`]).
    let row = |n: &str| walker::row(hw, n);
    for (n, ww, src) in [
        ("y", row_w, row("w_row")),
        ("x", xw, "lo_u".into()),
        ("len", xw + 1, format!("len_w[{xw}:0]")),
        ("tn", sum_w, row("w_tn")),
        ("gxn", sum_w, row("w_gxn")),
        ("an", area_w, row("w_an")),
        ("rn", recip_w, row("w_rn")),
    ] {
        sp.input_as(n, ww, false, &src);
    }
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
    for e in &ends {
        sp.def(e.gx, sum_w, false, format!("{} * {}", sp.at("gxn"), zext(&sp.at(e.x), xw, sum_w)));
    }
    sp.cut();
    i0_section(&mut sp);
    for e in &ends {
        sp.def(e.s2, sum_w, false, format!("(({} + {}) << 1) + {}", sp.at("tn"), sp.at(e.gx), zext(&sp.at("an"), area_w, sum_w)));
    }
    sp.cut();
    i0_section(&mut sp);
    let split = sp.registered_next();
    for e in &ends {
        let s2 = sp.at(e.s2);
        sp.def(e.lo, corr_w, false, format!("{s2}[{}:0]", corr_w - 1));
        if split {
            let rn = sp.at("rn");
            sp.def(
                e.pl,
                sum_w + half,
                false,
                format!("{} * {}", zext(&s2, sum_w, sum_w + half), zext(&format!("{rn}[{}:0]", half - 1), half, sum_w + half)),
            );
            sp.def(
                e.ph,
                sum_w + recip_w - half,
                false,
                format!(
                    "{} * {}",
                    zext(&s2, sum_w, sum_w + recip_w - half),
                    zext(&format!("{rn}[{}:{half}]", recip_w - 1), recip_w - half, sum_w + recip_w - half)
                ),
            );
        }
    }
    sp.cut();
    i0_section(&mut sp);
    sp.note(comment("verilator lint_off UNUSEDSIGNAL"));
    for e in &ends {
        let prod = if split {
            let (pl, ph) = (sp.at(e.pl), sp.at(e.ph));
            format!("{} + ({} << {half})", zext(&pl, sum_w + half, prod_w), zext(&ph, sum_w + recip_w - half, prod_w))
        } else {
            format!("{} * {}", zext(&sp.at(e.s2), sum_w, prod_w), zext(&sp.at("rn"), recip_w, prod_w))
        };
        sp.def(e.prod, prod_w, false, prod);
    }
    sp.note(comment("verilator lint_on UNUSEDSIGNAL"));
    for e in &ends {
        sp.def(e.qt, iw, false, format!("{}[{}:{sum_w}]", e.prod, sum_w + iw - 1));
    }
    sp.cut();
    i0_section(&mut sp);
    sp.def("an2", corr_w, false, format!("{} << 1", zext(&sp.at("an"), area_w, corr_w)));
    for e in &ends {
        sp.def(e.m, corr_w, false, format!("{} * an2", zext(&sp.at(e.qt), iw, corr_w)));
    }
    sp.cut();
    i0_section(&mut sp);
    let an2 = sp.at("an2");
    for e in &ends {
        let (lo, m, qt) = (sp.at(e.lo), sp.at(e.m), sp.at(e.qt));
        sp.def(e.corr, corr_w, false, format!("{lo} - {m}"));
        sp.def(e.out, iw, false, format!("{qt} + {}", zext(&format!("{} >= {an2}", e.corr), 1, iw)));
    }
    sp
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
