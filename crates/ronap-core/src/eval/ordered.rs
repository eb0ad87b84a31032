//! Numbered jobs on worker threads, their results handed on in number order with flat memory.
//!
//! Workers claim job numbers in order, but no further than [`Window`] ahead of the next result
//! to hand on, so a slow job holds back at most a window's worth of finished results (the
//! [`ReorderBuffer`]) whatever the run's length. Results are handed on by the calling thread.

use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Condvar, Mutex};

/// Results that finished out of order, held until every earlier one has come.
#[derive(Debug)]
pub struct ReorderBuffer<T> {
    /// The number of the next result to hand on.
    next: usize,
    /// Slot `i` holds result `next + i`, once it has come.
    waiting: VecDeque<Option<T>>,
}

impl<T> ReorderBuffer<T> {
    /// A buffer whose first result is number `first`.
    pub fn new(first: usize) -> Self {
        Self {
            next: first,
            waiting: VecDeque::new(),
        }
    }

    /// Keeps result `index`. A number already handed on, or given twice, is a caller's bug and
    /// is ignored (the first result stays).
    pub fn insert(&mut self, index: usize, item: T) {
        let Some(slot) = index.checked_sub(self.next) else {
            return;
        };
        if self.waiting.len() <= slot {
            self.waiting.resize_with(slot + 1, || None);
        }
        if let Some(s @ None) = self.waiting.get_mut(slot) {
            *s = Some(item);
        }
    }

    /// The next result in order, if it has come.
    pub fn pop(&mut self) -> Option<T> {
        match self.waiting.front() {
            Some(Some(_)) => {
                self.next += 1;
                self.waiting.pop_front().flatten()
            }
            _ => None,
        }
    }

    /// The number of the next result to hand on.
    pub fn next(&self) -> usize {
        self.next
    }
}

/// How far ahead of the next result to hand on workers may claim jobs: the most results a
/// [`ReorderBuffer`] ever holds.
#[derive(Clone, Copy, Debug)]
pub struct Window(pub usize);

impl Window {
    /// Jobs each worker may run ahead: enough that a worker rarely waits for a slow job of
    /// another, few enough that the records held stay a few hundred kilobytes.
    pub const PER_THREAD: usize = 64;

    /// The window for `threads` workers.
    pub fn for_threads(threads: usize) -> Self {
        Self(Self::PER_THREAD * threads.max(1))
    }
}

/// How an ordered run ended.
#[derive(Debug)]
pub struct Ordered<E> {
    /// Results handed on (jobs `0..handed`).
    pub handed: usize,
    /// The first failed job in number order and its error; nothing from it on was handed on.
    pub failed: Option<(usize, E)>,
    /// The sink refused a result (and the run stopped there).
    pub refused: bool,
}

#[derive(Debug, Default)]
struct Claims {
    /// Jobs claimed so far (`0..claimed`).
    claimed: usize,
    /// Results handed on so far.
    handed: usize,
    /// No more claims: a job failed or the sink refused.
    stop: bool,
    /// Workers waiting for the window to move (so the sink wakes them only then).
    waiting: usize,
}

/// A job: its number and the worker's state in, its result out.
pub type Job<'a, S, T, E> = dyn Fn(&mut Option<S>, usize) -> Result<T, E> + Sync + 'a;

