//! The front-end against the host set-up, the exact plane and itself (orders, windings, screens).

use super::incremental::{Cost, Step, Steps};
use super::*;
use crate::setup::Vertex;
use crate::Align;

/// xorshift64*: a small, stable generator (the test's sequence never changes with a crate).
pub(super) struct Rng(pub(super) u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn range(&mut self, lo: i64, hi: i64) -> i64 {
        lo + (self.next() % (hi - lo) as u64) as i64
    }
}

/// A random port-level triangle of one of several kinds: anywhere in the guard band, small,
/// slivers, vertices on centres, shared y (horizontal edges), at the band's edges.
pub(super) fn random_tri(rng: &mut Rng, fe: &FrontEnd) -> FixedTriangle {
    let kind = rng.range(0, 6) as usize;
    random_tri_of(rng, fe, kind)
}

/// A random triangle of one kind (0..6, as [`random_tri`] lists them).
fn random_tri_of(rng: &mut Rng, fe: &FrontEnd, kind: usize) -> FixedTriangle {
    let (w, h) = (fe.screen.width as i64 * 256, fe.screen.height as i64 * 256);
    let imax = (1i64 << fe.cfg.iw()) - 1;
    let mut x = [0i64; 3];
    let mut y = [0i64; 3];
    let (cx, cy) = (rng.range(-w / 4, w + w / 4), rng.range(-h / 4, h + h / 4));
    for k in 0..3 {
        let (px, py) = match kind {
            0 => (rng.range(-w, 2 * w), rng.range(-h, 2 * h)),
            1 => (cx + rng.range(-2000, 2000), cy + rng.range(-2000, 2000)),
            2 => (cx + rng.range(-20_000, 20_000), cy + rng.range(-300, 300)),
            3 => ((cx / 256) * 256 + 128 + 256 * rng.range(-20, 20), (cy / 256) * 256 + 128 + 256 * rng.range(-20, 20)),
            4 => (rng.range(-w, 2 * w), if k == 2 { rng.range(-h, 2 * h) } else { cy }),
            _ => (if rng.range(0, 2) == 0 { -w } else { 2 * w - 1 }, rng.range(-h, 2 * h)),
        };
        (x[k], y[k]) = (px, py);
    }
    if kind == 2 && rng.range(0, 2) == 0 {
        // A tall sliver instead of a wide one.
        (x, y) = (y.map(|v| cx + (v - cy) / 16), x.map(|v| cy + (v - cx)));
    }
    let x = x.map(|v| v.clamp(-w, 2 * w - 1));
    let y = y.map(|v| v.clamp(-h, 2 * h - 1));
    let i = [0, 1, 2].map(|_| rng.range(0, imax + 1) as u32);
    FixedTriangle { x, y, i }
}

fn check_against_host(fe: &FrontEnd, n: usize, seed: u64) {
    let mut rng = Rng(seed);
    let mut walked = 0;
    for _ in 0..n {
        let t = random_tri(&mut rng, fe);
        let (outcome, spans) = fe.span_list(&t);
        assert_ne!(outcome, Outcome::Guard);
        let mut host = Vec::new();
        t.snapped(fe.cfg.frac).spans(&fe.cfg, &fe.screen, |y, s| host.push((y, s.x0, s.len)));
        let ours: Vec<_> = spans.iter().map(|&(y, s)| (y, s.x0, s.len)).collect();
        if ours != host {
            let diff = ours.iter().zip(&host).position(|(a, b)| a != b).unwrap_or(ours.len().min(host.len()));
            panic!(
                "coverage differs for {t:?} at span {diff}: {:?} vs {:?} ({} vs {} spans)",
                ours.get(diff),
                host.get(diff),
                ours.len(),
                host.len()
            );
        }
        walked += (outcome == Outcome::Walked) as usize;
        // Every pixel within 1 of the exact plane through the port intensities.
        let (_, st) = fe.setup(&t);
        for (y, s) in &spans {
            let st = st.as_ref().unwrap();
            s.check(&fe.cfg).unwrap();
            // The error grows with j, so the last pixel is the one that matters; a stride
            // through the rest keeps the huge screens' triangles affordable.
            for j in (0..s.len).step_by(1 + s.len as usize / 64).chain([s.len - 1]) {
                let exact = st.plane.value((s.x0 + j) as i64, *y as i64, fe.cfg.frac);
                let got = s.pixel(j, fe.cfg.frac) as f64;
                assert!((got - exact).abs() <= 1.0, "pixel {j} of row {y}: {got} vs {exact} for {t:?}");
            }
        }
    }
    assert!(walked > n / 4, "only {walked} of {n} triangles were walked");
}

#[test]
fn coverage_equals_the_host_set_up_at_640x480() {
    let fe = FrontEnd::new(Config::default(), Screen::default()).unwrap();
    check_against_host(&fe, 8_000, 1);
}

