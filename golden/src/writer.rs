//! SPEC §7: the block video memory and the segment writer, bit-exact.
//!
//! Memory is tied to the screen in blocks of P pixels: block `x div P` of row `y` is word
//! `y * B + x div P` of a `B = ceil(W / P)` blocks-per-row memory, pixel `x mod P` in lane
//! `x mod P` (bits `[8i +: 8]`). A write carries one block address, P pixels and one enable per
//! pixel.
//!
//! **What the writer writes** does not depend on the alignment: for every span, each block the
//! span touches, once, in ascending order, with the enables of the pixels the span covers in it.
//! Screen alignment gets there by one write per segment (its segments *are* blocks). Span
//! alignment gets there by the seed's glue: each segment is rotated by `r = x0 mod P`, its head
//! (lanes `0..P-r`) lands in block `b`, its tail (lanes `P-r..P`) in block `b + 1` and waits to
//! be merged with the next segment's head; the last tail is written on its own. So the glue
//! turns a span's `ceil(m / P)` segments into `ceil((r + m) / P)` writes, at most one more, and
//! never two writes of one block (without the glue a straddling segment costs two writes, and
//! a block is written twice).
//!
//! Attribution (used by the scoreboard to know what each input segment owes): write `k` of a
//! span belongs to segment `k`, and a span-aligned span's extra tail write to its last segment.

use crate::format::{Config, Span};
use crate::raster::Frame;
use crate::setup::Screen;

/// A screen the writer cannot address.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum WriterError {
    /// Wider than `2^XW`: a span's `x` would not fit `in_x`.
    #[error("screen width {width} exceeds 2^XW = {max} pixels")]
    Width { width: u32, max: u32 },
    /// No rows, or more than 2^16.
    #[error("screen height {height} is outside 1..65536")]
    Height { height: u32 },
}

/// A block write outside the memory ([`Memory::apply`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("block address {addr} outside the {blocks}-block memory")]
pub struct AddressError {
    pub addr: u32,
    pub blocks: u32,
}

/// One block write: `we` bit `i` (word `i / 64`) enables lane `i`; `pix` holds the P pixels,
/// 0 under a clear enable (don't-care on the port).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BlockWrite {
    pub addr: u32,
    pub we: [u64; 4],
    pub pix: [u8; 256],
}

impl BlockWrite {
    pub fn enabled(&self, i: u32) -> bool {
        self.we[(i / 64) as usize] >> (i % 64) & 1 == 1
    }
}

/// The writer of one configuration and screen: the plan the generator prints and the
/// scoreboard checks against.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Writer {
    pub cfg: Config,
    pub screen: Screen,
}

/// Clocks from a segment's transfer to its write on the memory port: one output register.
pub const LATENCY: u32 = 1;

impl Writer {
    pub fn new(cfg: Config, screen: Screen) -> Result<Writer, WriterError> {
        if screen.width == 0 || screen.width > cfg.max_len() {
            return Err(WriterError::Width { width: screen.width, max: cfg.max_len() });
        }
        if screen.height == 0 || screen.height > 1 << 16 {
            return Err(WriterError::Height { height: screen.height });
        }
        Ok(Writer { cfg, screen })
    }

    /// `B`: blocks per row, the row stride of the memory.
    pub fn blocks_per_row(&self) -> u32 {
        self.screen.width.div_ceil(self.cfg.p)
    }

    /// Words of the memory: `B * H`.
    pub fn blocks(&self) -> u32 {
        self.blocks_per_row() * self.screen.height
    }

    /// Width of the block address.
    pub fn addr_bits(&self) -> u32 {
        bits(self.blocks() - 1).max(1)
    }

    /// Bits of x's block number (`x div P`) the address uses: the port's XW - log2(P), or fewer
    /// on a screen narrower than 2^XW, where x < W leaves the port's high bits zero. 0 when
    /// P = 2^XW: one block a row.
    pub fn block_bits(&self) -> u32 {
        (self.cfg.xbits - self.cfg.log2p()).min(self.addr_bits())
    }

