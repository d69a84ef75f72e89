//! Progress of long work, reported to whoever shows it: the command line draws bars, a program
//! embedding the library may log or ignore it.

use std::sync::atomic::{AtomicU64, Ordering};

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

/// Passes a piece of work's progress on as `budget` frames of a larger whole, whatever total the
/// piece tells of itself (that total is not passed on): a segmented encoding's analysis clip,
/// whose automatic choice tells its own trial frames, counts as its clip's frames of the whole
/// clip's bar. The frames passed on never go back nor past the budget; [`Budgeted::finish`]
/// passes on what is left once the piece is done.
pub(crate) struct Budgeted<'a> {
    inner: &'a dyn Progress,
    budget: u64,
    /// The piece's own total, as last told (0 until told).
    total: AtomicU64,
    /// The piece's frames done.
    done: AtomicU64,
    /// Frames passed on so far.
    told: AtomicU64,
}

impl<'a> Budgeted<'a> {
    /// A piece worth `budget` frames of `inner`'s whole.
    pub(crate) fn new(inner: &'a dyn Progress, budget: u64) -> Self {
        Self {
            inner,
            budget,
            total: AtomicU64::new(0),
            done: AtomicU64::new(0),
            told: AtomicU64::new(0),
        }
    }

    /// Raises the frames passed on to `target` (at most the budget).
    fn pass_on(&self, target: u64) {
        let target = target.min(self.budget);
        let before = self.told.fetch_max(target, Ordering::Relaxed);
        if target > before {
            self.inner.frames(target - before);
        }
    }

    /// Passes on the rest of the budget: the piece is done.
    pub(crate) fn finish(&self) {
        self.pass_on(self.budget);
    }
}

impl Progress for Budgeted<'_> {
    fn stage(&self, name: &str) {
        self.inner.stage(name);
    }

    fn total(&self, frames: u64) {
        self.total.store(frames, Ordering::Relaxed);
    }

    fn frames(&self, count: u64) {
        let done = self.done.fetch_add(count, Ordering::Relaxed) + count;
        // A piece that has not told its total, or has done more than it told, is nearly done.
        let total = self.total.load(Ordering::Relaxed).max(done).max(1);
        let share = u128::from(done) * u128::from(self.budget) / u128::from(total);
        self.pass_on(u64::try_from(share).unwrap_or(u64::MAX));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Default)]
    struct Count(AtomicU64, AtomicU64);

    impl Progress for Count {
        fn total(&self, frames: u64) {
            self.0.store(frames, Ordering::Relaxed);
        }
        fn frames(&self, count: u64) {
            self.1.fetch_add(count, Ordering::Relaxed);
        }
    }

    #[test]
    fn a_budgeted_piece_counts_its_budget_whatever_its_own_total() {
        let outer = Count::default();
        let piece = Budgeted::new(&outer, 10);
        piece.total(40);
        piece.frames(20);
        assert_eq!(
            outer.1.load(Ordering::Relaxed),
            5,
            "half the piece, half the budget"
        );
        assert_eq!(outer.0.load(Ordering::Relaxed), 0, "its total is its own");
        piece.total(80); // the piece found more work: the bar does not go back
        piece.frames(10);
        assert_eq!(outer.1.load(Ordering::Relaxed), 5);
        piece.frames(500); // past its total: never past the budget
        assert_eq!(outer.1.load(Ordering::Relaxed), 10);
        piece.finish();
        assert_eq!(outer.1.load(Ordering::Relaxed), 10);
        let quiet = Budgeted::new(&outer, 3);
        quiet.finish(); // a piece that told nothing still counts its budget once done
        assert_eq!(outer.1.load(Ordering::Relaxed), 13);
    }
}