#[test]
fn coverage_and_accuracy_on_the_widest_screens() {
    // The widest screen each configuration allows: 2^XW = 2^F = 4096 at the defaults (400
    // triangles: 1,000 took 5.5 s), and a 65536-pixel screen with XW = 16, F = 16.
    let fe = FrontEnd::new(Config::default(), Screen { width: 4096, height: 4096 }).unwrap();
    check_against_host(&fe, 400, 2);
    let wide = Config::new(8, 16, 16, Align::Span).unwrap();
    let fe = FrontEnd::new(wide, Screen { width: 65536, height: 65536 }).unwrap();
    // 100: a triangle here walks up to 65,536 rows (300 took three quarters of this test's
    // 4 s of CPU); the formats' widths, not the count, are what this screen adds.
    check_against_host(&fe, 100, 3);
    // Small screens: most triangles clip.
    let fe = FrontEnd::new(Config::default(), Screen { width: 37, height: 23 }).unwrap();
    check_against_host(&fe, 8_000, 4);
}

#[test]
fn a_span_across_the_widest_screen_stays_within_one() {
    // Full-width spans with the steepest gradient that still fits: the bound is tight here.
    let fe = FrontEnd::new(Config::default(), Screen { width: 4096, height: 64 }).unwrap();
    let mut rng = Rng(9);
    let mut worst = 0.0f64;
    for _ in 0..2000 {
        let (a, b) = (rng.range(0, 1 << 20) as u32, rng.range(0, 1 << 20) as u32);
        let t = FixedTriangle { x: [-256, 4096 * 256, -256], y: [-256, -256, 64 * 256], i: [a, b, a] };
        let (_, st) = fe.setup(&t);
        let st = st.unwrap();
        fe.walk(&st, |y, s| {
            for j in (0..s.len).step_by(97).chain([s.len - 1]) {
                let exact = st.plane.value((s.x0 + j) as i64, y as i64, 12);
                worst = worst.max((s.pixel(j, 12) as f64 - exact).abs());
            }
        });
    }
    eprintln!("widest screen (4096 px, F = 12): worst |pixel - plane| {worst:.4}");
    assert!(worst <= 1.0, "{worst}");
    assert!(worst > 0.5, "the test should reach past the rounding alone: {worst}");
}

/// The classical per-scanline `dI`: the same spans and `I0`, a `dI` per span that lands
/// within `(m - 1)/2` units of the exactly rounded last pixel, every pixel within 1.
#[test]
fn per_scanline_di_keeps_coverage_and_accuracy() {
    let tri = FrontEnd::new(Config::default(), Screen::default()).unwrap();
    let scan = tri.with_di(DiMode::Scanline);
    let mut rng = Rng(77);
    let (mut spans, mut differ) = (0, 0);
    for _ in 0..600 {
        let t = random_tri(&mut rng, &tri);
        let (o1, a) = tri.span_list(&t);
        let (o2, b) = scan.span_list(&t);
        assert_eq!((o1, a.len()), (o2, b.len()));
        let (_, st) = tri.setup(&t);
        for ((y, s), (y2, s2)) in a.iter().zip(&b) {
            assert_eq!((y, s.x0, s.len, s.i0), (y2, s2.x0, s2.len, s2.i0));
            let st = st.as_ref().unwrap();
            let last = (2 * st.plane.s((s.x0 + s.len - 1) as i64, *y as i64) + st.plane.a) / (2 * st.plane.a);
            let end = s2.i0 as i128 + (s2.len as i128 - 1) * s2.di as i128;
            assert!(2 * (end - last).abs() < s2.len as i128, "{s2:?}: ends at {end}, the plane at {last}");
            for j in 0..s2.len {
                let exact = st.plane.value((s2.x0 + j) as i64, *y as i64, 12);
                assert!((s2.pixel(j, 12) as f64 - exact).abs() <= 1.0, "{s2:?} pixel {j}");
            }
            spans += 1;
            differ += (s.di != s2.di) as usize;
        }
    }
    // Mostly the same dI (both are the plane's slope, rounded); where they differ, the test
    // above holds the scanline's to its own bound.
    assert!(spans > 10_000 && differ > 0, "{differ} of {spans} spans changed dI");
}

#[test]
fn guard_band_and_culling() {
    let fe = FrontEnd::new(Config::default(), Screen::default()).unwrap();
    let ok = FixedTriangle { x: [0, 2560, 0], y: [0, 0, 2560], i: [0, 0, 0] };
    assert_eq!(fe.span_list(&ok).0, Outcome::Walked);
    let outside = [(Some(-640 * 256 - 1), None), (Some(1280 * 256), None), (None, Some(-480 * 256 - 1)), (None, Some(960 * 256))];
    for (k, (bx, by)) in outside.into_iter().enumerate() {
        let mut t = ok;
        if let Some(v) = bx {
            t.x[k % 3] = v;
        }
        if let Some(v) = by {
            t.y[k % 3] = v;
        }
        assert_eq!(fe.span_list(&t), (Outcome::Guard, vec![]), "{t:?}");
    }
    // The band's own edges are inside it.
    let edge = FixedTriangle { x: [-640 * 256, 1280 * 256 - 1, 0], y: [-480 * 256, 0, 960 * 256 - 1], i: [0; 3] };
    assert_eq!(fe.span_list(&edge).0, Outcome::Walked);
    // Zero area, and entirely off each side: culled in set-up.
    let flat = FixedTriangle { x: [0, 2560, 5120], y: [0, 2560, 5120], i: [0; 3] };
    assert_eq!(fe.span_list(&flat).0, Outcome::Culled);
    for (dx, dy) in [(-620, 0), (700, 0), (0, -470), (0, 500)] {
        let t = FixedTriangle { x: ok.x.map(|v| v + dx * 256), y: ok.y.map(|v| v + dy * 256), i: [0; 3] };
        assert_eq!(fe.span_list(&t).0, Outcome::Culled, "{dx} {dy}");
    }
}

