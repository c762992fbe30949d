//! A long computation watched from outside: it counts the work it has done and stops at
//! its next check once told to. A host that cannot interrupt a thread (a Python call the
//! user presses Ctrl-C in, a progress bar) shares one [`Watch`] with the computation,
//! which calls [`Watch::advance`] between chunks or tiles; the host reads
//! [`Watch::done`] and calls [`Watch::stop`]. Relaxed atomics: the count is a progress
//! figure, and a stop is seen at the next check.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// The shared state of one watched computation.
#[derive(Debug, Default)]
pub struct Watch {
    done: AtomicU64,
    stopped: AtomicBool,
}

impl Watch {
    /// Counts `units` of work done; `false` when the computation must stop now.
    pub fn advance(&self, units: u64) -> bool {
        self.done.fetch_add(units, Ordering::Relaxed);
        !self.stopped.load(Ordering::Relaxed)
    }

    /// Whether a stop was asked.
    pub fn stopped(&self) -> bool {
        self.stopped.load(Ordering::Relaxed)
    }

    /// Asks the computation to stop at its next [`Watch::advance`].
    pub fn stop(&self) {
        self.stopped.store(true, Ordering::Relaxed);
    }

    /// The units of work counted so far.
    pub fn done(&self) -> u64 {
        self.done.load(Ordering::Relaxed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_watch_counts_and_stops() {
        let w = Watch::default();
        assert!(w.advance(3) && w.advance(4));
        assert_eq!(w.done(), 7);
        w.stop();
        assert!(w.stopped() && !w.advance(1));
        assert_eq!(w.done(), 8);
    }
}
