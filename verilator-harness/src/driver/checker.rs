//! The checking thread, and the batches that carry the driver's output records to it.

use super::unit::Check;
use crate::report::Report;
use std::sync::mpsc::{sync_channel, Receiver, SyncSender};

/// Bytes per batch of output records sent to the checker, and batches in flight. The checker
/// is faster than the model, so it waits for every batch, and waking it costs the driver tens
/// of microseconds on this kind of (virtual) machine: batches are large (7,000 outputs of a
/// P = 256 shader to 175,000 specular pixels) and recycled, not allocated anew.
const BATCH_BYTES: usize = 2 << 20;
const IN_FLIGHT: usize = 3;

/// A batch of output records: (span, output index) and the records back to back, room for
/// [`Batch::records`] of them (`at.len()` are filled).
pub(super) struct Batch {
    at: Vec<(u32, u32)>,
    data: Vec<u8>,
}

impl Batch {
    /// Records of `rb` bytes in a batch.
    fn records(rb: usize) -> usize {
        (BATCH_BYTES / (rb + std::mem::size_of::<(u32, u32)>())).max(1024)
    }

    fn new(rb: usize) -> Batch {
        Batch { at: Vec::with_capacity(Batch::records(rb)), data: vec![0; Batch::records(rb) * rb] }
    }
}

/// The driver's ends of the channels to the checking thread.
pub(super) struct Link {
    tx: SyncSender<Batch>,
    /// Checked batches, empty, to be filled again.
    back: Receiver<Batch>,
}

/// The channels between the driver and a checking thread: the driver's [`Link`], and the
/// checker's ends for [`consume`] (batches to check, and the way back for checked ones).
pub(super) fn channels() -> (Link, Receiver<Batch>, SyncSender<Batch>) {
    let (tx, rx) = sync_channel::<Batch>(IN_FLIGHT);
    // Checked batches come back empty, to be filled again.
    let (back_tx, back_rx) = sync_channel::<Batch>(IN_FLIGHT + 2);
    (Link { tx, back: back_rx }, rx, back_tx)
}

impl Link {
    /// Hands a full batch to the checker; false when the checker is gone, having panicked (the
    /// driver then stops and `stream` passes the panic on).
    #[inline]
    fn send(&self, batch: Batch) -> bool {
        self.tx.send(batch).is_ok()
    }

    /// An empty batch the checker is done with, if there is one.
    #[inline]
    fn recycled(&self) -> Option<Batch> {
        self.back.try_recv().ok()
    }
}

/// The driver's side of the batches: each output record goes into the current batch, which goes
/// to the checker when full, and is replaced by one the checker is done with.
pub(super) struct Outbox<'a> {
    link: &'a Link,
    batch: Batch,
    /// Bytes of one record, and records in a full batch.
    rb: usize,
    full: usize,
}

