//! The error measures of DESIGN.md "Measures": RMSE (symmetric surface distance), vertex RMSE,
//! KG error, Hausdorff distance and bpvf.
//!
//! Every distance is divided by the diagonal of the *original's* first-frame bounding box.
//! [`compare`] measures two animations held in memory; [`Comparison`] measures a long one a run of
//! frames at a time.

mod frame_sampling;
mod running;
internal! {
    bvh;
    grid;
    sampling;
    surface;
    triangle;
}

pub use frame_sampling::{FrameSampling, DEFAULT_RELATIVE_ERROR};
pub use running::Comparison;
pub use surface::Surface;
#[cfg(feature = "internals")]
pub use surface::{
    frame_distance, frame_distance_planned, FrameDistance, IndexCache, OneSided, SurfacePlans,
};

use crate::error::{Error, Result};
use crate::mesh::{AnimatedMesh, Point};
use serde::Serialize;

/// The unit of every measure: the bounding-box diagonal of the original's first frame, refused
/// when zero (or not a number), as no error could then be a fraction of it.
pub fn measure_unit(original_first_frame: &[Point]) -> Result<f64> {
    let diagonal = crate::mesh::bbox_diagonal(original_first_frame);
    if diagonal.is_nan() || diagonal <= 0.0 {
        return Err(Error::Mesh(
            "the original's first frame has a zero bounding-box diagonal, the unit of every measure"
                .into(),
        ));
    }
    Ok(diagonal)
}

/// The measures of one decoded animation against its original.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Measures {
    /// Symmetric RMS surface distance per frame (max of the two one-sided area-weighted RMS
    /// distances) over the original's first-frame bbox diagonal, averaged over frames (a fraction;
    /// ×10⁴ gives the papers' ×10⁻⁴ figures).
    pub rmse: f64,
    /// RMS per-vertex displacement over all vertices and frames, over the bbox diagonal; `None` when
    /// the vertex counts differ (vertices then do not correspond).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vertex_rmse: Option<f64>,
    /// Karni–Gotsman error (a percentage); `None` when the vertex counts differ or the original
    /// never moves away from its centroids.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub kg_error: Option<f64>,
    /// Largest sampled surface distance, both directions, all frames, over the bbox diagonal.
    pub hausdorff: f64,
    /// Bits per vertex per frame of the compressed file, when there is one (see [`bpvf`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bpvf: Option<f64>,
    /// Frames compared.
    pub frames: usize,
    /// Frames whose surface distances were measured in full: all of them unless the comparison
    /// sampled frames ([`FrameSampling::Converged`]), when `rmse` is an estimate from these.
    pub surface_frames: usize,
    /// Vertices of the original.
    pub vertices: usize,
    /// The symmetric RMS of each frame, normalised like `rmse` (not in the JSON summary).
    #[serde(skip)]
    pub frame_rmse: Vec<f64>,
}

impl Measures {
    /// Sets bpvf from the size of the compressed file in bits.
    pub fn with_bits(mut self, bits: u64) -> Self {
        self.bpvf = Some(bpvf(bits, self.vertices, self.frames));
        self
    }
}

/// Bits per vertex per frame: `bits / (vertices · frames)` (0 for an empty animation).
pub fn bpvf(bits: u64, vertices: usize, frames: usize) -> f64 {
    let n = vertices as f64 * frames as f64;
    if n > 0.0 {
        bits as f64 / n
    } else {
        0.0
    }
}

/// Compares `decoded` with `original`, every frame measured in full. Both need the same number
/// of frames; the connectivity and vertex count may differ (then only the surface measures are
/// given).
pub fn compare(original: &AnimatedMesh, decoded: &AnimatedMesh) -> Result<Measures> {
    compare_sampled(original, decoded, FrameSampling::Every)
}

/// [`compare`] measuring the frames `sampling` says in full (`eval`'s default: a converging sample,
/// [`FrameSampling::Converged`] at [`DEFAULT_RELATIVE_ERROR`]); the vertex measures and the
/// Hausdorff distance are exact either way.
pub fn compare_sampled(
    original: &AnimatedMesh,
    decoded: &AnimatedMesh,
    sampling: FrameSampling,
) -> Result<Measures> {
    same_frame_count(original.frame_count(), decoded.frame_count())?;
    let mut comparison = Comparison::new(
        Surface {
            triangles: original.triangles(),
            positions: original.frame(0),
        },
        Surface {
            triangles: decoded.triangles(),
            positions: decoded.frame(0),
        },
    )?
    .with_frame_sampling(sampling);
    comparison.add(original.frames(), decoded.frames())?;
    Ok(comparison.finish())
}

/// Refuses to compare animations whose frame counts differ: frames must correspond.
pub fn same_frame_count(original: usize, decoded: usize) -> Result<()> {
    if original == decoded {
        return Ok(());
    }
    Err(Error::Usage(format!(
        "the original has {original} frames but the decoded animation has {decoded}; frames must \
         correspond"
    )))
}

