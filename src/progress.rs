//! Progress of long work, reported to whoever shows it: the command line draws bars, a program
//! embedding the library may log or ignore it.

/// Receives progress reports; every method does nothing unless overridden.
pub trait Progress: Sync {
    /// A new stage starts (e.g. `segmentation`, `images`).
    fn stage(&self, _name: &str) {}
    /// The work ahead is `frames` frames in all: the animation's, or with an automatic choice
    /// every candidate's trial frames as well. Told before the first [`Progress::frames`], and
    /// again, larger, when a choice finds it must code a second candidate whole.
    fn total(&self, _frames: u64) {}
    /// `count` more frames are done.
    fn frames(&self, _count: u64) {}
}

/// Reports nothing.
#[derive(Debug, Clone, Copy, Default)]
pub struct Silent;

impl Progress for Silent {}
