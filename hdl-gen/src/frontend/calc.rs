//! CALC: the set-up's arithmetic (SPEC §6), written once as its stages
//! ([`golden::pipeline::SETUP_STAGES`]): one clock at level 0, a register boundary after each
//! stage above it.

use super::hw::{slit, Hw};
use super::stager::Stager;
use crate::verilog::{comment, lit, sext, zext, Item};
use golden::frontend::Widths;

/// CALC's stages, from the vertex registers' values to the dividers' loads. Values are computed
/// where their operands are ready, so a sign decided late (the area's) is applied to products
/// formed early: the products are taken of unoriented differences and negated with the
/// orientation. The caller reads what the last stage hands on before it declares the stage
/// registers ([`Stager::items`] refuses a register added after).
pub(super) fn calc(hw: &Hw) -> Stager {
    let c = Calc::new(hw);
    let mut st = Stager::new("c", vec![c.cuts > 0; golden::pipeline::SETUP_STAGES.len() - 1]);
    for k in 0..3 {
        st.input(&format!("vx{k}"), c.vx_w, true);
        st.input(&format!("vy{k}"), c.vy_w, true);
        st.input(&format!("vi{k}"), c.iw, false);
    }
    let stages: [fn(&Calc, &mut Stager); 5] = [Calc::stage0, Calc::stage1, Calc::stage2, Calc::stage3, Calc::stage4];
    for (j, stage) in stages.iter().enumerate() {
        c.section(&mut st);
        stage(&c, &mut st);
        if j + 1 < stages.len() {
            st.cut();
        }
    }
    st
}

/// The widths and screen CALC's stages share.
#[derive(Clone, Copy)]
struct Calc {
    row_w: u32,
    vx_w: u32,
    vy_w: u32,
    area_w: u32,
    bound_w: u32,
    sum_w: u32,
    shift_w: u32,
    iw: u32,
    w: i64,
    h: i64,
    nx_w: u32,
    ny_w: u32,
    col_s_w: u32,
    row_s_w: u32,
    edge_n_w: u32,
    /// Registered boundaries: 0 at level 0.
    cuts: usize,
}

/// Edge k runs from vertex k + 1 to vertex k + 2.
fn edge(k: usize) -> (usize, usize) {
    ((k + 1) % 3, (k + 2) % 3)
}

/// The smallest (`less`) or largest of three signals, as one expression.
fn min3(a: &str, b: &str, c: &str, less: bool) -> String {
    let op = if less { "<" } else { ">" };
    format!("(({a} {op} {b}) ? (({a} {op} {c}) ? {a} : {c}) : (({b} {op} {c}) ? {b} : {c}))")
}

impl Calc {
    fn new(hw: &Hw) -> Calc {
        let fe = &hw.fe;
        let cfg = &fe.cfg;
        let Widths { yw: row_w, cx: vx_w, cy: vy_w, aw: area_w, gw: bound_w, k: sum_w, sw: shift_w, .. } = fe.widths();
        let (xw, iw) = (cfg.xbits, cfg.iw());
        Calc {
            row_w,
            vx_w,
            vy_w,
            area_w,
            bound_w,
            sum_w,
            shift_w,
            iw,
            w: fe.screen.width as i64,
            h: fe.screen.height as i64,
            nx_w: iw + vy_w + 3,
            ny_w: iw + vx_w + 3,
            col_s_w: xw + 3,
            row_s_w: vy_w - 7,
            edge_n_w: vx_w + vy_w + 5,
            cuts: hw.pipeline.calc_clocks() as usize - 1,
        }
    }

    fn section(&self, st: &mut Stager) {
        let what = golden::pipeline::SETUP_STAGES[st.logical()];
        let head = if self.cuts == 0 { format!("CALC, step {} of the clock", st.logical()) } else { format!("CALC stage {}", st.stage()) };
        st.note(Item::Blank);
        st.note(comment(format!("{head}: {what}.")));
    }