#[test]
fn di_is_rounded_once_per_triangle_and_saturates() {
    let cfg = Config::default();
    let fe = FrontEnd::new(cfg, Screen::default()).unwrap();
    // dI/dx = 1 level per pixel exactly.
    let t = FixedTriangle::from_triangle(
        &Triangle {
            v: [Vertex { x: 10.0, y: 10.0, i: 0.0 }, Vertex { x: 110.0, y: 10.0, i: 100.0 }, Vertex { x: 10.0, y: 60.0, i: 255.0 }],
        },
        12,
    );
    let (_, spans) = fe.span_list(&t);
    assert!(spans.iter().all(|(_, s)| s.di == 1 << 12 && s.x0 == 10));
    // 255 levels over 1/256 pixel saturates both ways.
    let steep = FixedTriangle { x: [2688, 2689, 2688], y: [2560, 2560, 5120], i: [0, (1 << 20) - 1, 0] };
    assert_eq!(fe.setup(&steep).1.unwrap().di, (1 << 20) - 1);
    let steep = FixedTriangle { i: [(1 << 20) - 1, 0, (1 << 20) - 1], ..steep };
    assert_eq!(fe.setup(&steep).1.unwrap().di, -(1 << 20));
}

#[test]
fn every_order_and_winding_gives_the_same_coverage() {
    let fe = FrontEnd::new(Config::default(), Screen::default()).unwrap();
    let mut rng = Rng(5);
    for _ in 0..2000 {
        let t = random_tri(&mut rng, &fe);
        let want: Vec<_> = fe.span_list(&t).1.iter().map(|&(y, s)| (y, s.x0, s.len)).collect();
        for p in [[0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]] {
            let u = FixedTriangle { x: p.map(|k| t.x[k]), y: p.map(|k| t.y[k]), i: p.map(|k| t.i[k]) };
            let got: Vec<_> = fe.span_list(&u).1.iter().map(|&(y, s)| (y, s.x0, s.len)).collect();
            assert_eq!(got, want);
        }
    }
}

#[test]
fn refuses_screens_it_cannot_shade_within_one() {
    let cfg = Config::default();
    assert!(FrontEnd::new(cfg, Screen { width: 4096, height: 1 }).is_ok());
    let e = FrontEnd::new(Config::new(8, 8, 12, Align::Span).unwrap(), Screen { width: 257, height: 10 }).unwrap_err();
    assert!(e.to_string().contains("2^F = 256"), "{e}");
    assert!(FrontEnd::new(cfg, Screen { width: 4097, height: 1 }).is_err());
    assert!(FrontEnd::new(cfg, Screen { width: 640, height: 0 }).is_err());
}

#[test]
fn differs_from_the_host_set_up_only_where_f64_rounds_differently() {
    // Same triangles, intensities on the UQ8.F grid: the host rounds f64 plane values, the
    // front-end rounds exact rationals. They may part only at (near-)ties.
    let fe = FrontEnd::new(Config::default(), Screen::default()).unwrap();
    let mut rng = Rng(11);
    let (mut spans, mut i0_diff, mut di_diff, mut px_diff) = (0u64, 0u64, 0u64, 0u64);
    for _ in 0..5_000 {
        let t = random_tri(&mut rng, &fe);
        let t = FixedTriangle { i: t.i.map(|i| i.min(255 << 12)), ..t };
        let mut host = Vec::new();
        crate::setup::triangle_spans(&fe.cfg, &fe.screen, &t.to_triangle(12), |y, s| host.push((y, s))).unwrap();
        let (_, ours) = fe.span_list(&t);
        assert_eq!(ours.len(), host.len());
        for ((_, a), (_, b)) in ours.iter().zip(&host) {
            spans += 1;
            i0_diff += (a.i0 != b.i0) as u64;
            di_diff += (a.di != b.di) as u64;
            for j in 0..a.len {
                let d = (a.pixel(j, 12) as i32 - b.pixel(j, 12) as i32).abs();
                assert!(d <= 1, "{t:?}");
                px_diff += (d != 0) as u64;
            }
        }
    }
    eprintln!("host vs front-end: {spans} spans, I0 differs in {i0_diff}, dI in {di_diff}, {px_diff} pixels differ by 1");
    assert!(i0_diff * 1000 <= spans, "I0 should differ only at rare near-ties: {i0_diff} of {spans}");
}

