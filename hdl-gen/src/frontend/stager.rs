//! The set-up's CALC as register stages (`--pipeline 1` and above, [`golden::pipeline::SETUP_STAGES`]).
//!
//! CALC is written once, as a sequence of stages: each value is defined in one stage and read by
//! name in any later one. With the stages on, a value read after the stage that defines it is
//! carried there through one register per boundary (`c<j>_<name>`, loaded as the triangle moves
//! into stage j); with them off, every stage is the same clock and a name is just its wire. So
//! level 0 and the pipelined levels are one description and compute the same values.

use std::cell::{Cell, RefCell};
use std::collections::{BTreeSet, HashMap};

use crate::verilog::{comment, reg, set, sreg, swire, wire, Item, Stmt};

#[derive(Clone, Copy)]
struct Def {
    stage: usize,
    width: u32,
    signed: bool,
}

pub(super) struct Stager {
    /// Register boundaries: 0 (one clock) or `SETUP_STAGES.len() - 1`.
    cuts: usize,
    /// The stage being written.
    cur: usize,
    defs: HashMap<String, Def>,
    logic: Vec<Item>,
    /// Per boundary j (into stage j + 1): the registers it loads, `(name, width, signed, from)`.
    /// Reading a value adds them, so that reads can sit inside the expression being defined.
    carries: RefCell<Vec<Vec<Carry>>>,
    carried: RefCell<BTreeSet<String>>,
    /// Set once the registers are declared ([`Stager::items`]): no register may be added after.
    declared: Cell<bool>,
}

type Carry = (String, u32, bool, String);

impl Stager {
    pub fn new(cuts: usize) -> Stager {
        Stager {
            cuts,
            cur: 0,
            defs: HashMap::new(),
            logic: Vec::new(),
            carries: RefCell::new(vec![Vec::new(); cuts]),
            carried: RefCell::default(),
            declared: Cell::new(false),
        }
    }

    /// A value that exists before the first stage (a vertex register).
    pub fn input(&mut self, name: &str, width: u32, signed: bool) {
        self.defs.insert(name.into(), Def { stage: 0, width, signed });
    }

    /// Ends the stage being written: with the stages on, what follows is the next clock.
    pub fn cut(&mut self) {
        if self.cur < self.cuts {
            self.cur += 1;
        }
    }

    /// The stage being written (0 with the stages off).
    pub fn stage(&self) -> usize {
        self.cur
    }

    /// The name under which `name` reads in the stage being written, adding the registers that
    /// carry it there.
    pub fn at(&self, name: &str) -> String {
        let d = *self.defs.get(name).unwrap_or_else(|| panic!("set-up value {name} read before it is defined"));
        for j in d.stage + 1..=self.cur {
            let r = format!("c{j}_{name}");
            if self.carried.borrow_mut().insert(r.clone()) {
                assert!(!self.declared.get(), "set-up value {name} carried to stage {j} after the registers were declared");
                let from = if j - 1 == d.stage { name.to_string() } else { format!("c{}_{name}", j - 1) };
                self.carries.borrow_mut()[j - 1].push((r, d.width, d.signed, from));
            }
        }
        if d.stage == self.cur {
            name.to_string()
        } else {
            format!("c{}_{name}", self.cur)
        }
    }

    /// Where `name` is held in stage `j`, if it is there: its wire in the stage that defines
    /// it, or a register carrying it (for the proof's linking invariants).
    pub fn held(&self, name: &str, j: usize) -> Option<String> {
        let d = self.defs.get(name)?;
        let r = format!("c{j}_{name}");
        if self.carried.borrow().contains(&r) {
            Some(r)
        } else {
            (d.stage == j).then(|| name.to_string())
        }
    }

    /// Defines `name` in the stage being written.
    pub fn def(&mut self, name: &str, width: u32, signed: bool, value: impl Into<String>) {
        assert!(self.defs.insert(name.into(), Def { stage: self.cur, width, signed }).is_none(), "set-up value {name} defined twice");
        self.logic.push(if signed { swire(name, width, value) } else { wire(name, width, value) });
    }

    /// `out = a * b` at the product's natural width from two signed names (see `smul`).
    pub fn mul(&mut self, out: &str, a: &str, wa: u32, b: &str, wb: u32) {
        let (a, b) = (self.at(a), self.at(b));
        self.logic.push(comment("verilator lint_off WIDTH"));
        self.def(out, wa + wb, true, format!("{a} * {b}"));
        self.logic.push(comment("verilator lint_on WIDTH"));
    }

    /// A comment or blank line among the stage's logic.
    pub fn note(&mut self, item: Item) {
        self.logic.push(item);
    }

    /// The stage registers' declarations, then the logic in order.
    pub fn items(&self) -> Vec<Item> {
        self.declared.set(true);
        let mut v = Vec::new();
        if self.cuts > 0 {
            v.push(comment("Stage registers: c<j>_<name> holds <name> for stage j (whole values: a stage may read"));
            v.push(comment("a slice only)."));
            for (n, w, s, _) in self.carries.borrow().iter().flatten() {
                v.push(if *s { sreg(n, *w) } else { reg(n, *w) });
            }
        }
        v.extend(self.logic.iter().cloned());
        v
    }

    /// The registers boundary j loads (into stage j + 1): `(name, width, signed)`.
    pub fn regs(&self, j: usize) -> Vec<(String, u32, bool)> {
        self.carries.borrow()[j].iter().map(|(n, w, s, _)| (n.clone(), *w, *s)).collect()
    }

    /// The loads of boundary j's registers (into stage j + 1), for an `if (move) ...`.
    pub fn loads(&self, j: usize) -> Vec<Stmt> {
        self.carries.borrow()[j].iter().map(|(n, _, _, from)| set(n.clone(), from.clone())).collect()
    }
}
