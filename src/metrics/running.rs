//! The measures accumulated a run of frames at a time: `eval` of a long clip holds one
//! segment of each animation, not both whole. [`super::compare`] is one run of every frame, so the
//! figures agree to the last bit whatever the runs.

use super::surface::{frame_distance_planned, FrameDistance, IndexCache, Surface, SurfacePlans};
use super::{sampling, Measures, VertexSums};
use crate::error::{Error, Result};
use crate::mesh::{Point, Triangle};
use crate::progress::{Progress, Silent};
use rayon::prelude::*;

/// Measures of a decoded animation against its original, fed frames in order.
pub struct Comparison {
    original_triangles: Vec<Triangle>,
    decoded_triangles: Vec<Triangle>,
    plans: SurfacePlans,
    diagonal: f64,
    vertices: usize,
    /// Whether the vertices correspond (equal counts): vertex RMSE and KG error are then measured.
    corresponding: bool,
    frame_rmse: Vec<f64>,
    hausdorff: f64,
    vertex_sums: VertexSums,
}

impl Comparison {
    /// A comparison sampled where the two first frames say (every frame is measured alike).
    pub fn new(original: Surface<'_>, decoded: Surface<'_>) -> Result<Self> {
        let diagonal = super::measure_unit(original.positions)?;
        let plans = SurfacePlans::new(original, decoded, sampling::sample_spacing(diagonal));
        Ok(Self {
            original_triangles: original.triangles.to_vec(),
            decoded_triangles: decoded.triangles.to_vec(),
            plans,
            diagonal,
            vertices: original.positions.len(),
            corresponding: original.positions.len() == decoded.positions.len(),
            frame_rmse: Vec::new(),
            hausdorff: 0.0,
            vertex_sums: VertexSums::default(),
        })
    }

    /// Frames compared so far.
    pub fn frames(&self) -> usize {
        self.frame_rmse.len()
    }

    /// Measures the next frames: `original[i]` against `decoded[i]` (each run on several threads).
    pub fn add(&mut self, original: &[Vec<Point>], decoded: &[Vec<Point>]) -> Result<()> {
        self.add_with_progress(original, decoded, &Silent)
    }

    /// [`Self::add`], telling `progress` of each frame measured (from the threads measuring).
    pub fn add_with_progress(
        &mut self,
        original: &[Vec<Point>],
        decoded: &[Vec<Point>],
        progress: &dyn Progress,
    ) -> Result<()> {
        if original.len() != decoded.len() {
            return Err(Error::Usage(format!(
                "{} original frames against {} decoded ones",
                original.len(),
                decoded.len()
            )));
        }
        let first = self.frames();
        let per_frame: Vec<FrameDistance> = (0..original.len())
            .into_par_iter()
            .map_init(IndexCache::default, |cache, i| {
                frame_distance_planned(
                    Surface {
                        triangles: &self.original_triangles,
                        positions: &original[i],
                    },
                    Surface {
                        triangles: &self.decoded_triangles,
                        positions: &decoded[i],
                    },
                    &self.plans,
                    cache,
                )
                .map_err(|e| match e {
                    Error::Mesh(m) => Error::Mesh(format!("frame {}: {m}", first + i)),
                    other => other,
                })
                .inspect(|_| progress.frames(1))
            })
            .collect::<Result<_>>()?;
        for d in &per_frame {
            self.frame_rmse.push(d.rms() / self.diagonal);
            self.hausdorff = self.hausdorff.max(d.max());
        }
        if self.corresponding {
            for (a, b) in original.iter().zip(decoded) {
                self.vertex_sums.add_frame(a, b);
            }
        }
        Ok(())
    }

    /// The measures of every frame added.
    pub fn finish(self) -> Measures {
        let frames = self.frames();
        let rmse = self.frame_rmse.iter().sum::<f64>() / frames.max(1) as f64;
        let count = self.vertices as f64 * frames as f64;
        let vertex = (self.corresponding && frames > 0).then(|| self.vertex_sums.errors(count));
        Measures {
            rmse,
            vertex_rmse: vertex.map(|v| v.rmse / self.diagonal),
            kg_error: vertex.and_then(|v| v.kg),
            hausdorff: self.hausdorff / self.diagonal,
            bpvf: None,
            frames,
            vertices: self.vertices,
            frame_rmse: self.frame_rmse,
        }
    }
}
