//! The iCE40 targets' front-end forms in RTL (issue 27): the sequential engines, their
//! incremental `I0` and their sequential span path, each bit for bit golden's through
//! [`super::frontend`]'s engine scoreboard, each with planted faults. Slow tier.

use super::frontend::{assert_faults_caught, engine, engine_spans_of};
use golden::rng::SeedRng;
use rand::SeedableRng;
use verilator_harness::frontend::random_triangles;

/// The sequential engines (issue 27: golden's microprogram on one ALU, the values in a
/// block-RAM register file): the HX8K's (`--fe-setup ice40-hx8k`, a shift-add multiplier) at
/// 37x23 and 640x480, levels 0 and 1 (the target's), the UP5K's (`ice40-up5k`, its products as
/// SB_MAC16 tile passes) at 37x23 level 0 and 640x480 level 1 (its target's); 1,000 triangles
/// each (about 340 clocks a triangle); a fault planted in the HX8K's ALU (the subtract made an
/// add; the triangle taken, `in_ready`, a clock before its inputs' last read from the ports) and eleven in the UP5K's engine (the left
/// shift's power of two a place off, its SB_MAC16 products not joined, the tiles' sum not shifted a chunk up where
/// the pass's weight drops, its high half or the split ALU's without the low half's carry, the
/// divider's dividend bits not shifted in, the select's first choice never taken into `ax0`,
/// its second operand not zeroed before the adder that passes the choice, the
/// equality with zero a test of bit 0 alone, a
/// tile's held operand, only as wide as its unit's widest, without its top bit, the triangle
/// taken a clock early) are caught. Slow tier: `cargo nextest run -p verilator-harness --run-ignored only -E
/// 'test(/sequential_engine/)'`.
#[test]
#[ignore]
fn sequential_engine_spans_equal_golden() {
    use golden::frontend::engine::SetupForm;
    let small = golden::setup::Screen { width: 37, height: 23 };
    let big = golden::setup::Screen::default();
    let runs = [(SetupForm::Ice40Hx8k, small, 0), (SetupForm::Ice40Hx8k, big, 0), (SetupForm::Ice40Hx8k, small, 1)];
    for (form, screen, level) in runs.into_iter().chain([(SetupForm::Ice40Up5k, small, 0), (SetupForm::Ice40Up5k, big, 1)]) {
        let Some(opts) = engine(screen, form) else { return };
        engine_spans_of(hdl_gen::Options { pipeline: golden::pipeline::Pipeline::at(level), ..opts }, 1000);
    }
    for form in [SetupForm::Ice40Hx8k, SetupForm::Ice40Up5k] {
        let Some(opts) = engine(small, form) else { return };
        let base =
            verilator_harness::ondemand::describe(&opts, verilator_harness::models::Kind::Frontend).unwrap_or_else(|e| panic!("{e}"));
        let seed = verilator_harness::seed("frontend sequential engine fault");
        let fe = opts.frontend().unwrap().fe;
        let tris = random_triangles(&mut SeedRng::seed_from_u64(seed), &fe, 1000);
        let engine = &base.sources.iter().find(|(n, _)| n == "tri_fe_engine.v").expect("the engine's file").1;
        let line = |has: &str| engine.lines().find(|l| l.contains(has)).unwrap_or_else(|| panic!("no line with {has}")).to_string();
        let fault = |has: &str, from: &str, to: &str, what| {
            let l = line(has);
            (l.clone(), l.replacen(from, to, 1), what)
        };
        let faults = if form == SetupForm::Ice40Up5k {
            vec![
                fault(" m0lon = ", " m0s1 ? ", " 1'b0 ? ", "the tile's sum not shifted where the weight drops"),
                fault(" m0his = ", ", m0c2}", ", 1'b0}", "the tile's high half without the low half's carry"),
                fault(" addsub = ", "{bc ? ", "{1'b0 ? ", "the split ALU's high half without the low half's carry"),
                fault(" dt = ", "{dr, dl[", "{dr, 1'b0 & dl[", "the divider's dividend bits not shifted in"),
                fault(" a_b = ", "&& sc", "&& 1'b0", "the select's first choice (port B) never taken into the operand register"),
                fault(" b_z = ", "== 4'd8 ||", "== 4'd15 ||", "the select's second operand not zeroed, so the adder adds it to the choice"),
                fault(" bfl <= ", "~|ax0", "~ax0[0]", "the equality with zero a test of bit 0 alone"),
                fault(" m1b <= ", "];", "] << 1 >> 1;", "a tile's held operand without its top bit, the sign above its chunks"),
                fault(" at_read = ", "pc == ", "pc_n == ", "the triangle taken a clock before its inputs' last read"),
                fault(" shl_p = ", "'d1 << ", "'d2 << ", "the left shift's power of two (its SB_MAC16 operand) a place too high"),
                fault("shl_f = shl_f | ", "shl_f | ", "", "the left shift's products not joined: only the top 16 bits' kept"),
            ]
        } else {
            vec![
                fault(" sub = ", " == 4'd2 || ", " == 4'd15 || ", "the ALU's subtract made an add"),
                fault(" at_read = ", "pc == ", "pc_n == ", "the triangle taken a clock before its inputs' last read"),
            ]
        };
        assert_faults_caught(&base, "tri_fe_engine.v", "seqfault", faults, seed, &tris);
    }
}

