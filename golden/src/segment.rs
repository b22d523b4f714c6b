//! The segment shader's output, bit-exact (SPEC §3): which segments a span yields, which lanes
//! each one enables and what every enabled lane holds. Masked lanes are don't-care, so the model
//! says nothing about them.

use crate::format::{Align, Config, Span};
use crate::pipeline::{numbered, PipeReg, PipeStage, Pipeline};

/// One output segment of a span.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Segment {
    /// Index of the segment within its span.
    pub index: u32,
    /// `out_x`: the screen x of lane 0.
    pub x: u32,
    /// `out_last`.
    pub last: bool,
    /// Span pixel index `j` of lane 0; may be negative in screen mode (leading lanes masked).
    first_j: i64,
    len: u32,
    p: u32,
}

impl Segment {
    /// The span pixel `j` that lane `i` carries, or `None` when the lane is masked.
    pub fn lane_pixel(&self, i: u32) -> Option<u32> {
        let j = self.first_j + i as i64;
        (i < self.p && j >= 0 && j < self.len as i64).then_some(j as u32)
    }

    /// `out_mask` as bits, lane `i` in bit `i` of word `i / 64` (P is at most 256).
    pub fn mask(&self) -> [u64; 4] {
        let mut m = [0u64; 4];
        for i in 0..self.p {
            if self.lane_pixel(i).is_some() {
                m[(i / 64) as usize] |= 1 << (i % 64);
            }
        }
        m
    }
}

/// The segments of `span` in output order.
pub fn segments(cfg: &Config, span: &Span) -> impl Iterator<Item = Segment> {
    let (cfg, span) = (*cfg, *span);
    (0..cfg.segment_count(span.x0, span.len)).map(move |s| segment(&cfg, &span, s))
}

/// Segment `s` of `span` (`s` below `cfg.segment_count`).
pub fn segment(cfg: &Config, span: &Span, s: u32) -> Segment {
    let p = cfg.p;
    let lead = match cfg.align {
        Align::Span => 0,
        Align::Screen => span.x0 % p,
    };
    let count = cfg.segment_count(span.x0, span.len);
    Segment {
        index: s,
        // out_x is XW bits wide; a span that fits the screen never wraps it.
        x: (span.x0 - lead + s * p) & (cfg.max_len() - 1),
        last: s + 1 == count,
        first_j: s as i64 * p as i64 - lead as i64,
        len: span.len,
        p,
    }
}

/// Width of the shader's pixels-left counter: holds `lead + m` for any port value, and P.
pub fn rem_bits(cfg: &Config) -> u32 {
    let lead = (cfg.align == Align::Screen && cfg.p > 1) as u32;
    (cfg.xbits + 1 + lead).max(cfg.log2p() + 1)
}

