//! A picture codec's trials on a sample of frames: an evenly spread dozen coded as an animation
//! of their own, the per-frame parts scaled to the whole, and the sample's own stream decoded
//! for its error (docs/design.md, "Automatic choice: bits at equal error").

use super::{analysis, assemble, distortion, header, Analysed, Settings};
use crate::codec::ResidualInput;
use crate::error::Result;
use crate::mesh::{AnimatedMesh, Point};
use crate::progress::Progress;
use crate::stream::container::Part;

/// Frames the picture codecs' trials code per candidate when the animation has more than twice
/// as many.
pub const TRIAL_FRAMES: usize = 12;

/// The frames a picture codec's trials code: an evenly spread sample from frame 0 (whose bounding
/// box sets the step) to the last, as an animation of their own.
pub(super) struct Sample {
    pub(super) frames: Vec<usize>,
    mesh: AnimatedMesh,
}

impl Sample {
    /// `None` when every candidate is coded whole: a codec without sampled trials
    /// ([`crate::codec::Codec`]'s `sampled_trials`), or a short animation.
    pub(super) fn of(mesh: &AnimatedMesh, settings: Settings) -> Result<Option<Self>> {
        let count = mesh.frame_count();
        let whole = !settings.opts.codec.codec().sampled_trials();
        if whole || count <= 2 * TRIAL_FRAMES {
            return Ok(None);
        }
        let frames: Vec<usize> = (0..TRIAL_FRAMES)
            .map(|i| i * (count - 1) / (TRIAL_FRAMES - 1))
            .collect();
        let positions = frames.iter().map(|&f| mesh.frame(f).to_vec()).collect();
        let mesh = AnimatedMesh::new(mesh.triangles().to_vec(), positions)?;
        Ok(Some(Self { frames, mesh }))
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
        let coded = settings.plan.encoder()?.encode(&ResidualInput {
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