/// A fault planted in one line of a front-end's file: in `file`'s first line holding `line`,
/// `from` made `to`.
struct LineFault {
    file: &'static str,
    line: &'static str,
    from: &'static str,
    to: &'static str,
}

impl LineFault {
    /// The model of `opts` with this fault (tagged `<base><suffix>0`) is caught on 1,000
    /// random triangles (the seed named `seed_name`).
    fn caught(&self, opts: &hdl_gen::Options, seed_name: &str, suffix: &str, what: &'static str) {
        let base = verilator_harness::ondemand::describe(opts, verilator_harness::models::Kind::Frontend).unwrap_or_else(|e| panic!("{e}"));
        let seed = verilator_harness::seed(seed_name);
        let fe = opts.frontend().unwrap().fe;
        let tris = random_triangles(&mut SeedRng::seed_from_u64(seed), &fe, 1000);
        let text = &base.sources.iter().find(|(n, _)| n == self.file).unwrap_or_else(|| panic!("no {}", self.file)).1;
        let line = text.lines().find(|l| l.contains(self.line)).unwrap_or_else(|| panic!("{what}: no line with {}", self.line));
        let faults = [(line.to_string(), line.replacen(self.from, self.to, 1), what)];
        assert_faults_caught(&base, self.file, suffix, faults, seed, &tris);
    }
}

/// The HX8K's span path without a product (`--target ice40-hx8k --fe-i0 incremental`, issue
/// 27): the sequential engine's set-up, the incremental I0 with its starts on a shift-add
/// multiplier (RW clocks a product), at 37x23 and 640x480, levels 0 and 1, 1,000 triangles
/// each, bit for bit golden's spans; a fault planted in the shift-add (a partial product from
/// the wrong bit) is caught. Slow tier: `cargo nextest run -p verilator-harness --run-ignored
/// only -E 'test(/sequential_incremental/)'`.
#[test]
#[ignore]
fn sequential_incremental_i0_spans_equal_golden() {
    use golden::frontend::engine::SetupForm;
    use golden::frontend::I0Form;
    let small = golden::setup::Screen { width: 37, height: 23 };
    let form = |screen, level| {
        engine(screen, SetupForm::Ice40Hx8k).map(|o| hdl_gen::Options {
            fe_i0: I0Form::Incremental,
            pipeline: golden::pipeline::Pipeline::at(level),
            ..o
        })
    };
    for (screen, level) in [(small, 0), (golden::setup::Screen::default(), 1), (small, 1)] {
        let Some(opts) = form(screen, level) else { return };
        engine_spans_of(opts, 1000);
    }
    let Some(opts) = form(small, 0) else { return };
    let fault = LineFault { file: "tri_frontend.v", line: "ie_p <= ie_p + (ie_sb[0]", from: "ie_sb[0]", to: "ie_sb[1]" };
    fault.caught(&opts, "frontend sequential incremental fault", "seqincfault", "the shift-add's partial product from the wrong bit");
}