    /// Stage 0, from the vertex registers: the guard band, the differences, the bounding box.
    fn stage0(&self, st: &mut Stager) {
        let Calc { row_w: _, vx_w, vy_w, iw, w, h, .. } = *self;
        let gx = |v: &str| {
            let hi = 2 * w * 256;
            let below = if hi > (1i64 << (vx_w - 1)) - 1 { String::new() } else { format!(" && {v} < {}", slit(vx_w, hi)) };
            format!("({v} >= {}{below})", slit(vx_w, -w * 256))
        };
        let gy = |v: &str| {
            let hi = 2 * h * 256;
            let below = if hi > (1i64 << (vy_w - 1)) - 1 { String::new() } else { format!(" && {v} < {}", slit(vy_w, hi)) };
            format!("({v} >= {}{below})", slit(vy_w, -h * 256))
        };
        let guard: Vec<String> = (0..3).flat_map(|k| [gx(&format!("vx{k}")), gy(&format!("vy{k}"))]).collect();
        st.def("guard_ok", 1, false, guard.join(" && "));
        st.note(comment("Edge k runs from vertex k+1 to vertex k+2; u, v span the area, d the intensities."));
        for (n, a, b, ww) in
            [("u1", "vx1", "vx0", vx_w), ("u2", "vx2", "vx0", vx_w), ("v1", "vy1", "vy0", vy_w), ("v2", "vy2", "vy0", vy_w)]
        {
            st.def(n, ww + 1, true, format!("{} - {}", sext(a, ww, ww + 1), sext(b, ww, ww + 1)));
        }
        for k in 0..3 {
            let (a, b) = edge(k);
            st.def(
                &format!("rdx{k}"),
                vx_w + 1,
                true,
                format!("{} - {}", sext(&format!("vx{b}"), vx_w, vx_w + 1), sext(&format!("vx{a}"), vx_w, vx_w + 1)),
            );
            st.def(
                &format!("rdy{k}"),
                vy_w + 1,
                true,
                format!("{} - {}", sext(&format!("vy{b}"), vy_w, vy_w + 1), sext(&format!("vy{a}"), vy_w, vy_w + 1)),
            );
        }
        let iz = |v: &str, to: u32| zext(v, iw, to);
        st.def("d1", iw + 1, true, format!("{} - {}", iz("vi1", iw + 1), iz("vi0", iw + 1)));
        st.def("d2", iw + 1, true, format!("{} - {}", iz("vi2", iw + 1), iz("vi0", iw + 1)));
        st.note(comment("Bounding box in rows and columns (centres at +128 sub-pixels); each edge's rows."));
        st.def("ymin", vy_w, true, min3("vy0", "vy1", "vy2", true));
        st.def("ymax", vy_w, true, min3("vy0", "vy1", "vy2", false));
        st.def("xmin", vx_w, true, min3("vx0", "vx1", "vx2", true));
        st.def("xmax", vx_w, true, min3("vx0", "vx1", "vx2", false));
        st.def("xmin_c", vx_w + 1, true, format!("{} + {}", sext("xmin", vx_w, vx_w + 1), slit(vx_w + 1, 127)));
        st.def("xmax_c", vx_w + 1, true, format!("{} - {}", sext("xmax", vx_w, vx_w + 1), slit(vx_w + 1, 128)));
        for k in 0..3 {
            let (a, b) = edge(k);
            let (ya, yb2) = (format!("vy{a}"), format!("vy{b}"));
            st.def(&format!("yt{k}"), vy_w, true, format!("{ya} < {yb2} ? {ya} : {yb2}"));
            st.def(&format!("yb{k}"), vy_w, true, format!("{ya} < {yb2} ? {yb2} : {ya}"));
            st.def(&format!("ytc{k}"), vy_w + 1, true, format!("{} + {}", sext(&format!("yt{k}"), vy_w, vy_w + 1), slit(vy_w + 1, 127)));
            st.def(&format!("ybc{k}"), vy_w + 1, true, format!("{} - {}", sext(&format!("yb{k}"), vy_w, vy_w + 1), slit(vy_w + 1, 128)));
            // x distance from vertex a to the first column's centre, for e(128, .) below.
            st.def(&format!("rx{k}"), vx_w + 2, true, format!("{} - {}", lit(vx_w + 2, 128), sext(&format!("vx{a}"), vx_w, vx_w + 2)));
        }
        st.def("xo", vx_w + 2, true, format!("{} - {}", lit(vx_w + 2, 128), sext("vx0", vx_w, vx_w + 2)));
    }

