//! Cooperative cancellation of long computations.
//!
//! Long loops (integration, theta batches, frequency maps) call
//! [`Cancel::check`] between chunks of work. A [`Cancel`] made by
//! [`Cancel::with_poll`] asks its poll function (the Python binding passes one
//! that runs the interpreter's signal handlers, so that Ctrl-C is seen) at most
//! every [`POLL_INTERVAL`], and only from the thread that made it: Python runs
//! signal handlers in its main thread only. Worker threads see the shared flag.
//! The core never depends on Python: [`Cancel::never`] is the plain-Rust default.
//!
//! A computation split over rayon's pool runs through [`poll_during`], so that
//! the calling thread (which made the token) keeps polling while the pool works.
//!
//! A token also counts the work done ([`Cancel::advance`]; the integrators add
//! one per sample written), and a poll made by [`Cancel::with_progress_poll`]
//! sees that count: the Python binding reports it to a progress callback from
//! the same poll, so watching a run neither splits it nor changes its result.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::thread::ThreadId;
use std::time::{Duration, Instant};

use crate::error::{Error, Result};

/// How often the poll function runs at most. Ctrl-C must stop a call within
/// 0.5 s; 20 ms leaves the rest of that for the chunk of work between checks.
pub const POLL_INTERVAL: Duration = Duration::from_millis(20);

/// Steps (or step attempts) of an integrator between two [`Cancel::check`]s:
/// 64 steps are 0.02–0.2 ms of work (one trajectory, or a lane group of the
/// batch kernels), far below the 0.5 s promised for Ctrl-C, and the check
/// (~50 ns) is then free.
pub const CHECK_EVERY: u32 = 64;

/// How long the calling thread of [`poll_during`] sleeps between two polls
/// while the work runs. It wakes as soon as the work is done, so this adds no
/// latency; 5 ms keeps the poll (itself run at most every [`POLL_INTERVAL`])
/// on time.
pub const POLL_WAIT: Duration = Duration::from_millis(5);

type Poll = Box<dyn Fn(u64) -> bool + Send + Sync>;

/// A cancellation token shared by the threads of one computation.
pub struct Cancel {
    flag: AtomicBool,
    poll: Option<Poll>,
    owner: Option<ThreadId>,
    start: Instant,
    next_poll_ns: AtomicU64,
    done: AtomicU64,
}

impl std::fmt::Debug for Cancel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Cancel")
            .field("cancelled", &self.is_cancelled())
            .field("polls", &self.poll.is_some())
            .finish()
    }
}

impl Default for Cancel {
    fn default() -> Self {
        Self::never()
    }
}

impl Cancel {
    /// A token that is cancelled only by [`Cancel::cancel`].
    pub fn never() -> Self {
        Cancel {
            flag: AtomicBool::new(false),
            poll: None,
            owner: None,
            start: Instant::now(),
            next_poll_ns: AtomicU64::new(0),
            done: AtomicU64::new(0),
        }
    }

    /// A token that also asks `poll` (true = stop) from the calling thread.
    pub fn with_poll(poll: impl Fn() -> bool + Send + Sync + 'static) -> Self {
        Self::with_progress_poll(move |_| poll())
    }

    /// [`Cancel::with_poll`] whose `poll` also receives the work done so far
    /// (the sum of [`Cancel::advance`]).
    pub fn with_progress_poll(poll: impl Fn(u64) -> bool + Send + Sync + 'static) -> Self {
        Cancel {
            poll: Some(Box::new(poll)),
            owner: Some(std::thread::current().id()),
            ..Self::never()
        }
    }

    /// Counts `units` of work as done (any thread; the integrators count samples).
    pub fn advance(&self, units: u64) {
        self.done.fetch_add(units, Ordering::Relaxed);
    }

    /// The work counted by [`Cancel::advance`] so far.
    pub fn done(&self) -> u64 {
        self.done.load(Ordering::Relaxed)
    }

    /// Request cancellation; every later [`Cancel::check`] fails.
    pub fn cancel(&self) {
        self.flag.store(true, Ordering::Relaxed);
    }

    /// Whether cancellation was requested (without polling).
    pub fn is_cancelled(&self) -> bool {
        self.flag.load(Ordering::Relaxed)
    }

