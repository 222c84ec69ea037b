//! Deriving lots on worker threads (kept between calls, see `threads`)
//! while the calling thread takes what they produce, in lot order.

use std::sync::mpsc;

use crate::Error;

/// What the writing thread is handed for a lot, in order: the pieces of
/// its output as they are sent, then its result.
pub(crate) enum Taken<L, R> {
    Piece(L),
    Done(R),
}

/// What a worker sends for a lot: the channel its pieces will come
/// through (when it starts), then its result.
enum Delivery<L, R> {
    Pieces(mpsc::Receiver<L>),
    Done(R),
}

/// Derives lots `0..count` on `jobs` worker threads while the calling
/// thread hands what they produce to `take` in lot order: the pieces of a
/// lot's output as they come (`generate` sends them through its sink, each
/// piece a message: batches, not single leaves, so that the writing thread
/// is not woken for every leaf), then its result. So writing overlaps
/// deriving, even within one lot, and the output does not depend on the
/// number of threads. Each worker has a state of its own, made by `init`,
/// that `generate` uses for all its lots. A worker starts a lot only while
/// fewer than a few lots per worker wait to be taken, so memory holds a
/// bounded number of lots, not the whole city. An error from `take` stops
/// the workers and is returned. A worker with no lot left calls `idle`
/// with its state before it ends (where it may help the others).
pub(crate) fn run_pipeline<W, L: Send, R: Send>(
    count: usize,
    jobs: usize,
    init: impl Fn() -> W + Sync,
    generate: impl Fn(&mut W, usize, &mut dyn FnMut(L)) -> R + Sync,
    idle: impl Fn(&mut W) + Sync,
    take: &mut dyn FnMut(usize, Taken<L, R>) -> Result<(), Error>,
) -> Result<(), Error> {
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
    use std::sync::{Condvar, Mutex};

    /// Stops the other workers if this one panics (they would otherwise
    /// wait for a lot that never comes).
    struct StopOnPanic<'a>(&'a dyn Fn());
    impl Drop for StopOnPanic<'_> {
        fn drop(&mut self) {
            if std::thread::panicking() {
                (self.0)();
            }
        }
    }

    let window = jobs * 4;
    let next = AtomicUsize::new(0);
    let stop = AtomicBool::new(false);
    // Lots taken so far, and a signal when it grows or work stops.
    let taken = (Mutex::new(0usize), Condvar::new());
    let lock = || taken.0.lock().unwrap_or_else(|e| e.into_inner());
    let halt = || {
        // Under the lock, so that no worker misses the signal.
        let _done = lock();
        stop.store(true, Ordering::Relaxed);
        taken.1.notify_all();
    };
    crate::threads::scope(|scope| {
        let (tx, rx) = mpsc::channel::<(usize, Delivery<L, R>)>();
        for _ in 0..jobs.min(count) {
            let tx = tx.clone();
            let (next, stop, taken, init, generate, idle, lock, halt) =
                (&next, &stop, &taken, &init, &generate, &idle, &lock, &halt);
            let worker = move || {
                let _guard = StopOnPanic(halt);
                let mut state = init();
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    if i >= count {
                        break;
                    }
                    {
                        let mut done = lock();
                        while i >= *done + window && !stop.load(Ordering::Relaxed) {
                            done = taken.1.wait(done).unwrap_or_else(|e| e.into_inner());
                        }
                    }
                    let (piece_tx, piece_rx) = mpsc::channel();
                    if stop.load(Ordering::Relaxed)
                        || tx.send((i, Delivery::Pieces(piece_rx))).is_err()
                    {
                        break;
                    }
                    let r = generate(&mut state, i, &mut |piece| {
                        // A closed channel means the writing stopped.
                        let _ = piece_tx.send(piece);
                    });
                    drop(piece_tx);
                    if tx.send((i, Delivery::Done(r))).is_err() {
                        break;
                    }
                }
                idle(&mut state);
            };
            if let Err(e) = scope.spawn(worker) {
                halt();
                return Err(Error::Threads(e));
            }
        }
        drop(tx);
        let mut pieces = std::collections::BTreeMap::new();
        let mut results = std::collections::BTreeMap::new();
        // The next message for lot `i` of the kind asked for, out of the
        // waiting ones; `None` when the workers are gone.
        let mut wait_for = |i: usize, want_pieces: bool| loop {
            if want_pieces {
                if let Some(r) = pieces.remove(&i) {
                    return Some(Delivery::Pieces(r));
                }
            } else if let Some(r) = results.remove(&i) {
                return Some(Delivery::Done(r));
            }
            match rx.recv() {
                Ok((j, Delivery::Pieces(r))) => {
                    pieces.insert(j, r);
                }
                Ok((j, Delivery::Done(r))) => {
                    results.insert(j, r);
                }
                Err(_) => return None,
            }
        };
        let mut result = Ok(());
        'lots: for i in 0..count {
            let Some(Delivery::Pieces(piece_rx)) = wait_for(i, true) else {
                break;
            };
            for piece in piece_rx.iter() {
                result = take(i, Taken::Piece(piece));
                if result.is_err() {
                    break 'lots;
                }
            }
            let Some(Delivery::Done(r)) = wait_for(i, false) else {
                break;
            };
            result = take(i, Taken::Done(r));
            if result.is_err() {
                break;
            }
            *lock() = i + 1;
            taken.1.notify_all();
        }
        halt();
        result
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs the pipeline where lot `i` emits `i % 5` leaves `(i, k)` and
    /// results in `10 i`; returns what was taken, in order.
    fn run(count: usize, jobs: usize, fail_at: Option<usize>) -> (Vec<String>, bool) {
        let mut seen = Vec::new();
        // Each worker counts the lots it derived in its own state.
        let generate = |lots: &mut usize, i: usize, sink: &mut dyn FnMut((usize, usize))| {
            *lots += 1;
            assert!(*lots <= count);
            for k in 0..i % 5 {
                sink((i, k));
            }
            10 * i
        };
        let r = run_pipeline(count, jobs, || 0usize, generate, |_| {}, &mut |i, taken| {
            match taken {
                Taken::Piece((j, k)) => seen.push(format!("{i}:{j}.{k}")),
                Taken::Done(r) => seen.push(format!("{i}={r}")),
            }
            if Some(i) == fail_at {
                return Err(Error::Cancelled);
            }
            Ok(())
        });
        (seen, r.is_ok())
    }

    #[test]
    fn pipeline_takes_everything_in_lot_order() {
        let mut want = Vec::new();
        for i in 0..60 {
            for k in 0..i % 5 {
                want.push(format!("{i}:{i}.{k}"));
            }
            want.push(format!("{i}={}", 10 * i));
        }
        for jobs in [1, 2, 3, 8] {
            let (seen, ok) = run(60, jobs, None);
            assert!(ok);
            assert_eq!(seen, want, "{jobs} jobs");
        }
        assert_eq!(run(0, 2, None), (Vec::new(), true));
    }

    #[test]
    fn pipeline_stops_on_an_error() {
        let (seen, ok) = run(100, 3, Some(6));
        assert!(!ok);
        // Lot 6 has one leaf: taking it failed, nothing after it is taken.
        assert_eq!(seen.last().map(String::as_str), Some("6:6.0"));
        assert_eq!(seen.len(), 17);
    }

    #[test]
    fn a_worker_panic_does_not_hang_the_pipeline() {
        let r = std::panic::catch_unwind(|| {
            let generate = |_: &mut (), i: usize, _: &mut dyn FnMut(())| {
                assert!(i != 3, "lot 3 fails");
                i
            };
            run_pipeline(40, 2, || (), generate, |_| {}, &mut |_, _| Ok(()))
        });
        assert!(r.is_err());
    }
}
