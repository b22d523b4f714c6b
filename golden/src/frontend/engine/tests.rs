//! The engine against `FrontEnd::setup`: the program, and the program as each plan sequences it,
//! on random triangles of every kind (`stimulus::random_fixed_triangles`); planted faults.

use super::schedule::{self, EngineError, Result3, Schedule};
use super::*;
use crate::format::{Align, Config};
use crate::rng::{test_seed, SeedRng};
use crate::setup::Screen;
use crate::stimulus::random_fixed_triangles;
use rand::SeedableRng;

fn plan(mults: u32, dividers: u32, div_bits: u32, reciprocal: bool) -> Plan {
    Plan {
        mults,
        mul: Plan::TILE18,
        dividers,
        div_bits,
        div_form: DivForm::ShiftRemainder,
        reciprocal,
        i0_steps: true,
        run_sums: false,
        edge_t: false,
        div_chain: false,
        shifters: 0,
    }
}

/// The screens of the equivalence: the default, a small one at F = 4 and the widest (2^16).
fn screens() -> Vec<FrontEnd> {
    vec![
        FrontEnd::new(Config::default(), Screen::default()).unwrap(),
        FrontEnd::new(Config::new(8, 4, 4, Align::Span).unwrap(), Screen { width: 16, height: 8 }).unwrap(),
        FrontEnd::new(Config::new(8, 16, 16, Align::Span).unwrap(), Screen { width: 65536, height: 65536 }).unwrap(),
    ]
}

/// Plans that cover both division forms, one and several units, radix 2 to 16 and a
/// shift-add multiplier.
fn plans() -> Vec<Plan> {
    vec![
        plan(12, 4, 2, true),
        plan(4, 3, 4, false),
        plan(1, 1, 1, true),
        Plan { mul: MulUnit::ShiftAdd { bits: 4 }, i0_steps: false, ..plan(2, 2, 2, false) },
        Plan { mul: MulUnit::Tile { bits: 16 }, shifters: 1, ..plan(8, 6, 1, true) },
        Plan { shifters: 2, ..plan(4, 3, 4, false) },
    ]
}

/// The first triangle whose engine result differs from `setup`'s, if any.
fn first_mismatch(fe: &FrontEnd, s: &Schedule, tris: &[crate::frontend::FixedTriangle]) -> Option<String> {
    let got = s.run(tris);
    tris.iter().zip(got).find_map(|(t, g)| {
        let mut want: Result3 = reference(fe, &s.plan, t);
        if !s.plan.i0_steps {
            want.2 = want.2.and(None);
            if want.1.is_some() {
                want.2 = None;
            }
        }
        let g = (g.0, g.1, if s.plan.i0_steps { g.2 } else { None });
        (g != want).then(|| {
            let (a, b) = (format!("{g:?}"), format!("{want:?}"));
            let at = a.chars().zip(b.chars()).position(|(x, y)| x != y).unwrap_or(0).saturating_sub(60);
            format!("{t:?}\n engine ...{}\n setup  ...{}", &a[at..], &b[at..])
        })
    })
}

/// `n` triangles a screen through each plan, streamed in runs of at most 10,000 (each from
/// reset); returns how many were walked.
fn equivalence(n: usize, seed: u64) -> usize {
    let mut rng = SeedRng::seed_from_u64(seed);
    let mut walked = 0;
    for fe in screens() {
        let sched: Vec<Schedule> = plans().iter().map(|p| p.schedule(&fe).unwrap()).collect();
        for s in &sched {
            s.verify().unwrap();
        }
        let mut left = n;
        while left > 0 {
            let tris = random_fixed_triangles(&mut rng, &fe, left.min(10_000));
            left -= tris.len();
            walked += tris.iter().filter(|t| fe.setup(t).0 == Outcome::Walked).count();
            for s in &sched {
                if let Some(m) = first_mismatch(&fe, s, &tris) {
                    panic!("{:?} on {:?}: {m}", s.plan, fe.screen);
                }
            }
        }
    }
    walked
}

