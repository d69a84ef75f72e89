//! Surface-to-surface distances of one frame, as Metro computes them: sample one surface, measure
//! each sample's exact distance to the other surface, take the area-weighted RMS and the maximum.

use super::bvh::{Nearest, TriangleBvh};
use super::sampling::{Sample, SamplingPlan};
use super::triangle::Vec3;
use crate::error::{Error, Result};
use crate::mesh::{Point, Triangle};
use serde::Serialize;

/// One-sided distance from a sampled surface A to a surface B, in the meshes' own units.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct OneSided {
    /// Area-weighted root mean square distance.
    pub rms: f64,
    /// Area-weighted mean distance.
    pub mean: f64,
    /// Largest sampled distance.
    pub max: f64,
    /// Number of samples taken on A.
    pub samples: usize,
    /// Area of A.
    pub area: f64,
}

/// Both one-sided distances of one frame, in the meshes' own units.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FrameDistance {
    /// From the first surface (the original) to the second.
    pub forward: OneSided,
    /// From the second surface back to the first.
    pub backward: OneSided,
}

impl FrameDistance {
    /// The symmetric RMS distance: the larger of the two one-sided RMS distances.
    pub fn rms(&self) -> f64 {
        self.forward.rms.max(self.backward.rms)
    }

    /// The symmetric (Hausdorff) distance: the larger of the two one-sided maxima.
    pub fn max(&self) -> f64 {
        self.forward.max.max(self.backward.max)
    }
}

/// One surface of one frame: its triangles and vertex positions.
#[derive(Debug, Clone, Copy)]
pub struct Surface<'a> {
    /// The triangles.
    pub triangles: &'a [Triangle],
    /// The vertex positions the triangles index.
    pub positions: &'a [Point],
}

/// Distance from surface `a`, sampled at `samples` (see [`SamplingPlan::apply`]), to the surface
/// indexed by `b`. `same_triangles` says that `a`'s face `i` corresponds to `b`'s face `i` (shared
/// connectivity), which makes it the first candidate for samples on face `i`.
pub fn one_sided(
    samples: &[Sample],
    a: Surface<'_>,
    b: &TriangleBvh,
    same_triangles: bool,
) -> Result<OneSided> {
    let (mut area, mut sum, mut sum_sq, mut max) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut last = None;
    let mut stack = Vec::new();
    for s in samples {
        // The same-numbered face is right when the surfaces barely differ; the previous sample's
        // answer when they differ a lot (a neighbouring sample has a neighbouring answer).
        let same_face = if same_triangles { Some(s.face) } else { None };
        let hints = same_face.into_iter().chain(last);
        // A face that did not move holds its samples exactly (a query would add rounding noise).
        let unmoved = same_triangles && b.corners(s.face) == Some(&corners(a, s.face));
        let nearest = if unmoved {
            Nearest {
                triangle: s.face,
                distance_squared: 0.0,
            }
        } else {
            b.nearest_with(s.point, hints, &mut stack)
        };
        last = Some(nearest.triangle);
        let d = nearest.distance_squared.sqrt();
        area += s.weight;
        sum += s.weight * d;
        sum_sq += s.weight * nearest.distance_squared;
        max = max.max(d);
    }
    if area <= 0.0 || !area.is_finite() {
        return Err(Error::Mesh(
            "the surface has zero area, so a distance averaged over it is undefined".into(),
        ));
    }
    Ok(OneSided {
        rms: (sum_sq / area).sqrt(),
        mean: sum / area,
        max,
        samples: samples.len(),
        area,
    })
}

fn corners(s: Surface<'_>, face: u32) -> [Vec3; 3] {
    let at = |i: u32| {
        s.positions
            .get(i as usize)
            .map_or([f64::NAN; 3], |p| [p[0] as f64, p[1] as f64, p[2] as f64])
    };
    s.triangles
        .get(face as usize)
        .map_or([[f64::NAN; 3]; 3], |t| [at(t[0]), at(t[1]), at(t[2])])
}

/// Builds the nearest-triangle index of a surface, or says that it has no triangles.
pub fn index_surface(s: Surface<'_>, which: &str) -> Result<TriangleBvh> {
    TriangleBvh::new(s.triangles, s.positions).ok_or_else(|| {
        Error::Mesh(format!(
            "the {which} mesh has no triangles, so it has no surface to measure against"
        ))
    })
}

/// Nearest-triangle indexes and a sample buffer kept from one frame to the next: a later frame
/// refits the trees instead of building them anew. Any surfaces may be passed (a tree is rebuilt
/// when the triangle count changes); answers stay exact, only speed depends on the frames sharing
/// triangles.
#[derive(Debug, Clone, Default)]
pub struct IndexCache {
    first: Option<TriangleBvh>,
    second: Option<TriangleBvh>,
    samples: Vec<Sample>,
}