/// Walked triangles of every kind in turn until each kind has made `want / 6` spans: `f` takes
/// one and returns the spans it counts. The small kinds (slivers, tiny triangles) make few spans
/// each, so every kind gets its own share. Returns the spans per kind.
fn spans_of_every_kind(rng: &mut Rng, fe: &FrontEnd, want: u64, mut f: impl FnMut(&FixedTriangle, &TriSetup) -> u64) -> [u64; 6] {
    let (mut per_kind, mut kind) = ([0u64; 6], 0);
    while per_kind.iter().any(|&n| n < want / 6) {
        kind = (kind + 1) % 6;
        if per_kind[kind] >= want / 6 {
            continue;
        }
        let t = random_tri_of(rng, fe, kind);
        if let Some(st) = fe.setup(&t).1 {
            per_kind[kind] += f(&t, &st);
        }
    }
    per_kind
}

/// The span path's truncated reciprocal (`q~` from `S2n >> t`, the correction modulo
/// 2^(AW+3)) is exact rounding, `round(S / A)`, on 10^6 random spans of every kind at 640x480 and
/// on every kind on the widest screens, F = 16 and 20, a 16x8 screen and the scanline dI (whose
/// last pixel takes the same path).
#[test]
fn truncated_reciprocal_i0_is_exact_on_a_million_spans() {
    let configs = [
        (Config::default(), Screen::default(), DiMode::Triangle, 1_000_000u64),
        (Config::default(), Screen { width: 4096, height: 4096 }, DiMode::Scanline, 60_000),
        (Config::new(8, 16, 16, Align::Span).unwrap(), Screen { width: 65536, height: 65536 }, DiMode::Triangle, 60_000),
        (Config::new(8, 20, 16, Align::Span).unwrap(), Screen { width: 40_000, height: 30_000 }, DiMode::Triangle, 60_000),
        (Config::new(8, 4, 4, Align::Span).unwrap(), Screen { width: 16, height: 8 }, DiMode::Scanline, 30_000),
    ];
    let mut rng = Rng(2727);
    for (cfg, screen, di, want) in configs {
        let fe = FrontEnd::new(cfg, screen).unwrap().with_di(di);
        let exact = |st: &TriSetup, c: u32, r: u32| ((2 * st.plane.s(c as i64, r as i64) + st.plane.a) / (2 * st.plane.a)) as u32;
        let per_kind = spans_of_every_kind(&mut rng, &fe, want, |t, st| {
            let mut spans = 0;
            fe.walk(st, |y, s| {
                assert_eq!(s.i0, exact(st, s.x0, y), "I0 of row {y} at column {} of {t:?} on {screen:?}", s.x0);
                spans += 1;
            });
            if di == DiMode::Scanline {
                // The last pixel's I0 is the same path at the span's other end.
                let km = mask(fe.widths().k);
                fe.walk(st, |y, s| {
                    let tn = (st.tn + (y - st.first) as u128 * st.dyn_) & km;
                    let hi = s.x0 + s.len - 1;
                    assert_eq!(fe.i0(st, tn, hi), exact(st, hi, y), "last pixel of row {y} of {t:?}");
                });
            }
            spans
        });
        eprintln!(
            "{}x{} F={} {di:?}: I0 exact on {} spans (per kind {per_kind:?})",
            screen.width,
            screen.height,
            cfg.frac,
            per_kind.iter().sum::<u64>()
        );
        assert!(per_kind.iter().all(|&n| n >= want / 6), "every kind of triangle: {per_kind:?}");
    }
}

/// The span path's formats for its adversarial tests: the defaults at 640x480, the widest screens
/// at F = 16 and 20, the narrowest format on 16x8.
fn span_path_formats() -> [(Config, Screen); 4] {
    [
        (Config::default(), Screen::default()),
        (Config::new(8, 16, 16, Align::Span).unwrap(), Screen { width: 65536, height: 65536 }),
        (Config::new(8, 20, 16, Align::Span).unwrap(), Screen { width: 65536, height: 65536 }),
        (Config::new(8, 4, 4, Align::Span).unwrap(), Screen { width: 16, height: 8 }),
    ]
}