/// The program in order and as each plan sequences it equals `setup` and `i0_steps` (about
/// 1.5 s at the suite's opt-level; the million is `engine_equals_setup_on_a_million_triangles`).
#[test]
fn engine_equals_setup() {
    let seed = test_seed("engine_equals_setup");
    let walked = equivalence(2_000, seed);
    assert!(walked > 2_000, "too few walked triangles: {walked}");
    let fe = FrontEnd::new(Config::default(), Screen::default()).unwrap();
    let prog = Program::setup(&fe, &plan(1, 1, 1, true));
    let mut rng = SeedRng::seed_from_u64(seed);
    for t in random_fixed_triangles(&mut rng, &fe, 2_000) {
        assert_eq!(prog.eval(&t), reference(&fe, &plan(1, 1, 1, true), &t), "{t:?}");
    }
}

/// The named plans the RTL runs (`SetupForm`), as they schedule, equal `setup` on 500 random
/// triangles at 640x480 and at 37x23, the co-simulation's screens (about 0.3 s).
#[test]
fn the_named_plans_equal_setup() {
    let seed = test_seed("the_named_plans_equal_setup");
    let mut rng = SeedRng::seed_from_u64(seed);
    for screen in [Screen::default(), Screen { width: 37, height: 23 }] {
        let fe = FrontEnd::new(Config::default(), screen).unwrap();
        let tris = random_fixed_triangles(&mut rng, &fe, 500);
        for form in SetupForm::ALL {
            let Some(p) = form.plan() else { continue };
            let s = p.schedule(&fe).unwrap();
            s.verify().unwrap();
            if let Some(m) = first_mismatch(&fe, &s, &tris) {
                panic!("{form:?} on {screen:?}: {m}");
            }
        }
    }
}

/// 10^6 random triangles of every kind at 640x480, and as many on the small and the widest
/// screen, through every plan of `plans()`: `cargo test --release -p golden --lib
/// engine_equals_setup_on -- --ignored` (time in docs/design.md).
#[test]
#[ignore]
fn engine_equals_setup_on_a_million_triangles() {
    let walked = equivalence(1_000_000, test_seed("engine million"));
    eprintln!("{walked} walked triangles");
}

fn fe640() -> FrontEnd {
    FrontEnd::new(Config::default(), Screen::default()).unwrap()
}

fn caught(fe: &FrontEnd, s: &Schedule) -> bool {
    let mut rng = SeedRng::seed_from_u64(2027);
    let tris = random_fixed_triangles(&mut rng, fe, 3_000);
    first_mismatch(fe, s, &tris).is_some()
}

/// Planted faults: a wrong operation, an operation started before its operand is ready, a
/// value with one register copy too few. The equivalence catches each, and so does
/// `Schedule::verify` for the two schedule faults.
#[test]
fn planted_faults_are_caught() {
    let fe = fe640();
    let p = plan(6, 3, 2, true);
    let good = p.schedule(&fe).unwrap();
    if let Some(m) = first_mismatch(&fe, &good, &random_fixed_triangles(&mut SeedRng::seed_from_u64(2027), &fe, 3_000)) {
        panic!("the good schedule must pass: {m}");
    }

    let mut prog = Program::setup(&fe, &p);
    let e = prog.ops.iter().position(|o| o.name == "e1").unwrap();
    let Kind::Sub(a, b) = prog.ops[e].kind else { panic!("e1 is a difference") };
    prog.ops[e].kind = Kind::Add(a, b);
    assert!(caught(&fe, &Schedule::new(prog, p).unwrap()), "a wrong operation");

    let mut early = good.clone();
    let g = early.prog.ops.iter().position(|o| o.name == "g0").unwrap();
    let Kind::Div { n, .. } = early.prog.ops[g].kind else { panic!("g0 is a division") };
    early.slots[g].start = early.slots[n.0 as usize].ready - 1;
    assert!(early.verify().is_err(), "verify: a read before the value is ready");
    assert!(caught(&fe, &early), "a read before the value is ready");

    let mut short = good.clone();
    let o = (0..short.copies.len())
        .filter(|&o| short.slots[o].class != schedule::Class::Wire)
        .max_by_key(|&o| (short.copies[o] >= 2, short.prog.ops[o].w))
        .unwrap();
    assert!(short.copies[o] >= 2, "some value outlives II");
    short.copies[o] -= 1;
    assert!(short.verify().is_err(), "verify: a register copy too few");
    assert!(caught(&fe, &short), "a register copy too few ({})", short.prog.ops[o].name);
}