    /// Width of the scanline port (`in_y`): the same as the front-end's `out_y`.
    pub fn y_bits(&self) -> u32 {
        self.screen.y_bits()
    }

    /// The block address of pixel `(x, y)`.
    pub fn addr(&self, x: u32, y: u32) -> u32 {
        y * self.blocks_per_row() + x / self.cfg.p
    }

    /// Writes of a span: the blocks it touches.
    pub fn write_count(&self, span: &Span) -> u32 {
        if span.len == 0 {
            return 0;
        }
        let p = self.cfg.p;
        (span.x0 % p + span.len).div_ceil(p)
    }

    /// Writes owed for segment `s` of the span (see the module documentation).
    pub fn owed(&self, span: &Span, s: u32) -> u32 {
        let segments = self.cfg.segment_count(span.x0, span.len);
        match s + 1 == segments {
            true => self.write_count(span) - s,
            false => 1,
        }
    }

    /// Write `k` (below [`Writer::write_count`]) of span `span` on row `y`.
    pub fn write(&self, y: u32, span: &Span, k: u32) -> BlockWrite {
        let p = self.cfg.p;
        let block = span.x0 / p + k;
        let mut w = BlockWrite { addr: self.addr(block * p, y), we: [0; 4], pix: [0; 256] };
        for i in 0..p {
            let x = block * p + i;
            if x >= span.x0 && x < span.x0 + span.len {
                w.we[(i / 64) as usize] |= 1 << (i % 64);
                w.pix[i as usize] = span.pixel(x - span.x0, self.cfg.frac);
            }
        }
        w
    }

    /// Every write of a span, in order.
    pub fn writes<'a>(&'a self, y: u32, span: &'a Span) -> impl Iterator<Item = BlockWrite> + 'a {
        (0..self.write_count(span)).map(move |k| self.write(y, span, k))
    }

    /// Writes a span-aligned span would cost with no glue: every segment written as it comes,
    /// split in two where it straddles blocks (the seed's problem the glue solves).
    pub fn unglued_writes(&self, span: &Span) -> u32 {
        let p = self.cfg.p;
        (0..span.len.div_ceil(p))
            .map(|s| {
                let (x, n) = (span.x0 + s * p, p.min(span.len - s * p));
                (x % p + n).div_ceil(p)
            })
            .sum()
    }
}

/// The block memory behind the write port: what every write leaves, enables honoured.
#[derive(Clone, Debug)]
pub struct Memory {
    pub writer: Writer,
    data: Vec<u8>,
    written: Vec<bool>,
}

impl Memory {
    pub fn new(writer: Writer) -> Memory {
        let n = (writer.blocks() * writer.cfg.p) as usize;
        Memory { writer, data: vec![0; n], written: vec![false; n] }
    }

    /// Applies one write; `Err` if the address is outside the memory.
    pub fn apply(&mut self, w: &BlockWrite) -> Result<(), AddressError> {
        let p = self.writer.cfg.p;
        if w.addr >= self.writer.blocks() {
            return Err(AddressError { addr: w.addr, blocks: self.writer.blocks() });
        }
        for i in (0..p).filter(|&i| w.enabled(i)) {
            let at = (w.addr * p + i) as usize;
            self.data[at] = w.pix[i as usize];
            self.written[at] = true;
        }
        Ok(())
    }

    /// The screen as memory holds it: pixel `(x, y)` is lane `x mod P` of block `addr(x, y)`;
    /// the lanes past the screen's right edge in the last block of a row are not shown.
    pub fn frame(&self) -> Frame {
        let s = self.writer.screen;
        let mut f = Frame::new(s.width, s.height);
        let p = self.writer.cfg.p;
        for y in 0..s.height {
            for x in 0..s.width {
                let at = (self.writer.addr(x, y) * p + x % p) as usize;
                if self.written[at] {
                    f.set(x, y, self.data[at]);
                }
            }
        }
        f
    }

