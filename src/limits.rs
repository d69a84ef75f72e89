//! The positions limit: how many vertex positions (vertices × frames) a reader agrees to produce.
//!
//! The decoder refuses a stream whose header promises more, and glTF baking a clip that would bake
//! to more, before either allocates anything per vertex or frame: a small file can describe a huge
//! animation (a 15 KB stream can claim millions of frames, a small glTF a long clip at a high rate),
//! and the reader would otherwise find out only when memory runs out.

use crate::error::{Error, Result};

/// Default of [`DecodeOptions::max_positions`](crate::DecodeOptions::max_positions) and
/// [`ReadOptions::max_positions`](crate::ReadOptions::max_positions): 10⁹ positions are 12 GB as
/// f32 points, about what a machine of a few tens of GB holds as one decoded or baked clip; ten
/// times the 50 000-vertex × 2 000-frame clip of the long-clip benchmark, and 84 times the largest
/// real animation tried (28 374 vertices × 418 frames). Larger clips are read by raising the limit.
pub const DEFAULT_MAX_POSITIONS: u64 = 1_000_000_000;

/// Refuses a stream whose header promises more than `limit` positions.
pub fn check_stream(vertices: u32, frames: u32, limit: u64) -> Result<()> {
    let positions = u64::from(vertices) * u64::from(frames);
    if positions <= limit {
        return Ok(());
    }
    Err(Error::option(
        "max_positions",
        format!(
            "is {limit}, but the stream's header promises {vertices} vertices × {frames} frames = \
             {positions} positions ({} as f32 points); raise the limit to decode it",
            memory(positions as f64)
        ),
    ))
}

/// Memory of `positions` f32 points, in MB or GB to one decimal.
fn memory(positions: f64) -> String {
    let bytes = positions * 12.0;
    match bytes < 1e9 {
        true => format!("{:.1} MB", bytes / 1e6),
        false => format!("{:.1} GB", bytes / 1e9),
    }
}

/// What a clip bakes to, for [`check_bake`].
pub(crate) struct Bake<'a> {
    /// The file, named in the message.
    pub(crate) file: &'a str,
    /// Seconds from the clip's first key to its last.
    pub(crate) seconds: f64,
    /// Frames per second it is baked at.
    pub(crate) rate: f64,
    /// Frames it bakes to.
    pub(crate) frames: f64,
    /// Vertices of each frame.
    pub(crate) vertices: usize,
}

/// Refuses a glTF clip that bakes to more than `limit` positions, naming the frame rate and the
/// clip length that would fit. The error is about `fps`, the knob a reader turns first.
pub(crate) fn check_bake(bake: &Bake, limit: u64) -> Result<()> {
    let positions = bake.frames * bake.vertices as f64;
    if bake.frames.is_finite() && positions <= limit as f64 {
        return Ok(());
    }
    let Bake {
        file,
        seconds,
        rate,
        frames,
        vertices,
    } = *bake;
    let fit_frames = limit / (vertices.max(1) as u64);
    let fits = if fit_frames == 0 {
        format!(
            "not one frame of {vertices} vertices fits: raise the positions limit (max_positions)"
        )
    } else {
        // `frames` = ⌊seconds × rate⌋ + 1: rates and lengths giving at most `fit_frames`.
        let span = (fit_frames - 1) as f64;
        let fit_rate = (span / seconds * 100.0).floor() / 100.0;
        let fit_seconds = (span / rate * 1000.0).floor() / 1000.0;
        format!(
            "at most {fit_frames} frames fit: a rate of {fit_rate} frames/s or lower, a clip of at \
             most {fit_seconds} s at {rate} frames/s, or a higher positions limit (max_positions)"
        )
    };
    Err(Error::option(
        "fps",
        format!(
            "{rate} bakes the {seconds:.3} s clip of {file} to {frames} frames of {vertices} \
             vertices, {positions} positions ({} as f32 points), past the limit of {limit}; {fits}",
            memory(positions)
        ),
    ))
}