/// Adversarial `S2n` straight into the arithmetic: ties (`S / A` half-way, remainder 0), the
/// largest remainder, the quotient 0 and 2^IW - 1, areas at 1, at powers of two and either side
/// (where `Rn` is exact or furthest from it), on every format's widths; and the planted faults it
/// must catch: `S2n` shifted one bit further, one compare dropped, the estimate uncorrected.
#[test]
fn truncated_reciprocal_adversarial_and_negative_controls() {
    let mut rng = Rng(99);
    for (cfg, screen) in span_path_formats() {
        let wd = FrontEnd::new(cfg, screen).unwrap().widths();
        let (aw, iw, t) = (wd.aw as i64, cfg.iw() as i64, wd.i0_shift());
        let mut areas = vec![1i64, 2, 3, (1 << aw) - 1, (1 << aw) - 2];
        for b in 1..=aw {
            areas.extend([0, 1, 2, 3, -1, -2].map(|d| (1i64 << (b - 1)) + d));
            areas.push(rng.range(1 << (b - 1), 1 << b));
        }
        let (mut checked, mut caught_shift, mut caught_compare, mut caught_uncorrected) = (0, 0, 0, 0);
        for a in areas.into_iter().filter(|&a| (1..1 << aw).contains(&a)) {
            let s = wd.aw - bits(a as u128);
            let an = (a as u128) << s;
            let rn = (1u128 << wd.k) / (2 * an);
            for q in [0, 1, 2, (1 << iw) - 1, (1 << iw) - 2, rng.range(0, 1 << iw)] {
                // 2S + A has A's parity: a tie is remainder 0 (A even) or 1; the largest is 2A - 1 or 2A - 2.
                let p = a % 2;
                for r in [p, p + 2, 2 * a - 2 + p, 2 * a - 4 + p, 2 * rng.range(0, a) + p] {
                    if !(0..2 * a).contains(&r) {
                        continue;
                    }
                    let s2n = ((2 * a as u128 * q as u128) + r as u128) << s;
                    assert_eq!(wd.reciprocal_quotient(s2n, an, rn), q as u32, "A {a} q {q} r {r} in {cfg:?}");
                    let c = Widths::I0_COMPARES;
                    caught_shift += (wd.corrected_quotient(s2n, an, rn, t + 1, c) != q as u32) as u32;
                    caught_compare += (wd.corrected_quotient(s2n, an, rn, t, c - 1) != q as u32) as u32;
                    caught_uncorrected += (wd.quotient_estimate(s2n, rn, t) != q as u128) as u32;
                    checked += 1;
                }
            }
        }
        eprintln!(
            "{cfg:?}: {checked} adversarial S2n exact; wrong with the shift one further on {caught_shift}, \
             a compare dropped on {caught_compare}, the estimate alone on {caught_uncorrected}"
        );
        assert!(caught_shift > 0 && caught_compare > 0 && caught_uncorrected > 0, "a planted fault went uncaught in {cfg:?}");
    }
}

/// The span path's `Gxn lo` from `Gxn >> 8` ([`Widths::gx_lo`]): `Gxn`'s low 8 bits are zero on
/// every set-up (every kind of triangle, the widest screens, F = 16 and 20, 16x8), and `Gxn lo`
/// from them equals the full product. The planted fault drops one bit more than the fewest
/// trailing zeros seen (`8 + s`, the smallest `s` the guard band allows): the check catches it
/// on some of the same spans (it moves `S2n`'s low bits, the remainder's, so `I0` itself only
/// near a tie). The exactness of the spans themselves is the million-span
/// test's (`FrontEnd::i0` is this form). About 0.2 s.
#[test]
fn gxn_low_bits_are_zero_and_a_planted_shift_is_caught() {
    let mut rng = Rng(2708);
    for (cfg, screen) in span_path_formats() {
        let fe = FrontEnd::new(cfg, screen).unwrap();
        let wd = fe.widths();
        let z = Widths::GXN_ZEROS;
        let km = mask(wd.k);
        let mut set_ups = Vec::new();
        spans_of_every_kind(&mut rng, &fe, 12_000, |t, st| {
            assert_eq!(st.gxn & mask(z), 0, "Gxn's low {z} bits of {t:?}");
            set_ups.push(*st);
            let mut n = 0;
            fe.walk(st, |_, sp| {
                // Both ends: the scanline dI's last pixel takes the same path.
                for c in [sp.x0, sp.x0 + sp.len - 1] {
                    let full = (st.gxn * c as u128) & mask(wd.k - 2);
                    assert_eq!(wd.gx_lo(st.gxn, c, z), full, "Gxn lo at column {c} of {t:?}");
                }
                n += 1;
            });
            n
        });
        let fewest = set_ups.iter().filter(|st| st.gxn != 0).map(|st| st.gxn.trailing_zeros()).min().unwrap();
        assert!(fewest >= z);
        let (mut spans, mut caught, mut caught_i0) = (0u64, 0u64, 0u64);
        for st in &set_ups {
            fe.walk(st, |y, sp| {
                let c = sp.x0 + sp.len - 1;
                caught += (wd.gx_lo(st.gxn, c, fewest + 1) != (st.gxn * c as u128) & mask(wd.k - 2)) as u64;
                let planted = wd.gx_lo(st.gxn, sp.x0, fewest + 1);
                let tn = (st.tn + (y - st.first) as u128 * st.dyn_) & km;
                let s2n = (2 * (tn + planted) + st.an) & mask(wd.k - 1);
                caught_i0 += (wd.reciprocal_quotient(s2n, st.an, st.rn) != sp.i0) as u64;
                spans += 1;
            });
        }
        eprintln!(
            "{cfg:?} on {screen:?}: Gxn lo from Gxn >> {z} exact on {spans} spans; fewest trailing zeros {fewest}; \
             Gxn >> {} wrong on {caught} (their I0 on {caught_i0})",
            fewest + 1
        );
        assert!(caught > 0, "the planted Gxn >> {} went uncaught on {screen:?}", fewest + 1);
    }
}

