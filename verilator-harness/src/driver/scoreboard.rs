//! What the accepted spans still owe: the driver's bookkeeping of outputs, span by span, so that
//! each output transfer is numbered for the checker and an output nobody asked for is caught.

use std::collections::VecDeque;

/// A span accepted with outputs still owed.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Owed {
    span: usize,
    /// The output the next transfer is.
    next: u32,
    /// Outputs the span yields in all.
    owed: u32,
}

/// Every accepted span with outputs still owed, oldest first: the oldest in `front` (kept in
/// registers: every output transfer updates it), the rest queued behind it.
#[derive(Default)]
pub(super) struct Scoreboard {
    front: Option<Owed>,
    behind: VecDeque<Owed>,
}

impl Scoreboard {
    /// Span `span` was accepted and yields `owed` outputs (none: there is nothing to wait for).
    #[inline]
    pub(super) fn accept(&mut self, span: usize, owed: u32) {
        if owed == 0 {
            return;
        }
        let o = Owed { span, next: 0, owed };
        if self.front.is_none() {
            self.front = Some(o);
        } else {
            self.behind.push_back(o);
        }
    }

    /// An output transferred: which it is, as (span, output index), or `None` when no span owes
    /// one.
    #[inline]
    pub(super) fn transfer(&mut self) -> Option<(usize, u32)> {
        let f = self.front.as_mut()?;
        let at = (f.span, f.next);
        f.next += 1;
        if f.next == f.owed {
            self.front = self.behind.pop_front();
        }
        Some(at)
    }

    /// A reset: every span in flight is cut (its remaining outputs are owed no more). Returns
    /// how many were.
    pub(super) fn cut(&mut self) -> u64 {
        let n = self.front.is_some() as u64 + self.behind.len() as u64;
        self.front = None;
        self.behind.clear();
        n
    }

    /// Whether no output is owed.
    #[inline]
    pub(super) fn is_empty(&self) -> bool {
        self.front.is_none()
    }

    /// The oldest span still owed outputs.
    pub(super) fn oldest(&self) -> Option<usize> {
        self.front.map(|f| f.span)
    }

    /// Outputs still owed, all spans together.
    pub(super) fn left(&self) -> u64 {
        self.front.iter().chain(&self.behind).map(|o| (o.owed - o.next) as u64).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outputs_are_numbered_span_by_span_and_spans_owing_none_are_skipped() {
        let mut s = Scoreboard::default();
        assert!(s.is_empty() && s.transfer().is_none(), "an output with nothing owed is caught");
        s.accept(0, 2);
        s.accept(1, 0);
        s.accept(2, 1);
        assert_eq!((s.oldest(), s.left()), (Some(0), 3));
        let got: Vec<_> = std::iter::from_fn(|| s.transfer()).collect();
        assert_eq!(got, [(0, 0), (0, 1), (2, 0)]);
        assert!(s.is_empty() && s.left() == 0 && s.oldest().is_none());
    }

    #[test]
    fn a_reset_cuts_every_span_in_flight() {
        let mut s = Scoreboard::default();
        s.accept(4, 3);
        s.accept(5, 2);
        assert_eq!(s.transfer(), Some((4, 0)));
        assert_eq!(s.left(), 4);
        assert_eq!(s.cut(), 2);
        assert!(s.is_empty() && s.left() == 0);
        assert_eq!(s.cut(), 0);
        s.accept(6, 1);
        assert_eq!(s.transfer(), Some((6, 0)), "nothing of a cut span comes back");
    }
}
