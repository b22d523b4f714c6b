//! The sequential engine against `FrontEnd::setup`, its planted faults, its figures.

use super::*;
use crate::format::{Align, Config};
use crate::frontend::engine::reference;
use crate::rng::{test_seed, SeedRng};
use crate::setup::Screen;
use crate::stimulus::random_fixed_triangles;
use rand::SeedableRng;

/// The first triangle whose sequenced set-up differs from `setup`'s (the plans divide no
/// incremental steps, so those are left out).
fn first_mismatch(fe: &FrontEnd, s: &SeqSchedule, tris: &[FixedTriangle]) -> Option<String> {
    tris.iter().zip(s.run(tris)).find_map(|(t, g)| {
        let want = reference(fe, &Plan::ICE40_HX8K, t);
        ((g.0, g.1) != (want.0, want.1)).then(|| format!("{t:?}\n sequential {:?}\n setup {:?}", g.1, want.1))
    })
}

fn screens() -> [FrontEnd; 2] {
    [Screen::default(), Screen { width: 37, height: 23 }].map(|s| FrontEnd::new(Config::default(), s).unwrap())
}

/// The engine tests' other screens: F = 4 on 16x8, and the widest (F = 16, XW = 16).
fn other_screens() -> [FrontEnd; 2] {
    [
        FrontEnd::new(Config::new(8, 4, 4, Align::Span).unwrap(), Screen { width: 16, height: 8 }).unwrap(),
        FrontEnd::new(Config::new(8, 16, 16, Align::Span).unwrap(), Screen { width: 65536, height: 65536 }).unwrap(),
    ]
}

/// Both iCE40 plans, sequenced, equal `setup` on random triangles of every kind, run back
/// to back from reset: 300 at 640x480 and 37x23, 100 at 16x8 (F = 4) and on the widest
/// screen (about 0.2 s; the co-simulation runs 1,000 a screen through the RTL).
#[test]
fn the_sequential_plans_equal_setup() {
    let mut rng = SeedRng::seed_from_u64(test_seed("the_sequential_plans_equal_setup"));
    for (fe, n) in screens().into_iter().map(|f| (f, 300)).chain(other_screens().into_iter().map(|f| (f, 100))) {
        let tris = random_fixed_triangles(&mut rng, &fe, n);
        for plan in [SeqPlan::ICE40_HX8K, SeqPlan::ICE40_UP5K] {
            let s = plan.schedule(&fe).unwrap();
            s.verify().unwrap();
            if let Some(m) = first_mismatch(&fe, &s, &tris) {
                panic!("{plan:?} on {:?}: {m}", fe.screen);
            }
        }
    }
}

fn planted(fault: impl Fn(&mut SeqSchedule)) -> (Result<(), String>, Option<String>) {
    let fe = &screens()[0];
    let mut s = SeqPlan::ICE40_HX8K.schedule(fe).unwrap();
    fault(&mut s);
    let tris = random_fixed_triangles(&mut SeedRng::seed_from_u64(test_seed("sequential planted")), fe, 200);
    (s.verify(), first_mismatch(fe, &s, &tris))
}

/// The RAM values whose lifetimes overlap the first's that is read after another value's
/// write: `(a, b)` with `b` written while `a` is live.
fn overlapping(s: &SeqSchedule) -> (usize, usize) {
    let ram = |o: usize| matches!(s.slots[o].loc, Loc::Ram(_)) && !matches!(s.slots[o].exec, Exec::Const | Exec::Dead);
    let n = s.slots.len();
    (0..n)
        .filter(|&a| ram(a))
        .flat_map(|a| (0..n).map(move |b| (a, b)))
        .find(|&(a, b)| ram(b) && b != a && s.slots[a].write < s.slots[b].write && s.slots[b].write < s.last_read(a))
        .expect("two values live at once")
}

/// Negative controls, each caught by `verify` and by the clocked run: two live values on
/// one address, an operation reading its operand in the clock it is written, a constant's
/// address given to a value.
#[test]
fn planted_sequencing_faults_are_caught() {
    let (v, m) = planted(|s| {
        let (a, b) = overlapping(s);
        s.slots[b].loc = s.slots[a].loc;
    });
    assert!(v.is_err() && m.is_some(), "two live values on one address: {v:?}");
    let (v, m) = planted(|s| {
        // The first ALU operation reading a value the ALU wrote to the register file.
        let alu_ram = |a: &V| s.slots[a.0 as usize].exec == Exec::Alu && matches!(s.slots[a.0 as usize].loc, Loc::Ram(_));
        let o = (0..s.slots.len()).find(|&o| s.slots[o].exec == Exec::Alu && s.prog.ops[o].kind.args().iter().any(alu_ram)).unwrap();
        let a = s.prog.ops[o].kind.args().into_iter().find(alu_ram).unwrap();
        s.slots[o].issue = s.slots[a.0 as usize].write;
    });
    assert!(v.is_err() && m.is_some(), "a read in its operand's write clock: {v:?}");
    let (v, m) = planted(|s| {
        let c = s.slots.iter().find(|x| x.exec == Exec::Const).unwrap().loc;
        let o = (0..s.slots.len()).find(|&o| s.slots[o].exec == Exec::Alu && matches!(s.slots[o].loc, Loc::Ram(_))).unwrap();
        s.slots[o].loc = c;
    });
    assert!(v.is_err() && m.is_some(), "a constant overwritten: {v:?}");
}

