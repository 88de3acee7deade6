//! The worker threads of one process: each starts every phase on the same block of
//! subdomains, waits for the next phase spinning (so that a phase starts in about a
//! microsecond), and a phase ends when its work is done, not when every thread has come.
//!
//! A decomposed step has two parallel phases separated by a little serial work (the
//! forward's routing, a reduction). Rayon's fork-join put its workers to sleep in that gap
//! and woke them through the kernel for the next phase: 8% of a 2-thread heap run went to
//! the scheduler, and two threads reached 1.7x one where two MPI ranks (each busy-polling
//! in MPI) reached 1.9x. The team spins for `SPIN` before it sleeps, as OpenMP's runtimes
//! do, and gives subdomain `s` first to the same thread, whose cache then holds it.
//!
//! The threads of a VM are not always running: the host takes a vCPU away for milliseconds
//! at a time. A phase that waited for every thread stalled for as long, several steps'
//! worth (a heap step takes about half a millisecond); here a thread that finishes early
//! takes over the subdomains another has not started, and a thread that arrives after the
//! phase is over skips it.

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

/// A phase's task, called with the thread's index (0 is the caller) by the caller and by
/// each worker that joins before the phase closes: the caller's call must do whatever no
/// worker has taken.
type Job<'a> = dyn Fn(usize) + Sync + 'a;

/// The caller plus `threads - 1` workers.
pub struct Team {
    shared: Arc<Shared>,
    workers: Vec<JoinHandle<()>>,
    /// Held during a phase; a phase started meanwhile runs on its caller alone.
    running: Mutex<()>,
}

/// The phase word: the phase's number in the high 32 bits, whether workers may still join
/// in bit 31, and how many are inside its task in the low bits. One word, so that joining
/// (while open) and closing (by the caller) cannot cross.
struct Phase;

impl Phase {
    const OPEN: u64 = 1 << 31;
    const INSIDE: u64 = Phase::OPEN - 1;

    fn number(word: u64) -> u64 {
        word >> 32
    }

    fn opened(number: u64) -> u64 {
        (number << 32) | Phase::OPEN
    }
}

struct Shared {
    /// See [`Phase`]; a worker joins a phase when its number changes.
    phase: AtomicU64,
    /// The phase's task with its lifetime erased: written by `run` only while no worker
    /// can read it (before the phase opens, after it closed with no worker inside).
    job: UnsafeCell<Option<*const Job<'static>>>,
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
            phase: AtomicU64::new(0),
            job: UnsafeCell::new(None),
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