/// Today's dividers are the calibration's: eight, 357 partial-remainder bits at 640x480, and
/// the model gives back both measured points.
#[test]
fn the_lut_model_reproduces_its_calibration() {
    assert_eq!(schedule::today_pw(), 357);
    let per = schedule::lut_per_bit_step();
    for (bits, lut) in schedule::MEASURED_LUT4 {
        assert_eq!(schedule::lut_rest() + (per * (357 * bits) as f64).round() as u32, lut);
    }
}

/// Refused plans. The products: CALC's 15, a step's 3 (`Nx Qs`) and 2 per division by `2A`
/// by reciprocal (dI and seven steps).
#[test]
fn plans_without_units_are_refused() {
    let fe = fe640();
    assert_eq!(plan(0, 2, 1, true).schedule(&fe).unwrap_err(), EngineError::NoMultiplier(34));
    assert!(matches!(plan(2, 0, 1, true).schedule(&fe), Err(EngineError::NoDivider(_))));
    assert!(matches!(plan(2, 2, 0, true).schedule(&fe), Err(EngineError::Range { .. })));
}

/// One row of docs/design.md's table of plans.
fn row(s: &Schedule) -> String {
    let p = &s.plan;
    let c = &s.cost;
    let mul = match p.mul {
        MulUnit::Tile { bits } => format!("{} × {bits}²", p.mults),
        MulUnit::ShiftAdd { bits } => format!("{} shift-add × {bits}", p.mults),
    };
    format!(
        "| {mul} | {} × {} bit{}{} | {} | {} | **{}** | {} | {} | {} | {} | {} | {} | {} |",
        p.dividers,
        p.div_bits,
        if p.div_bits > 1 { "s" } else { "" },
        if p.div_form == DivForm::ShiftDivisor { " (today's form)" } else { "" },
        if p.reciprocal { "yes" } else { "no" },
        if p.i0_steps { "yes" } else { "no" },
        s.ii,
        s.latency,
        c.tiles,
        c.mul_passes,
        c.div_clocks,
        c.lut_units,
        c.lut_mux,
        c.lut_units + c.lut_mux,
    )
}

/// docs/design.md's table: `cargo test -p golden --lib engine_grid -- --ignored --nocapture`.
#[test]
#[ignore]
fn engine_grid() {
    let fe = fe640();
    eprintln!(
        "calibration: {:.2} LUT4 per remainder bit per quotient bit a clock; the rest {} LUT4",
        schedule::lut_per_bit_step(),
        schedule::lut_rest()
    );
    let filter = std::env::var("ENGINE_GRID").unwrap_or_default();
    // Today's set-up as a plan: 66 tiles (one a pass), eight dividers of 4 bits in today's form.
    let today = Plan {
        mults: 66,
        mul: Plan::TILE18,
        dividers: 8,
        div_bits: 4,
        div_form: DivForm::ShiftDivisor,
        reciprocal: false,
        i0_steps: false,
        run_sums: false,
        edge_t: false,
        div_chain: false,
        shifters: 0,
    };
    println!("{} (today)", row(&today.schedule(&fe).unwrap()));
    for steps in [false, true] {
        for reciprocal in [false, true] {
            let prog = Program::setup(&fe, &Plan { reciprocal, i0_steps: steps, ..plan(1, 1, 1, false) });
            let count = |f: fn(&Kind) -> bool| prog.ops.iter().filter(|o| f(&o.kind)).count();
            eprintln!(
                "reciprocal {reciprocal}, steps {steps}: {} operations, {} products, {} divisions",
                prog.ops.len(),
                count(|k| matches!(k, Kind::Mul(..))),
                count(|k| matches!(k, Kind::Div { .. }))
            );
            for mul in [Plan::TILE18, MulUnit::Tile { bits: 16 }, MulUnit::ShiftAdd { bits: 1 }, MulUnit::ShiftAdd { bits: 4 }] {
                for mults in [1, 2, 3, 4, 6, 8, 12] {
                    for dividers in [1, 2, 3, 4, 6, 8, 10, 12] {
                        for (div_bits, div_form) in
                            [1, 2, 4].into_iter().flat_map(|b| [(b, DivForm::ShiftRemainder), (b, DivForm::ShiftDivisor)])
                        {
                            let p = Plan {
                                mults,
                                mul,
                                dividers,
                                div_bits,
                                div_form,
                                reciprocal,
                                i0_steps: steps,
                                run_sums: false,
                                edge_t: false,
                                div_chain: false,
                                shifters: 1,
                            };
                            let s = p.schedule(&fe).unwrap();
                            let r = row(&s);
                            if r.contains(&filter) {
                                println!("{r}");
                            }
                        }
                    }
                }
            }
        }
    }
}