/// Runs jobs `0..count` on the workers of `pool`, handing each result to `sink` in number order
/// on the calling thread. `work(state, i)` runs job `i` with the worker's own `state` (made by
/// `work` itself when `None`, e.g. a policy). Stops claiming when `cancel` is set, when a job
/// fails, or when `sink` returns `false`; the jobs already claimed still finish, so what was
/// handed on is always a prefix `0..handed`.
pub fn run_in_order<S, T: Send, E: Send>(
    pool: &rayon::ThreadPool,
    count: usize,
    window: Window,
    cancel: &AtomicBool,
    work: &Job<'_, S, T, E>,
    sink: &mut dyn FnMut(T) -> bool,
) -> Ordered<E> {
    let window = window.0.max(1);
    let claims = Mutex::new(Claims::default());
    let moved = Condvar::new();
    let lock = || claims.lock().unwrap_or_else(|e| e.into_inner());
    // The next job for a worker, or `None` when it should stop.
    let claim = || {
        let mut c = lock();
        loop {
            if c.stop || c.claimed >= count || cancel.load(Ordering::Relaxed) {
                return None;
            }
            if c.claimed < c.handed + window {
                c.claimed += 1;
                return Some(c.claimed - 1);
            }
            c.waiting += 1;
            c = moved.wait(c).unwrap_or_else(|e| e.into_inner());
            c.waiting -= 1;
        }
    };
    let stop = || {
        lock().stop = true;
        moved.notify_all();
    };
    let (tx, rx) = mpsc::channel::<(usize, Result<T, E>)>();
    let mut buffer = ReorderBuffer::new(0);
    let mut ended = Ordered {
        handed: 0,
        failed: None,
        refused: false,
    };
    pool.in_place_scope(|scope| {
        for _ in 0..pool.current_num_threads() {
            let tx = tx.clone();
            let (claim, stop) = (&claim, &stop);
            scope.spawn(move |_| {
                let mut state = None;
                while let Some(i) = claim() {
                    let result = work(&mut state, i);
                    if result.is_err() {
                        stop();
                    }
                    // The receiver lives until every worker is done.
                    let _ = tx.send((i, result));
                }
            });
        }
        drop(tx);
        for (i, result) in &rx {
            buffer.insert(i, result);
            while let Some(result) = buffer.pop() {
                if ended.failed.is_some() || ended.refused {
                    continue;
                }
                match result {
                    Ok(item) => {
                        if sink(item) {
                            ended.handed += 1;
                            let mut c = lock();
                            c.handed = ended.handed;
                            if c.waiting > 0 {
                                moved.notify_all();
                            }
                        } else {
                            ended.refused = true;
                            stop();
                        }
                    }
                    Err(e) => ended.failed = Some((buffer.next() - 1, e)),
                }
            }
        }
    });
    ended
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Results `b` holds (come, but waiting for an earlier one).
    fn held<T>(b: &ReorderBuffer<T>) -> usize {
        b.waiting.iter().filter(|s| s.is_some()).count()
    }
    use std::sync::atomic::AtomicUsize;

    #[test]
    fn results_come_out_in_order_whatever_order_they_go_in() {
        let mut b = ReorderBuffer::new(5);
        b.insert(7, "c");
        b.insert(6, "b");
        assert_eq!(b.pop(), None);
        assert_eq!(held(&b), 2);
        b.insert(5, "a");
        assert_eq!(
            (b.pop(), b.pop(), b.pop(), b.pop()),
            (Some("a"), Some("b"), Some("c"), None)
        );
        assert_eq!(b.next(), 8);
        // Old or repeated numbers are ignored.
        b.insert(3, "old");
        b.insert(9, "x");
        b.insert(9, "y");
        b.insert(8, "w");
        assert_eq!((b.pop(), b.pop(), b.pop()), (Some("w"), Some("x"), None));
    }

    fn pool(threads: usize) -> rayon::ThreadPool {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool")
    }

    #[test]
    fn every_result_is_handed_on_once_in_order() {
        for threads in [1, 2, 4] {
            let mut got = Vec::new();
            let ended = run_in_order::<(), usize, ()>(
                &pool(threads),
                500,
                Window(3),
                &AtomicBool::new(false),
                &|_, i| {
                    // Uneven job lengths, so results finish out of order.
                    std::thread::sleep(std::time::Duration::from_micros((i % 7) as u64 * 50));
                    Ok(i * 10)
                },
                &mut |x| {
                    got.push(x);
                    true
                },
            );
            assert_eq!(got, (0..500).map(|i| i * 10).collect::<Vec<_>>());
            assert_eq!(ended.handed, 500);
            assert!(ended.failed.is_none() && !ended.refused);
        }
    }

    #[test]
    fn a_slow_job_holds_back_at_most_a_window() {
        // Job 0 waits until the others can go no further; workers must then stop at the window.
        let window = 8;
        let started = AtomicUsize::new(0);
        let most_ahead = AtomicUsize::new(0);
        let mut handed = Vec::new();
        let ended = run_in_order::<(), usize, ()>(
            &pool(3),
            100,
            Window(window),
            &AtomicBool::new(false),
            &|_, i| {
                started.fetch_add(1, Ordering::SeqCst);
                if i == 0 {
                    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(2);
                    while started.load(Ordering::SeqCst) < window
                        && std::time::Instant::now() < deadline
                    {
                        std::thread::sleep(std::time::Duration::from_millis(1));
                    }
                    std::thread::sleep(std::time::Duration::from_millis(50));
                    most_ahead.store(started.load(Ordering::SeqCst), Ordering::SeqCst);
                }
                Ok(i)
            },
            &mut |x| {
                handed.push(x);
                true
            },
        );
        assert_eq!(ended.handed, 100);
        assert_eq!(handed, (0..100).collect::<Vec<_>>());
        // While job 0 ran, no more than the window of jobs had been started.
        assert_eq!(most_ahead.load(Ordering::SeqCst), window);
    }

    #[test]
    fn a_failure_stops_the_run_at_the_first_failed_number() {
        let mut got = Vec::new();
        let ended = run_in_order::<(), usize, String>(
            &pool(2),
            1000,
            Window(16),
            &AtomicBool::new(false),
            &|_, i| {
                if i == 40 || i == 45 {
                    Err(format!("job {i}"))
                } else {
                    Ok(i)
                }
            },
            &mut |x| {
                got.push(x);
                true
            },
        );
        assert_eq!(got, (0..40).collect::<Vec<_>>());
        assert_eq!(ended.handed, 40);
        assert_eq!(ended.failed, Some((40, "job 40".to_string())));
    }

    #[test]
    fn a_refusing_sink_and_the_cancel_flag_stop_the_run_after_a_prefix() {
        let mut got = Vec::new();
        let ended = run_in_order::<(), usize, ()>(
            &pool(2),
            1000,
            Window(4),
            &AtomicBool::new(false),
            &|_, i| Ok(i),
            &mut |x| {
                got.push(x);
                x < 9
            },
        );
        assert!(ended.refused);
        assert_eq!(ended.handed, 9);
        assert_eq!(got, (0..10).collect::<Vec<_>>());

        let cancel = AtomicBool::new(false);
        let mut got = Vec::new();
        let ended = run_in_order::<usize, usize, ()>(
            &pool(2),
            100_000,
            Window(4),
            &cancel,
            &|state, i| {
                // Each worker's state is made once and kept.
                *state.get_or_insert(0) += 1;
                if i == 30 {
                    cancel.store(true, Ordering::Relaxed);
                }
                Ok(i)
            },
            &mut |x| {
                got.push(x);
                true
            },
        );
        assert!(ended.failed.is_none() && !ended.refused);
        assert!(ended.handed > 30 && ended.handed < 100_000);
        assert_eq!(got, (0..ended.handed).collect::<Vec<_>>());
    }
}