    /// Runs `job(0)` here and `job(t)` on each worker `t` that joins before `job(0)` has
    /// returned, and returns when every call has; a panic in any is raised here.
    fn run(&self, job: &Job<'_>) {
        if self.workers.is_empty() {
            job(0);
            return;
        }
        // Busy with another phase (a task that starts a phase itself, or a clone of the
        // decomposition stepped on another thread): this one runs on its caller alone.
        let _one_phase = match self.running.try_lock() {
            Ok(guard) => guard,
            Err(std::sync::TryLockError::Poisoned(e)) => e.into_inner(),
            Err(std::sync::TryLockError::WouldBlock) => {
                job(0);
                return;
            }
        };
        let s = &*self.shared;
        // SAFETY: a worker reads the pointer only after joining the phase, and this
        // function returns (or unwinds) only after the phase has closed with no worker
        // inside.
        let erased: *const Job<'static> =
            unsafe { std::mem::transmute::<&Job<'_>, &'static Job<'static>>(job) };
        unsafe { *s.job.get() = Some(erased) };
        let number = Phase::number(s.phase.load(Ordering::Relaxed)) + 1;
        s.phase.store(Phase::opened(number), Ordering::SeqCst);
        if s.sleepers.load(Ordering::SeqCst) > 0 {
            let _guard = s.lock.lock().unwrap_or_else(PoisonError::into_inner);
            s.wake.notify_all();
        }
        let mine = catch_unwind(AssertUnwindSafe(|| job(0)));
        // Closed, no worker joins any more; wait for those inside.
        s.phase.fetch_and(!Phase::OPEN, Ordering::AcqRel);
        let started = Instant::now();
        let mut spins = 0u32;
        while s.phase.load(Ordering::Acquire) & Phase::INSIDE != 0 {
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
        // A new number, closed: the workers wake, see `stop` and return.
        s.phase.fetch_add(1 << 32, Ordering::SeqCst);
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

/// A worker's life: wait for a phase, join it if still open, run its part, leave; until
/// the team is dropped.
fn work(s: &Shared, index: usize) {
    let mut seen = 0;
    loop {
        let word = next_phase(s, seen);
        if s.stop.load(Ordering::SeqCst) {
            return;
        }
        seen = Phase::number(word);
        if !join(s, word) {
            continue;
        }
        // SAFETY: published before the phase opened, and kept until this worker has left.
        let job = unsafe { (*s.job.get()).expect("a phase publishes its task") };
        if let Err(payload) = catch_unwind(AssertUnwindSafe(|| unsafe { (*job)(index) })) {
            let mut first = s.panic.lock().unwrap_or_else(PoisonError::into_inner);
            first.get_or_insert(payload);
        }
        s.phase.fetch_sub(1, Ordering::Release);
    }
}

/// Counts this worker inside the phase `word` names if it is still open.
fn join(s: &Shared, mut word: u64) -> bool {
    let number = Phase::number(word);
    while Phase::number(word) == number && word & Phase::OPEN != 0 {
        match s
            .phase
            .compare_exchange_weak(word, word + 1, Ordering::AcqRel, Ordering::Acquire)
        {
            Ok(_) => return true,
            Err(now) => word = now,
        }
    }
    false
}

/// Waits until the phase's number differs from `seen`: spinning for `SPIN`, then asleep.
/// Returns the phase word.
fn next_phase(s: &Shared, seen: u64) -> u64 {
    let started = Instant::now();
    let mut spins = 0u32;
    loop {
        let now = s.phase.load(Ordering::Acquire);
        if Phase::number(now) != seen {
            return now;
        }
        spins = spins.wrapping_add(1);
        if spins.is_multiple_of(64) && started.elapsed() > SPIN {
            break;
        }
        std::hint::spin_loop();
    }
    // `run` opens the phase and then reads `sleepers`; this thread counts itself in
    // `sleepers` and then reads the phase (all SeqCst): one of the two sees the other, and
    // the notify, taken under the lock, cannot fall between the check and the wait.
    let mut guard = s.lock.lock().unwrap_or_else(PoisonError::into_inner);
    s.sleepers.fetch_add(1, Ordering::SeqCst);
    let mut now = s.phase.load(Ordering::SeqCst);
    while Phase::number(now) == seen {
        guard = s.wake.wait(guard).unwrap_or_else(PoisonError::into_inner);
        now = s.phase.load(Ordering::SeqCst);
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
    /// `task(&mut items[s])` for each `s` of `chosen` (distinct, increasing), each thread
    /// starting on its own contiguous block of `chosen` (the same block every phase) and
    /// then taking, from the back, what is left of the others'; the results by index of
    /// `items`, `None` where not chosen. Which thread runs a task changes nothing in it.
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
        let claimed: Vec<AtomicBool> = (0..m).map(|_| AtomicBool::new(false)).collect();
        let block = |t: usize| t * m / threads..(t + 1) * m / threads;
        let take = |k: usize| {
            if !claimed[k].swap(true, Ordering::AcqRel) {
                let s = chosen[k];
                // SAFETY: `claimed[k]` goes to one thread only, and the indices of
                // `chosen` are distinct and in bounds (asserted above).
                unsafe { *outputs.at(s) = Some(task(&mut *inputs.at(s))) };
            }
        };
        self.run(&|t: usize| {
            if t >= threads {
                return;
            }
            // Its own block from the front, then what is left of the others' from their
            // backs: a thread that finishes early takes over the items a slower one has
            // not reached, and in a balanced phase each keeps its own (and its cache).
            block(t).for_each(take);
            for other in (t + 1..threads).chain(0..t) {
                block(other).rev().for_each(take);
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

    fn on_a_worker() -> bool {
        std::thread::current()
            .name()
            .is_some_and(|n| n.starts_with("cgdem-worker"))
    }

    /// Waits (up to 10 s) until `flag` is set: the caller holds its first item until a
    /// worker has taken one, so that the worker surely works in the phase.
    fn wait_for(flag: &AtomicBool) {
        let started = Instant::now();
        while !flag.load(Ordering::Acquire) && started.elapsed() < Duration::from_secs(10) {
            std::thread::yield_now();
        }
    }

    #[test]
    fn a_panic_on_a_worker_reaches_the_caller_and_the_team_goes_on() {
        let team = Team::new(2);
        let mut items = vec![0u32; 2];
        let worker_started = AtomicBool::new(false);
        let caught = catch_unwind(AssertUnwindSafe(|| {
            team.each_of(&mut items, &[0, 1], |x| {
                if on_a_worker() {
                    worker_started.store(true, Ordering::Release);
                    panic!("planted");
                }
                wait_for(&worker_started);
                *x += 1;
            })
        }));
        assert!(
            worker_started.load(Ordering::Acquire),
            "the worker never joined"
        );
        assert!(caught.is_err());
        team.each_of(&mut items, &[0, 1], |x| *x += 10);
        assert_eq!(items[0], 11);
    }

    #[test]
    fn the_caller_takes_over_what_a_slow_worker_has_not_started() {
        let team = Team::new(2);
        let mut items: Vec<Option<bool>> = vec![None; 8];
        let chosen: Vec<usize> = (0..8).collect();
        // The worker's first item (item 4, the front of its block) takes 500 ms; the
        // caller's first waits until the worker is in it, the others are quick.
        let worker_started = AtomicBool::new(false);
        let started = Instant::now();
        team.each_of(&mut items, &chosen, |ran_on_worker| {
            let worker = on_a_worker();
            if worker {
                worker_started.store(true, Ordering::Release);
                std::thread::sleep(Duration::from_millis(500));
            } else {
                wait_for(&worker_started);
            }
            *ran_on_worker = Some(worker);
        });
        assert!(
            worker_started.load(Ordering::Acquire),
            "the worker never joined"
        );
        assert!(
            items.iter().all(Option::is_some),
            "every item ran: {items:?}"
        );
        let on_worker: Vec<usize> = (0..8).filter(|&k| items[k] == Some(true)).collect();
        assert_eq!(
            on_worker,
            vec![4],
            "the worker's block is items 4-7; the caller takes 5-7 while it sleeps in 4"
        );
        // The phase returned only once the worker had left its item.
        assert!(started.elapsed() >= Duration::from_millis(500));
    }

    #[test]
    fn every_item_runs_once_whether_or_not_a_sleeping_worker_joins() {
        let team = Team::new(2);
        for _ in 0..20 {
            let mut items = vec![0u32; 8];
            let chosen: Vec<usize> = (0..8).collect();
            team.each_of(&mut items, &chosen, |x| *x += 1);
            assert_eq!(items, vec![1; 8]);
            // The worker falls asleep between the phases.
            std::thread::sleep(SPIN * 5);
        }
    }
}
