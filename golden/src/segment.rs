//! The segment shader's output, bit-exact (SPEC §3): which segments a span yields, which lanes
//! each one enables and what every enabled lane holds. Masked lanes are don't-care, so the model
//! says nothing about them.

use crate::format::{Align, Config, Span};

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
}
