//! A fixed team of threads for the force pass, which forks and joins twice per time step.
//!
//! A step takes about a millisecond, and a general-purpose pool's sleeping worker takes tens of microseconds to wake
//! (more in a virtual machine), which measurably limited the two-thread speed-up. Here the helpers spin for a short
//! while after each job, so a job that follows within that time starts at once; past it they park on a condition
//! variable and cost nothing. The neighbour lists' work and the drift of a step that is not fused into the force pass
//! run on the same team. [`Team::rest`] parks the helpers at once (a simulation does so when `run_steps` returns), so
//! that spinning helpers do not compete for cores with whatever the caller does next.
//!
//! Thread r of a job always gets index r (the caller is index 0), so a job can hand each index its own part of the
//! data; which thread runs which part never affects results.

use std::cell::UnsafeCell;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// How long a helper spins for the next job before parking.
const SPIN: Duration = Duration::from_micros(300);

type Job = dyn Fn(usize) + Sync;

struct Shared {
    /// Bumped (SeqCst) to publish a job or a rest/stop request.
    generation: AtomicU64,
    /// The current job, lifetime-erased; valid while `remaining` > 0 (see [`Team::run`]).
    job: UnsafeCell<Option<*const Job>>,
    /// Helpers that have not finished the current job.
    remaining: AtomicUsize,
    /// Helpers park immediately instead of spinning (set by `rest`, cleared by `run`).
    resting: AtomicBool,
    stop: AtomicBool,
    /// A helper's job panicked.
    panicked: AtomicBool,
    sleeping: AtomicUsize,
    lock: Mutex<()>,
    wake: Condvar,
}

// SAFETY: `job` is written only by the owner while no helper reads it (all helpers have finished the previous job
// and none starts until `generation` is bumped after the write); helpers only read it.
unsafe impl Sync for Shared {}
unsafe impl Send for Shared {}

pub struct Team {
    shared: Arc<Shared>,
    helpers: Vec<JoinHandle<()>>,
}

impl std::fmt::Debug for Team {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Team({} threads)", self.size())
    }
}

impl Team {
    /// A team of `threads` (≥ 1): the calling thread plus `threads − 1` helpers.
    pub fn new(threads: usize) -> Team {
        let shared = Arc::new(Shared {
            generation: AtomicU64::new(0),
            job: UnsafeCell::new(None),
            remaining: AtomicUsize::new(0),
            resting: AtomicBool::new(true),
            stop: AtomicBool::new(false),
            panicked: AtomicBool::new(false),
            sleeping: AtomicUsize::new(0),
            lock: Mutex::new(()),
            wake: Condvar::new(),
        });
        let helpers = (1..threads.max(1))
            .map(|index| {
                let shared = Arc::clone(&shared);
                std::thread::Builder::new()
                    .name(format!("granflow-team-{index}"))
                    .spawn(move || helper(&shared, index))
                    .expect("spawning a helper thread")
            })
            .collect();
        Team { shared, helpers }
    }

    pub fn size(&self) -> usize {
        self.helpers.len() + 1
    }

