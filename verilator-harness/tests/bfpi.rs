//! Every `bfpi_p<P>` model built, exhaustively over every increment of its width: each lane
//! equals golden's bit-exact evaluation of the same adder graph, and that is `(i+1)*di`.

use golden::bfpi::BfpiPlan;
use verilator_harness::ffi::{to_port, BfpiIn, BfpiOut, Rtl};
use verilator_harness::registry::{require_models, BFPI_MODELS};

#[test]
fn bfpi_matches_golden_for_every_increment() {
    let Some(models) = require_models(&BFPI_MODELS, "bfpi", "bfpi: every increment") else { return };
    for info in models {
        let cfg = info.cfg;
        let (dw, mw, p) = (cfg.dw(), cfg.mw(), cfg.p as usize);
        let plan = BfpiPlan::new(cfg.p);
        let mut rtl: Rtl<BfpiIn, BfpiOut> = Rtl::new(info, 1);
        let mut out = BfpiOut::default();
        let (mut nodes, mut want) = (vec![0; p + 1], vec![0; p]);
        let half = 1i64 << (dw - 1);
        for di in -half..half {
            rtl.step_into(&BfpiIn { di: to_port(di, dw) }, &mut out);
            plan.evaluate_into(di, mw, &mut nodes, &mut want);
            for (i, w) in want.iter().enumerate() {
                let got = out.lane(i as u32, mw);
                assert_eq!(got, *w, "{}: di = {di}, lane {i}: golden {w}, RTL {got}", info.tag);
                assert_eq!(*w, (i as i64 + 1) * di, "golden plan for p = {p} at di = {di}, lane {i}");
            }
        }
    }
}
