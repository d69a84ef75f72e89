//! A clip coded as temporal segments ([`super::segments`]): which frames make its analysis clip,
//! and the driver that reads the clip's frames a segment at a time (the analysis clip's first,
//! kept for their segments when parsing them again would cost) and codes them, several segments
//! side by side on rayon's threads.

use super::segments::{CodedSegment, SegmentedEncoder};
use super::{EncodeOptions, Encoded, Reuse};
use crate::error::Result;
use crate::mesh::{AnimatedMesh, FrameSource, Point};
use crate::progress::Progress;
use rayon::prelude::*;
use std::ops::Range;

/// The frames of the analysis clip of a clip of `frames` frames cut into segments of `length`:
/// `length` frames spread evenly from the first to the last (all of a clip no longer than that).
pub fn analysis_frames(frames: usize, length: usize) -> Vec<usize> {
    let n = length.clamp(1, frames.max(1));
    if n == 1 {
        return vec![0];
    }
    (0..n).map(|i| i * (frames - 1) / (n - 1)).collect()
}

/// The segments of a clip of `frames` frames cut into runs of `length` (the last one shorter):
/// the ranges [`SegmentedEncoder::code_segment`] codes and [`SegmentedEncoder::add`] takes, in
/// order.
pub fn segment_ranges(frames: usize, length: usize) -> Vec<Range<usize>> {
    crate::stream::segments::split(frames, length)
}

/// The analysis clip of `source` cut into segments of `length` frames: its
/// [`analysis_frames`], with the first frame's connectivity, attributes and frame rate — what
/// [`SegmentedEncoder::start`] takes, as [`encode_source`] builds it (so that segments coded
/// elsewhere from it join into the stream `encode_source` writes).
pub fn analysis_clip(source: &mut FrameSource, length: usize) -> Result<AnimatedMesh> {
    let (frames, first) = (source.frame_count(), source.first().clone());
    spread_clip(&first, frames, length, |list| source.read_list(list))
}

/// The analysis clip of a clip of `frames` frames read by ranges with `read`, one frame at a
/// time; `first` gives the connectivity, attributes and frame rate.
fn spread_clip(
    first: &AnimatedMesh,
    frames: usize,
    length: usize,
    mut read: impl FnMut(&[usize]) -> Result<Vec<Vec<Point>>>,
) -> Result<AnimatedMesh> {
    let spread = read(&analysis_frames(frames, length))?;
    AnimatedMesh::new(first.triangles().to_vec(), spread)?
        .with_attributes(first.attributes().clone())
        .map(|mesh| mesh.with_frame_rate(first.frame_rate()))
}

/// Encodes `mesh` in segments of `length` frames, its analysis clip on what `reuse` holds (see
/// [`super::encode_reusing`]).
pub(crate) fn encode_reusing(
    mesh: &AnimatedMesh,
    opts: &EncodeOptions,
    length: usize,
    progress: &dyn Progress,
    reuse: Option<&Reuse>,
) -> Result<Encoded> {
    let frames = mesh.frame_count();
    let read = |list: &[usize], _| Ok(list.iter().map(|&f| mesh.frame(f).to_vec()).collect());
    encode_runs(mesh, frames, length, (opts, reuse), progress, read)
}

/// Encodes the animation `source` reads, in segments when it is longer than the options' segment
/// length: memory holds `parallel_segments` segments' frames and working data (one by default),
/// whatever the clip's length.
pub fn encode_source(
    source: &mut FrameSource,
    opts: &EncodeOptions,
    progress: &dyn Progress,
) -> Result<Encoded> {
    let frames = source.frame_count();
    let length = match opts.segment_frames {
        Some(n) if frames > n => n,
        _ => return super::encode_with_progress(&source.clip(0..frames)?, opts, progress),
    };
    let first = source.first().clone();
    encode_runs(&first, frames, length, (opts, None), progress, |list, again| {
        match again {
            ReadAgain::Yes => source.read_list_keeping(list),
            ReadAgain::No => source.read_list(list),
        }
    })
}

/// Whether frames being read will be read again (the analysis clip's, once more in their
/// segments): a source that parses its frames keeps them.
#[derive(Clone, Copy)]
enum ReadAgain {
    Yes,
    No,
}

/// Encodes a clip of `frames` frames in segments of `length`, reading its frames by ranges with
/// `read`: the analysis clip's frames, then `parallel_segments` segments at a time,
/// coded on rayon's threads. `first` gives the connectivity, attributes and frame rate.
fn encode_runs(
    first: &AnimatedMesh,
    frames: usize,
    length: usize,
    (opts, reuse): (&EncodeOptions, Option<&Reuse>),
    progress: &dyn Progress,
    mut read: impl FnMut(&[usize], ReadAgain) -> Result<Vec<Vec<Point>>>,
) -> Result<Encoded> {
    let analysis = spread_clip(first, frames, length, |list| read(list, ReadAgain::Yes))?;
    // The analysis counts as its clip's frames (see `SegmentedEncoder::start`), then each
    // segment its own.
    progress.total((frames + analysis.frame_count()) as u64);
    let mut encoder = SegmentedEncoder::start_reusing(&analysis, opts, length, progress, reuse)?;
    drop(analysis);
    progress.stage("segments");
    let ranges = segment_ranges(frames, length);
    for batch in ranges.chunks(opts.parallel_segments.max(1)) {
        let runs = batch
            .iter()
            .map(|r| Ok((r.start, read(&r.clone().collect::<Vec<_>>(), ReadAgain::No)?)))
            .collect::<Result<Vec<_>>>()?;
        let coded: Vec<Result<CodedSegment>> = runs
            .into_par_iter()
            .map(|(start, frames)| encoder.code_segment(start, frames, progress))
            .collect();
        for segment in coded {
            encoder.add(segment?)?;
        }
    }
    encoder.finish()
}