/// Issue 27's exact incremental I0 gives today's spans bit for bit: 10^6 spans of every kind at
/// 640x480, and every kind on four more screens and formats and the scanline dI. It also prints how
/// many reciprocal evaluations (starts) a triangle needs, the shared unit's load.
#[test]
fn incremental_i0_equals_the_per_row_formula_on_a_million_spans() {
    let configs = [
        (Config::default(), Screen::default(), DiMode::Triangle, 6_000_000u64),
        (Config::default(), Screen { width: 37, height: 23 }, DiMode::Triangle, 120_000),
        (Config::default(), Screen { width: 320, height: 240 }, DiMode::Scanline, 120_000),
        (Config::new(8, 16, 16, Align::Span).unwrap(), Screen { width: 4096, height: 4096 }, DiMode::Triangle, 120_000),
        (Config::new(8, 4, 4, Align::Span).unwrap(), Screen { width: 16, height: 8 }, DiMode::Triangle, 60_000),
    ];
    let mut rng = Rng(27);
    let mut total = 0u64;
    for (cfg, screen, di, want) in configs {
        let fe = FrontEnd::new(cfg, screen).unwrap().with_di(di);
        let (mut cost, mut walked) = (Cost::default(), 0u64);
        let per_kind = spans_of_every_kind(&mut rng, &fe, want, |t, st| {
            let mut old = Vec::new();
            fe.walk(st, |y, s| old.push((y, s)));
            let mut new = Vec::new();
            let c = fe.walk_incremental(st, |y, s| new.push((y, s)));
            assert_eq!(new, old, "{t:?} on {screen:?}, {di:?}");
            walked += 1;
            cost.rows += c.rows;
            cost.spans += c.spans;
            cost.starts += c.starts;
            cost.most_starts = cost.most_starts.max(c.most_starts);
            c.spans
        });
        eprintln!(
            "{}x{} F={} {di:?}: {} spans of {walked} triangles (per kind {per_kind:?}); starts {:.2} a triangle, at most {}, {:.3} a span",
            screen.width,
            screen.height,
            cfg.frac,
            cost.spans,
            cost.starts as f64 / walked as f64,
            cost.most_starts,
            cost.starts as f64 / cost.spans as f64
        );
        assert!(per_kind.iter().all(|&n| n > 0), "every kind of triangle: {per_kind:?}");
        total += cost.spans;
    }
    assert!(total >= 6_000_000);
}

/// The comparison above catches a wrong step: each planted fault (a quotient, a remainder, the
/// carry's step, column 0's) makes some span differ.
#[test]
fn incremental_i0_negative_controls() {
    let fe = FrontEnd::new(Config::default(), Screen::default()).unwrap();
    type Plant = fn(&mut Steps);
    let faults: [(&str, Plant); 4] = [
        ("edge quotient + 1", |s| {
            for e in &mut s.edge {
                if let Some(d) = &mut e[0] {
                    d.q += 1;
                }
            }
        }),
        ("edge remainder + 1", |s| {
            for e in &mut s.edge {
                if let Some(d) = &mut e[0] {
                    d.rn += 1 << 20;
                }
            }
        }),
        ("carry step taken for the plain one", |s| {
            for e in &mut s.edge {
                e[1] = e[0];
            }
        }),
        ("column 0's quotient + 1", |s| {
            if let Some(d) = &mut s.col0 {
                d.q += 1;
            }
        }),
    ];
    for (what, plant) in faults {
        let mut rng = Rng(270);
        let caught = (0..20_000).any(|_| {
            let t = random_tri(&mut rng, &fe);
            let Some(st) = fe.setup(&t).1 else { return false };
            let mut old = Vec::new();
            fe.walk(&st, |y, s| old.push((y, s)));
            let mut steps = fe.i0_steps(&st);
            plant(&mut steps);
            let mut new = Vec::new();
            fe.walk_with_steps(&st, &steps, |y, s| new.push((y, s)));
            new != old
        });
        assert!(caught, "planted fault not caught: {what}");
    }
}

