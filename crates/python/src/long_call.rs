//! Long calls from Python: Ctrl-C, `progress=` and `threads=`. The work runs on a thread
//! of its own (inside a rayon pool of the caller's `threads`, `pool.install`, never a
//! global pool: docs/architecture.md), while the calling thread sleeps with the GIL
//! released and, every [`POLL`], takes it back for a moment to run Python's signal
//! handlers (`check_signals`: Ctrl-C raises `KeyboardInterrupt` there) and the `progress`
//! callback. The work counts its units on a shared [`Watch`] between chunks or tiles and
//! stops at the next check once told, so Ctrl-C ends any call within a chunk (milliseconds)
//! plus one poll. A library call with no chunks to check between (the ROM's generation,
//! `size`'s syntheses) runs on an owned thread instead ([`detached`]): Ctrl-C returns at
//! once and the abandoned thread finishes in the background, its result dropped.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use pyo3::exceptions::{PyRuntimeError, PyTypeError};
use pyo3::prelude::*;
use pyo3::types::PyBool;
use tofprobe_io::watch::Watch;

use crate::errors;

/// How often the calling thread checks for Ctrl-C and reports progress.
pub const POLL: Duration = Duration::from_millis(50);

/// The `progress` argument: a callable `progress(done, total)`, `True` for a tqdm bar
/// (`tofprobe._progress.Bar`), or nothing.
pub struct Progress<'py> {
    callback: Option<Bound<'py, PyAny>>,
    /// The units of the whole call.
    pub total: u64,
}

impl<'py> Progress<'py> {
    /// `progress` as given (`desc` and `unit` label a tqdm bar); a `TypeError` for anything
    /// but None, a bool or a callable.
    pub fn new(
        py: Python<'py>,
        progress: Option<&Bound<'py, PyAny>>,
        desc: &str,
        unit: &str,
        total: u64,
    ) -> PyResult<Self> {
        let callback = match progress {
            None => None,
            Some(p) if p.is_none() => None,
            Some(p) if p.is_instance_of::<PyBool>() => match p.extract::<bool>()? {
                true => Some(
                    py.import("tofprobe._progress")?
                        .getattr("Bar")?
                        .call1((desc, unit))?,
                ),
                false => None,
            },
            Some(p) if p.is_callable() => Some(p.clone()),
            Some(p) => {
                return Err(PyTypeError::new_err(format!(
                    "`progress` must be a callable progress(done, total), True (a tqdm bar) \
                     or None, got {}",
                    p.get_type().name()?
                )));
            }
        };
        Ok(Progress { callback, total })
    }

    /// No progress reported (calls run from another call).
    pub fn none(total: u64) -> Self {
        Progress {
            callback: None,
            total,
        }
    }

    fn report(&self, done: u64) -> PyResult<()> {
        match &self.callback {
            Some(cb) => cb.call1((done.min(self.total), self.total)).map(drop),
            None => Ok(()),
        }
    }

    fn close(&self) -> PyResult<()> {
        match &self.callback {
            Some(cb) if cb.hasattr("close")? => cb.call_method0("close").map(drop),
            _ => Ok(()),
        }
    }
}

/// A rayon pool of `threads` threads (1 ..= 1024), `None` for rayon's current pool.
pub fn pool(threads: Option<usize>) -> PyResult<Option<rayon::ThreadPool>> {
    let Some(t) = threads else {
        return Ok(None);
    };
    if !(1..=1024).contains(&t) {
        return Err(errors::input(format!(
            "`threads` = {t} is out of range: use 1 ..= 1024 (e.g. os.cpu_count()), or None \
             for all cores"
        )));
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(t)
        .build()
        .map(Some)
        .map_err(errors::input_error)
}

/// Runs `work` on a thread of its own (in `pool` when given), watching it: Ctrl-C (or an
/// exception from `progress`) stops it at its next [`Watch::advance`] and is raised here.
/// The outer result is Python's (interrupt, progress), the inner the work's own.
pub fn run<T: Send, E: Send>(
    py: Python<'_>,
    progress: &Progress<'_>,
    pool: Option<&rayon::ThreadPool>,
    work: impl FnOnce(&Watch) -> Result<T, E> + Send,
) -> PyResult<Result<T, E>> {
    let watch = Watch::default();
    let finished = AtomicBool::new(false);
    let caller = std::thread::current();
    let out = std::thread::scope(|s| {
        let (w, finished) = (&watch, &finished);
        let handle = s.spawn(move || {
            let r = match pool {
                Some(p) => p.install(|| work(w)),
                None => work(w),
            };
            // Flagged before the wake-up, so the caller never sleeps a poll for nothing.
            finished.store(true, Ordering::Release);
            caller.unpark();
            r
        });
        let mut raised: Option<PyErr> = None;
        while !finished.load(Ordering::Acquire) {
            py.detach(|| std::thread::park_timeout(POLL));
            if raised.is_some() || finished.load(Ordering::Acquire) {
                continue;
            }
            if let Err(e) = py.check_signals().and_then(|()| progress.report(w.done())) {
                w.stop();
                raised = Some(e);
            }
        }
        let result = handle
            .join()
            .map_err(|_| PyRuntimeError::new_err("tofprobe: the computation panicked"))?;
        match raised {
            Some(e) => Err(e),
            None => Ok(result),
        }
    });
    let closed = match &out {
        Ok(_) => progress
            .report(progress.total)
            .and_then(|()| progress.close()),
        Err(_) => progress.close(),
    };
    let out = out?;
    closed?;
    Ok(out)
}

/// Runs `work` (owning what it reads) on an owned thread, checking Ctrl-C every [`POLL`]:
/// on Ctrl-C the call returns `KeyboardInterrupt` at once and the thread is left to finish
/// in the background, its result dropped (for a library call with no chunks to stop
/// between).
pub fn detached<T: Send + 'static>(
    py: Python<'_>,
    work: impl FnOnce() -> T + Send + 'static,
) -> PyResult<T> {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::Builder::new()
        .name("tofprobe".into())
        .spawn(move || {
            let _ = tx.send(work());
        })
        .map_err(|e| PyRuntimeError::new_err(format!("tofprobe: cannot start a thread: {e}")))?;
    let mut rx = rx;
    loop {
        let (got, back) = py.detach(move || (rx.recv_timeout(POLL), rx));
        rx = back;
        match got {
            Ok(v) => return Ok(v),
            Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
                return Err(PyRuntimeError::new_err(
                    "tofprobe: the computation panicked",
                ));
            }
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => py.check_signals()?,
        }
    }
}
