//! A computation written once as a sequence of stages, registered where the pipeline level asks:
//! the set-up's CALC ([`golden::pipeline::SETUP_STAGES`]) and the spans' I0 path
//! ([`golden::pipeline::I0_STAGES`]).
//!
//! Each value is defined in one stage and read by name in any later one. Between two stages is
//! a boundary, registered or not: a value read after a registered boundary is carried through
//! one register per registered boundary (`<prefix><j>_<name>` in physical stage j, loaded as the
//! stage moves on); across an unregistered one a name is just its wire. So every level is one
//! description and computes the same values.

use std::cell::{Cell, RefCell};
use std::collections::{BTreeSet, HashMap};

use crate::verilog::{comment, reg, set, sreg, swire, wire, Item, Stmt};

#[derive(Clone)]
struct Def {
    stage: usize,
    width: u32,
    signed: bool,
    /// What the name reads as in its own stage: its wire, or the signal it stands for.
    here: String,
}

type Carry = (String, u32, bool, String);

pub(super) struct Stager {
    /// Register names: `<prefix><j>_<name>`.
    prefix: &'static str,
    /// Per boundary between two logical stages: registered or not.
    cuts: Vec<bool>,
    /// The logical stage being written, and the physical one (registered boundaries behind it).
    logical: usize,
    cur: usize,
    defs: HashMap<String, Def>,
    logic: Vec<Item>,
    /// Per registered boundary j (into physical stage j + 1): the registers it loads, `(name,
    /// width, signed, from)`. Reading a value adds them, so reads can sit inside the expression
    /// being defined.
    carries: RefCell<Vec<Vec<Carry>>>,
    carried: RefCell<BTreeSet<String>>,
    /// Set once the registers are declared ([`Stager::items`]): no register may be added after.
    declared: Cell<bool>,
}

impl Stager {
    pub fn new(prefix: &'static str, cuts: Vec<bool>) -> Stager {
        let regs = cuts.iter().filter(|&&c| c).count();
        Stager {
            prefix,
            cuts,
            logical: 0,
            cur: 0,
            defs: HashMap::new(),
            logic: Vec::new(),
            carries: RefCell::new(vec![Vec::new(); regs]),
            carried: RefCell::default(),
            declared: Cell::new(false),
        }
    }

    /// A value of the stage being written that is an existing signal (a vertex register, the
    /// walker's): no wire of its own; its first register loads `src`.
    pub fn input_as(&mut self, name: &str, width: u32, signed: bool, src: &str) {
        let d = Def { stage: self.cur, width, signed, here: src.into() };
        assert!(self.defs.insert(name.into(), d).is_none(), "staged value {name} defined twice");
    }

    /// [`Stager::input_as`] under its own name.
    pub fn input(&mut self, name: &str, width: u32, signed: bool) {
        self.input_as(name, width, signed, name);
    }

    /// Ends the logical stage being written; a registered boundary starts the next clock.
    pub fn cut(&mut self) {
        if self.cuts[self.logical] {
            self.cur += 1;
        }
        self.logical += 1;
    }

    /// The physical stage being written: registered boundaries behind it.
    pub fn stage(&self) -> usize {
        self.cur
    }

    /// The logical stage being written.
    pub fn logical(&self) -> usize {
        self.logical
    }

    /// The name under which `name` reads in the stage being written, adding the registers that
    /// carry it there.
    pub fn at(&self, name: &str) -> String {
        self.read_in(name, self.cur)
    }

    /// The name under which `name` reads in the physical stage before the one being written (a
    /// tile's operand as its own input register loads it: `tri_fe_mul18`).
    pub fn before(&self, name: &str) -> String {
        assert!(self.cur >= 1, "staged value {name} read before stage 0");
        self.read_in(name, self.cur - 1)
    }

    fn read_in(&self, name: &str, cur: usize) -> String {
        let d = self.defs.get(name).unwrap_or_else(|| panic!("staged value {name} read before it is defined"));
        assert!(d.stage <= cur, "staged value {name} read in stage {cur}, before its own ({})", d.stage);
        let reg = |j: usize| format!("{}{j}_{name}", self.prefix);
        for j in d.stage + 1..=cur {
            if self.carried.borrow_mut().insert(reg(j)) {
                assert!(!self.declared.get(), "staged value {name} carried to stage {j} after the registers were declared");
                let from = if j - 1 == d.stage { d.here.clone() } else { reg(j - 1) };
                self.carries.borrow_mut()[j - 1].push((reg(j), d.width, d.signed, from));
            }
        }
        if d.stage == cur {
            d.here.clone()
        } else {
            reg(cur)
        }
    }

    /// The width `name` was defined with.
    pub fn width(&self, name: &str) -> u32 {
        self.defs.get(name).unwrap_or_else(|| panic!("staged value {name} read before it is defined")).width
    }

    /// Where `name` is held in physical stage `j`, if it is there: its wire in the stage that
    /// defines it, or a register carrying it (for the proof's linking invariants).
    pub fn held(&self, name: &str, j: usize) -> Option<String> {
        let d = self.defs.get(name)?;
        let r = format!("{}{j}_{name}", self.prefix);
        if self.carried.borrow().contains(&r) {
            Some(r)
        } else {
            (d.stage == j).then(|| d.here.clone())
        }
    }

    /// Defines `name` in the stage being written.
    pub fn def(&mut self, name: &str, width: u32, signed: bool, value: impl Into<String>) {
        let d = Def { stage: self.cur, width, signed, here: name.into() };
        assert!(self.defs.insert(name.into(), d).is_none(), "staged value {name} defined twice");
        self.logic.push(if signed { swire(name, width, value) } else { wire(name, width, value) });
    }

    /// `out = a * b` at the product's natural width from two signed names: the language extends
    /// them to the result, and synthesis builds a `wa` x `wb` multiplier (extending them by hand
    /// would make it as wide as the result on both sides).
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
        if self.carries.borrow().iter().any(|c| !c.is_empty()) {
            let p = self.prefix;
            v.push(comment(format!("Stage registers: {p}<j>_<name> holds <name> in stage j (whole values: a stage")));
            v.push(comment("may read a slice only)."));
            for (n, w, s, _) in self.carries.borrow().iter().flatten() {
                v.push(if *s { sreg(n, *w) } else { reg(n, *w) });
            }
        }
        v.extend(self.logic.iter().cloned());
        v
    }

    /// The registers registered boundary j loads (into physical stage j + 1): `(name, width,
    /// signed)`.
    pub fn regs(&self, j: usize) -> Vec<(String, u32, bool)> {
        self.carries.borrow()[j].iter().map(|(n, w, s, _)| (n.clone(), *w, *s)).collect()
    }

    /// The loads of registered boundary j's registers, for an `if (move) ...`.
    pub fn loads(&self, j: usize) -> Vec<Stmt> {
        self.carries.borrow()[j].iter().map(|(n, _, _, from)| set(n.clone(), from.clone())).collect()
    }
}
