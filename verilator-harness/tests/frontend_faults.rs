//! Negative controls of the front-end's co-simulation (issue 27's forms): faults planted in the
//! generated engine, walker and span path, each a model built on first use, must be caught on the
//! triangles the clean model passes. Slow tier: run them with `cargo nextest run -p
//! verilator-harness --run-ignored only -E 'test(/planted/)'`.

use crate::frontend::{assert_faults_caught, engine};
use golden::rng::SeedRng;
use rand::SeedableRng;
use verilator_harness::ffi::{FeOut, TriIn};
use verilator_harness::frontend::{random_triangles, run_frontend};
use verilator_harness::segment::{Stress, Traffic};

/// The line of `text` that `f` picks, for a fault to replace; panics naming `what` if the
/// generated text has none (a renamed signal must fail the test, not skip the fault).
fn line(text: &str, what: &str, f: &dyn Fn(&str) -> bool) -> String {
    text.lines().find(|l| f(l)).unwrap_or_else(|| panic!("no line for {what}")).to_string()
}

/// The walker's faults' base: the ECP5 plan's front-end at 37x23, level 1 (the row stages), its
/// seed for `label` and 3,000 random triangles; `None` where `engine` skips (COSIM_RTL_DIR).
fn row_stage_base(label: &str) -> Option<(verilator_harness::models::Model, u64, Vec<golden::frontend::FixedTriangle>)> {
    let opts = engine(golden::setup::Screen { width: 37, height: 23 }, golden::frontend::engine::SetupForm::Ecp5_25f)?;
    let opts = hdl_gen::Options { pipeline: golden::pipeline::Pipeline::at(1), ..opts };
    let base = verilator_harness::ondemand::describe(&opts, verilator_harness::models::Kind::Frontend).unwrap_or_else(|e| panic!("{e}"));
    let seed = verilator_harness::seed(label);
    let fe = opts.frontend().unwrap().fe;
    let tris = random_triangles(&mut SeedRng::seed_from_u64(seed), &fe, 3000);
    Some((base, seed, tris))
}