/// The recommended plans schedule as docs/design.md says: the ECP5-25F's at 12 clocks on 8
/// tiles, the fewest that keep 12 (one fewer is slower), so that with the span path's 17 per-row
/// products the front-end stays within the LFE5U-25F's 28 MULT18X18D; the iCE40s' within the
/// device's multipliers.
#[test]
fn the_recommended_plans() {
    let fe = fe640();
    let s = Plan::ECP5_25F.schedule(&fe).unwrap();
    assert!(s.ii <= 12 && s.cost.tiles + 17 <= 28, "ECP5-25F: {} clocks, {} tiles", s.ii, s.cost.tiles);
    let fewer = Plan { mults: Plan::ECP5_25F.mults - 1, ..Plan::ECP5_25F }.schedule(&fe).unwrap();
    assert!(fewer.ii > s.ii, "ECP5-25F: {} tiles keep {} clocks too", fewer.cost.tiles, fewer.ii);
    let s = Plan::ICE40_UP5K.schedule(&fe).unwrap();
    assert!(s.cost.tiles <= 8 && s.ii <= 120, "UP5K: {} clocks, {} tiles", s.ii, s.cost.tiles);
    let s = Plan::ICE40_HX8K.schedule(&fe).unwrap();
    assert!(s.cost.tiles == 0 && s.ii <= 314, "HX8K: {} clocks", s.ii);
}

/// The ECP5-25F plan's schedule, for reviews: `cargo test -p golden --lib engine_listing --
/// --ignored --nocapture`.
#[test]
#[ignore]
fn engine_listing() {
    let s = Plan::ECP5_25F.schedule(&fe640()).unwrap();
    println!("II {} latency {}\n{}", s.ii, s.latency, s.listing());
}

/// The binding the RTL runs is periodic: every plan the generator offers, at three screens.
#[test]
fn the_binding_is_periodic() {
    use crate::frontend::engine::SetupForm;
    let wide = Config::new(8, 20, 16, Align::Span).unwrap();
    let small = Config::new(8, 4, 4, Align::Span).unwrap();
    let cases = [
        (Config::default(), Screen::default()),
        (Config::default(), Screen { width: 37, height: 23 }),
        (Config::default(), Screen { width: 4096, height: 4096 }),
        (wide, Screen::default()),
        (small, Screen { width: 16, height: 8 }),
    ];
    for (cfg, screen) in cases {
        let fe = FrontEnd::new(cfg, screen).unwrap();
        for form in SetupForm::ALL {
            let Some(plan) = form.plan() else { continue };
            let s = plan.schedule(&fe).unwrap();
            let r = s.epochs().unwrap_or_else(|| panic!("{form:?} at {screen:?}: no period in {:?}", s.binding));
            eprintln!("{form:?} {}x{}: II {} latency {} epochs {r}", screen.width, screen.height, s.ii, s.latency);
            assert_eq!(s.verify_binding(), Ok(r));
            // Negative control: a binding broken in one triangle has no period.
            let mut bad = s.clone();
            let o = bad.binding.iter().position(|b| !b.is_empty()).unwrap();
            let last = bad.binding[o].len() - 1;
            bad.binding[o][last] += 1;
            assert_eq!(bad.epochs(), None);
            // And one that puts two operations on one unit at once is refused.
            let mut bad = s.clone();
            let o = bad.binding.iter().position(|b| !b.is_empty()).unwrap();
            let same = |k: usize| k != o && bad.slots[k].class == bad.slots[o].class && bad.slots[k].start == bad.slots[o].start;
            if let Some(p) = (0..bad.binding.len()).find(|&k| same(k)) {
                bad.binding[p] = bad.binding[o].clone();
                assert!(bad.verify_binding().is_err());
            }
        }
    }
}