/// The sequential span path (`--fe-span sequential`, the iCE40 targets' choice) behind both
/// iCE40 engines, 1,000 triangles each (37x23 and 640x480, levels 0 and 1; both targets, 640x480
/// at level 0, with the edges' lean DDA, the span's ends from their bounds side by side and the
/// walk's constants in block RAM), as [`engine_spans_of`]; a fault (the correction's `q~ + 1`
/// made `q~`), one in the lean DDA (the bound's step with its carry subtracted), two in the
/// side-by-side ends (an edge's bound the right end without its side test; the pixel test
/// without one pair's sum) and eight in the walk's memories (on the UP5K: `Gxn`'s read
/// addressed as `An`'s; the read slot not moved on at the take, so a triangle's first row reads
/// the one before's; the edges' fields, preloaded from the second memory, and `Tn` read from
/// the walked triangle's slot; each edge field loaded a clock after its read; on the HX8K, whose
/// walker holds `dYn` in a register: `Tn` so again, the register not loaded at the take, so it
/// steps by the triangle before's `dYn`; `dYn` read from the walked triangle's slot; `dYn` read
/// while the last row waits for the span path, whose next load then reads it) are caught. Slow tier: `cargo nextest run -p verilator-harness --run-ignored only
/// -E 'test(/sequential_span/)'`.
#[test]
#[ignore]
fn sequential_span_path_spans_equal_golden() {
    use golden::frontend::{engine::SetupForm::*, SpanForm};
    let (small, big) = (golden::setup::Screen { width: 37, height: 23 }, golden::setup::Screen::default());
    let form = |screen, setup, level| {
        engine(screen, setup).map(|o| hdl_gen::Options {
            fe_span: SpanForm::Sequential,
            pipeline: golden::pipeline::Pipeline::at(level),
            ..o
        })
    };
    let runs = [
        (small, Ice40Hx8k, 0),
        (big, Ice40Hx8k, 0),
        (big, Ice40Hx8k, 1),
        (small, Ice40Up5k, 0),
        (big, Ice40Up5k, 0),
        (small, Ice40Up5k, 1),
        (big, Ice40Up5k, 1),
    ];
    for (screen, setup, level) in runs {
        let Some(opts) = form(screen, setup, level) else { return };
        engine_spans_of(opts, 1000);
    }
    let Some(opts) = form(small, Ice40Hx8k, 1) else { return };
    let fault = LineFault { file: "tri_frontend.v", line: "sq_qt_now} + ", from: "} + ", to: "} - " };
    fault.caught(&opts, "frontend sequential span fault", "seqspanfault", "the correction's q~ + 1 made q~ - 1");
    let Some(opts) = form(small, Ice40Hx8k, 0) else { return };
    let fault = LineFault { file: "tri_fe_edge.v", line: " gnext = w_g + w_qs + ", from: "w_qs + {", to: "w_qs - {" };
    fault.caught(&opts, "frontend lean edge fault", "leanedgefault", "the lean DDA's bound step with its carry subtracted");
    let fault = LineFault { file: "tri_frontend.v", line: " bhw0 = ", from: "bh0 &&", to: "1'b1 &&" };
    fault.caught(&opts, "frontend side by side ends fault", "sideendsfault", "an edge's bound made the right end without its side test");
    let fault = LineFault { file: "tri_frontend.v", line: " covered = ", from: "!sg01[", to: "1'b1 || !sg01[" };
    fault.caught(&opts, "frontend pixel test fault", "pixeltestfault", "the pixel test without edges 0 and 1's sum");
    let Some(opts) = form(small, Ice40Up5k, 0) else { return };
    let fault = LineFault { file: "tri_frontend.v", line: " wk_ra = (sq_busy && sq_ph == 3'd0) ? 2'd1", from: "? 2'd1", to: "? 2'd0" };
    fault.caught(&opts, "frontend walk ram fault", "walkramfault", "Gxn's read addressed as An's");
    let fault = LineFault { file: "tri_frontend.v", line: " wk_slot = wk_rs ^ take", from: "^ take", to: "^ 1'b0" };
    fault.caught(&opts, "frontend walk ram slot fault", "walkslotfault", "the read slot not moved on at the take");
    // The UP5K's edges' fields in the second memory, preloaded one a clock before the take:
    // read (and Tn with them) from the walked triangle's slot, and each read a word early, so
    // that every field is loaded a clock late (the word before's).
    let fault = LineFault { file: "tri_frontend.v", line: " wk_da = wk_pre ? {!wk_rs", from: "{!wk_rs", to: "{wk_rs" };
    fault.caught(&opts, "frontend walk ram tn fault", "walktnfault", "the edges' fields and Tn read from the walked triangle's slot");
    let fault = LineFault { file: "tri_frontend.v", line: " wk_da = wk_pre ? {!wk_rs", from: "wk_lk + 5'd2", to: "wk_lk + 5'd1" };
    fault.caught(&opts, "frontend walk ram preload fault", "walkpreloadfault", "each edge field loaded a clock after its read");
    // The UP5K's dI beside An in the first memory (the output loads it from the read register
    // with the span path's result): written into the walked triangle's slot, or into the free
    // fourth word, which the span path's last phase does not read.
    let di_write = "] <= {res_bus[15:0], res_bus[20:16]};";
    let fault = LineFault { file: "tri_frontend.v", line: di_write, from: "{wk_ws,", to: "{!wk_ws," };
    fault.caught(&opts, "frontend walk ram di slot fault", "walkdislotfault", "dI written into the walked triangle's slot");
    let fault = LineFault { file: "tri_frontend.v", line: di_write, from: "wk_wa}", to: "2'd3}" };
    fault.caught(&opts, "frontend walk ram di word fault", "walkdiwordfault", "dI written into the fourth word, not An's");
    // The UP5K's pixel test after the ends' picks (`Hw::fewest_cells`): a one-pixel row
    // (hi3 + mg = 0) dropped.
    let fault = LineFault { file: "tri_frontend.v", line: " room = ", from: "mg[15]}}, mg}", to: "mg[15]}}, mg} - 17'sd1" };
    fault.caught(&opts, "frontend up5k pixel test fault", "uppixelfault", "the pixel test after the picks dropping one-pixel rows");
    // The HX8K's walker holds dYn in a register loaded at the take: a stale dYn, the one
    // before's, must be caught, and so must its reads' slot and clock.
    let Some(opts) = form(small, Ice40Hx8k, 0) else { return };
    let fault = LineFault { file: "tri_frontend.v", line: " wk_dq <= wk_d[{!wk_rs", from: "{!wk_rs", to: "{wk_rs" };
    fault.caught(
        &opts,
        "frontend walk ram hx8k tn fault",
        "walktnhxfault",
        "Tn read from the walked triangle's slot, not the queued one's",
    );
    let fault = LineFault { file: "tri_frontend.v", line: " w_dyn <= wk_dyn;", from: "<= wk_dyn", to: "<= w_dyn" };
    fault.caught(&opts, "frontend walk ram dyn fault", "walkdynfault", "dYn not loaded at the take: the triangle before's");
    let fault = LineFault { file: "tri_frontend.v", line: " wk_ma = wk_dnr ? {!wk_rs", from: "{!wk_rs", to: "{wk_rs" };
    fault.caught(
        &opts,
        "frontend walk ram dyn slot fault",
        "walkdynslotfault",
        "dYn read from the walked triangle's slot, not the queued one's",
    );
    let fault = LineFault { file: "tri_frontend.v", line: " wk_dnr = ", from: "w_end && adv", to: "w_end" };
    fault.caught(
        &opts,
        "frontend walk ram dyn read fault",
        "walkdynreadfault",
        "dYn read while the span path may load the last row's field",
    );
}