/// Negative controls of the engine's co-simulation: a fault planted in the generated engine
/// (each a model built on first use, 37x23) is caught on the triangles the clean model passes:
/// one logic operation reading its operand's copy of the next triangle (a copy off by one
/// period), a tile's passes added at the wrong weights (its accumulator never shifted), a division's quotient taken from the
/// divider of another epoch (a binding rotated), the shared shifter's amount read from the next
/// triangle's copy, the leading-zero count's lowest bit stuck at one (an even count one too
/// large: the normalised `|A|` loses its top bit; stuck at zero, 0 mismatches at 37x23), a
/// tile's operand register loaded on every clock (its registered load ignored: a held chunk
/// overwritten), a tile port's registered select bit stuck at zero (a source never selected),
/// a chained division's second divider taking the first's loaded dividend bits for its
/// quotient bits so far, an edge's `dy < 0` (its sign bit, not a compare) read inverted;
/// and in `tri_frontend.v`, a triangle taken with no queue entry reserved for its
/// result (the credits ignored), and in `tri_fe_queue.v` the registered head refilled from the
/// memory while it holds an entry (that entry lost), under backpressure heavy enough to fill
/// the queue, which the clean model passes. Slow tier.
#[test]
#[ignore]
fn engine_planted_faults_are_caught() {
    let Some(opts) = engine(golden::setup::Screen { width: 37, height: 23 }, golden::frontend::engine::SetupForm::Ecp5_25f) else { return };
    let base = verilator_harness::ondemand::describe(&opts, verilator_harness::models::Kind::Frontend).unwrap_or_else(|e| panic!("{e}"));
    let seed = verilator_harness::seed("frontend engine faults");
    let fe = opts.frontend().unwrap().fe;
    let tris = random_triangles(&mut SeedRng::seed_from_u64(seed), &fe, 3000);
    let engine = &base.sources.iter().find(|(n, _)| n == "tri_fe_engine.v").expect("the engine's file").1;
    // The faults, found in the generated text (its names depend on the program's order).
    let copy_line = engine
        .lines()
        .find(|l| l.trim_start().starts_with("wire [") && l.contains(" t") && l.contains("_1 "))
        .expect("a logic operation reading a second copy");
    let weight_line =
        engine.lines().find(|l| l.trim_start().starts_with("assign m") && l.contains("_sh[")).expect("a tile's weight shifts");
    let shift_line = engine
        .lines()
        .find(|l| l.trim_start().starts_with("sh0_n <=") && l.contains("_1)"))
        .expect("a shift's amount read from a second copy");
    let epoch_line =
        engine.lines().find(|l| l.contains("<= (") && l.contains("_q[") && l.contains("ep[0]")).expect("a quotient captured by epoch");
    let lzc_line = engine.lines().find(|l| l.contains("_h & ")).expect("the leading-zero count's bits");
    let load_line =
        line(engine, "a tile operand register's registered load", &|l| l.trim_start().starts_with("m") && l.contains("_la0 <= "));
    let sel_line = line(engine, "a tile port's registered select", &|l| l.trim_start().starts_with("m") && l.contains("_sa0[0] <= "));
    let lzc_odd = format!("{}, 1'b1}};", lzc_line.rsplit_once(", |(").expect("the count's lowest bit").0);
    let below_zero = line(engine, "an edge's dy below zero as its sign bit", &|l| {
        let l = l.trim();
        l.starts_with("wire t")
            && l.contains("_dy")
            && l.split_once(" = ").is_some_and(|(_, r)| r.starts_with('v') && r.ends_with("];") && !r.contains(' '))
    });
    // A chained division's second divider (its divisor the first's `_dv`) taking its quotient
    // bits from the first's load port (the dividend's low bits) instead of the first's step:
    // two lines on. (Its load a clock early or late is no fault: the first keeps stepping.)
    let lines: Vec<&str> = engine.lines().collect();
    let chained = lines
        .iter()
        .position(|l| l.trim_start().starts_with("assign d") && l.contains("_d[") && l.contains("_dv["))
        .expect("a chained division");
    let chain_q = lines[chained + 2].to_string();
    assert!(
        chain_q.contains("_lo[") && chain_q.contains("= d") && chain_q.contains("_q["),
        "the second divider's quotient bits: {chain_q}"
    );
    let (lhs, rhs) = chain_q.split_once('=').unwrap();
    let chain_bad = format!("{lhs}={}", rhs.replacen("_q[", "_lo[", 1));
    let faults = [
        (copy_line.to_string(), copy_line.replacen("_1 ", "_0 ", 1), "an operand's copy off by one period"),
        (
            weight_line.to_string(),
            format!("{}= 1'b0;", weight_line.split_once('=').unwrap().0),
            "a tile's passes at the wrong weights (no shift)",
        ),
        (epoch_line.to_string(), epoch_line.replacen("ep[0]", "ep[1]", 1), "a quotient from another epoch's divider"),
        (shift_line.to_string(), shift_line.replacen("_1)", "_0)", 1), "a shared shift's amount from the next triangle's copy"),
        (lzc_line.to_string(), lzc_odd, "the leading-zero count's lowest bit stuck at one"),
        (load_line.clone(), format!("{}<= 1'b1;", load_line.split_once("<=").unwrap().0), "a tile's operand register loaded every clock"),
        (sel_line.clone(), format!("{}<= 1'b0;", sel_line.split_once("<=").unwrap().0), "a tile port's select bit stuck at zero"),
        (chain_q, chain_bad, "a chained division's second divider taking the dividend's bits for the first's quotient bits"),
        (below_zero.clone(), below_zero.replacen(" = v", " = !v", 1), "an edge's dy below zero read as at or above it"),
    ];
    assert_faults_caught(&base, "tri_fe_engine.v", "fault", faults, seed, &tris);
    // The credits: with out_ready high a clock in ten, triangles arrive faster than they are
    // walked and the queue fills (under Traffic::RANDOM it never does at this depth).
    let heavy = Traffic { valid: 1.0, ready: 0.1 };
    let run = |m: &verilator_harness::models::Model| {
        let info = verilator_harness::ondemand::load::<TriIn, FeOut>(m).unwrap_or_else(|e| panic!("{e}"));
        run_frontend(info, seed, heavy, Stress::NONE, &tris)
    };
    assert!(run(&base).ok(), "the clean model under heavy backpressure");
    let faults = [
        (
            "tri_frontend.v",
            "wire q_room = cr != 0;",
            "wire q_room = 1'b1;",
            "cfault",
            "a triangle taken with no queue entry for its result",
        ),
        (
            "tri_fe_queue.v",
            "wire ld = !hv && ne;",
            "wire ld = ne;",
            "qfault",
            "the queue's registered head refilled while it holds an entry",
        ),
    ];
    for (file, from, to, tag, what) in faults {
        let mut m = base.clone();
        let text = &mut m.sources.iter_mut().find(|(n, _)| n == file).unwrap_or_else(|| panic!("no {file}")).1;
        assert!(text.contains(from), "{what}: the fault does not apply");
        *text = text.replacen(from, to, 1);
        m.tag = format!("{}_{tag}", base.tag);
        let report = run(&m);
        eprintln!("{what}: {} mismatches", report.mismatch_count);
        assert!(!report.ok(), "planted fault not caught: {what}");
    }
}

