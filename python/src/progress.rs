//! Progress as a Python callback `progress(done, total)`, in frames. The library reports from
//! its worker threads while the interpreter's lock is released; each report takes the lock for
//! the call only. A callback that raises is not called again, and its exception is raised once
//! the coding has finished.

use mcgv_video::Progress;
use pyo3::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

/// Reports to an optional Python callable.
pub struct Callback {
    callback: Option<Py<PyAny>>,
    total: AtomicU64,
    done: AtomicU64,
    error: Mutex<Option<PyErr>>,
}

impl Callback {
    /// Reports to `callback`, if any (any callable; anything else is a `TypeError`).
    pub fn new(callback: Option<Bound<'_, PyAny>>) -> PyResult<Self> {
        if let Some(c) = &callback {
            if !c.is_callable() {
                return Err(pyo3::exceptions::PyTypeError::new_err(
                    "progress: expected a callable progress(done, total), or None",
                ));
            }
        }
        Ok(Self {
            callback: callback.map(Bound::unbind),
            total: AtomicU64::new(0),
            done: AtomicU64::new(0),
            error: Mutex::new(None),
        })
    }

    /// `Ok(value)`, unless the callback raised: then its exception.
    pub fn finish<T>(self, value: T) -> PyResult<T> {
        match self.error.into_inner().ok().flatten() {
            Some(e) => Err(e),
            None => Ok(value),
        }
    }

    fn report(&self) {
        let Some(callback) = &self.callback else {
            return;
        };
        let Ok(mut error) = self.error.lock() else {
            return;
        };
        if error.is_some() {
            return;
        }
        Python::attach(|py| {
            // Read under the lock: reports from several threads never go backwards.
            let done = self.done.load(Ordering::SeqCst);
            let total = self.total.load(Ordering::SeqCst).max(done);
            if let Err(e) = callback.bind(py).call1((done, total)) {
                *error = Some(e);
            }
        });
    }
}

impl Progress for Callback {
    fn total(&self, frames: u64) {
        self.total.store(frames, Ordering::SeqCst);
        self.report();
    }

    fn frames(&self, count: u64) {
        self.done.fetch_add(count, Ordering::SeqCst);
        self.report();
    }
}