/// The shader's register stages at `pipe`, input first; a span transferred in clock t has its
/// first segment valid in clock t + `stages().len()`. Every stage moves when the output
/// register is free, so one segment leaves per clock at every level.
pub fn stages(cfg: &Config, pipe: Pipeline) -> Vec<PipeStage> {
    let (p, f, xw) = (cfg.p, cfg.frac, cfg.xbits);
    let (aw, rw, qw) = (cfg.aw(), rem_bits(cfg), cfg.aw() - cfg.frac);
    let screen = cfg.align == Align::Screen && p > 1;
    let acc = PipeReg::new("acc", aw, &format!("signed Q{}.{f}, lane 0 + 2^-{}", aw - f, f + 1));
    let pos = [PipeReg::new("x", xw, "uint"), PipeReg::new("rem", rw, "uint, pixels left"), PipeReg::new("valid", 1, "flag")];
    let lead = screen.then(|| PipeReg::new("lead", cfg.log2p(), "uint, masked leading lanes"));
    let start = if screen { format!("I0 + 2^{} - (x0 mod {p})*dI", f - 1) } else { format!("I0 + 2^{}", f - 1) };
    let lanes = "lane i = clamp((acc + inc_i) >> F, 0, 255), inc_i = i*dI (BFPI lane i - 1); \
                 mask_i = i < rem (and i >= lead)";
    let out = vec![
        PipeReg::new("out_pix", 8 * p, "P x UQ8.0"),
        PipeReg::new("out_mask", p, "bit per lane"),
        PipeReg::new("out_x", xw, "uint"),
        PipeReg::new("out_last", 1, "flag"),
        PipeReg::new("out_valid", 1, "flag"),
    ];
    let mut body = Vec::new();
    if pipe.span_stage() {
        let mut regs = vec![
            PipeReg::new("x0", xw, "uint"),
            PipeReg::new("m", xw + 1, "uint"),
            PipeReg::new("i0", cfg.iw(), &format!("UQ8.{f}")),
            PipeReg::new("di", cfg.dw(), &format!("signed Q8.{f}")),
            PipeReg::new("valid", 1, "flag (m != 0)"),
        ];
        let mut logic = "the accepted span; m = 0 is dropped here".to_string();
        if pipe.split_adds() {
            let first = first_level(cfg.p);
            if !first.is_empty() {
                let list = first.iter().map(|c| format!("{c}*dI")).collect::<Vec<_>>().join(", ");
                regs.push(PipeReg::new(
                    "fund",
                    first.len() as u32 * cfg.mw(),
                    &format!("{} x signed Q{}.{f}: {list}", first.len(), cfg.mw() - f),
                ));
                logic.push_str("; the BFPI's first adder level of the input's dI");
            }
        }
        body.push(("span", logic, regs));
    }
    let mut cur = vec![acc];
    if pipe.span_stage() {
        cur.push(PipeReg::new("inc", p * cfg.mw(), &format!("{p} x signed Q{}.{f}, (i+1)*dI", cfg.mw() - f)));
        cur.push(PipeReg::new("last", 1, "flag, rem <= P"));
    } else {
        cur.push(PipeReg::new("di", cfg.dw(), &format!("signed Q8.{f}")));
    }
    cur.extend(pos.clone());
    cur.extend(lead);
    let cur_logic = if pipe.span_stage() {
        format!("acc <= start ? {start} : acc + P*dI; inc <= (i+1)*dI, the BFPI of the waiting span's dI")
    } else {
        format!("acc <= accept ? {start} : acc + P*dI")
    };
    body.push(("current", cur_logic, cur));
    if pipe.split_adds() {
        let regs = vec![
            PipeReg::new(
                "hi_carry",
                p * (qw + 1),
                &format!("{p} x {{signed {qw}-bit (acc >> F) + (inc_i >> F), carry out of the {f} fraction bits of acc + inc_i}}"),
            ),
            PipeReg::new("mask", p, "bit per lane"),
            PipeReg::new("x", xw, "uint"),
            PipeReg::new("last", 1, "flag"),
            PipeReg::new("valid", 1, "flag"),
        ];
        let logic = "hi_i, carry_i: acc + inc_i cut at the binary point; mask_i = i < rem (and i >= lead)";
        body.push(("sum", logic.to_string(), regs));
        body.push(("output", "lane i = clamp(hi_i + carry_i, 0, 255)".to_string(), out));
    } else if pipe.sum_stage() {
        let regs = vec![
            PipeReg::new("q", p * qw, &format!("{p} x signed {qw}-bit integer part of acc + inc_i")),
            PipeReg::new("mask", p, "bit per lane"),
            PipeReg::new("x", xw, "uint"),
            PipeReg::new("last", 1, "flag"),
            PipeReg::new("valid", 1, "flag"),
        ];
        body.push(("sum", "q_i = (acc + inc_i) >> F; mask_i = i < rem (and i >= lead)".to_string(), regs));
        body.push(("output", "lane i = clamp(q_i, 0, 255)".to_string(), out));
    } else {
        body.push(("output", lanes.to_string(), out));
    }
    numbered(body)
}