/// Negative controls of the walker behind the row stages (`--pipeline 1`, the ECP5 plan at
/// 37x23, each a model built on first use): an edge's place among its rows moved onto its first
/// row a row late, an edge starting at the walk's first row never entered, the DDA's carry read
/// from the bit under the sign of its offset remainder `t = rem - thr`, `t` loaded one too
/// large, `g`'s distance to the screen's bound (its sign the compare `g < bound`) never
/// stepped or loaded against the other side's bound, the engine's `t` formed with the previous
/// triangle's `thr`, the span's left end taken
/// from one slot alone in the row stages, the walk's registered end made a row early, and the
/// right end's slot a always edge 0 (edge 1 lost where it and edge 2 are the right edges).
/// Caught on the triangles the clean model passes
/// (`engine_spans_equal_golden_at_the_targets_pipeline_level`). (The place not moved past an
/// edge's last row is no fault: beyond its end vertex an edge's line lies outside the triangle,
/// so its bound never wins.) Slow tier: nine models, about 15 s of CPU each to build.
#[test]
#[ignore]
fn walker_planted_faults_are_caught() {
    let Some((base, seed, tris)) = row_stage_base("frontend walker faults") else { return };
    let text = |file: &str| base.sources.iter().find(|(n, _)| n == file).unwrap_or_else(|| panic!("no {file}")).1.clone();
    let edge = text("tri_fe_edge.v");
    let step = line(&edge, "the row's place moved against rs", &|l| l.contains("w_ge <= w_ge ||"));
    let load = line(&edge, "the row's place loaded against rs", &|l| l.contains("w_ge <= first >= rs;"));
    let one = step.split(" + ").nth(1).and_then(|t| t.split(" == ").next()).expect("the step's row + 1").to_string();
    let carry = line(&edge, "the carry from t's sign", &|l| l.contains("wire cy = !w_t["));
    let sign: u32 = carry.split("!w_t[").nth(1).and_then(|t| t.split(']').next()).and_then(|b| b.parse().ok()).expect("t's sign bit");
    let t_load = line(&edge, "t's load from the engine", &|l| l.contains("w_t <= t;"));
    let gd_step = line(&edge, "g's distance to the screen's bound stepped", &|l| l.contains("w_gd <= gdnext;"));
    let gd_load = line(&edge, "g's distance to the screen's bound loaded", &|l| l.contains("w_gd <= ") && l.contains("(right ?"));
    let faults = [
        (step.clone(), step.replacen(&format!(" + {one}"), "", 1), "an edge's first row entered a row late"),
        (load.clone(), load.replacen(">=", ">", 1), "an edge starting at the walk's first row never entered"),
        (carry.clone(), carry.replacen(&format!("[{sign}]"), &format!("[{}]", sign - 1), 1), "the carry from the bit under t's sign"),
        (t_load.clone(), t_load.replacen("t;", "t + 1'b1;", 1), "t loaded one too large"),
        (gd_step.clone(), gd_step.replacen("gdnext", "w_gd", 1), "g's distance to the screen's bound never stepped"),
        (gd_load.clone(), gd_load.replacen("(right ?", "(!right ?", 1), "g's distance loaded against the other side's bound"),
    ];
    assert_faults_caught(&base, "tri_fe_edge.v", "wfault", faults, seed, &tris);
    // The engine's DDA start (golden's `Plan::edge_t`): t = (rem >> 8) - thr with the previous
    // triangle's thr (a copy off by one period).
    let engine = text("tri_fe_engine.v");
    let t_op = line(&engine, "the engine's t = (rem >> 8) - thr", &|l| {
        l.trim_start().starts_with("wire [") && l.contains("_rem_0} - ") && l.contains("_thr")
    });
    let (head, tail) = t_op.rsplit_once("_0}").expect("thr's copy 0");
    let faults = [(t_op.clone(), format!("{head}_1}}{tail}"), "t formed with the previous triangle's thr")];
    assert_faults_caught(&base, "tri_fe_engine.v", "tfault", faults, seed, &tris);
    let fe_text = text("tri_frontend.v");
    let mg = line(&fe_text, "the span's left end", &|l| l.contains("we_mg <= mg_w;"));
    let end = line(&fe_text, "the walk's end stepped", &|l| l.contains("w_end <= w_row + ") && l.contains(" == w_last;"));
    let ra = line(&fe_text, "the right end's slot a", &|l| l.contains("w_ra <= e_act[0] && e_right[0];"));
    let faults = [
        (mg.clone(), mg.replacen("mg_w", "wr_la", 1), "the span's left end from one slot alone"),
        (end.clone(), end.replacen("'d1 == w_last", "'d2 == w_last", 1), "the walk's registered end a row early"),
        (ra.clone(), ra.replacen("e_act[0] && e_right[0]", "1'b1", 1), "the right end's slot a always edge 0"),
    ];
    assert_faults_caught(&base, "tri_frontend.v", "wsfault", faults, seed, &tris);
}