/// The plan's I0 form decides what `spans` evaluates, with the same spans; a plan without the
/// field (every one written before it) reads as the reciprocal form, and the default form is
/// left out when written, so those plans' bytes stay as they were.
#[test]
fn the_plan_names_its_i0_form() {
    let rec = FrontEnd::new(Config::default(), Screen::default()).unwrap();
    let inc = rec.with_i0(I0Form::Incremental);
    let mut rng = Rng(27);
    for _ in 0..2000 {
        let t = random_tri(&mut rng, &rec);
        assert_eq!(rec.span_list(&t), inc.span_list(&t), "{t:?}");
    }
    let text = serde_json::to_string(&rec).unwrap();
    assert!(!text.contains("i0"), "{text}");
    assert_eq!(serde_json::from_str::<FrontEnd>(&text).unwrap(), rec);
    let text = serde_json::to_string(&inc).unwrap();
    assert!(text.contains("\"i0\":\"incremental\""), "{text}");
    assert_eq!(serde_json::from_str::<FrontEnd>(&text).unwrap(), inc);
}

/// The walk of `t` restarts a source after a step out of `[-2^IW, 2^IW)` (column 0's, or an
/// edge's without its carry) that a front-end ignoring the range would have taken: the window
/// where a fault in that range check shows. Returns (starts, starts with those steps taken
/// modulo 2^IW) when it does.
fn restarts_after_out_of_range_step(fe: &FrontEnd, t: &FixedTriangle) -> Option<(u64, u64)> {
    let st = fe.setup(t).1?;
    let (a2, iw) = (2 * st.plane.a, fe.cfg.iw());
    let taken = |x: i128| Some(Step { q: (x.div_euclid(a2) as u32) & mask(iw) as u32, rn: (x.rem_euclid(a2) as u128) << st.s });
    let steps = fe.i0_steps(&st);
    let mut forced = steps;
    forced.col0 = forced.col0.or(taken(512 * st.plane.ny));
    // The steps without the DDA's carry, whose range check is the one `ie_ok0` makes in the RTL.
    for (k, e) in st.edges.iter().enumerate() {
        forced.edge[k][0] = forced.edge[k][0].or(taken(512 * st.plane.ny - 512 * st.plane.nx * e.qs as i128));
    }
    let starts = fe.walk_incremental(&st, |_, _| {}).starts;
    let forced_starts = fe.walk_with_steps(&st, &forced, |_, _| {}).starts;
    (forced_starts < starts).then_some((starts, forced_starts))
}

/// The directed triangles of [`crate::stimulus::out_of_range_step_triangles`] keep the property
/// the co-simulation's planted fault "a step out of range taken" needs (a left edge's step
/// without its carry out of range, taken, the edge then used again), reach column 0 and walk to
/// today's spans; a plain triangle has not the property (the check's negative control).
#[test]
fn directed_triangles_take_an_out_of_range_step() {
    let fe = FrontEnd::new(Config::default(), Screen::default()).unwrap().with_i0(I0Form::Incremental);
    let iw = fe.cfg.iw();
    for t in crate::stimulus::out_of_range_step_triangles() {
        let st = fe.setup(&t).1.unwrap_or_else(|| panic!("{t:?} is not walked"));
        let steps = fe.i0_steps(&st);
        let out = (0..3).filter(|&k| {
            let x = 512 * st.plane.ny - 512 * st.plane.nx * st.edges[k].qs as i128;
            let q = x.div_euclid(2 * st.plane.a);
            let outside = !(-(1i128 << iw)..1i128 << iw).contains(&q);
            assert_eq!(steps.edge[k][0].is_none(), outside, "{t:?}: edge {k}'s step is None exactly when out of range");
            outside && !st.edges[k].right
        });
        assert!(out.count() > 0, "{t:?}: no left edge's step without carry is out of range");
        let (starts, forced) = restarts_after_out_of_range_step(&fe, &t).unwrap_or_else(|| panic!("{t:?}: no restart after such a step"));
        let (mut old, mut new) = (Vec::new(), Vec::new());
        fe.walk(&st, |y, s| old.push((y, s)));
        fe.walk_incremental(&st, |y, s| new.push((y, s)));
        assert_eq!(new, old, "{t:?}");
        assert!(new.iter().any(|(_, s)| s.x0 == 0), "{t:?}: no span reaches column 0");
        eprintln!("{t:?}: {} spans, {starts} starts ({forced} with the out-of-range steps taken)", new.len());
    }
    let plain = FixedTriangle { x: [2560, 25600, 5120], y: [2560, 7680, 25600], i: [0, 500_000, 1_000_000] };
    assert!(fe.setup(&plain).1.is_some() && restarts_after_out_of_range_step(&fe, &plain).is_none());
}

/// The running sums' `Gxn lo` ([`sums`], the ECP5-25F engine form's span path) equals the
/// product's ([`Widths::gx_lo`], the oracle) on every span, and `I0` from it is exact: 10^6
/// spans of every kind at 640x480, and every kind on the widest screens at F = 16 and 20, 4096
/// square with the scanline dI and 16x8 at F = 4; spans whose two left edges tie on the row
/// (a left vertex on a row's centre) counted. Negative controls: the carry ignored, one slot
/// for both, the clamp not zeroed, each caught on some of the same spans. About 2 s: the slow
/// tier; the default tier runs a tenth (`running_sums_equal_the_product`, about 0.2 s).
#[test]
#[ignore]
fn running_sums_equal_the_product_on_a_million_spans() {
    running_sums_against_the_product(1);
}

