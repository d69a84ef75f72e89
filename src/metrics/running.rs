//! The measures accumulated a run of frames at a time: `eval` of a long clip holds one
//! segment of each animation, not both whole. [`super::compare`] is one run of every frame, so the
//! figures agree to the last bit whatever the runs.

use super::frame_sampling::{
    estimate, sampled_at, FrameSampling, FrameValue, MIN_SAMPLED_RUN, STRIDES,
};
use super::surface::{
    frame_bound_planned, frame_distance_planned, FrameDistance, IndexCache, Surface, SurfacePlans,
};
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
    /// Each frame's symmetric RMS (in the meshes' units), or its bound when only bounded.
    frame_values: Vec<FrameValue>,
    hausdorff: f64,
    vertex_sums: VertexSums,
    sampling: FrameSampling,
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
            frame_values: Vec::new(),
            hausdorff: 0.0,
            vertex_sums: VertexSums::default(),
            sampling: FrameSampling::Every,
        })
    }

    /// Which frames to measure in full ([`FrameSampling::Every`] unless told otherwise).
    pub fn with_frame_sampling(mut self, sampling: FrameSampling) -> Self {
        self.sampling = sampling;
        self
    }

    /// Frames compared so far.
    pub fn frames(&self) -> usize {
        self.frame_values.len()
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
        let tolerance = match self.sampling {
            FrameSampling::Converged { relative_error }
                if original.len() >= MIN_SAMPLED_RUN && self.plans.faces_pair_up() =>
            {
                Some(relative_error)
            }
            _ => None,
        };
        match tolerance {
            Some(tolerance) => self.add_sampled(original, decoded, progress, tolerance)?,
            None => {
                let all: Vec<usize> = (0..original.len()).collect();
                for d in self.measure(&all, original, decoded, progress)? {
                    self.frame_values.push(measured(&d));
                    self.hausdorff = self.hausdorff.max(d.max());
                }
            }
        }
        if self.corresponding {
            for (a, b) in original.iter().zip(decoded) {
                self.vertex_sums.add_frame(a, b);
            }
        }
        Ok(())
    }

    /// Measures frames `which` of the run (`original[i]` against `decoded[i]`) in full, in
    /// parallel.
    fn measure(
        &self,
        which: &[usize],
        original: &[Vec<Point>],
        decoded: &[Vec<Point>],
        progress: &dyn Progress,
    ) -> Result<Vec<FrameDistance>> {
        self.each_frame(which, (original, decoded), progress, |a, b, cache| {
            frame_distance_planned(a, b, &self.plans, cache)
        })
    }

    /// `per_frame` of frames `which` of the run, in parallel, each thread keeping its indexes
    /// from frame to frame; `progress` is told of each frame, an error names its frame.
    fn each_frame<T: Send>(
        &self,
        which: &[usize],
        (original, decoded): (&[Vec<Point>], &[Vec<Point>]),
        progress: &dyn Progress,
        per_frame: impl Fn(Surface<'_>, Surface<'_>, &mut IndexCache) -> Result<T> + Sync,
    ) -> Result<Vec<T>> {
        let first = self.frames();
        which
            .par_iter()
            .map_init(IndexCache::default, |cache, &i| {
                let (a, b) = self.surfaces(original, decoded, i)?;
                per_frame(a, b, cache)
                    .map_err(|e| in_frame(e, first + i))
                    .inspect(|_| progress.frames(1))
            })
            .collect()
    }

    /// Frame `i` of the run, both surfaces.
    fn surfaces<'s>(
        &'s self,
        original: &'s [Vec<Point>],
        decoded: &'s [Vec<Point>],
        i: usize,
    ) -> Result<(Surface<'s>, Surface<'s>)> {
        match (original.get(i), decoded.get(i)) {
            (Some(a), Some(b)) => Ok((
                Surface {
                    triangles: &self.original_triangles,
                    positions: a,
                },
                Surface {
                    triangles: &self.decoded_triangles,
                    positions: b,
                },
            )),
            _ => Err(Error::Usage(format!("no frame {i} in this run"))),
        }
    }

    /// [`Self::add_with_progress`] measuring a converging sample of the run's frames in full and
    /// bounding the others (see [`super::frame_sampling`]).
    fn add_sampled(
        &mut self,
        original: &[Vec<Point>],
        decoded: &[Vec<Point>],
        progress: &dyn Progress,
        tolerance: f64,
    ) -> Result<()> {
        let first = self.frames();
        let n = original.len();
        let unseen = FrameValue {
            measured: None,
            bound: 0.0,
        };
        let mut run = vec![unseen; n];
        let mut hausdorff = self.hausdorff;
        for (pass, stride) in STRIDES.into_iter().enumerate() {
            // The bar counts each frame once, in the first pass; the stage says what the later
            // passes, which measure more of the same frames, are doing.
            progress.stage(&sample_stage(pass, stride));
            let which: Vec<usize> = sampled_at(stride, first, n)
                .into_iter()
                .filter(|&i| run[i].measured.is_none())
                .collect();
            let bar = if pass == 0 { progress } else { &Silent };
            for (&i, d) in which
                .iter()
                .zip(self.measure(&which, original, decoded, bar)?)
            {
                run[i] = measured(&d);
                hausdorff = hausdorff.max(d.max());
            }
            if pass == 0 {
                self.bound(&mut run, original, decoded, progress, &mut hausdorff)?;
            }
            // The estimate draws on every frame so far: earlier runs' samples count too.
            let mut all = self.frame_values.clone();
            all.extend_from_slice(&run);
            if estimate(&all).1 <= tolerance {
                break;
            }
        }
        self.frame_values.extend(run);
        self.hausdorff = hausdorff;
        Ok(())
    }

    /// Bounds the run's frames not measured yet, raising `hausdorff` to any larger distance
    /// their samples reach.
    fn bound(
        &self,
        frames: &mut [FrameValue],
        original: &[Vec<Point>],
        decoded: &[Vec<Point>],
        progress: &dyn Progress,
        hausdorff: &mut f64,
    ) -> Result<()> {
        let floor = *hausdorff;
        let which: Vec<usize> = (0..frames.len())
            .filter(|&i| frames[i].measured.is_none())
            .collect();
        let bounds = self.each_frame(&which, (original, decoded), progress, |a, b, cache| {
            frame_bound_planned(a, b, &self.plans, cache, floor)
        })?;
        for (&i, b) in which.iter().zip(bounds) {
            if let Some(f) = frames.get_mut(i) {
                f.bound = b.bound_rms;
            }
            *hausdorff = hausdorff.max(b.max);
        }
        Ok(())
    }

    /// The measures of every frame added.
    pub fn finish(self) -> Measures {
        let frames = self.frames();
        let (values, _) = estimate(&self.frame_values);
        let frame_rmse: Vec<f64> = values.iter().map(|v| v / self.diagonal).collect();
        let rmse = frame_rmse.iter().sum::<f64>() / frames.max(1) as f64;
        let count = self.vertices as f64 * frames as f64;
        let vertex = (self.corresponding && frames > 0).then(|| self.vertex_sums.errors(count));
        Measures {
            rmse,
            vertex_rmse: vertex.map(|v| v.rmse / self.diagonal),
            kg_error: vertex.and_then(|v| v.kg),
            hausdorff: self.hausdorff / self.diagonal,
            bpvf: None,
            frames,
            surface_frames: self
                .frame_values
                .iter()
                .filter(|f| f.measured.is_some())
                .count(),
            vertices: self.vertices,
            frame_rmse,
        }
    }
}