/// Per-vertex errors of two animations with corresponding vertices.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VertexErrors {
    /// RMS displacement over all vertices and frames, in the meshes' units.
    pub rmse: f64,
    /// Karni–Gotsman error, percent; `None` when the original is all at its centroids.
    pub kg: Option<f64>,
}

/// Vertex RMSE (unnormalised) and KG error; `None` when vertex or frame counts differ.
pub fn vertex_errors(original: &AnimatedMesh, decoded: &AnimatedMesh) -> Option<VertexErrors> {
    if original.vertex_count() != decoded.vertex_count()
        || original.frame_count() != decoded.frame_count()
    {
        return None;
    }
    let mut sums = VertexSums::default();
    for (a, b) in original.frames().iter().zip(decoded.frames()) {
        sums.add_frame(a, b);
    }
    Some(sums.errors(original.vertex_count() as f64 * original.frame_count() as f64))
}

/// The running sums behind vertex RMSE and KG error, a frame at a time: what `eval --fast`
/// measures, at the cost of reading the frames.
#[derive(Debug, Clone, Copy, Default)]
pub struct VertexSums {
    /// Squared vertex displacements.
    err: f64,
    /// Squared distances of the original's vertices to their frame's centroid.
    spread: f64,
}

impl VertexSums {
    /// Adds one frame: original `a` against decoded `b` (corresponding vertices).
    pub fn add_frame(&mut self, a: &[crate::mesh::Point], b: &[crate::mesh::Point]) {
        let n = a.len().max(1) as f64;
        let mut c = [0.0f64; 3];
        for p in a {
            for k in 0..3 {
                c[k] += p[k] as f64 / n;
            }
        }
        for (p, q) in a.iter().zip(b) {
            for k in 0..3 {
                self.err += (p[k] as f64 - q[k] as f64).powi(2);
                self.spread += (p[k] as f64 - c[k]).powi(2);
            }
        }
    }

    /// The errors over `count` vertex positions (vertices × frames).
    pub fn errors(self, count: f64) -> VertexErrors {
        VertexErrors {
            rmse: (self.err / count).sqrt(),
            kg: (self.spread > 0.0).then(|| 100.0 * self.err.sqrt() / self.spread.sqrt()),
        }
    }
}

