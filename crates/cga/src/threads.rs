//! Worker threads kept from one generation to the next.
//!
//! A program that generates again and again in one process (a Python
//! session, the live preview) made new worker threads for every call: each
//! came with an empty allocator heap, so the memory the last call's
//! workers had used (and the arrays they had handed out, freed since) was
//! not theirs to reuse, and every call but the first few touched fresh
//! pages the kernel had to zero (20 Candler buildings into numpy meshes:
//! the second call took up to two fifths longer than the later ones, the
//! third up to a seventh). Here a
//! worker that has finished its job waits for the next one instead of
//! ending, and [`scope`] runs jobs on waiting workers, making new ones only
//! when none waits. Unlike a shared pool, a call never waits for another
//! call's jobs: a worker runs one job at a time, and a call that finds no
//! worker waiting makes its own.
//!
//! [`scope`] has the shape of `std::thread::scope`: jobs may borrow from
//! the caller, because the scope returns (or unwinds) only once every job
//! it started has ended.

use std::any::Any;
use std::marker::PhantomData;
use std::panic::{catch_unwind, resume_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{mpsc, Arc, Condvar, Mutex, MutexGuard};

use crate::stack::STACK_SIZE;

/// A job as a waiting worker receives it.
type Job = Box<dyn FnOnce() + Send + 'static>;

/// Workers that wait for a job, by the channel that hands it over, with
/// the process they wait in: a process forked from this one (Python's
/// `multiprocessing`) inherits the list but not the threads, and must not
/// hand its jobs to workers that are not there.
static WAITING: Mutex<Waiting> = Mutex::new(Waiting {
    process: 0,
    workers: Vec::new(),
});

struct Waiting {
    process: u32,
    workers: Vec<mpsc::Sender<Job>>,
}

impl Waiting {
    /// The waiting workers of this process.
    fn here(&mut self) -> &mut Vec<mpsc::Sender<Job>> {
        let process = std::process::id();
        if self.process != process {
            self.process = process;
            self.workers.clear();
        }
        &mut self.workers
    }
}

/// Workers kept waiting at most; one more ends when its job is done (a
/// call with many jobs does not keep as many threads for ever).
const KEPT: usize = 64;

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    // A job's panic is caught before it could poison these locks; a
    // poisoned one holds nothing a later call could misread.
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// Runs `job` on a waiting worker, or on a new one.
fn start(mut job: Job) -> std::io::Result<()> {
    loop {
        let waiting = lock(&WAITING).here().pop();
        let Some(tx) = waiting else { break };
        match tx.send(job) {
            Ok(()) => return Ok(()),
            // The worker is gone (its thread ended): try another.
            Err(mpsc::SendError(j)) => job = j,
        }
    }
    let (tx, rx) = mpsc::channel::<Job>();
    std::thread::Builder::new()
        .name("cga-worker".into())
        .stack_size(STACK_SIZE)
        .spawn(move || {
            let mut job = job;
            loop {
                job();
                {
                    let mut waiting = lock(&WAITING);
                    let waiting = waiting.here();
                    if waiting.len() >= KEPT {
                        return;
                    }
                    waiting.push(tx.clone());
                }
                match rx.recv() {
                    Ok(next) => job = next,
                    Err(_) => return,
                }
            }
        })
        .map(drop)
}

/// What a scope counts: jobs not yet ended, and panics of jobs whose
/// handle was not joined.
#[derive(Default)]
struct Running {
    jobs: Mutex<usize>,
    ended: Condvar,
    unjoined_panics: AtomicUsize,
}

impl Running {
    fn wait_for_all(&self) {
        let mut jobs = lock(&self.jobs);
        while *jobs > 0 {
            jobs = self.ended.wait(jobs).unwrap_or_else(|e| e.into_inner());
        }
    }
}

/// Where jobs are started from (see [`scope`]).
pub(crate) struct Scope<'scope, 'env: 'scope> {
    running: Arc<Running>,
    /// Invariant in both lifetimes, as `std::thread::Scope` is.
    _scope: PhantomData<&'scope mut &'scope ()>,
    _env: PhantomData<&'env mut &'env ()>,
}

/// A job's result once it has ended.
type Outcome<T> = Result<T, Box<dyn Any + Send + 'static>>;

/// What a job leaves for its handle.
struct Slot<T> {
    outcome: Mutex<Option<Outcome<T>>>,
    ended: Condvar,
}

/// A started job, to wait for its result with [`Handle::join`].
pub(crate) struct Handle<'scope, T> {
    slot: Arc<Slot<T>>,
    running: &'scope Running,
}

impl<T> Handle<'_, T> {
    /// Waits for the job to end: its result, or what it panicked with.
    pub fn join(self) -> Outcome<T> {
        let mut outcome = lock(&self.slot.outcome);
        loop {
            if let Some(o) = outcome.take() {
                if o.is_err() {
                    // Joined: the caller sees this panic itself.
                    self.running.unjoined_panics.fetch_sub(1, Ordering::Relaxed);
                }
                return o;
            }
            outcome = self
                .slot
                .ended
                .wait(outcome)
                .unwrap_or_else(|e| e.into_inner());
        }
    }
}