/// Every product keeps its tile on every triangle, for every plan the generator offers at the
/// screens of `the_binding_is_periodic` (golden's scheduler reserves the tiles one by one), so
/// the tiles' operand multiplexers select by phase alone.
#[test]
fn the_products_keep_their_tiles() {
    use crate::frontend::engine::SetupForm;
    let wide = Config::new(8, 20, 16, Align::Span).unwrap();
    for (cfg, screen) in
        [(Config::default(), Screen::default()), (Config::default(), Screen { width: 37, height: 23 }), (wide, Screen::default())]
    {
        let fe = FrontEnd::new(cfg, screen).unwrap();
        for plan in SetupForm::ALL.iter().filter_map(|f| f.plan()) {
            let s = plan.schedule(&fe).unwrap();
            assert_eq!(s.rotating_products(), Vec::<&str>::new(), "{plan:?} at {screen:?}");
        }
    }
    // Negative control: a product moved to another tile on every other triangle.
    let mut bad = Plan::ECP5_25F.schedule(&fe640()).unwrap();
    let o = (0..bad.slots.len()).find(|&o| bad.slots[o].class == schedule::Class::Mul).unwrap();
    for (j, u) in bad.binding[o].iter_mut().enumerate() {
        *u = (*u + j as u32 % 2) % Plan::ECP5_25F.mults;
    }
    assert_eq!(bad.rotating_products(), vec![bad.prog.ops[o].name.as_str()]);
}

/// The ECP5 plan's dividers each run one division, its `Qs`, `g` and `Rn` on a pair of their
/// own (so no divider needs an operand multiplexer), in series (`Plan::div_chain`): each stage
/// at most II clocks, back to back, every triangle on the same dividers (one epoch); without
/// the chain the pair alternates by the triangle's parity (two epochs). Negative control: on 12
/// dividers, the fewest 120 divider clocks need at II = 12, divisions share dividers and rotate
/// over three.
#[test]
fn the_ecp5_divisions_keep_their_pairs() {
    let sharing = |s: &Schedule| -> usize {
        let mut ops_on: Vec<Vec<usize>> = vec![Vec::new(); s.plan.dividers as usize];
        for (o, b) in s.binding.iter().enumerate().filter(|(o, _)| s.slots[*o].class == schedule::Class::Div) {
            for &u in b {
                if !ops_on[u as usize].contains(&o) {
                    ops_on[u as usize].push(o);
                }
            }
        }
        ops_on.iter().filter(|v| v.len() > 1).count()
    };
    let s = Plan::ECP5_25F.schedule(&fe640()).unwrap();
    assert_eq!((s.ii, s.epochs(), s.verify_binding()), (12, Some(1), Ok(1)));
    assert_eq!(sharing(&s), 0, "{:?}", s.binding);
    for o in (0..s.slots.len()).filter(|&o| s.slots[o].class == schedule::Class::Div) {
        let (t, b) = (s.slots[o].start, s.slots[o].busy);
        let [(u0, a0, b0), (u1, a1, b1)] = s.div_stages(o).expect("every ECP5 division is chained");
        assert!(u0 != u1 && a0 == t && b0 == a1 && b1 == t + b, "{}", s.prog.ops[o].name);
        assert!(b0 - a0 <= s.ii && b1 - a1 <= s.ii, "{}: stages of {} and {} clocks", s.prog.ops[o].name, b0 - a0, b1 - a1);
    }
    let parity = Plan { div_chain: false, ..Plan::ECP5_25F }.schedule(&fe640()).unwrap();
    assert_eq!((parity.epochs(), parity.verify_binding()), (Some(2), Ok(2)));
    assert!((0..parity.slots.len()).all(|o| parity.div_stages(o).is_none()));
    let twelve = Plan { dividers: 12, div_chain: false, ..Plan::ECP5_25F }.schedule(&fe640()).unwrap();
    assert_eq!(twelve.ii, 12);
    assert!(sharing(&twelve) > 0 && twelve.epochs() > Some(2), "{:?}", twelve.epochs());
}