    /// Stage 1: the area's and the normal's products; the rows.
    fn stage1(&self, st: &mut Stager) {
        let Calc { row_w, vx_w, vy_w, iw, h, col_s_w, row_s_w, .. } = *self;
        st.mul("m_a1", "u1", vx_w + 1, "v2", vy_w + 1);
        st.mul("m_a2", "v1", vy_w + 1, "u2", vx_w + 1);
        st.mul("m_x1", "d1", iw + 1, "v2", vy_w + 1);
        st.mul("m_x2", "d2", iw + 1, "v1", vy_w + 1);
        st.mul("m_y1", "d2", iw + 1, "u1", vx_w + 1);
        st.mul("m_y2", "d1", iw + 1, "u2", vx_w + 1);
        st.def("ymin_c", vy_w + 1, true, format!("{} + {}", sext(&st.at("ymin"), vy_w, vy_w + 1), slit(vy_w + 1, 127)));
        st.def("first_raw", row_s_w, true, format!("ymin_c[{vy_w}:8]"));
        st.def("first_s", row_s_w, true, format!("first_raw[{}] ? {} : first_raw", row_s_w - 1, slit(row_s_w, 0)));
        st.def("cfirst", col_s_w, true, format!("{}[{vx_w}:8]", st.at("xmin_c")));
        st.def("clast", col_s_w, true, format!("{}[{vx_w}:8]", st.at("xmax_c")));
        let first_centre = format!("{{first_s[{}:0], 8'd128}}", row_w - 1);
        st.def("yo", vy_w + 2, true, format!("{} - {}", zext(&first_centre, row_w + 8, vy_w + 2), sext(&st.at("vy0"), vy_w, vy_w + 2)));
        st.note(comment("Per edge: its rows on the screen, and the y distance from vertex a to its first row's centre."));
        for k in 0..3 {
            let (a, _) = edge(k);
            st.def(&format!("rs_raw{k}"), row_s_w, true, format!("{}[{vy_w}:8]", st.at(&format!("ytc{k}"))));
            st.def(&format!("re_raw{k}"), row_s_w, true, format!("{}[{vy_w}:8]", st.at(&format!("ybc{k}"))));
            st.def(&format!("rs{k}"), row_s_w, true, format!("rs_raw{k} > first_s ? rs_raw{k} : first_s"));
            st.def(&format!("rsu{k}"), row_w, false, format!("rs{k}[{}:0]", row_w - 1));
            st.def(
                &format!("ry{k}"),
                vy_w + 2,
                true,
                format!(
                    "{} - {}",
                    zext(&format!("{{rsu{k}, 8'd128}}"), row_w + 8, vy_w + 2),
                    sext(&st.at(&format!("vy{a}")), vy_w, vy_w + 2)
                ),
            );
            let r = st.at(&format!("rdy{k}"));
            st.def(&format!("ady{k}"), vy_w, false, format!("{r}[{vy_w}] ? -{r}[{}:0] : {r}[{}:0]", vy_w - 1, vy_w - 1));
            // The signs the orientation needs, before it is known: it only flips them.
            st.def(&format!("rdz{k}"), 1, false, format!("{r} == {}", slit(vy_w + 1, 0)));
            let x = st.at(&format!("rdx{k}"));
            st.def(&format!("rdxp{k}"), 1, false, format!("{x} > {}", slit(vx_w + 1, 0)));
            st.def(&format!("rdxn{k}"), 1, false, format!("{x}[{vx_w}]"));
        }
        st.note(comment("The last row both ways: as it is, and one sub-pixel up for a bottom edge on a row's centres."));
        let ymax = st.at("ymax");
        for (n, off) in [("0", 128), ("1", 129)] {
            st.def(&format!("ymax_c{n}"), vy_w + 1, true, format!("{} - {}", sext(&ymax, vy_w, vy_w + 1), slit(vy_w + 1, off)));
            st.def(&format!("last_raw{n}"), row_s_w, true, format!("ymax_c{n}[{vy_w}:8]"));
            st.def(
                &format!("last_s{n}"),
                row_s_w,
                true,
                format!("last_raw{n} > {} ? {} : last_raw{n}", slit(row_s_w, h - 1), slit(row_s_w, h - 1)),
            );
        }
    }

