//! The engine's clock: a phase ring modulo II, an epoch ring modulo the binding's period, the
//! vertex registers and the entry of a triangle every II clocks, and a valid bit per period in
//! flight, so a bubble (no triangle at the entry) flows through the schedule like a triangle
//! and only its result is not taken.

use crate::verilog::{bit, comment, reg, set, wire, Item, Stmt};
use golden::frontend::Widths;

/// What the sequencer decides for the rest: the condition that schedule clock `t` of a triangle
/// of epoch `e` is now.
pub(super) struct Seq {
    pub ii: u32,
    pub epochs: u32,
}

impl Seq {
    /// Phase `p` (a one-hot ring, reset to phase 0).
    pub fn phase(&self, p: u32) -> String {
        if self.ii == 1 {
            "1'b1".into()
        } else {
            bit("ph", self.ii, p)
        }
    }

    /// Schedule clock `t` of a triangle of one of the epochs `es` is this clock: the phase alone
    /// when `es` are all of them (an operation that keeps its unit).
    pub fn when_any(&self, t: u32, es: &[u32]) -> String {
        let p = self.phase(t % self.ii);
        if es.len() as u32 >= self.epochs {
            return p;
        }
        let eps: Vec<String> = es.iter().map(|e| bit("ep", self.epochs, (e + t / self.ii) % self.epochs)).collect();
        if eps.len() == 1 {
            format!("({p} && {})", eps[0])
        } else {
            format!("({p} && ({}))", eps.join(" || "))
        }
    }

    /// The units an operation runs on, each with the epochs of the triangles it runs there.
    pub fn units_of(&self, s: &golden::frontend::engine::schedule::Schedule, o: usize) -> Vec<(u32, Vec<u32>)> {
        let mut v: Vec<(u32, Vec<u32>)> = Vec::new();
        for e in 0..self.epochs {
            let u = s.unit_of(o, e).expect("an operation bound to a unit");
            match v.iter_mut().find(|(x, _)| *x == u) {
                Some((_, es)) => es.push(e),
                None => v.push((u, vec![e])),
            }
        }
        v
    }

    /// The entry: the last phase, a triangle (or a bubble) moves from the vertex registers into
    /// the program's inputs (the engine never freezes: the front-end's credits keep the queue
    /// from overflowing).
    pub fn entry(&self) -> String {
        self.phase(self.ii - 1)
    }
}

/// The sequencer's registers and its always block; `latency` is the schedule's.
pub(super) fn emit(seq: &Seq, wd: &Widths, iw: u32, latency: u32, body: &mut Vec<Item>) {
    let (ii, r) = (seq.ii, seq.epochs);
    let periods = latency / ii + 1;
    body.push(comment(if r > 1 {
        format!("Sequencer: phase ring ph (II = {ii}), epoch ring ep ({r} triangles: the units' binding repeats), a valid bit per period in flight.")
    } else {
        format!("Sequencer: phase ring ph (II = {ii}; every triangle on the same units), a valid bit per period in flight.")
    }));
    if ii > 1 {
        body.push(reg("ph", ii));
    }
    if r > 1 {
        body.push(reg("ep", r));
    }
    body.push(reg("vld", periods));
    body.push(reg("v_full", 1));
    for k in 0..3 {
        body.push(crate::verilog::sreg(&format!("vx{k}"), wd.cx));
        body.push(crate::verilog::sreg(&format!("vy{k}"), wd.cy));
        body.push(reg(&format!("vi{k}"), iw));
    }
    body.push(wire("enter", 1, seq.entry()));
    body.push(Item::Assign("in_ready".into(), "!v_full || enter".into()));
    body.push(Item::Assign("res_v".into(), format!("{} && {}", seq.phase(latency % ii), bit("vld", periods, latency / ii))));
    let rot = |n: &str, w: u32| if w == 1 { n.to_string() } else { format!("{{{n}[{}:0], {n}[{}]}}", w - 2, w - 1) };
    let mut run = Vec::new();
    if ii > 1 {
        run.push(set("ph", rot("ph", ii)));
    }
    let mut at_entry = vec![set("vld", if periods == 1 { "v_full".to_string() } else { format!("{{vld[{}:0], v_full}}", periods - 2) })];
    if r > 1 {
        at_entry.push(set("ep", rot("ep", r)));
    }
    run.push(Stmt::If(seq.phase(ii - 1), at_entry, vec![]));
    let mut take = vec![set("v_full", "1'b1")];
    for k in 0..3 {
        for (v, p) in [("vx", "in_x"), ("vy", "in_y"), ("vi", "in_i")] {
            take.push(set(format!("{v}{k}"), format!("{p}{k}")));
        }
    }
    let one_hot = |w: u32| if w == 1 { "1'b1".to_string() } else { format!("{{{}'d0, 1'b1}}", w - 1) };
    let mut reset = vec![set("v_full", "1'b0"), set("vld", format!("{periods}'d0"))];
    if ii > 1 {
        reset.push(set("ph", one_hot(ii)));
    }
    if r > 1 {
        reset.push(set("ep", one_hot(r)));
    }
    run.insert(0, Stmt::If("in_valid && in_ready".into(), take, vec![Stmt::If("enter".into(), vec![set("v_full", "1'b0")], vec![])]));
    body.push(Item::Always(vec![Stmt::If("rst".into(), reset, run)]));
    body.push(Item::Blank);
}