/// `e` naming the frame it happened in.
fn in_frame(e: Error, frame: usize) -> Error {
    match e {
        Error::Mesh(m) => Error::Mesh(format!("frame {frame}: {m}")),
        other => other,
    }
}

/// A frame measured in full, as the sample's estimate counts it.
fn measured(d: &FrameDistance) -> FrameValue {
    FrameValue {
        measured: Some(d.rms()),
        bound: d.forward.bound_rms.max(d.backward.bound_rms),
    }
}

/// What a sampled comparison's pass `pass` (at `stride`) tells as its stage.
fn sample_stage(pass: usize, stride: usize) -> String {
    match (pass, stride) {
        (0, _) => format!("1 frame in {stride} measured, the others bounded"),
        (_, 1) => "refining: every frame measured".to_string(),
        _ => format!("refining: 1 frame in {stride} measured"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::AnimatedMesh;

    /// A bumpy 12×12 patch swaying over `frames` frames, and a copy whose vertices are jittered
    /// by an amount that swells and fades over the frames (as a codec's error does).
    fn pair(frames: usize) -> (AnimatedMesh, AnimatedMesh) {
        let n = 12u32;
        let triangles = super::super::grid_triangles(n, false);
        let frame = |f: usize, jitter: f32| -> Vec<Point> {
            (0..n * n)
                .map(|v| {
                    let (x, y) = ((v % n) as f32 / 11.0, (v / n) as f32 / 11.0);
                    let wobble = |k: f32| jitter * (v as f32 * 12.99 + f as f32 * 0.37 + k).sin();
                    let z = 0.2 * (3.0 * x + f as f32 * 0.3).sin() * y;
                    [x + wobble(0.0), y + wobble(1.3), z + wobble(2.9)]
                })
                .collect()
        };
        let amount = |f: usize| 0.004 * (1.5 + (f as f32 * 0.1).sin());
        let original = (0..frames).map(|f| frame(f, 0.0)).collect();
        let decoded = (0..frames).map(|f| frame(f, amount(f))).collect();
        let mesh =
            |frames| AnimatedMesh::new(triangles.clone(), frames).unwrap_or_else(|e| panic!("{e}"));
        (mesh(original), mesh(decoded))
    }

    fn measures(
        a: &AnimatedMesh,
        b: &AnimatedMesh,
        sampling: FrameSampling,
        runs: usize,
    ) -> Measures {
        let mut c = Comparison::new(surface(a), surface(b))
            .unwrap_or_else(|e| panic!("{e}"))
            .with_frame_sampling(sampling);
        let step = a.frame_count().div_ceil(runs);
        for (x, y) in a.frames().chunks(step).zip(b.frames().chunks(step)) {
            c.add(x, y).unwrap_or_else(|e| panic!("{e}"));
        }
        c.finish()
    }

    fn surface(m: &AnimatedMesh) -> Surface<'_> {
        Surface {
            triangles: m.triangles(),
            positions: m.frame(0),
        }
    }

    const SAMPLED: FrameSampling = FrameSampling::Converged {
        relative_error: 0.002,
    };

    #[test]
    fn a_sampled_comparison_agrees_with_every_frame_measured() {
        let (a, b) = pair(96);
        let every = measures(&a, &b, FrameSampling::Every, 1);
        assert_eq!(every.surface_frames, 96);
        for runs in [1, 2] {
            let sampled = measures(&a, &b, SAMPLED, runs);
            assert!(sampled.surface_frames < 96, "{runs} runs: {sampled:?}");
            let off = sampled.rmse / every.rmse - 1.0;
            assert!(off.abs() < 0.01, "{runs} runs: {off}");
            assert_eq!(sampled.hausdorff, every.hausdorff, "{runs} runs");
            assert_eq!(sampled.vertex_rmse, every.vertex_rmse);
            assert_eq!(sampled.frame_rmse.len(), 96);
        }
    }

    #[test]
    fn no_tolerance_or_a_short_run_measures_every_frame() {
        let (a, b) = pair(40);
        let every = measures(&a, &b, FrameSampling::Every, 1);
        let strict = FrameSampling::Converged {
            relative_error: 0.0,
        };
        assert_eq!(measures(&a, &b, strict, 1), every);
        // Two runs of 20 frames: each too short to sample.
        assert_eq!(measures(&a, &b, SAMPLED, 2).rmse, every.rmse);
    }

    #[test]
    fn other_connectivity_is_measured_in_full() {
        let (a, b) = pair(40);
        // The decoded quads split along the other diagonal: no face pairs with the original's.
        let flipped = super::super::grid_triangles(12, true);
        let b = AnimatedMesh::new(flipped, b.frames().to_vec()).unwrap_or_else(|e| panic!("{e}"));
        let every = measures(&a, &b, FrameSampling::Every, 1);
        let sampled = measures(&a, &b, SAMPLED, 1);
        assert_eq!(sampled, every);
        assert_eq!(sampled.surface_frames, 40);
    }

    #[test]
    fn a_sampled_comparison_tells_each_frame_once() {
        struct Count(std::sync::atomic::AtomicU64, std::sync::Mutex<Vec<String>>);
        impl Progress for Count {
            fn stage(&self, name: &str) {
                if let Ok(mut stages) = self.1.lock() {
                    stages.push(name.to_string());
                }
            }
            fn frames(&self, count: u64) {
                self.0
                    .fetch_add(count, std::sync::atomic::Ordering::Relaxed);
            }
        }
        let (a, b) = pair(64);
        let mut c = Comparison::new(surface(&a), surface(&b))
            .unwrap_or_else(|e| panic!("{e}"))
            .with_frame_sampling(FrameSampling::Converged {
                relative_error: 0.0,
            });
        let count = Count(std::sync::atomic::AtomicU64::new(0), Default::default());
        c.add_with_progress(a.frames(), b.frames(), &count)
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(count.0.load(std::sync::atomic::Ordering::Relaxed), 64);
        // No tolerance: every pass runs, each telling its stage, though the bar is full.
        let stages = count.1.lock().map(|s| s.clone()).unwrap_or_default();
        let want = [
            "1 frame in 8 measured, the others bounded",
            "refining: 1 frame in 4 measured",
            "refining: 1 frame in 2 measured",
            "refining: every frame measured",
        ];
        assert_eq!(stages, want);
    }
}