    /// Stage 2: the area and its sign; the orientation; the edges' products.
    fn stage2(&self, st: &mut Stager) {
        let Calc { vx_w, vy_w, area_w, bound_w, nx_w, ny_w, row_s_w, edge_n_w, .. } = *self;
        st.note(comment("Twice the signed area: its sign orients the edges and the plane (interior positive)."));
        st.def("area", area_w + 1, true, format!("{} - {}", st.at("m_a1"), st.at("m_a2")));
        st.def("neg", 1, false, format!("area[{area_w}]"));
        st.def("area_n", area_w + 1, false, "neg ? -area : area");
        st.def("aabs", area_w, false, format!("area_n[{}:0]", area_w - 1));
        st.note(comment("The plane's normal, unoriented, and |Nx| (the orientation does not change it)."));
        st.def("nx", nx_w, true, format!("{} - {}", sext(&st.at("m_x1"), nx_w - 1, nx_w), sext(&st.at("m_x2"), nx_w - 1, nx_w)));
        st.def("ny", ny_w, true, format!("{} - {}", sext(&st.at("m_y1"), ny_w - 1, ny_w), sext(&st.at("m_y2"), ny_w - 1, ny_w)));
        st.def("mag", nx_w, false, format!("nx[{}] ? -nx : nx", nx_w - 1));
        for k in 0..3 {
            st.mul(&format!("m_e{k}"), &format!("rdx{k}"), vx_w + 1, &format!("ry{k}"), vy_w + 2);
            st.mul(&format!("m_f{k}"), &format!("rdy{k}"), vy_w + 1, &format!("rx{k}"), vx_w + 2);
        }
        st.note(comment("Orientation: edge k's direction with the interior on its left (dy < 0: going up); the"));
        st.note(comment("top-left rule. From the signs alone: the orientation flips them."));
        for k in 0..3 {
            let (z, xp, xn) = (st.at(&format!("rdz{k}")), st.at(&format!("rdxp{k}")), st.at(&format!("rdxn{k}")));
            let ry = st.at(&format!("rdy{k}"));
            st.def(&format!("dyneg{k}"), 1, false, format!("!{z} && (neg ? !{ry}[{vy_w}] : {ry}[{vy_w}])"));
            st.def(&format!("tl{k}"), 1, false, format!("dyneg{k} || ({z} && (neg ? {xn} : {xp}))"));
        }
        st.note(comment("A horizontal edge that is not top-left is a bottom edge: centres on it are not covered."));
        st.def("kill", 1, false, (0..3).map(|k| format!("({} && !tl{k})", st.at(&format!("rdz{k}")))).collect::<Vec<_>>().join(" || "));
        st.def("last_s", row_s_w, true, format!("kill ? {} : {}", st.at("last_s1"), st.at("last_s0")));
        st.note(comment("Per edge, the offset of its first bound's dividend: B D, 1 less off a top-left edge."));
        for k in 0..3 {
            let ady = st.at(&format!("ady{k}"));
            st.def(
                &format!("base{k}"),
                edge_n_w,
                false,
                format!("({} << {}) - {}", zext(&ady, vy_w, edge_n_w), bound_w + 7, zext(&format!("!tl{k}"), 1, edge_n_w)),
            );
        }
    }