    /// `Err(Error::Interrupted)` once cancelled; polls when due on the owner thread.
    pub fn check(&self) -> Result<()> {
        if self.is_cancelled() {
            return Err(Error::Interrupted);
        }
        if let (Some(poll), Some(owner)) = (&self.poll, self.owner) {
            if std::thread::current().id() == owner {
                let now = self.start.elapsed().as_nanos() as u64;
                if now >= self.next_poll_ns.load(Ordering::Relaxed) {
                    self.next_poll_ns
                        .store(now + POLL_INTERVAL.as_nanos() as u64, Ordering::Relaxed);
                    if poll(self.done()) {
                        self.cancel();
                        return Err(Error::Interrupted);
                    }
                }
            }
        }
        Ok(())
    }
}

/// Runs `work` (which splits itself over rayon's pool) while the calling
/// thread polls `cancel` every [`POLL_WAIT`]: the caller is not a pool
/// thread, so without this it would only wait, and a poll that must run on
/// the thread that made the token (Python's signal handlers) would never run.
/// On cancellation the shared flag stops the workers at their next check;
/// the call returns once `work` has returned (no thread outlives it).
pub fn poll_during<T: Send>(cancel: &Cancel, work: impl FnOnce() -> Result<T> + Send) -> Result<T> {
    use std::sync::mpsc::{sync_channel, RecvTimeoutError};
    let (done, finished) = sync_channel::<()>(1);
    let mut out = None;
    rayon::in_place_scope(|s| {
        let slot = &mut out;
        s.spawn(move |_| {
            *slot = Some(work());
            // The receiver lives until the scope ends; a failed send cannot happen.
            let _ = done.send(());
        });
        // recv_timeout wakes as soon as the work is done: no added latency.
        while let Err(RecvTimeoutError::Timeout) = finished.recv_timeout(POLL_WAIT) {
            if cancel.check().is_err() {
                break;
            }
        }
    });
    // The scope returns after the spawned work (re-raising its panic, if any),
    // so the slot is filled; `Interrupted` only to avoid an unwrap.
    out.unwrap_or(Err(Error::Interrupted))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::AtomicUsize;
    use std::sync::Arc;

    #[test]
    fn never_is_never_cancelled_until_asked() {
        let c = Cancel::never();
        assert!(c.check().is_ok());
        c.cancel();
        assert_eq!(c.check(), Err(Error::Interrupted));
    }

    #[test]
    fn the_poll_sees_the_work_done() {
        let seen = Arc::new(AtomicU64::new(u64::MAX));
        let k = seen.clone();
        let c = Cancel::with_progress_poll(move |done| {
            k.store(done, Ordering::Relaxed);
            false
        });
        c.advance(3);
        std::thread::scope(|s| {
            s.spawn(|| c.advance(4)); // counted from any thread
        });
        assert!(c.check().is_ok());
        assert_eq!((c.done(), seen.load(Ordering::Relaxed)), (7, 7));
    }

    #[test]
    fn poll_runs_on_the_owner_thread_at_most_every_interval() {
        let calls = Arc::new(AtomicUsize::new(0));
        let k = calls.clone();
        let c = Cancel::with_poll(move || k.fetch_add(1, Ordering::Relaxed) >= 1);
        assert!(c.check().is_ok()); // first poll: false
        assert!(c.check().is_ok()); // not due yet
        assert_eq!(calls.load(Ordering::Relaxed), 1);
        std::thread::scope(|s| {
            s.spawn(|| assert!(c.check().is_ok())); // other thread: no poll
        });
        assert_eq!(calls.load(Ordering::Relaxed), 1);
        std::thread::sleep(POLL_INTERVAL + Duration::from_millis(5));
        assert_eq!(c.check(), Err(Error::Interrupted)); // second poll: true
        std::thread::scope(|s| {
            s.spawn(|| assert_eq!(c.check(), Err(Error::Interrupted))); // the flag is shared
        });
    }

    #[test]
    fn poll_during_returns_the_work_and_polls_while_it_runs() {
        assert_eq!(poll_during(&Cancel::never(), || Ok(7)), Ok(7));
        // A poll that asks to stop on its first call: the work sees the flag.
        let c = Cancel::with_poll(|| true);
        let r = poll_during(&c, || {
            let t0 = Instant::now();
            while t0.elapsed() < Duration::from_secs(5) {
                c.check()?;
                std::thread::sleep(Duration::from_millis(1));
            }
            Ok(())
        });
        assert_eq!(r, Err(Error::Interrupted));
    }
}
