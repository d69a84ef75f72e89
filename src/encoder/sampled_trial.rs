//! A picture codec's trials on a sample of frames, coded as an animation of their own, the
//! per-frame parts scaled to the whole, and the sample's own stream decoded for its error
//! (docs/design.md, "Automatic choice: bits at equal error"). Intra-coded pictures (JPEG, or a
//! group of one picture) are sampled as an evenly spread dozen; P-frames as runs of consecutive
//! frames spread over the clip, each run a group of pictures of its own: spread P-frames would
//! cost like key frames and misrank the candidates.

use super::{analysis, assemble, distortion, header, Analysed, Settings};
use crate::codec::ResidualInput;
use crate::error::Result;
use crate::mesh::{AnimatedMesh, Point};
use crate::progress::Progress;
use crate::stream::container::Part;

/// Frames the trials of intra-coded pictures code per candidate when the animation has more
/// than twice as many.
pub const TRIAL_FRAMES: usize = 12;

/// Runs of consecutive frames the trials of P-frame codecs code per candidate, when the
/// animation has at least twice as many frames in all (shorter ones are tried whole: their
/// winner's whole encoding, one group of pictures on one thread, would take as long again).
pub const TRIAL_RUNS: usize = 2;
/// Frames a run of [`TRIAL_RUNS`].
pub const RUN_FRAMES: usize = 16;

/// The frames a picture codec's trials code, from frame 0 (whose bounding box sets the step)
/// towards the last, as an animation of their own.
pub(super) struct Sample {
    pub(super) frames: Vec<usize>,
    mesh: AnimatedMesh,
    /// The sample's group of pictures when it is not the plan's (a run is one group at most).
    gop: Option<usize>,
}

impl Sample {
    /// `None` when every candidate is coded whole: a codec without pictures (tdct estimates
    /// instead), or an animation too short to sample.
    pub(super) fn of(mesh: &AnimatedMesh, settings: Settings) -> Result<Option<Self>> {
        let count = mesh.frame_count();
        let Some(pictures) = settings.plan.pictures.as_ref() else {
            return Ok(None);
        };
        let (frames, gop) = match pictures.gop {
            0 | 1 if count > 2 * TRIAL_FRAMES => {
                let spread = (0..TRIAL_FRAMES).map(|i| i * (count - 1) / (TRIAL_FRAMES - 1));
                (spread.collect::<Vec<usize>>(), None)
            }
            0 | 1 => return Ok(None),
            gop if count >= 2 * TRIAL_RUNS * RUN_FRAMES => {
                let last = TRIAL_RUNS.saturating_sub(1).max(1);
                let starts = (0..TRIAL_RUNS).map(|i| i * (count - RUN_FRAMES) / last);
                let runs = starts.flat_map(|start| start..start + RUN_FRAMES);
                (runs.collect(), Some(gop.min(RUN_FRAMES)))
            }
            _ => return Ok(None),
        };
        let positions = frames.iter().map(|&f| mesh.frame(f).to_vec()).collect();
        let mesh = AnimatedMesh::new(mesh.triangles().to_vec(), positions)?;
        Ok(Some(Self { frames, mesh, gop }))
    }

    /// The stream bytes of `analysed` estimated from the sample: every part but the codec's
    /// per-frame ones (those after the predictor's) exact, those scaled from the sample to the
    /// whole; and the vertex RMSE of the sample's own stream (its frames' pictures with their
    /// affine maps), decoded, as the whole stream's error. `reference` is the decoded first
    /// frame, `leading` the parts before the partition.
    pub(super) fn estimate(
        &self,
        mesh: &AnimatedMesh,
        (reference, leading): (&[Point], &[Part]),
        settings: Settings,
        analysed: &Analysed,
        progress: &dyn Progress,
    ) -> Result<(u64, f64)> {
        let prediction = analysed.prediction;
        let sampled = analysis::Prediction {
            track: prediction.track.select(&self.frames)?,
            weights: prediction.weights.clone(),
            residuals: self
                .frames
                .iter()
                .map(|&f| prediction.residuals[f].clone())
                .collect(),
        };
        // The depth of the whole encoding, decided on every frame's residuals as it will be.
        let mut plan = settings.plan.clone().at_depth_for(&prediction.residuals);
        if let (Some(gop), Some(pictures)) = (self.gop, plan.pictures.as_mut()) {
            pictures.gop = gop;
        }
        let coded = plan.encoder()?.encode(&ResidualInput {
            mesh: &self.mesh,
            reference,
            partition: analysed.partition,
            residuals: &sampled.residuals,
            progress,
            atlas: analysed.atlas,
        })?;
        let partition = analysed.partition;
        let header_of = |m: &AnimatedMesh| header(m, settings, analysed.model, partition);
        let per_frame: usize = coded.after_predictor.iter().map(|p| p.bytes.len()).sum();
        let parts = coded.into_parts();
        let sample_stream = assemble(
            &header_of(&self.mesh),
            leading.to_vec(),
            (&self.mesh, reference),
            partition,
            &sampled,
            parts.clone(),
        )?
        .to_bytes();
        let error = distortion::stream_rmse(&self.mesh, &sample_stream)?;
        let whole = assemble(
            &header_of(mesh),
            leading.to_vec(),
            (mesh, reference),
            partition,
            prediction,
            parts,
        )?;
        let scale = mesh.frame_count() as f64 / self.frames.len() as f64 - 1.0;
        Ok((
            whole.len() + (per_frame as f64 * scale).round() as u64,
            error,
        ))
    }
}
