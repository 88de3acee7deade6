//! The worker threads of one process: each steps the same block of subdomains every phase,
//! and waits for the next phase spinning, so that a phase starts in about a microsecond.
//!
//! A decomposed step has two parallel phases separated by a little serial work (the
//! forward's routing, a reduction). Rayon's fork-join put its workers to sleep in that gap
//! and woke them through the kernel for the next phase: 8% of a 2-thread heap run went to
//! the scheduler, and two threads reached 1.7x one where two MPI ranks (each busy-polling
//! in MPI) reached 1.9x. The team spins for `SPIN` before it sleeps, as OpenMP's runtimes
//! do, and always gives subdomain `s` to the same thread, whose cache then holds it.

use std::any::Any;
use std::cell::UnsafeCell;
use std::panic::{catch_unwind, resume_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// How long a worker spins for the next phase before it sleeps: longer than the serial
/// work between the phases of a step, short enough that a worker left idle (outputs, a
/// run on fewer subdomains than threads) frees its core at once.
const SPIN: Duration = Duration::from_micros(200);

/// A phase's task: called once per thread with the thread's index (0 is the caller).
type Job<'a> = dyn Fn(usize) + Sync + 'a;

/// The caller plus `threads - 1` workers.
pub struct Team {
    shared: Arc<Shared>,
    workers: Vec<JoinHandle<()>>,
    /// Held during a phase; a phase started meanwhile runs on its caller alone.
    running: Mutex<()>,
}

struct Shared {
    /// Counts the phases; a worker runs `job` when it changes.
    epoch: AtomicU64,
    /// The phase's task with its lifetime erased: written by `run` only while no worker
    /// reads it (before the epoch moves, after every worker has finished).
    job: UnsafeCell<Option<*const Job<'static>>>,
    /// Workers still running this phase.
    pending: AtomicUsize,
    sleepers: AtomicUsize,
    lock: Mutex<()>,
    wake: Condvar,
    stop: AtomicBool,
    /// The first panic of a worker in this phase, raised again on the caller.
    panic: Mutex<Option<Box<dyn Any + Send>>>,
}

// SAFETY: `job` is written only by `run` while no worker can read it (see `run`), and
// what it points to is `Sync`.
unsafe impl Sync for Shared {}
unsafe impl Send for Shared {}

impl Team {
    /// A team of `threads` threads: the caller and `threads - 1` new ones.
    pub fn new(threads: usize) -> Team {
        let shared = Arc::new(Shared {
            epoch: AtomicU64::new(0),
            job: UnsafeCell::new(None),
            pending: AtomicUsize::new(0),
            sleepers: AtomicUsize::new(0),
            lock: Mutex::new(()),
            wake: Condvar::new(),
            stop: AtomicBool::new(false),
            panic: Mutex::new(None),
        });
        let workers = (1..threads.max(1))
            .map(|index| {
                let shared = Arc::clone(&shared);
                std::thread::Builder::new()
                    .name(format!("cgdem-worker-{index}"))
                    .spawn(move || work(&shared, index))
                    .expect("cannot start a worker thread")
            })
            .collect();
        Team {
            shared,
            workers,
            running: Mutex::new(()),
        }
    }

    pub fn threads(&self) -> usize {
        self.workers.len() + 1
    }

    /// Runs `job(t)` on every thread `t` of the team (the caller is 0) and returns when all
    /// have finished; a panic in any is raised here.
    pub fn run(&self, job: &Job<'_>) {
        if self.workers.is_empty() {
            job(0);
            return;
        }
        // Busy with another phase (a task that starts a phase itself, or a clone of the
        // decomposition stepped on another thread): this one runs every part here.
        let _one_phase = match self.running.try_lock() {
            Ok(guard) => guard,
            Err(std::sync::TryLockError::Poisoned(e)) => e.into_inner(),
            Err(std::sync::TryLockError::WouldBlock) => {
                (0..self.threads()).for_each(job);
                return;
            }
        };
        let s = &*self.shared;
        // SAFETY: the workers read the pointer only during this phase, and this function
        // returns (or unwinds) only after every worker has finished with it.
        let erased: *const Job<'static> =
            unsafe { std::mem::transmute::<&Job<'_>, &'static Job<'static>>(job) };
        unsafe { *s.job.get() = Some(erased) };
        s.pending.store(self.workers.len(), Ordering::Relaxed);
        s.epoch.fetch_add(1, Ordering::SeqCst);
        if s.sleepers.load(Ordering::SeqCst) > 0 {
            let _guard = s.lock.lock().unwrap_or_else(PoisonError::into_inner);
            s.wake.notify_all();
        }
        let mine = catch_unwind(AssertUnwindSafe(|| job(0)));
        let started = Instant::now();
        let mut spins = 0u32;
        while s.pending.load(Ordering::Acquire) != 0 {
            spins = spins.wrapping_add(1);
            // On a machine with more threads than cores, spinning starves the worker waited
            // for: yield once the wait is long.
            if spins.is_multiple_of(64) && started.elapsed() > SPIN {
                std::thread::yield_now();
            } else {
                std::hint::spin_loop();
            }
        }
        unsafe { *s.job.get() = None };
        if let Err(payload) = mine {
            resume_unwind(payload);
        }
        let worker_panic = s
            .panic
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .take();
        if let Some(payload) = worker_panic {
            resume_unwind(payload);
        }
    }
}

impl Drop for Team {
    fn drop(&mut self) {
        let s = &*self.shared;
        s.stop.store(true, Ordering::SeqCst);
        s.epoch.fetch_add(1, Ordering::SeqCst);
        {
            let _guard = s.lock.lock().unwrap_or_else(PoisonError::into_inner);
            s.wake.notify_all();
        }
        for worker in self.workers.drain(..) {
            let _ = worker.join();
        }
    }
}

impl std::fmt::Debug for Team {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Team {{ threads: {} }}", self.threads())
    }
}

/// A worker's life: wait for a phase, run its part, say so; until the team is dropped.
fn work(s: &Shared, index: usize) {
    let mut seen = 0;
    loop {
        seen = next_epoch(s, seen);
        if s.stop.load(Ordering::SeqCst) {
            return;
        }
        // SAFETY: published before the epoch moved, and kept alive until `pending` is 0.
        let job = unsafe { (*s.job.get()).expect("a phase publishes its task") };
        if let Err(payload) = catch_unwind(AssertUnwindSafe(|| unsafe { (*job)(index) })) {
            let mut first = s.panic.lock().unwrap_or_else(PoisonError::into_inner);
            first.get_or_insert(payload);
        }
        s.pending.fetch_sub(1, Ordering::Release);
    }
}

/// Waits until the epoch differs from `seen`: spinning for `SPIN`, then asleep.
fn next_epoch(s: &Shared, seen: u64) -> u64 {
    let started = Instant::now();
    let mut spins = 0u32;
    loop {
        let now = s.epoch.load(Ordering::Acquire);
        if now != seen {
            return now;
        }
        spins = spins.wrapping_add(1);
        if spins.is_multiple_of(64) && started.elapsed() > SPIN {
            break;
        }
        std::hint::spin_loop();
    }
    // `run` moves the epoch and then reads `sleepers`; this thread counts itself in
    // `sleepers` and then reads the epoch (all SeqCst): one of the two sees the other, and
    // the notify, taken under the lock, cannot fall between the check and the wait.
    let mut guard = s.lock.lock().unwrap_or_else(PoisonError::into_inner);
    s.sleepers.fetch_add(1, Ordering::SeqCst);
    let mut now = s.epoch.load(Ordering::SeqCst);
    while now == seen {
        guard = s.wake.wait(guard).unwrap_or_else(PoisonError::into_inner);
        now = s.epoch.load(Ordering::SeqCst);
    }
    s.sleepers.fetch_sub(1, Ordering::SeqCst);
    drop(guard);
    now
}

/// `items[s]` for `s` in a set of distinct indices, handed to the threads of a phase.
struct Disjoint<T>(*mut T);

// SAFETY: every index is given to one thread only (`each_of`), so no two threads touch the
// same item.
unsafe impl<T: Send> Sync for Disjoint<T> {}

impl<T> Disjoint<T> {
    /// Item `s`: valid to dereference when `s` is in bounds and no other thread uses it.
    fn at(&self, s: usize) -> *mut T {
        self.0.wrapping_add(s)
    }
}

impl Team {
    /// `task(&mut items[s])` for each `s` of `chosen` (distinct, increasing), the
    /// threads taking contiguous blocks of `chosen` (the same blocks every phase); the
    /// results by index of `items`, `None` where not chosen.
    pub fn each_of<T: Send, R: Send>(
        &self,
        items: &mut [T],
        chosen: &[usize],
        task: impl Fn(&mut T) -> R + Sync,
    ) -> Vec<Option<R>> {
        assert!(
            chosen.windows(2).all(|w| w[0] < w[1])
                && chosen.last().is_none_or(|&s| s < items.len()),
            "chosen indices must be distinct, increasing and in bounds"
        );
        let mut results: Vec<Option<R>> = (0..items.len()).map(|_| None).collect();
        let threads = self.threads().min(chosen.len());
        if threads <= 1 {
            for &s in chosen {
                results[s] = Some(task(&mut items[s]));
            }
            return results;
        }
        let (inputs, outputs) = (Disjoint(items.as_mut_ptr()), Disjoint(results.as_mut_ptr()));
        let m = chosen.len();
        self.run(&|t: usize| {
            if t >= threads {
                return;
            }
            for &s in &chosen[t * m / threads..(t + 1) * m / threads] {
                // SAFETY: the blocks of `chosen` do not overlap and its indices are
                // distinct and in bounds (asserted above).
                unsafe { *outputs.at(s) = Some(task(&mut *inputs.at(s))) };
            }
        });
        results
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_chosen_item_is_visited_once_and_results_come_back_by_index() {
        for threads in 1..=4 {
            let team = Team::new(threads);
            for phase in 0..50 {
                let mut items: Vec<u64> = (0..7).collect();
                let chosen = [0, 2, 3, 6];
                let out = team.each_of(&mut items, &chosen, |x| {
                    *x += 100;
                    *x * 2 + phase
                });
                assert_eq!(items, vec![100, 1, 102, 103, 4, 5, 106]);
                let want = [
                    Some(200 + phase),
                    None,
                    Some(204 + phase),
                    Some(206 + phase),
                ];
                assert_eq!(&out[..4], &want);
                assert_eq!(out[6], Some(212 + phase));
            }
        }
    }

    #[test]
    fn a_phase_started_inside_a_phase_runs_on_its_caller() {
        let team = Team::new(2);
        let mut outer = vec![0u32; 2];
        team.each_of(&mut outer, &[0, 1], |x| {
            let mut inner = vec![1u32; 3];
            team.each_of(&mut inner, &[0, 1, 2], |y| *y += 1);
            *x = inner.iter().sum();
        });
        assert_eq!(outer, vec![6, 6]);
    }

    #[test]
    fn a_sleeping_team_wakes_for_the_next_phase() {
        let team = Team::new(2);
        let mut items = vec![0u32; 2];
        for _ in 0..3 {
            team.each_of(&mut items, &[0, 1], |x| *x += 1);
            std::thread::sleep(SPIN * 5);
        }
        assert_eq!(items, vec![3, 3]);
    }

    #[test]
    fn a_panic_on_a_worker_reaches_the_caller_and_the_team_goes_on() {
        let team = Team::new(2);
        let mut items = vec![0u32; 2];
        let caught = catch_unwind(AssertUnwindSafe(|| {
            team.each_of(&mut items, &[0, 1], |x| {
                if *x == 0 && std::thread::current().name() == Some("cgdem-worker-1") {
                    panic!("planted");
                }
                *x += 1;
            })
        }));
        assert!(caught.is_err());
        team.each_of(&mut items, &[0, 1], |x| *x += 10);
        assert_eq!(items[0], 11);
    }
}
