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
    /// Per registered boundary j: the multiplier tiles' operand registers it loads ([`Stager::tap`]).
    taps: RefCell<Vec<Vec<Carry>>>,
    /// Names defined as a slice of another value ([`Stager::def_slice`]): `(of, lowest bit)`.
    slices: HashMap<String, (String, u32)>,
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
            taps: RefCell::new(vec![Vec::new(); regs]),
            slices: HashMap::new(),
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
        self.at_stage(name, self.cur)
    }

    /// [`Stager::at`] in physical stage `stage`, at or before the one being written.
    fn at_stage(&self, name: &str, stage: usize) -> String {
        let d = self.defs.get(name).unwrap_or_else(|| panic!("staged value {name} read before it is defined"));
        let reg = |j: usize| format!("{}{j}_{name}", self.prefix);
        for j in d.stage + 1..=stage {
            if self.carried.borrow_mut().insert(reg(j)) {
                assert!(!self.declared.get(), "staged value {name} carried to stage {j} after the registers were declared");
                let from = if j - 1 == d.stage { d.here.clone() } else { reg(j - 1) };
                self.carries.borrow_mut()[j - 1].push((reg(j), d.width, d.signed, from));
            }
        }
        if d.stage == stage {
            d.here.clone()
        } else {
            reg(stage)
        }
    }

    /// `name[hi:lo]` for a multiplier tile's operand: from a register of its own
    /// (`<prefix><j>_<name>_<hi>_<lo>`, loaded with the slice from the stage before) when a
    /// registered boundary lies between the value (or the value it is a slice of,
    /// [`Stager::def_slice`]) and the stage being written, so that its only loads are the tiles
    /// reading that slice and placement can put it by its MULT18X18D; else the slice read here.
    /// Its load enable is the move alone ([`Stager::tap_loads`]): with the stage registers'
    /// (the move, not in reset) Yosys would merge it with them, flip-flops of one input and
    /// enable being one. A tap differs from them only while in reset, when no stage is valid.
    pub fn tap(&self, name: &str, hi: u32, lo: u32) -> String {
        let (mut of, mut off) = (name, 0);
        while let Some((o, l)) = self.slices.get(of) {
            (of, off) = (o, off + l);
        }
        let d = self.defs.get(of).unwrap_or_else(|| panic!("staged value {of} read before it is defined"));
        if d.stage == self.cur {
            return bits_of(&self.at(name), self.width(name), hi, lo);
        }
        let (hi, lo) = (hi + off, lo + off);
        let r = format!("{}{}_{of}_{hi}_{lo}", self.prefix, self.cur);
        if self.carried.borrow_mut().insert(r.clone()) {
            assert!(!self.declared.get(), "tap {r} added after the registers were declared");
            let from = bits_of(&self.at_stage(of, self.cur - 1), d.width, hi, lo);
            self.taps.borrow_mut()[self.cur - 1].push((r.clone(), hi - lo + 1, false, from));
        }
        r
    }

    /// Defines `name` as `of[lo + width - 1:lo]` in the stage being written; a [`Stager::tap`] of
    /// it is a tap of `of`.
    pub fn def_slice(&mut self, name: &str, of: &str, lo: u32, width: u32) {
        let src = bits_of(&self.at(of), self.width(of), lo + width - 1, lo);
        self.def(name, width, false, src);
        self.slices.insert(name.into(), (of.into(), lo));
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
        let tapped = self.taps.borrow().iter().any(|t| !t.is_empty());
        if self.carries.borrow().iter().any(|c| !c.is_empty()) {
            let p = self.prefix;
            v.push(comment(format!("Stage registers: {p}<j>_<name> holds <name> in stage j (whole values: a stage")));
            v.push(comment("may read a slice only)."));
            if tapped {
                v.push(comment(format!("A multiplier tile reads its operands from {p}<j>_<name>_<hi>_<lo>, its own; a stage register's")));
                v.push(comment("bits that only tiles read are unread."));
                v.push(comment("verilator lint_off UNUSEDSIGNAL"));
            }
            for (n, w, s, _) in self.carries.borrow().iter().flatten() {
                v.push(if *s { sreg(n, *w) } else { reg(n, *w) });
            }
            for (n, w, _, _) in self.taps.borrow().iter().flatten() {
                v.push(reg(n, *w));
            }
            if tapped {
                v.push(comment("verilator lint_on UNUSEDSIGNAL"));
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

    /// The loads of registered boundary j's tile operand registers ([`Stager::tap`]), for an `if
    /// (move) ...` apart from the stage registers'.
    pub fn tap_loads(&self, j: usize) -> Vec<Stmt> {
        self.taps.borrow()[j].iter().map(|(n, _, _, from)| set(n.clone(), from.clone())).collect()
    }

    /// The loads of registered boundary j's registers, for an `if (move) ...`.
    pub fn loads(&self, j: usize) -> Vec<Stmt> {
        self.carries.borrow()[j].iter().map(|(n, _, _, from)| set(n.clone(), from.clone())).collect()
    }
}

/// `x[hi:lo]` of a value as it reads in a stage: its whole self, a slice of a name, or of a
/// slice (the walker's `hi3[..]`).
pub(super) fn bits_of(x: &str, w: u32, hi: u32, lo: u32) -> String {
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