/// The UP5K plan's latencies (the ALU over three clocks, a registered write bus) are its
/// schedule's, and `verify` holds it to them: an ALU result planted a clock early (where the
/// RTL's result is not there yet) fails it.
#[test]
fn the_plans_latencies_are_the_schedules() {
    let fe = &screens()[1];
    let s = SeqPlan::ICE40_UP5K.schedule(fe).unwrap();
    let alu = READ + s.plan.alu_lat + s.plan.bus_lat;
    assert!(s.slots.iter().filter(|x| x.exec == Exec::Alu).all(|x| x.write == x.issue + alu));
    assert!(s.slots.iter().filter(|x| x.exec == Exec::Input).all(|x| x.write >= 2 * s.plan.bus_lat));
    let mut bad = s.clone();
    let o = (0..bad.slots.len()).find(|&o| bad.slots[o].exec == Exec::Alu).unwrap();
    bad.slots[o].write -= 1;
    assert!(bad.verify().is_err(), "an ALU result a clock early");
}

/// The figures docs/design.md quotes: `cargo test -p golden --lib sequential_figures --
/// --ignored --nocapture`.
#[test]
#[ignore]
fn sequential_figures() {
    for fe in screens().into_iter().chain(other_screens()) {
        for (plan, form) in [(SeqPlan::ICE40_HX8K, SetupForm::Ice40Hx8k), (SeqPlan::ICE40_UP5K, SetupForm::Ice40Up5k)] {
            let s = plan.schedule(&fe).unwrap();
            let p = form.plan().unwrap().schedule(&fe).unwrap();
            let c = s.cost;
            let alu = s.slots.iter().filter(|x| x.exec == Exec::Alu).count();
            let units: u32 = s.slots.iter().filter(|x| matches!(x.exec, Exec::Unit(..))).map(|x| x.write - x.issue).sum();
            println!("{form:?}: {alu} ALU operations, {units} unit clocks (issue to write) a triangle");
            println!(
                "{form:?} {}x{}: {} clocks a triangle (pipelined: II {} latency {}); RAM {} words x {} bits, {} + {} EBR (micro {} bits), {} flags; value bits in RAM {} (pipelined engine's registers {}); est. SB_LUT4 {} (ALU {}, shifter {}, mul {}, div {}, control {}), FF {} (results {}); pipelined engine's estimate {} LUT4",
                fe.screen.width,
                fe.screen.height,
                c.clocks,
                p.ii,
                p.latency,
                c.ram_words,
                c.ram_width,
                c.ebr_regfile,
                c.ebr_micro,
                c.micro_bits,
                c.flags,
                c.value_bits_ram,
                p.cost.reg_bits,
                c.lut4(),
                c.lut_alu,
                c.lut_shift,
                c.lut_mul,
                c.lut_div,
                c.lut_ctl,
                c.ff,
                c.result_bits,
                p.cost.lut_units + p.cost.lut_mux
            );
        }
    }
}

/// The vertex register holds a triangle only until its inputs are read (the engine keeps no
/// second copy of them): that clock is early in the period, and an input read at the period's
/// last clock (the entry's) is refused.
#[test]
fn the_inputs_are_read_before_the_next_entry() {
    let fe = &screens()[1];
    for plan in [SeqPlan::ICE40_HX8K, SeqPlan::ICE40_UP5K] {
        let s = plan.schedule(fe).unwrap();
        let last = s.inputs_read_by();
        let reads: Vec<u32> = s.slots.iter().filter(|x| x.exec == Exec::Input).map(|x| x.write - 2 * s.plan.bus_lat).collect();
        assert!(reads.iter().all(|&r| r <= last) && reads.contains(&last));
        assert!(last < s.clocks / 4, "inputs read by clock {last} of {}", s.clocks);
        let mut bad = s.clone();
        let o = (0..bad.slots.len()).find(|&o| bad.slots[o].exec == Exec::Input).unwrap();
        bad.slots[o].write = bad.clocks - 1 + 2 * bad.plan.bus_lat;
        assert!(std::panic::catch_unwind(|| bad.inputs_read_by()).is_err(), "an input read at the entry's clock");
    }
}