    /// Runs `job(r)` for every r in 0..size, r = 0 on the calling thread, and returns when all have finished.
    /// A panic in any of them is resumed here after all have finished.
    pub fn run(&self, job: &(dyn Fn(usize) + Sync)) {
        let s = &*self.shared;
        if self.helpers.is_empty() {
            job(0);
            return;
        }
        // SAFETY: no helper is running a job (the previous `run` waited for all), so none reads `job` now. The
        // pointer's lifetime is erased; it is dereferenced only until `remaining` reaches 0, which this function
        // waits for before returning, also when `job(0)` panics (the guard below).
        unsafe {
            let erased: *const Job = std::mem::transmute::<*const (dyn Fn(usize) + Sync + '_), *const Job>(job);
            *s.job.get() = Some(erased);
        }
        s.remaining.store(self.helpers.len(), Ordering::SeqCst);
        s.resting.store(false, Ordering::SeqCst);
        s.generation.fetch_add(1, Ordering::SeqCst);
        if s.sleeping.load(Ordering::SeqCst) > 0 {
            let _guard = s.lock.lock().unwrap_or_else(|e| e.into_inner());
            s.wake.notify_all();
        }
        struct WaitForHelpers<'a>(&'a Shared);
        impl Drop for WaitForHelpers<'_> {
            fn drop(&mut self) {
                let mut spins = 0u32;
                while self.0.remaining.load(Ordering::Acquire) > 0 {
                    pause(&mut spins);
                }
            }
        }
        {
            let _wait = WaitForHelpers(s);
            job(0);
        }
        if s.panicked.swap(false, Ordering::SeqCst) {
            panic!("a granflow team thread panicked (its message is printed above)");
        }
    }

    /// Applies `f(k, part)` to every part and returns the results in part order.
    ///
    /// The parts are dealt out as one contiguous block per thread, which the thread works through from the front;
    /// a thread that has finished its block takes the others' remaining parts from their backs. Each thread thus
    /// mostly gets the same parts job after job (their data stays in its caches), and a thread that the machine
    /// delays is relieved of the parts it has not started. Which thread runs a part never affects its result.
    pub fn map_parts<P: Send, R: Send>(&self, parts: Vec<P>, f: impl Fn(usize, P) -> R + Sync) -> Vec<R> {
        let count = parts.len();
        let inputs: Vec<Mutex<Option<P>>> = parts.into_iter().map(|p| Mutex::new(Some(p))).collect();
        let outputs: Vec<Mutex<Option<R>>> = (0..count).map(|_| Mutex::new(None)).collect();
        let size = self.size();
        let blocks: Vec<Block> = (0..size)
            .map(|b| Block::new(b * count / size, (b + 1) * count / size))
            .collect();
        let work = |k: usize| {
            let part = inputs[k].lock().unwrap_or_else(|e| e.into_inner()).take();
            let result = f(k, part.expect("each part is taken once"));
            *outputs[k].lock().unwrap_or_else(|e| e.into_inner()) = Some(result);
        };
        self.run(&|r| {
            while let Some(k) = blocks[r].take_front() {
                work(k);
            }
            for other in (1..size).map(|d| (r + d) % size) {
                while let Some(k) = blocks[other].take_back() {
                    work(k);
                }
            }
        });
        outputs
            .into_iter()
            .map(|o| {
                o.into_inner()
                    .unwrap_or_else(|e| e.into_inner())
                    .expect("every part was run")
            })
            .collect()
    }

    /// `f` over the consecutive ranges of `chunk_len` indices (the last may be shorter) that cover `0..n`, with the
    /// results in range order: as parts of [`Team::map_parts`] when the team has several threads and there is more
    /// than one range, else on the calling thread. Results are the same either way.
    pub fn map_chunks<T: Send>(
        &self,
        n: usize,
        chunk_len: usize,
        f: impl Fn(std::ops::Range<usize>) -> T + Sync,
    ) -> Vec<T> {
        let chunk_len = chunk_len.max(1);
        let ranges = (0..n.div_ceil(chunk_len)).map(|k| k * chunk_len..((k + 1) * chunk_len).min(n));
        if self.size() > 1 && n > chunk_len {
            self.map_parts(ranges.collect(), |_, range| f(range))
        } else {
            ranges.map(f).collect()
        }
    }

    /// Parks the helpers until the next [`Team::run`].
    pub fn rest(&self) {
        self.shared.resting.store(true, Ordering::SeqCst);
    }
}

impl Drop for Team {
    fn drop(&mut self) {
        let s = &*self.shared;
        s.stop.store(true, Ordering::SeqCst);
        s.generation.fetch_add(1, Ordering::SeqCst);
        {
            let _guard = s.lock.lock().unwrap_or_else(|e| e.into_inner());
            s.wake.notify_all();
        }
        for h in self.helpers.drain(..) {
            let _ = h.join();
        }
    }
}

/// The parts `front..back` of one thread's block in [`Team::map_parts`], packed in one word so that the owner
/// (taking from the front) and a thief (taking from the back) never both get the last part.
struct Block(AtomicU64);

impl Block {
    fn new(front: usize, back: usize) -> Block {
        Block(AtomicU64::new(((front as u64) << 32) | back as u64))
    }

    fn take(&self, from_front: bool) -> Option<usize> {
        let mut current = self.0.load(Ordering::Acquire);
        loop {
            let (front, back) = (current >> 32, current & 0xffff_ffff);
            if front >= back {
                return None;
            }
            let (next, taken) = if from_front {
                (((front + 1) << 32) | back, front)
            } else {
                ((front << 32) | (back - 1), back - 1)
            };
            match self
                .0
                .compare_exchange_weak(current, next, Ordering::AcqRel, Ordering::Acquire)
            {
                Ok(_) => return Some(taken as usize),
                Err(actual) => current = actual,
            }
        }
    }

    fn take_front(&self) -> Option<usize> {
        self.take(true)
    }

    fn take_back(&self) -> Option<usize> {
        self.take(false)
    }
}

/// One round of a spin wait: a CPU hint at first, then also a yield, so that a waiting thread does not hold a core
/// that the thread it waits for needs (more threads than cores).
#[inline]
fn pause(spins: &mut u32) {
    *spins = spins.wrapping_add(1);
    if *spins < 2048 {
        std::hint::spin_loop();
    } else {
        std::thread::yield_now();
    }
}