/// Negative controls of the span path's truncated reciprocal (golden's
/// `Widths::reciprocal_quotient`), planted in the generated `tri_frontend.v` at 640x480, level
/// 0 (each a model built on first use): the compare for an estimate two below dropped (about one
/// span in 4,000 needs it, golden's random spans), a partial product in logic dropped (the
/// estimate's top 3 bits of `S2n` against `Rn`), the correction's corner dropped (`An`'s top 6
/// bits against `q~`'s low 8, in logic since issue 27's stop 30), and a tile's partial product
/// of `Gxn lo` dropped (its top one, of `Gxn >> 8`). The clean model's co-simulation is the
/// default suite's. Slow tier: four front-end models, about a minute of CPU each to build.
#[test]
#[ignore]
fn span_path_planted_faults_are_caught() {
    if verilator_harness::registry::rtl_dir().is_some() {
        eprintln!("span path faults: skipped: COSIM_RTL_DIR provides the models");
        return;
    }
    let opts = hdl_gen::Options { screen: Some(golden::setup::Screen::default()), ..Default::default() };
    let base = verilator_harness::ondemand::describe(&opts, verilator_harness::models::Kind::Frontend).unwrap_or_else(|e| panic!("{e}"));
    let seed = verilator_harness::seed("frontend span path faults");
    let fe = opts.frontend().unwrap().fe;
    let tris = random_triangles(&mut SeedRng::seed_from_u64(seed), &fe, 3000);
    let text = &base.sources.iter().find(|(n, _)| n == "tri_frontend.v").expect("the front-end's file").1;
    let up = line(text, "the correction's select", &|l| l.contains(" i0 = ") && l.contains("i0_ge4"));
    let prod = line(text, "the estimate's sum", &|l| l.contains(" prod = ") && l.contains("prod_2"));
    let m = line(text, "the correction's sum", &|l| l.contains(" m_an = ") && l.contains("m_an_2"));
    let gx = line(text, "Gxn lo's sum", &|l| l.contains(" gx = ") && l.contains("gx_2"));
    let faults = [
        (up.clone(), up.replacen("i0_ge4 ? qt2 : ", "", 1), "the second compare dropped"),
        (prod.clone(), prod.replacen(" + ({18'd0, prod_2} << 18)", "", 1), "the estimate's partial product in logic dropped"),
        (m.clone(), m.replacen(" + ({36'd0, m_an_2} << 36)", "", 1), "the correction's corner in logic dropped"),
        (gx.clone(), gx.replacen(" + ({36'd0, gx_2} << 36)", "", 1), "Gxn lo's top tile dropped"),
    ];
    assert_faults_caught(&base, "tri_frontend.v", "i0fault", faults, seed, &tris);
}