/// The odd multiples of dI the BFPI's first adder level makes (depth 1), which `--pipeline 3`
/// registers with the span; every deeper adder reads only these and dI itself.
pub fn first_level(p: u32) -> Vec<u32> {
    crate::bfpi::BfpiPlan::new(p).adders.iter().filter(|a| a.depth == 1).map(|a| a.value).collect()
}

/// Clocks from a span's transfer to its first segment's `out_valid` at `pipe`.
pub fn latency(cfg: &Config, pipe: Pipeline) -> u32 {
    stages(cfg, pipe).len() as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cfg(p: u32, align: Align) -> Config {
        Config { p, align, ..Config::default() }
    }

    fn lanes(c: &Config, span: &Span) -> Vec<(u32, Vec<Option<u32>>, bool)> {
        segments(c, span).map(|s| (s.x, (0..c.p).map(|i| s.lane_pixel(i)).collect(), s.last)).collect()
    }

    #[test]
    fn span_mode_starts_at_the_first_pixel() {
        let c = cfg(4, Align::Span);
        let span = Span { x0: 5, len: 6, i0: 0, di: 0 };
        assert_eq!(
            lanes(&c, &span),
            vec![(5, vec![Some(0), Some(1), Some(2), Some(3)], false), (9, vec![Some(4), Some(5), None, None], true),]
        );
    }

    #[test]
    fn screen_mode_writes_whole_blocks() {
        let c = cfg(4, Align::Screen);
        let span = Span { x0: 5, len: 6, i0: 0, di: 0 };
        assert_eq!(
            lanes(&c, &span),
            vec![(4, vec![None, Some(0), Some(1), Some(2)], false), (8, vec![Some(3), Some(4), Some(5), None], true),]
        );
        let one = Span { x0: 7, len: 1, i0: 0, di: 0 };
        assert_eq!(lanes(&c, &one), vec![(4, vec![None, None, None, Some(0)], true)]);
    }

    #[test]
    fn every_pixel_of_a_span_appears_once_in_order() {
        for p in [1, 2, 8, 64] {
            for align in Align::ALL {
                let c = cfg(p, align);
                for (x0, len) in [(0, 1), (3, 64), (4095, 1), (4000, 96), (7, 0), (0, 4096)] {
                    let span = Span { x0, len, i0: 0, di: 0 };
                    let mut seen = Vec::new();
                    for s in segments(&c, &span) {
                        for i in 0..p {
                            if let Some(j) = s.lane_pixel(i) {
                                assert_eq!(s.x + i, x0 + j, "lane {i} of {s:?}");
                                seen.push(j);
                            }
                        }
                        if align == Align::Screen {
                            assert_eq!(s.x % p, 0);
                        }
                    }
                    assert_eq!(seen, (0..len).collect::<Vec<_>>(), "p = {p}, {align}, {span:?}");
                }
            }
        }
    }

    #[test]
    fn mask_bits_follow_the_lanes() {
        let c = cfg(128, Align::Screen);
        let span = Span { x0: 70, len: 100, i0: 0, di: 0 };
        let first = segments(&c, &span).next().unwrap();
        assert_eq!(first.mask(), [0, !0 << 6, 0, 0]);
    }

    #[test]
    fn each_pipeline_level_adds_stages_and_level_0_is_the_seed() {
        for align in Align::ALL {
            let c = cfg(8, align);
            assert_eq!(latency(&c, Pipeline::NONE), 2, "SPEC's seed: current span and output registers");
            let lat: Vec<u32> = Pipeline::all().map(|pipe| latency(&c, pipe)).collect();
            assert_eq!(lat, [2, 3, 4, 4], "level 3 cuts adders within level 2's stages");
            let all: Vec<Vec<PipeStage>> = Pipeline::all().map(|pipe| stages(&c, pipe)).collect();
            assert!(all.windows(2).all(|w| w[0] != w[1]), "a level that changes no register");
            for pipe in Pipeline::all() {
                let st = stages(&c, pipe);
                assert!(st.iter().enumerate().all(|(i, s)| s.stage == i as u32));
                assert_eq!(st.last().unwrap().name, "output");
            }
        }
    }
}
