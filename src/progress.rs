//! Progress of long work, reported to whoever shows it: the command line draws bars, a program
//! embedding the library may log or ignore it.

/// Receives progress reports; every method does nothing unless overridden.
pub trait Progress: Sync {
    /// A new stage starts (e.g. `segmentation`, `images`).
    fn stage(&self, _name: &str) {}
    /// `count` more frames are done.
    fn frames(&self, _count: u64) {}
}

/// Reports nothing.
#[derive(Debug, Clone, Copy, Default)]
pub struct Silent;

impl Progress for Silent {}