/// Negative controls of the walker's running sums of `Gxn g` (`--target ecp5-25f`'s span path,
/// golden's `frontend::sums`; the ECP5 plan at level 1, 37x23, each a model built on first use):
/// slot a's sum stepped by `Gxn Qs` alone (its edge's carries not added), the span's source always
/// slot a, the screen's clamp taking slot a's sum instead of 0 (golden's three planted faults;
/// 4,406, 2,317 and 3,215 mismatches), and the source selected from the first row stage's sums
/// (a row ahead's) instead of the second's (5,236).
/// Caught on the triangles the clean model passes
/// (`engine_spans_equal_golden_at_the_targets_pipeline_level`). Slow tier: four models.
#[test]
#[ignore]
fn running_sums_planted_faults_are_caught() {
    let Some((base, seed, tris)) = row_stage_base("frontend running sums faults") else { return };
    let text = &base.sources.iter().find(|(n, _)| n == "tri_frontend.v").expect("the front-end's file").1;
    let step = line(text, "slot a's carry", &|l| l.contains("w_ca <= w_ca + "));
    let source = line(text, "the span's source", &|l| l.contains(" we_gxs = "));
    let clamp = source.split_once(" ? ").expect("the clamp's test").0.split_once("= ").expect("the source's value").1.to_string();
    let faults = [
        (step.clone(), format!("{}w_ca <= w_ca;", step.split_once("w_ca").unwrap().0), "slot a's carry ignored"),
        (source.clone(), source.replacen("? we_pa : we_pb", "? we_pa : we_pa", 1), "the span's source always slot a"),
        (source.clone(), source.replacen(&format!("{clamp} ?"), "1'b1 ?", 1), "the clamp takes slot a's sum"),
        (source.clone(), source.replacen("? we_pa : we_pb", "? wr_pa : wr_pb", 1), "the source's sums a row stage early"),
    ];
    assert_faults_caught(&base, "tri_frontend.v", "sumfault", faults, seed, &tris);
}

/// Negative controls of `tri_fe_mul18`, the tiles with their own registers (`--target
/// ecp5-25f`'s engine and span path; the ECP5 plan at level 1, 37x23, each a model built on
/// first use), planted in the model the simulators read (the file's last branch, after the
/// primitive's): the product register loaded on every clock (the span path's stall ignored), an
/// operand register loaded on every clock (the engine's held chunk overwritten), and the
/// operands' signedness ignored (the engine's signed top chunks read unsigned). Caught on the
/// triangles the clean model passes (`engine_spans_equal_golden_at_the_targets_pipeline_level`).
/// Slow tier: three models.
#[test]
#[ignore]
fn mul18_planted_faults_are_caught() {
    let Some((base, seed, tris)) = row_stage_base("frontend mul18 faults") else { return };
    let text = &base.sources.iter().find(|(n, _)| n == "tri_fe_mul18.v").expect("the tile's file").1;
    // The model after the primitive's branch: unique with the file's end in it.
    let model = text.rsplit_once("`else\n").expect("the simulators' branch").1.to_string();
    let fault = |from: &str, to: &str| {
        assert!(model.contains(from), "no {from:?} in the model");
        model.replacen(from, to, 1)
    };
    let faults = [
        (model.clone(), fault("if (cep) begin", "if (1'b1) begin"), "the product register loaded every clock"),
        (model.clone(), fault("if (cea) begin", "if (1'b1) begin"), "an operand register loaded every clock"),
        (model.clone(), fault("A_SIGNED != 0 && ", "1'b0 && "), "operand a's signedness ignored"),
    ];
    assert_faults_caught(&base, "tri_fe_mul18.v", "mulfault", faults, seed, &tris);
}
