//! Long calls that stop on Ctrl-C: the work on a thread of its own, the caller's thread
//! looking for a signal meanwhile (`phase`'s blocks, `risk`'s chunks, `plan`'s searches,
//! `calibrate`'s simulator fit).

use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::Thread;
use std::time::Duration;

use pyo3::prelude::*;

/// Runs `work` on a thread of its own with the GIL released, and checks for Ctrl-C here at
/// least every 50 ms meanwhile. On a signal it raises the flag `work` is given (which `work`
/// polls to stop early) and, once `work` has ended, returns the signal's error
/// (`KeyboardInterrupt`). A panic in `work` resumes here, where PyO3 turns it into a Python
/// exception.
pub fn interruptibly<T: Send>(py: Python<'_>, work: impl FnOnce(&AtomicBool) -> T + Send) -> PyResult<T> {
    /// Wakes the waiting thread when the worker ends, returning or unwinding.
    struct Wake(Thread);
    impl Drop for Wake {
        fn drop(&mut self) {
            self.0.unpark();
        }
    }
    let stop = AtomicBool::new(false);
    let waiter = std::thread::current();
    std::thread::scope(|scope| {
        let flag = &stop;
        let worker = scope.spawn(move || {
            let _wake = Wake(waiter);
            work(flag)
        });
        let mut interrupted = None;
        while !worker.is_finished() {
            py.detach(|| std::thread::park_timeout(Duration::from_millis(50)));
            if interrupted.is_none() {
                if let Err(e) = py.check_signals() {
                    stop.store(true, Ordering::Relaxed);
                    interrupted = Some(e);
                }
            }
        }
        let r = worker.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        interrupted.map_or(Ok(r), Err)
    })
}