fn refit_or_build<'c>(
    slot: &'c mut Option<TriangleBvh>,
    s: Surface<'_>,
    which: &str,
) -> Result<&'c TriangleBvh> {
    let refitted = slot
        .as_mut()
        .is_some_and(|t| t.refit(s.triangles, s.positions));
    if !refitted {
        *slot = Some(index_surface(s, which)?);
    }
    slot.as_ref()
        .ok_or_else(|| Error::Mesh(format!("the {which} mesh could not be indexed")))
}

/// Where both surfaces of a comparison are sampled, fixed for all frames.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfacePlans {
    /// The first (original) surface's plan.
    pub first: SamplingPlan,
    /// The second surface's plan.
    pub second: SamplingPlan,
}

impl SurfacePlans {
    /// Plans both surfaces from their reference frames `a` and `b` with the sample `spacing`
    /// (see `sampling::sample_spacing`).
    pub fn new(a: Surface<'_>, b: Surface<'_>, spacing: f64) -> Self {
        Self {
            first: SamplingPlan::new(a.triangles, a.positions, spacing),
            second: SamplingPlan::new(b.triangles, b.positions, spacing),
        }
    }
}

#[cfg(any(test, feature = "internals"))]
/// Both one-sided distances between surfaces `a` and `b` of one frame, each sampled with `spacing`.
pub fn frame_distance(a: Surface<'_>, b: Surface<'_>, spacing: f64) -> Result<FrameDistance> {
    let plans = SurfacePlans::new(a, b, spacing);
    frame_distance_planned(a, b, &plans, &mut IndexCache::default())
}

/// [`frame_distance`] with sampling fixed by `plans` (made for these triangles), reusing and
/// updating the trees in `cache` from an earlier frame.
pub fn frame_distance_planned(
    a: Surface<'_>,
    b: Surface<'_>,
    plans: &SurfacePlans,
    cache: &mut IndexCache,
) -> Result<FrameDistance> {
    let same = a.triangles == b.triangles;
    let a_index = refit_or_build(&mut cache.first, a, "first")?;
    let b_index = refit_or_build(&mut cache.second, b, "second")?;
    plans
        .first
        .apply(a.triangles, a.positions, &mut cache.samples);
    let forward = one_sided(&cache.samples, a, b_index, same)?;
    plans
        .second
        .apply(b.triangles, b.positions, &mut cache.samples);
    let backward = one_sided(&cache.samples, b, a_index, same)?;
    Ok(FrameDistance { forward, backward })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(z: f32) -> (Vec<Triangle>, Vec<Point>) {
        (
            vec![[0, 1, 2], [0, 2, 3]],
            vec![[0.0, 0.0, z], [1.0, 0.0, z], [1.0, 1.0, z], [0.0, 1.0, z]],
        )
    }

    #[test]
    fn parallel_planes_are_their_gap_apart() {
        let (t, a) = square(0.0);
        let (_, b) = square(0.25);
        let d = frame_distance(
            Surface {
                triangles: &t,
                positions: &a,
            },
            Surface {
                triangles: &t,
                positions: &b,
            },
            0.1,
        )
        .unwrap_or_else(|e| panic!("{e}"));
        for one in [d.forward, d.backward] {
            assert!((one.rms - 0.25).abs() < 1e-7);
            assert!((one.mean - 0.25).abs() < 1e-7);
            assert!((one.max - 0.25).abs() < 1e-7);
            assert!((one.area - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn a_smaller_patch_is_near_but_the_big_one_is_not() {
        // A: the unit square; B: its left half. Every point of B lies on A (distance 0), while the
        // right half of A is up to 0.5 from B: RMS² = ∫₀^½ x² dx over unit height = 1/24.
        let (t, a) = square(0.0);
        let b = vec![
            [0.0, 0.0, 0.0],
            [0.5, 0.0, 0.0],
            [0.5, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let d = frame_distance(
            Surface {
                triangles: &t,
                positions: &a,
            },
            Surface {
                triangles: &t,
                positions: &b,
            },
            0.05,
        )
        .unwrap_or_else(|e| panic!("{e}"));
        assert!(d.backward.rms < 1e-7);
        assert!(
            (d.forward.rms - (1.0f64 / 24.0).sqrt()).abs() < 1e-6,
            "{}",
            d.forward.rms
        );
        assert!((d.forward.max - 0.5).abs() < 1e-7);
        assert_eq!(d.rms(), d.forward.rms);
    }

    #[test]
    fn no_triangles_is_an_error_that_says_so() {
        let (t, a) = square(0.0);
        let err = frame_distance(
            Surface {
                triangles: &t,
                positions: &a,
            },
            Surface {
                triangles: &[],
                positions: &a,
            },
            0.1,
        );
        assert!(matches!(err, Err(Error::Mesh(m)) if m.contains("no triangles")));
    }
}