    /// Stage 3: cull, the edges' dividends, the plane oriented, the normalising shift.
    fn stage3(&self, st: &mut Stager) {
        let Calc { vx_w, vy_w, area_w, bound_w, shift_w, iw, w, nx_w, ny_w, col_s_w, row_s_w, edge_n_w, .. } = *self;
        let neg = st.at("neg");
        for k in 0..3 {
            st.def(&format!("dx{k}"), vx_w + 1, true, format!("{neg} ? -{r} : {r}", r = st.at(&format!("rdx{k}"))));
        }
        let (first_s, cfirst, clast, last_s) = (st.at("first_s"), st.at("cfirst"), st.at("clast"), st.at("last_s"));
        st.def(
            "cull",
            1,
            false,
            format!(
                "{} == {} || {first_s} > {last_s} || {cfirst} > {clast} || {cfirst} > {} || {clast}[{}]",
                st.at("area"),
                slit(area_w + 1, 0),
                slit(col_s_w, w - 1),
                col_s_w - 1
            ),
        );
        // e(128, 256 rs + 128) - t + B D from vertex a on the edge's line: the oriented products'
        // difference (one subtraction, its operands swapped by the orientation), 1 less off a
        // top-left edge, offset by B = 2^(GW-1) divisors so both quotients are non-negative (q = g + B).
        st.note(comment("Per edge: its active rows; the dividends of its first bound and of its step."));
        let step_n_w = (vx_w + 2).max(bound_w + vy_w + 1);
        for k in 0..3 {
            let re_raw = st.at(&format!("re_raw{k}"));
            st.def(&format!("re{k}"), row_s_w, true, format!("{re_raw} < {last_s} ? {re_raw} : {last_s}"));
            st.def(&format!("act{k}"), 1, false, format!("!{} && {} <= re{k}", st.at(&format!("rdz{k}")), st.at(&format!("rs{k}"))));
            let (me, mf, ady) = (st.at(&format!("m_e{k}")), st.at(&format!("m_f{k}")), st.at(&format!("ady{k}")));
            let (me, mf) = (sext(&me, edge_n_w - 2, edge_n_w), sext(&mf, edge_n_w - 2, edge_n_w));
            st.def(&format!("e{k}"), edge_n_w, false, format!("({neg} ? {mf} : {me}) - ({neg} ? {me} : {mf})"));
            st.def(&format!("n{k}"), edge_n_w, false, format!("e{k} + {}", st.at(&format!("base{k}"))));
            st.def(
                &format!("sn{k}"),
                step_n_w,
                false,
                format!("{} + ({} << {})", sext(&format!("dx{k}"), vx_w + 1, step_n_w), zext(&ady, vy_w, step_n_w), bound_w - 1),
            );
        }
        st.note(comment("The plane: Nx, Ny oriented; dI's dividend 2*256|Nx| + |A| and its saturation."));
        let aabs = st.at("aabs");
        st.def("onx", nx_w, true, format!("{neg} ? -{nx} : {nx}", nx = st.at("nx")));
        st.def("ony", ny_w, true, format!("{neg} ? -{ny} : {ny}", ny = st.at("ny")));
        st.def("nx_neg", 1, false, format!("onx[{}]", nx_w - 1));
        let x2w = (nx_w + 9).max(area_w + 1);
        let cmpw = x2w.max(area_w + iw + 1);
        st.def("x2", x2w, false, format!("({} << 9) + {}", zext(&st.at("mag"), nx_w, x2w), zext(&aabs, area_w, x2w)));
        st.def("di_sat", 1, false, format!("{} >= ({} << {})", zext("x2", x2w, cmpw), zext(&aabs, area_w, cmpw), iw + 1));
        st.note(comment("Normalisation: s leading zeros of |A|, An = |A| << s."));
        let mut chain = lit(shift_w, (area_w - 1) as u64);
        for bit in 1..area_w {
            chain = format!("{aabs}[{bit}] ? {} : {chain}", lit(shift_w, (area_w - 1 - bit) as u64));
        }
        st.def("lz", shift_w, false, chain);
        st.note(comment("The first row's sum S(0, first) = I0 |A| + Nx xo + Ny yo: its products, unoriented."));
        st.note(comment("verilator lint_off WIDTH"));
        st.def("m_s1", iw + area_w, false, format!("{} * {aabs}", st.at("vi0")));
        st.note(comment("verilator lint_on WIDTH"));
        st.mul("m_s2", "nx", nx_w, "xo", vx_w + 2);
        st.mul("m_s3", "ny", ny_w, "yo", vy_w + 2);
    }

    /// Stage 4: the sum modulo 2^K, oriented, and everything normalised by the shift s.
    fn stage4(&self, st: &mut Stager) {
        let Calc { row_w, vx_w, vy_w, area_w, sum_w, iw, nx_w, ny_w, .. } = *self;
        let low = |m: &str, w: u32| if w > sum_w { format!("{m}[{}:0]", sum_w - 1) } else { sext(m, w, sum_w) };
        let neg = st.at("neg");
        let (s2, s3) = (low(&st.at("m_s2"), nx_w + vx_w + 2), low(&st.at("m_s3"), ny_w + vy_w + 2));
        st.def(
            "s0",
            sum_w,
            false,
            format!("{} + ({neg} ? -{s2} : {s2}) + ({neg} ? -{s3} : {s3})", zext(&st.at("m_s1"), iw + area_w, sum_w)),
        );
        let lz = st.at("lz");
        st.def("an", area_w, false, format!("{} << {lz}", st.at("aabs")));
        st.def("tn0", sum_w, false, format!("s0 << {lz}"));
        st.note(comment("The rows, once the triangle is not culled: first_s >= 0, first_s <= last_s < height."));
        st.def("first_u", row_w, false, format!("{}[{}:0]", st.at("first_s"), row_w - 1));
        st.def("last_u", row_w, false, format!("{}[{}:0]", st.at("last_s"), row_w - 1));
        st.def("gxn0", sum_w, false, format!("({} << 8) << {lz}", sext(&st.at("onx"), nx_w, sum_w)));
        st.def("dyn0", sum_w, false, format!("({} << 8) << {lz}", sext(&st.at("ony"), ny_w, sum_w)));
    }
}