fn helper(s: &Shared, index: usize) {
    let mut seen = 0u64;
    loop {
        // Wait for a new generation: spin for a while unless resting, then park.
        let spin_until = Instant::now() + SPIN;
        let mut spins = 0u32;
        while s.generation.load(Ordering::SeqCst) == seen && !s.resting.load(Ordering::Relaxed) {
            pause(&mut spins);
            if spins.is_multiple_of(1024) && Instant::now() > spin_until {
                break;
            }
        }
        if s.generation.load(Ordering::SeqCst) == seen {
            let mut guard = s.lock.lock().unwrap_or_else(|e| e.into_inner());
            s.sleeping.fetch_add(1, Ordering::SeqCst);
            while s.generation.load(Ordering::SeqCst) == seen {
                guard = s.wake.wait(guard).unwrap_or_else(|e| e.into_inner());
            }
            s.sleeping.fetch_sub(1, Ordering::SeqCst);
        }
        seen = s.generation.load(Ordering::SeqCst);
        if s.stop.load(Ordering::SeqCst) {
            return;
        }
        if s.remaining.load(Ordering::Acquire) == 0 {
            // A rest request or a spurious generation with no job for us.
            continue;
        }
        // SAFETY: the owner wrote `job` before bumping the generation we just saw and keeps it alive until
        // `remaining` reaches 0, which happens only after our decrement below.
        let job = unsafe { (*s.job.get()).expect("a job is published with its generation") };
        let result = catch_unwind(AssertUnwindSafe(|| unsafe { (*job)(index) }));
        if result.is_err() {
            s.panicked.store(true, Ordering::SeqCst);
        }
        s.remaining.fetch_sub(1, Ordering::Release);
    }
}

/// `f` over `0..n`, collected in order: on `team`'s threads in parts of `part_len` indices when the team has
/// several threads, else on the calling thread. A simulation passes the force pass's team, whose helpers are still
/// spinning from the last force pass, so the hand-over costs no thread wake-up. Results are the same either way.
pub fn map_indices<T: Send>(team: &Team, n: usize, part_len: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    if team.size() == 1 || n <= part_len {
        return (0..n).map(f).collect();
    }
    let results = team.map_chunks(n, part_len, |part| part.map(&f).collect::<Vec<T>>());
    let mut out = Vec::with_capacity(n);
    results.into_iter().for_each(|mut part| out.append(&mut part));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_index_runs_once_per_job_and_the_team_parks_and_wakes() {
        let team = Team::new(3);
        for round in 0..200u64 {
            let hits: Vec<AtomicU64> = (0..3).map(|_| AtomicU64::new(0)).collect();
            team.run(&|r| {
                hits[r].fetch_add(round + 1, Ordering::Relaxed);
            });
            for h in &hits {
                assert_eq!(h.load(Ordering::Relaxed), round + 1);
            }
            if round % 50 == 0 {
                team.rest();
                std::thread::sleep(Duration::from_millis(2));
            }
        }
    }

    #[test]
    fn map_parts_keeps_part_order_for_any_count() {
        let team = Team::new(2);
        for count in [0usize, 1, 2, 5, 16, 33] {
            let out = team.map_parts((0..count).map(|k| k * 10).collect(), |k, p| (k, p + 1));
            assert_eq!(out, (0..count).map(|k| (k, k * 10 + 1)).collect::<Vec<_>>());
        }
    }

    #[test]
    fn map_chunks_covers_every_index_once_in_order() {
        for threads in [1, 2] {
            let team = Team::new(threads);
            for (n, len) in [(0usize, 4usize), (3, 4), (4, 4), (9, 4), (100, 7)] {
                let out = team.map_chunks(n, len, |range| range);
                let flat: Vec<usize> = out.iter().flat_map(|r| r.clone()).collect();
                assert_eq!(flat, (0..n).collect::<Vec<_>>());
                assert!(out.iter().all(|r| r.len() <= len && !r.is_empty()));
            }
        }
    }

    #[test]
    fn map_parts_runs_every_part_once_when_one_thread_is_slow() {
        let team = Team::new(2);
        for round in 0..50 {
            let runs: Vec<AtomicU64> = (0..12).map(|_| AtomicU64::new(0)).collect();
            let out = team.map_parts((0..12).collect(), |k, p: usize| {
                if k == round % 12 {
                    std::thread::sleep(Duration::from_micros(300));
                }
                runs[k].fetch_add(1, Ordering::Relaxed);
                p * 2
            });
            assert_eq!(out, (0..12).map(|p| p * 2).collect::<Vec<_>>());
            assert!(runs.iter().all(|r| r.load(Ordering::Relaxed) == 1));
        }
    }

    #[test]
    fn a_helper_panic_reaches_the_caller() {
        let team = Team::new(2);
        let result = catch_unwind(AssertUnwindSafe(|| team.run(&|r| assert_ne!(r, 1, "helper fails"))));
        assert!(result.is_err());
        // The team still works afterwards.
        let sum = AtomicU64::new(0);
        team.run(&|r| {
            sum.fetch_add(r as u64 + 1, Ordering::Relaxed);
        });
        assert_eq!(sum.load(Ordering::Relaxed), 3);
    }
}
