//! The BFPI's formal reference: what `scripts/prove` proves `bfpi_p<P>` equivalent to.

use crate::verilog::{assign, sext, Item, Module, Port};
use golden::Config;

/// The reference `bfpi_p<P>` is proven equal to (Yosys `equiv_*`, lane by lane, for all di):
/// `<bfpi>_ref`, each lane `(i+1) * di` written with `*`. A second module rather than an
/// assertion, because SAT on `x * constant` against a shift-and-add graph takes minutes at
/// P = 64 where structural equivalence takes seconds.
pub fn bfpi_reference(cfg: &Config, bfpi: &str) -> Module {
    let (p, dw, mw) = (cfg.p, cfg.dw(), cfg.mw());
    Module {
        name: format!("{bfpi}_ref"),
        header: vec![],
        params: vec![],
        ports: vec![
            Port::input("di", dw, "", "increment").signed(),
            Port::output("inc", p * mw, "", "lane i = (i+1)*di, by multiplication"),
        ],
        body: vec![Item::ForGenerate {
            var: "k".into(),
            count: p,
            label: "lane".into(),
            body: vec![
                Item::Localparam { name: "K".into(), width: mw, value: "k + 1".into() },
                assign(format!("inc[k*{mw} +: {mw}]"), format!("{} * K", sext("di", dw, mw))),
            ],
        }],
    }
}
