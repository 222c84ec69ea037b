//! Workers out of lots help those still deriving.
//!
//! Lots are shared out one at a time, so the workers run out of them at
//! different moments: with 20 buildings on two workers, one often waited
//! for most of a building's time while the other derived the last lot
//! (0–22 ms of 0.25 s, 10 on average). A worker with no lot left offers
//! itself ([`Help::offer`]); a worker still deriving that sees the offer
//! hands it the encoding of its leaves ([`Help::ask`]): its batcher (the
//! encoder and the batch it was filling) goes to the helper, the leaves
//! follow in order, and the pieces the helper encodes come back to be sent
//! on as the worker's own. The same batcher encodes the same leaves in the
//! same order, so the pieces and the file are what the worker alone would
//! have made; the worker meanwhile only derives (encoding is about two
//! fifths of a Candler building's time).

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{mpsc, Condvar, Mutex, MutexGuard};

use cga_engine::derive::Leaf;

use crate::generate::{Batcher, Piece};

/// Leaves handed to a helper in one message: one per leaf would wake it
/// for each.
const LEAVES_PER_MESSAGE: usize = 64;

/// Where idle workers wait for encoding to take over.
pub(crate) struct Help {
    state: Mutex<HelpState>,
    wake: Condvar,
    /// Helpers waiting with nothing to do: what a deriving worker reads
    /// after each leaf, without taking the lock.
    idle: AtomicUsize,
}

struct HelpState {
    /// Encoding handed over, for the next idle helper.
    job: Option<Job>,
    /// Workers that have begun and not yet run out of lots (or ended).
    deriving: usize,
}

/// A worker's encoding, handed to a helper.
struct Job {
    batcher: Batcher,
    leaves: mpsc::Receiver<Vec<Leaf>>,
    pieces: mpsc::Sender<Piece>,
    back: mpsc::Sender<Batcher>,
}

impl Job {
    /// Encodes the leaves as they come, sending the pieces back, and
    /// returns the batcher (with the batch it was filling) when the leaves
    /// end.
    fn run(mut self) {
        for batch in self.leaves.iter() {
            for leaf in batch {
                self.batcher.add(leaf, &mut |piece| {
                    let _ = self.pieces.send(piece);
                });
            }
        }
        drop(self.pieces);
        let _ = self.back.send(self.batcher);
    }
}

/// A worker's side of encoding handed over: its leaves go to the helper,
/// the helper's pieces are sent on.
pub(crate) struct Handoff {
    leaves: mpsc::Sender<Vec<Leaf>>,
    pending: Vec<Leaf>,
    pieces: mpsc::Receiver<Piece>,
    back: mpsc::Receiver<Batcher>,
}

impl Handoff {
    /// Passes `leaf` on to the helper, and sends on the pieces it made so
    /// far.
    pub fn add(&mut self, leaf: Leaf, send: &mut dyn FnMut(Piece)) {
        self.pending.push(leaf);
        if self.pending.len() == LEAVES_PER_MESSAGE {
            let batch =
                std::mem::replace(&mut self.pending, Vec::with_capacity(LEAVES_PER_MESSAGE));
            let _ = self.leaves.send(batch);
        }
        while let Ok(piece) = self.pieces.try_recv() {
            send(piece);
        }
    }

    /// The lot's leaves are all derived: sends on the rest of the
    /// helper's pieces and returns the batcher (`None` if the helper
    /// failed).
    pub fn finish(mut self, send: &mut dyn FnMut(Piece)) -> Option<Batcher> {
        if !self.pending.is_empty() {
            let _ = self.leaves.send(std::mem::take(&mut self.pending));
        }
        drop(self.leaves);
        for piece in self.pieces.iter() {
            send(piece);
        }
        self.back.recv().ok()
    }
}

impl Help {
    /// Help for the workers that register ([`Helping::new`]): counted as
    /// they begin, so that a worker that was never started (its thread
    /// could not be made) is not waited for.
    pub fn new() -> Help {
        Help {
            state: Mutex::new(HelpState {
                job: None,
                deriving: 0,
            }),
            wake: Condvar::new(),
            idle: AtomicUsize::new(0),
        }
    }

    fn lock(&self) -> MutexGuard<'_, HelpState> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// A worker with no lot left: takes over the encoding of workers still
    /// deriving, as they hand it over, until none is.
    pub fn offer(&self) {
        let mut state = self.lock();
        state.deriving = state.deriving.saturating_sub(1);
        if state.deriving == 0 {
            // Every worker is out of lots: those waiting stop.
            self.wake.notify_all();
            return;
        }
        self.idle.fetch_add(1, Ordering::SeqCst);
        loop {
            if let Some(job) = state.job.take() {
                // `ask` counted this helper out of the idle ones.
                drop(state);
                job.run();
                state = self.lock();
                self.idle.fetch_add(1, Ordering::SeqCst);
                continue;
            }
            if state.deriving == 0 {
                return;
            }
            state = self.wake.wait(state).unwrap_or_else(|e| e.into_inner());
        }
    }

