//! Progress bars on stderr that honour `--quiet` (and stay silent when stderr is not a terminal).

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// A bar of `len` steps labelled `what`, hidden when `quiet`.
pub fn bar(len: u64, what: &str, quiet: bool) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let pb = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
    if let Ok(style) = ProgressStyle::with_template(
        "{prefix:>8} [{bar:30}] {pos}/{len} frames {msg} ({elapsed}, eta {eta})",
    ) {
        pb.set_style(style.progress_chars("=> "));
    }
    pb.set_prefix(what.to_string());
    pb
}

/// A spinner for work of unknown length, hidden when `quiet`.
pub fn spinner(what: &str, quiet: bool) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let pb = ProgressBar::new_spinner();
    pb.set_message(what.to_string());
    pb.enable_steady_tick(std::time::Duration::from_millis(120));
    pb
}

/// The library's progress reports drawn on a bar: stages as its message, frames as its position.
pub struct Reporter<'a>(pub &'a ProgressBar);

impl mcgv_video::Progress for Reporter<'_> {
    fn stage(&self, name: &str) {
        self.0.set_message(name.to_string());
    }

    fn total(&self, frames: u64) {
        self.0.set_length(frames);
    }

    fn frames(&self, count: u64) {
        self.0.inc(count);
    }
}