    /// Whether a pixel past the right edge of the screen was ever written (never, by SPEC §7).
    pub fn wrote_off_screen(&self) -> bool {
        let (s, p) = (self.writer.screen, self.writer.cfg.p);
        (0..s.height)
            .any(|y| (s.width..self.writer.blocks_per_row() * p).any(|x| self.written[(self.writer.addr(x, y) * p + x % p) as usize]))
    }
}

fn bits(v: u32) -> u32 {
    32 - v.leading_zeros()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::format::Align;
    use crate::segment::segments;

    fn writer(p: u32, align: Align, width: u32) -> Writer {
        Writer::new(Config { p, align, ..Config::default() }, Screen { width, height: 4 }).unwrap()
    }

    /// The writes of every span, painted into memory, are the span's golden pixels; each pixel
    /// once, every write with an enable, addresses ascending, and the count the glue promises.
    #[test]
    fn writes_cover_each_pixel_of_a_span_once() {
        for p in [1, 2, 4, 8, 16] {
            for align in Align::ALL {
                let w = writer(p, align, 37);
                for x0 in 0..37 {
                    for len in 0..=37 - x0 {
                        let span = Span { x0, len, i0: 3 << 12, di: 517 };
                        let mut seen = [0u32; 37];
                        let mut last = None;
                        for wr in w.writes(2, &span) {
                            assert!(wr.we.iter().any(|&m| m != 0), "p {p} span {span:?}: a write with no enable");
                            assert!(last.is_none_or(|a| wr.addr > a), "addresses ascend");
                            last = Some(wr.addr);
                            for i in (0..p).filter(|&i| wr.enabled(i)) {
                                let x = (wr.addr - 2 * w.blocks_per_row()) * p + i;
                                seen[x as usize] += 1;
                                assert_eq!(wr.pix[i as usize], span.pixel(x - x0, 12));
                            }
                        }
                        for (x, n) in seen.iter().enumerate() {
                            let inside = (x as u32) >= x0 && (x as u32) < x0 + len;
                            assert_eq!(*n, inside as u32, "p {p} {align} span {span:?}: pixel {x}");
                        }
                        let segs = segments(&w.cfg, &span).count() as u32;
                        assert_eq!((0..segs).map(|s| w.owed(&span, s)).sum::<u32>(), w.write_count(&span));
                        match align {
                            Align::Screen => assert_eq!(w.write_count(&span), segs),
                            Align::Span => assert!(w.write_count(&span) <= segs + 1 && w.write_count(&span) >= segs),
                        }
                        assert!(w.unglued_writes(&span) >= w.write_count(&span));
                    }
                }
            }
        }
    }

    #[test]
    fn memory_shows_what_was_written() {
        let w = writer(8, Align::Span, 21);
        assert_eq!((w.blocks_per_row(), w.blocks(), w.addr_bits()), (3, 12, 4));
        let mut m = Memory::new(w);
        let span = Span { x0: 5, len: 16, i0: 100 << 12, di: 1 << 12 };
        for wr in w.writes(1, &span) {
            m.apply(&wr).unwrap();
        }
        let f = m.frame();
        assert_eq!(f.get(4, 1), None);
        assert_eq!(f.get(5, 1), Some(100));
        assert_eq!(f.get(20, 1), Some(115));
        assert!(!m.wrote_off_screen());
        let mut off = w.write(1, &span, 0);
        off.addr = 2 * 3 + 2;
        off.we = [1 << 7, 0, 0, 0];
        m.apply(&off).unwrap();
        assert!(m.wrote_off_screen(), "x = 23 lies past the 21-pixel row");
        off.addr = 12;
        assert_eq!(m.apply(&off), Err(AddressError { addr: 12, blocks: 12 }));
    }

    #[test]
    fn screens_it_cannot_address_are_refused() {
        let cfg = Config::default();
        assert!(Writer::new(cfg, Screen { width: cfg.max_len() + 1, height: 2 }).is_err());
        assert!(Writer::new(cfg, Screen { width: 2, height: 0 }).is_err());
        assert!(Writer::new(cfg, Screen { width: cfg.max_len(), height: 1 << 16 }).is_ok());
    }
}