    /// A worker that ends without offering (it failed): no longer waited
    /// for.
    pub fn leave(&self) {
        let mut state = self.lock();
        state.deriving = state.deriving.saturating_sub(1);
        if state.deriving == 0 {
            self.wake.notify_all();
        }
    }

    /// Hands the encoding of a deriving worker's leaves to an idle helper,
    /// if there is one: `batcher` goes to it (replaced by one that drops
    /// leaves), and the worker passes its leaves on through the handoff.
    pub fn ask(&self, batcher: &mut Batcher) -> Option<Handoff> {
        if self.idle.load(Ordering::Relaxed) == 0 {
            return None;
        }
        let mut state = self.lock();
        if state.job.is_some() || self.idle.load(Ordering::SeqCst) == 0 {
            return None;
        }
        self.idle.fetch_sub(1, Ordering::SeqCst);
        let (leaves_tx, leaves) = mpsc::channel();
        let (pieces, pieces_rx) = mpsc::channel();
        let (back, back_rx) = mpsc::channel();
        state.job = Some(Job {
            batcher: std::mem::replace(batcher, Batcher::Drop),
            leaves,
            pieces,
            back,
        });
        self.wake.notify_all();
        Some(Handoff {
            leaves: leaves_tx,
            pending: Vec::with_capacity(LEAVES_PER_MESSAGE),
            pieces: pieces_rx,
            back: back_rx,
        })
    }
}

/// A worker's place in [`Help`]: if the worker ends without offering
/// itself (a panic), it leaves, so that the helpers do not wait for it.
pub(crate) struct Helping<'a> {
    help: &'a Help,
    offered: bool,
}

impl<'a> Helping<'a> {
    pub fn new(help: &'a Help) -> Helping<'a> {
        help.lock().deriving += 1;
        Helping {
            help,
            offered: false,
        }
    }

    /// See [`Help::offer`].
    pub fn offer(&mut self) {
        self.offered = true;
        self.help.offer();
    }

    pub fn ask(&self, batcher: &mut Batcher) -> Option<Handoff> {
        self.help.ask(batcher)
    }
}

impl Drop for Helping<'_> {
    fn drop(&mut self) {
        if !self.offered {
            self.help.leave();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    fn leaf(name: u32) -> Leaf {
        Leaf {
            mesh: Arc::new(cga_geometry::Mesh::default()),
            transform: cga_geometry::DAffine3::IDENTITY,
            materials: Default::default(),
            asset: false,
            rule: None,
            name,
        }
    }

    /// Names of the leaves in the pieces, piece by piece.
    fn names(pieces: &[Piece]) -> Vec<Vec<u32>> {
        pieces
            .iter()
            .map(|p| match p {
                Piece::Leaves(batch) => batch.iter().map(|l| l.name).collect(),
                Piece::Encoded(_) => panic!("leaves were batched, not encoded"),
            })
            .collect()
    }

    /// A worker out of lots takes over a deriving worker's batcher: the
    /// batch begun goes on filling in the helper, full batches come back
    /// in order, and the batcher returns with the rest; the same pieces
    /// as the worker alone would have sent.
    #[test]
    fn an_idle_worker_takes_over_the_batching_in_order() {
        let help = Help::new();
        std::thread::scope(|scope| {
            let mut worker = Helping::new(&help);
            let helper = scope.spawn(|| Helping::new(&help).offer());
            let mut batcher = Batcher::Leaves(Vec::new());
            let mut sent = Vec::new();
            let mut send = |p: Piece| sent.push(p);
            // 100 leaves batched before the helper is there.
            for k in 0..100 {
                batcher.add(leaf(k), &mut send);
            }
            while help.idle.load(Ordering::SeqCst) == 0 {
                std::thread::yield_now();
            }
            let mut handoff = worker.ask(&mut batcher).expect("a helper is idle");
            assert!(matches!(batcher, Batcher::Drop));
            assert!(
                worker.ask(&mut batcher).is_none(),
                "the only helper is busy"
            );
            for k in 100..1200 {
                handoff.add(leaf(k), &mut send);
            }
            batcher = handoff.finish(&mut send).expect("the helper gives it back");
            batcher.flush(&mut send);
            worker.offer();
            helper
                .join()
                .expect("the helper ends when no worker derives");
            let all: Vec<u32> = (0..1200).collect();
            let expected: Vec<Vec<u32>> = all.chunks(512).map(<[u32]>::to_vec).collect();
            assert_eq!(names(&sent), expected);
        });
    }

    /// Helpers stop waiting when the last worker ends, also one that ends
    /// without offering itself.
    #[test]
    fn helpers_stop_when_every_worker_is_done() {
        let help = Help::new();
        std::thread::scope(|scope| {
            let failing = Helping::new(&help);
            let helpers: Vec<_> = (0..2)
                .map(|_| {
                    let helping = Helping::new(&help);
                    scope.spawn(move || {
                        let mut helping = helping;
                        helping.offer()
                    })
                })
                .collect();
            // The third worker fails: its place is dropped.
            drop(failing);
            for h in helpers {
                h.join().expect("helper ends");
            }
        });
    }
}