impl<'scope> Scope<'scope, '_> {
    /// Starts `f` on a worker thread.
    pub fn spawn<T, F>(&'scope self, f: F) -> std::io::Result<Handle<'scope, T>>
    where
        F: FnOnce() -> T + Send + 'scope,
        T: Send + 'scope,
    {
        let slot = Arc::new(Slot {
            outcome: Mutex::new(None),
            ended: Condvar::new(),
        });
        *lock(&self.running.jobs) += 1;
        let (job_slot, job_running) = (slot.clone(), self.running.clone());
        let job = move || {
            // `f` and what it holds are dropped before the scope hears
            // that the job ended.
            let outcome = catch_unwind(AssertUnwindSafe(f));
            if outcome.is_err() {
                job_running.unjoined_panics.fetch_add(1, Ordering::Relaxed);
            }
            *lock(&job_slot.outcome) = Some(outcome);
            job_slot.ended.notify_all();
            drop(job_slot);
            let mut jobs = lock(&job_running.jobs);
            *jobs -= 1;
            job_running.ended.notify_all();
        };
        let job: Box<dyn FnOnce() + Send + 'scope> = Box::new(job);
        // SAFETY: the job borrows for 'scope at most, and `scope` does not
        // return or unwind before every job started from it has ended
        // (`Running::wait_for_all`, also run while unwinding), so nothing
        // the job borrows is gone while it runs. The job itself (with what
        // it captured) is dropped before it counts itself ended.
        let job: Job =
            unsafe { std::mem::transmute::<Box<dyn FnOnce() + Send + 'scope>, Job>(job) };
        if let Err(e) = start(job) {
            *lock(&self.running.jobs) -= 1;
            return Err(e);
        }
        Ok(Handle {
            slot,
            running: &self.running,
        })
    }
}

/// Runs `f` with a [`Scope`] whose jobs run on worker threads kept between
/// calls, and returns once all of them have ended. Like
/// `std::thread::scope`, it panics if a job panicked and its handle was
/// not joined.
pub(crate) fn scope<'env, T>(f: impl for<'scope> FnOnce(&'scope Scope<'scope, 'env>) -> T) -> T {
    /// Waits for the scope's jobs, also when `f` unwinds.
    struct WaitForAll<'a>(&'a Running);
    impl Drop for WaitForAll<'_> {
        fn drop(&mut self) {
            self.0.wait_for_all();
        }
    }
    let scope = Scope {
        running: Arc::new(Running::default()),
        _scope: PhantomData,
        _env: PhantomData,
    };
    let result = {
        let _wait = WaitForAll(&scope.running);
        catch_unwind(AssertUnwindSafe(|| f(&scope)))
    };
    match result {
        Err(panic) => resume_unwind(panic),
        Ok(_) if scope.running.unjoined_panics.load(Ordering::Relaxed) > 0 => {
            panic!("a worker thread panicked")
        }
        Ok(r) => r,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::AtomicBool;

    /// The name of the thread a job ran on.
    fn thread_name() -> String {
        std::thread::current().name().unwrap_or("").to_string()
    }

    /// Jobs borrow from the caller, run on threads of their own, and the
    /// threads of one call are the ones the next call's jobs run on.
    #[test]
    fn jobs_borrow_and_threads_are_kept_for_the_next_call() {
        let words = ["a", "b", "c"];
        let ids = |_: usize| {
            scope(|s| {
                let handles: Vec<_> = words
                    .iter()
                    .map(|w| {
                        s.spawn(move || {
                            (w.to_uppercase(), std::thread::current().id(), thread_name())
                        })
                        .expect("a thread")
                    })
                    .collect();
                handles
                    .into_iter()
                    .map(|h| h.join().expect("no panic"))
                    .collect::<Vec<_>>()
            })
        };
        let first = ids(0);
        assert_eq!(
            first.iter().map(|(w, ..)| w.as_str()).collect::<Vec<_>>(),
            ["A", "B", "C"]
        );
        assert!(first.iter().all(|(_, _, name)| name == "cga-worker"));
        // Other tests run scopes at the same time, so the threads of this
        // call need not all come back to it; most waiting workers are
        // reused rather than new ones made.
        let before: std::collections::HashSet<_> = first.iter().map(|(_, id, _)| *id).collect();
        let reused = (0..20)
            .flat_map(ids)
            .filter(|(_, id, _)| before.contains(id))
            .count();
        assert!(reused > 0, "no thread of the first call ran a later job");
    }

    /// A scope returns only once its jobs have ended, even those whose
    /// handles were dropped.
    #[test]
    fn a_scope_waits_for_every_job() {
        let done = AtomicBool::new(false);
        scope(|s| {
            let _ = s.spawn(|| {
                std::thread::sleep(std::time::Duration::from_millis(50));
                done.store(true, Ordering::SeqCst);
            });
        });
        assert!(done.load(Ordering::SeqCst));
    }

    /// A job's panic reaches `join`; one not joined panics the scope, after
    /// the other jobs have ended.
    #[test]
    fn panics_reach_the_caller() {
        let joined = scope(|s| s.spawn(|| panic!("joined")).expect("a thread").join());
        assert!(joined.is_err());
        let finished = AtomicBool::new(false);
        let unjoined = std::panic::catch_unwind(AssertUnwindSafe(|| {
            scope(|s| {
                let _ = s.spawn(|| panic!("not joined"));
                let _ = s.spawn(|| {
                    std::thread::sleep(std::time::Duration::from_millis(30));
                    finished.store(true, Ordering::SeqCst);
                });
            })
        }));
        assert!(unjoined.is_err());
        assert!(finished.load(Ordering::SeqCst));
    }
}