impl<'a> Outbox<'a> {
    pub(super) fn new(link: &'a Link, rb: usize) -> Outbox<'a> {
        Outbox { link, batch: link.recycled().unwrap_or_else(|| Batch::new(rb)), rb, full: Batch::records(rb) }
    }

    /// Output `j` of span `k`, its record written by `write` (`rb` bytes). False when the
    /// checker is gone, having panicked: the driver then stops and `stream` passes the panic on.
    #[inline]
    pub(super) fn push(&mut self, k: usize, j: u32, write: impl FnOnce(&mut [u8])) -> bool {
        let (n, rb) = (self.batch.at.len(), self.rb);
        write(&mut self.batch.data[n * rb..(n + 1) * rb]);
        self.batch.at.push((k as u32, j));
        if self.batch.at.len() < self.full {
            return true;
        }
        let empty = self.link.recycled().unwrap_or_else(|| Batch::new(rb));
        self.link.send(std::mem::replace(&mut self.batch, empty))
    }

    /// Sends the last batch, if it holds anything (a checker gone by now has panicked, and
    /// `stream` passes the panic on).
    pub(super) fn flush(self) {
        if !self.batch.at.is_empty() {
            self.link.send(self.batch);
        }
    }
}

/// The checking thread: every record of every batch, in order; each batch then goes back.
/// Returns the report and the index (in transfer order) of the first output that failed.
pub(super) fn consume(rx: Receiver<Batch>, back: SyncSender<Batch>, rb: usize, mut check: impl Check) -> (Report, Option<usize>) {
    let mut report = Report::default();
    let (mut n, mut first_bad) = (0, None);
    for mut batch in rx {
        for (&(k, j), rec) in batch.at.iter().zip(batch.data.chunks_exact(rb)) {
            let before = report.mismatch_count;
            check.check(k as usize, j, rec, &mut report);
            if report.mismatch_count != before && first_bad.is_none() {
                first_bad = Some(n);
            }
            n += 1;
        }
        batch.at.clear();
        // The driver may have finished, or hold enough spares already: then it is dropped.
        let _ = back.try_send(batch);
    }
    (report, first_bad)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::Mismatch;

    /// The checking thread hands back the index, in transfer order, of the first output that
    /// failed, over batches; the driver names the waveform after it.
    #[test]
    fn the_checker_names_its_first_failing_output() {
        struct FailFrom(usize, usize);
        impl Check for FailFrom {
            fn check(&mut self, _k: usize, _j: u32, _rec: &[u8], report: &mut Report) {
                if self.1 >= self.0 {
                    report.mismatch(Mismatch { triangle: None, context: String::new(), what: "planted".into() });
                }
                self.1 += 1;
            }
        }
        let (tx, rx) = sync_channel(IN_FLIGHT);
        let (back, _back_rx) = sync_channel(IN_FLIGHT + 2);
        let rb = 4;
        let per = Batch::records(rb);
        let sender = std::thread::spawn(move || {
            for b in 0..3 {
                let mut batch = Batch::new(rb);
                for r in 0..per {
                    batch.at.push((b, r as u32));
                }
                tx.send(batch).unwrap();
            }
        });
        let (report, first_bad) = consume(rx, back, rb, FailFrom(per + 5, 0));
        sender.join().unwrap();
        assert_eq!(first_bad, Some(per + 5));
        assert_eq!(report.mismatch_count, (3 * per - per - 5) as u64);
    }

    /// The outbox hands over every record once, in order, in full batches and then the rest;
    /// with the checker gone it says so, and the driver stops.
    #[test]
    fn the_outbox_delivers_every_record_in_order() {
        /// Sends every record it is given back to the test's thread.
        struct Out(std::sync::mpsc::Sender<(usize, u32, u32)>);
        impl Check for Out {
            fn check(&mut self, k: usize, j: u32, rec: &[u8], _report: &mut Report) {
                self.0.send((k, j, u32::from_le_bytes(rec.try_into().unwrap()))).unwrap();
            }
        }
        let rb = 4;
        let n = 2 * Batch::records(rb) + 7;
        let (link, rx, back) = channels();
        let (got_tx, got_rx) = std::sync::mpsc::channel();
        let checker = std::thread::spawn(move || consume(rx, back, rb, Out(got_tx)));
        let mut outbox = Outbox::new(&link, rb);
        for i in 0..n {
            assert!(outbox.push(i / 3, (i % 3) as u32, |r| r.copy_from_slice(&(i as u32).to_le_bytes())));
        }
        outbox.flush();
        drop(link);
        checker.join().unwrap();
        let got: Vec<_> = got_rx.iter().collect();
        let want: Vec<_> = (0..n).map(|i| (i / 3, (i % 3) as u32, i as u32)).collect();
        assert_eq!(got, want);

        // Negative control: no checker at the other end.
        let (link, rx, _back) = channels();
        drop(rx);
        let mut outbox = Outbox::new(&link, rb);
        let pushed = (0..Batch::records(rb)).map(|i| outbox.push(0, i as u32, |r| r.fill(0))).collect::<Vec<_>>();
        assert!(pushed[..pushed.len() - 1].iter().all(|&ok| ok) && !pushed[pushed.len() - 1], "only the full batch finds the checker gone");
    }
}