/// The binding's check sees a chained division's stages: two divisions chained on the same
/// pair of dividers (edge 0's `Qs` on `g`'s, the stages overlapping) fail it.
#[test]
fn a_chained_division_on_a_busy_divider_fails_the_binding() {
    let mut bad = Plan::ECP5_25F.schedule(&fe640()).unwrap();
    let name = |s: &Schedule, n: &str| (0..s.slots.len()).find(|&o| s.prog.ops[o].name == n).unwrap();
    let (qs, g) = (name(&bad, "qs0"), name(&bad, "g0"));
    assert!(bad.verify_binding().is_ok());
    bad.binding[qs] = bad.binding[g].clone();
    assert!(bad.div_stages(qs).is_some());
    let e = bad.verify_binding().unwrap_err();
    assert!(e.contains("overlap"), "{e}");
}

/// The estimate sees the barrel shifters: the ECP5 plan's five shifts by `s` (four of 64 bits)
/// cost over 1,000 LUT4 more each on its own shifter than on one shared shifter (measured:
/// about 1,560 against 637 plus its multiplexer, docs/fpga.md).
#[test]
fn the_estimate_counts_the_shifters() {
    let shared = Plan::ECP5_25F.schedule(&fe640()).unwrap().cost;
    let own = Plan { shifters: 0, ..Plan::ECP5_25F }.schedule(&fe640()).unwrap().cost;
    assert!(own.lut_units + own.lut_mux > shared.lut_units + shared.lut_mux + 1000, "{own:?} against {shared:?}");
}

/// With `Plan::edge_t` (the ECP5 plan) each stepped edge's `(thr, t)` are `setup`'s
/// `(D - rs256) >> 8` and `(rem >> 8) - thr`, in their declared widths (the program wraps each
/// value to its width, so a width too narrow differs): on 2,000 random triangles a screen at
/// 640x480, 37x23 and the widest, about 0.2 s. A `t` one off is its negative control.
#[test]
fn the_edges_dda_starts_are_the_setups() {
    let mut rng = SeedRng::seed_from_u64(test_seed("the_edges_dda_starts_are_the_setups"));
    let check = |fe: &FrontEnd, prog: &Program, t: &crate::frontend::FixedTriangle, off: i128| -> bool {
        let (_, st, _) = reference(fe, &Plan::ECP5_25F, t);
        let Some(st) = st else { return true };
        let val = prog.values(t);
        st.edges.iter().zip(&prog.out.edges).filter(|(e, _)| e.active && e.re > e.rs).all(|(e, o)| {
            let (thr, tv) = o.dda.expect("the ECP5 plan forms the edges' DDA starts");
            let want_thr = ((e.d - e.rs256) >> 8) as i128;
            val[thr.0 as usize] == want_thr && val[tv.0 as usize] + off == (e.rem >> 8) as i128 - want_thr
        })
    };
    let mut stepped = 0;
    for fe in [screens()[0], FrontEnd::new(Config::default(), Screen { width: 37, height: 23 }).unwrap(), screens()[2]] {
        let prog = Program::setup(&fe, &Plan::ECP5_25F);
        assert!(Program::setup(&fe, &Plan::ICE40_UP5K).out.edges.iter().all(|e| e.dda.is_none()), "only with edge_t");
        let tris = random_fixed_triangles(&mut rng, &fe, 2_000);
        for t in &tris {
            assert!(check(&fe, &prog, t, 0), "{fe:?} {t:?}");
        }
        let walked: Vec<_> =
            tris.iter().filter(|t| fe.setup(t).1.is_some_and(|s| s.edges.iter().any(|e| e.active && e.re > e.rs))).collect();
        stepped += walked.len();
        assert!(walked.iter().any(|t| !check(&fe, &prog, t, 1)), "the negative control: t one off is caught");
    }
    assert!(stepped > 1_000, "too few stepped edges: {stepped}");
}