/// [`running_sums_equal_the_product_on_a_million_spans`] on a tenth of its spans.
#[test]
fn running_sums_equal_the_product() {
    running_sums_against_the_product(10);
}

fn running_sums_against_the_product(fraction: u64) {
    use super::sums::SumFault;
    let configs = [
        (Config::default(), Screen::default(), DiMode::Triangle, 1_000_000 / fraction),
        (Config::default(), Screen { width: 4096, height: 4096 }, DiMode::Scanline, 60_000 / fraction),
        (Config::new(8, 16, 16, Align::Span).unwrap(), Screen { width: 65536, height: 65536 }, DiMode::Triangle, 60_000 / fraction),
        (Config::new(8, 20, 16, Align::Span).unwrap(), Screen { width: 40_000, height: 30_000 }, DiMode::Triangle, 60_000 / fraction),
        (Config::new(8, 4, 4, Align::Span).unwrap(), Screen { width: 16, height: 8 }, DiMode::Triangle, 30_000 / fraction),
    ];
    let faults = [SumFault::NoCarry, SumFault::OneSlot, SumFault::NoClamp];
    let mut rng = Rng(272_727);
    for (cfg, screen, di, want) in configs {
        let fe = FrontEnd::new(cfg, screen).unwrap().with_di(di).with_setup(SetupForm::Ecp5_25f);
        let wd = fe.widths();
        let z = Widths::GXN_ZEROS;
        let exact = |st: &TriSetup, c: u32, r: u32| ((2 * st.plane.s(c as i64, r as i64) + st.plane.a) / (2 * st.plane.a)) as u32;
        let (mut ties, mut caught, mut caught_i0) = (0u64, [0u64; 3], [0u64; 3]);
        // Every active edge is in its side's slots (hdl-gen's row stages); slot b on 1, 2 misses some.
        let mut missed_by_bad_pairs = 0u64;
        let per_kind = spans_of_every_kind(&mut rng, &fe, want, |t, st| {
            assert!(st.sums.is_some(), "the ECP5-25F form's set-up has the sums");
            for right in [false, true] {
                let side = |pairs| {
                    let s = super::sums::slots(&st.edges, right, pairs);
                    st.edges.iter().enumerate().all(|(k, e)| !(e.active && e.right == right) || s.contains(&k))
                };
                let ours = if right { super::sums::right_slots(&st.edges) } else { super::sums::left_slots(&st.edges) };
                assert!(side(super::sums::LEFT_SLOTS) && ours == super::sums::slots(&st.edges, right, super::sums::LEFT_SLOTS), "{t:?}");
                missed_by_bad_pairs += !side([(0, 1), (1, 2)]) as u64;
            }
            let mut edges = st.edges;
            let mut row = st.first;
            let mut spans = 0;
            fe.walk_with(st, SumFault::None, |y, s, gx| {
                assert_eq!(gx, Some(wd.gx_lo(st.gxn, s.x0, z)), "Gxn lo of row {y} at column {} of {t:?}", s.x0);
                assert_eq!(s.i0, exact(st, s.x0, y), "I0 of row {y} at column {} of {t:?}", s.x0);
                // The edges on this row, stepped as the walker steps them, for the ties' count.
                for r in row..y {
                    for e in edges.iter_mut().filter(|e| e.active && r >= e.rs) {
                        e.step_carry();
                    }
                }
                row = y;
                let left: Vec<i64> = edges.iter().filter(|e| e.active && !e.right && (e.rs..=e.re).contains(&y)).map(|e| e.g).collect();
                ties += (left.len() == 2 && left[0] == left[1] && s.x0 as i64 == -left[0]) as u64;
                spans += 1;
            });
            for (k, f) in faults.iter().enumerate() {
                fe.walk_with(st, *f, |y, s, gx| {
                    caught[k] += (gx != Some(wd.gx_lo(st.gxn, s.x0, z))) as u64;
                    caught_i0[k] += (s.i0 != exact(st, s.x0, y)) as u64;
                });
            }
            spans
        });
        let spans: u64 = per_kind.iter().sum();
        eprintln!(
            "{}x{} F={} {di:?}: Gxn lo from the sums exact on {spans} spans ({ties} left-edge ties); \
             planted (carry ignored, one slot, no clamp) wrong on {caught:?} spans, I0 on {caught_i0:?}",
            screen.width, screen.height, cfg.frac
        );
        assert!(per_kind.iter().all(|&n| n >= want / 6), "every kind of triangle: {per_kind:?}");
        assert!(caught.iter().all(|&c| c > 0), "a planted fault went uncaught on {screen:?}: {caught:?}");
        assert!(missed_by_bad_pairs > 0, "slots on the wrong pairs went uncaught on {screen:?}");
        if screen == Screen::default() {
            assert!(ties > 0 && caught_i0.iter().all(|&c| c > 0), "ties {ties}, I0 caught {caught_i0:?}");
        }
    }
}