#[cfg(test)]
/// The triangles of a grid of `n`×`n` vertices numbered row by row, each square cut along the
/// diagonal from its second corner (`flip`: from its first).
pub(crate) fn grid_triangles(n: u32, flip: bool) -> Vec<crate::mesh::Triangle> {
    let mut triangles = Vec::new();
    for i in 0..n.saturating_sub(1) {
        for j in 0..n - 1 {
            let v = i * n + j;
            if flip {
                triangles.push([v, v + 1, v + n + 1]);
                triangles.push([v, v + n + 1, v + n]);
            } else {
                triangles.push([v, v + 1, v + n]);
                triangles.push([v + 1, v + n + 1, v + n]);
            }
        }
    }
    triangles
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Point;

    #[test]
    fn the_unit_is_the_first_frames_diagonal_and_never_zero() {
        let corners: Vec<Point> = vec![[0.0, 0.0, 0.0], [1.0, 2.0, 2.0]];
        assert_eq!(measure_unit(&corners).ok(), Some(3.0));
        let still: Vec<Point> = vec![[1.0, 1.0, 1.0]; 4];
        let e = measure_unit(&still).err().map(|e| e.to_string());
        assert!(e.is_some_and(|e| e.contains("zero bounding-box diagonal")));
        assert!(measure_unit(&[]).is_err());
    }

    /// A bumpy 12×12 grid patch, swaying over `frames` frames.
    fn patch(frames: usize) -> AnimatedMesh {
        let n = 12u32;
        let triangles = grid_triangles(n, false);
        let frames: Vec<Vec<Point>> = (0..frames)
            .map(|f| {
                (0..n * n)
                    .map(|v| {
                        let (x, y) = ((v % n) as f32 / 11.0, (v / n) as f32 / 11.0);
                        [x, y, 0.2 * (3.0 * x + f as f32 * 0.3).sin() * y]
                    })
                    .collect()
            })
            .collect();
        AnimatedMesh::new(triangles, frames).unwrap_or_else(|e| panic!("{e}"))
    }

    fn moved(mesh: &AnimatedMesh, by: Point) -> AnimatedMesh {
        let frames = mesh
            .frames()
            .iter()
            .map(|f| {
                f.iter()
                    .map(|p| [p[0] + by[0], p[1] + by[1], p[2] + by[2]])
                    .collect()
            })
            .collect();
        AnimatedMesh::new(mesh.triangles().to_vec(), frames).unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn identical_meshes_give_zero() {
        let m = patch(3);
        let r = compare(&m, &m).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!((r.rmse, r.hausdorff), (0.0, 0.0), "{r:?}");
        assert_eq!(r.vertex_rmse, Some(0.0));
        assert_eq!(r.kg_error, Some(0.0));
        assert_eq!((r.frames, r.vertices), (3, 144));
    }

    #[test]
    fn a_translated_copy_is_off_by_the_translation() {
        // A flat sheet lifted by t along its normal is exactly t away everywhere.
        let flat = {
            let m = patch(1);
            let frame: Vec<Point> = m.frame(0).iter().map(|p| [p[0], p[1], 0.0]).collect();
            AnimatedMesh::new(m.triangles().to_vec(), vec![frame.clone(), frame])
                .unwrap_or_else(|e| panic!("{e}"))
        };
        let t = 0.01f32;
        let r = compare(&flat, &moved(&flat, [0.0, 0.0, t])).unwrap_or_else(|e| panic!("{e}"));
        let diag = flat.bbox_diagonal();
        let want = t as f64 / diag;
        assert!((r.rmse - want).abs() < 1e-6 * want, "{} vs {want}", r.rmse);
        assert!((r.hausdorff - want).abs() < 1e-6 * want);
        let v = r.vertex_rmse.unwrap_or(f64::NAN);
        assert!((v - want).abs() < 1e-6 * want);
        // A bumpy patch shifted by t: the vertices move by exactly t, the surfaces by at most t.
        let bumpy = patch(4);
        let r = compare(&bumpy, &moved(&bumpy, [0.0, 0.0, t])).unwrap_or_else(|e| panic!("{e}"));
        let want = t as f64 / bumpy.bbox_diagonal();
        assert!(
            r.rmse <= want * (1.0 + 1e-6) && r.rmse > 0.8 * want,
            "{}",
            r.rmse
        );
        assert!((r.vertex_rmse.unwrap_or(f64::NAN) - want).abs() < 1e-6 * want);
    }

    #[test]
    fn a_comparison_tells_its_progress_frame_by_frame() {
        struct Count(std::sync::atomic::AtomicU64);
        impl crate::progress::Progress for Count {
            fn frames(&self, count: u64) {
                self.0
                    .fetch_add(count, std::sync::atomic::Ordering::Relaxed);
            }
        }
        let (a, b) = (patch(5), moved(&patch(5), [0.0, 0.0, 0.01]));
        fn surface(m: &AnimatedMesh) -> Surface<'_> {
            Surface {
                triangles: m.triangles(),
                positions: m.frame(0),
            }
        }
        let start = || Comparison::new(surface(&a), surface(&b)).unwrap_or_else(|e| panic!("{e}"));
        let (mut told, mut silent) = (start(), start());
        let count = Count(std::sync::atomic::AtomicU64::new(0));
        told.add_with_progress(a.frames(), b.frames(), &count)
            .unwrap_or_else(|e| panic!("{e}"));
        silent
            .add(a.frames(), b.frames())
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(count.0.load(std::sync::atomic::Ordering::Relaxed), 5);
        assert_eq!(told.finish(), silent.finish());
    }

    #[test]
    fn kg_error_follows_its_definition() {
        // Two vertices at ±1 on x (centroid 0, spread² = 2 per frame); the copy moves one by 0.1.
        let a = AnimatedMesh::new(
            vec![[0, 1, 1]],
            vec![vec![[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]],
        )
        .unwrap_or_else(|e| panic!("{e}"));
        let b = AnimatedMesh::new(
            vec![[0, 1, 1]],
            vec![vec![[-1.0, 0.0, 0.0], [1.1, 0.0, 0.0]]],
        )
        .unwrap_or_else(|e| panic!("{e}"));
        let v = vertex_errors(&a, &b).unwrap_or_else(|| panic!("counts match"));
        let want = 100.0 * 0.1 / 2f64.sqrt();
        assert!((v.kg.unwrap_or(f64::NAN) - want).abs() < 1e-4, "{:?}", v.kg);
        assert!((v.rmse - (0.01f64 / 2.0).sqrt()).abs() < 1e-6);
    }

    #[test]
    fn different_vertex_counts_keep_only_surface_measures() {
        let a = patch(2);
        // The same surface with one extra, unused vertex.
        let frames = a
            .frames()
            .iter()
            .map(|f| f.iter().copied().chain([[0.0, 0.0, 0.0]]).collect())
            .collect();
        let b = AnimatedMesh::new(a.triangles().to_vec(), frames).unwrap_or_else(|e| panic!("{e}"));
        let r = compare(&a, &b).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!((r.vertex_rmse, r.kg_error), (None, None));
        assert!(r.rmse < 1e-12);
        let json = serde_json::to_value(&r).unwrap_or_default();
        assert!(json.get("vertex_rmse").is_none() && json.get("rmse").is_some());
    }

    #[test]
    fn frame_counts_must_match() {
        let err = compare(&patch(2), &patch(3));
        assert!(matches!(err, Err(Error::Usage(m)) if m.contains("2 frames")));
    }

    #[test]
    fn bpvf_is_bits_over_vertices_and_frames() {
        assert_eq!(bpvf(1000, 10, 50), 2.0);
        let m = patch(2);
        let r = compare(&m, &m)
            .unwrap_or_else(|e| panic!("{e}"))
            .with_bits(144 * 2 * 3);
        assert_eq!(r.bpvf, Some(3.0));
    }
}
