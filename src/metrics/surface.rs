//! Surface-to-surface distances of one frame, as Metro computes them: sample one surface, measure
//! each sample's exact distance to the other surface, take the area-weighted RMS and the maximum.

use super::bvh::{Nearest, TriangleBvh};
use super::sampling::{Sample, SamplingPlan};
use super::triangle::Vec3;
use crate::error::{Error, Result};
use crate::mesh::{Point, Triangle};
use rustc_hash::FxHashMap;
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
    /// Area-weighted RMS distance from each sample to its hints (see `hint`): an upper bound on
    /// `rms` found on the way, which a frame only bounded ([`frame_bound_planned`]) has too.
    pub bound_rms: f64,
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
/// indexed by `b`. `same_triangles` says that `a`'s face `i` is `b`'s face `i` (shared
/// connectivity); `twins[i]`, when given, is the face of `b` on the same vertices as `a`'s face `i`
/// (the first candidate for samples on face `i`; [`NO_TWIN`] when there is none).
pub fn one_sided(
    samples: &[Sample],
    a: Surface<'_>,
    b: &mut TriangleBvh,
    same_triangles: bool,
    twins: Option<&[u32]>,
) -> Result<OneSided> {
    let (mut area, mut sum, mut sum_sq, mut max_sq) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut bound_sq = 0.0f64;
    let mut last = None;
    let mut stack = Vec::new();
    for s in samples {
        let nearest = if unmoved(s, a, b, same_triangles) {
            Nearest {
                triangle: s.face,
                distance_squared: 0.0,
            }
        } else {
            let hinted = b.nearest_hint(s.point, hint(s, same_triangles, twins, last));
            bound_sq += s.weight * hinted.distance_squared;
            // A sample of no weight counts only for the maximum: when its hint is no farther
            // than the maximum so far, the exact distance (no farther still) cannot change it.
            if s.weight == 0.0 && hinted.distance_squared <= max_sq {
                last = Some(hinted.triangle);
                continue;
            }
            b.nearest_from(s.point, hinted, &mut stack)
        };
        last = Some(nearest.triangle);
        area += s.weight;
        sum += s.weight * nearest.distance_squared.sqrt();
        sum_sq += s.weight * nearest.distance_squared;
        max_sq = max_sq.max(nearest.distance_squared);
    }
    averaged_over(area)?;
    Ok(OneSided {
        rms: (sum_sq / area).sqrt(),
        mean: sum / area,
        max: max_sq.sqrt(),
        samples: samples.len(),
        area,
        bound_rms: (bound_sq / area).sqrt(),
    })
}

/// Where the search for sample `s`'s nearest face starts. The same-numbered face is right when
/// the surfaces barely differ; without one, the previous sample's answer `last` (a neighbouring
/// sample has a neighbouring answer; both at once cost an exact distance per query for a bound
/// seldom tighter). A sample on an edge also tries the face across it: its bound is then the
/// true distance far more often (the measured / bound ratio that `eval`'s frame sampling scales
/// by went from 0.82 to 0.94 on chickenCrossing's tdct stream, spread over frames 2.4 → 1.5 %),
/// at no cost to a full measure (pdance 3.59–3.82 against 3.68–3.83 CPU s).
fn hint(
    s: &Sample,
    same_triangles: bool,
    twins: Option<&[u32]>,
    last: Option<u32>,
) -> impl Iterator<Item = u32> {
    let own = |f: u32| match twins {
        Some(t) => t.get(f as usize).copied().filter(|&f| f != NO_TWIN),
        None => same_triangles.then_some(f),
    };
    let (first, second) = (own(s.face), own(s.other_face));
    first.or(last).into_iter().chain(second)
}

/// Whether sample `s` lies on a face that did not move: it is then exactly on `b` (a query would
/// add rounding noise).
fn unmoved(s: &Sample, a: Surface<'_>, b: &TriangleBvh, same_triangles: bool) -> bool {
    same_triangles && b.corners(s.face) == Some(&corners(a, s.face))
}

/// [`one_sided`] bounded rather than measured: the distance to each sample's hint bounds its
/// distance to `b`, and only the samples whose bound exceeds `floor` (a distance found elsewhere)
/// are measured exactly. Gives the bound's area-weighted RMS and the largest exact distance above
/// `floor` (0 when none is): the maximum stays exact, the RMS is left to an estimate.
pub fn one_sided_bound(
    samples: &[Sample],
    a: Surface<'_>,
    b: &mut TriangleBvh,
    same_triangles: bool,
    twins: Option<&[u32]>,
    floor: f64,
) -> Result<(f64, f64)> {
    let (mut area, mut bound_sq, mut max_sq) = (0.0f64, 0.0f64, floor * floor);
    let mut last = None;
    let mut stack = Vec::new();
    for s in samples {
        area += s.weight;
        if unmoved(s, a, b, same_triangles) {
            continue;
        }
        let hinted = b.nearest_hint(s.point, hint(s, same_triangles, twins, last));
        bound_sq += s.weight * hinted.distance_squared;
        last = Some(hinted.triangle);
        if hinted.distance_squared > max_sq {
            let nearest = b.nearest_from(s.point, hinted, &mut stack);
            last = Some(nearest.triangle);
            max_sq = max_sq.max(nearest.distance_squared);
        }
    }
    averaged_over(area)?;
    // Only a distance beyond the floor raised the maximum.
    let found = if max_sq > floor * floor { max_sq } else { 0.0 };
    Ok(((bound_sq / area).sqrt(), found.sqrt()))
}

/// Refuses a surface of no area: a distance averaged over it is undefined.
fn averaged_over(area: f64) -> Result<()> {
    if area <= 0.0 || !area.is_finite() {
        return Err(Error::Mesh(
            "the surface has zero area, so a distance averaged over it is undefined".into(),
        ));
    }
    Ok(())
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
) -> Result<&'c mut TriangleBvh> {
    let refitted = slot
        .as_mut()
        .is_some_and(|t| t.refit(s.triangles, s.positions));
    if !refitted {
        *slot = Some(index_surface(s, which)?);
    }
    slot.as_mut()
        .ok_or_else(|| Error::Mesh(format!("the {which} mesh could not be indexed")))
}

/// Where both surfaces of a comparison are sampled, fixed for all frames.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfacePlans {
    /// The first (original) surface's plan.
    pub first: SamplingPlan,
    /// The second surface's plan.
    pub second: SamplingPlan,
    /// For each face of the first surface, the second's face on the same vertices ([`NO_TWIN`]
    /// if none), and the reverse; `None` when no face has a twin.
    twins: Option<(Vec<u32>, Vec<u32>)>,
}

impl SurfacePlans {
    /// Plans both surfaces from their reference frames `a` and `b` with the sample `spacing`
    /// (see `sampling::sample_spacing`).
    pub fn new(a: Surface<'_>, b: Surface<'_>, spacing: f64) -> Self {
        Self {
            first: SamplingPlan::new(a.triangles, a.positions, spacing),
            second: SamplingPlan::new(b.triangles, b.positions, spacing),
            twins: twins(a.triangles, b.triangles),
        }
    }

    /// Whether every face of each surface has a face on the same vertices in the other: each
    /// sample's hint is then its own face's twin, the same in every frame.
    pub fn faces_pair_up(&self) -> bool {
        self.twins.as_ref().is_some_and(|(f, b)| {
            f.iter().chain(b).all(|&t| t != NO_TWIN)
        })
    }
}

/// No face on the same vertices.
pub const NO_TWIN: u32 = u32::MAX;

/// Pairs the faces of `a` and `b` on the same three vertices, in both directions. A decoded
/// stream's faces are the original's in another order (the first-frame coder renumbers them), so
/// a sample's own face is found through this map; `None` when nothing pairs.
fn twins(a: &[Triangle], b: &[Triangle]) -> Option<(Vec<u32>, Vec<u32>)> {
    let key = |t: &Triangle| {
        let mut k = *t;
        k.sort_unstable();
        k
    };
    let mut of_b: FxHashMap<Triangle, u32> = FxHashMap::default();
    of_b.reserve(b.len());
    for (i, t) in b.iter().enumerate() {
        of_b.entry(key(t)).or_insert(i as u32);
    }
    let forward: Vec<u32> = a
        .iter()
        .map(|t| of_b.get(&key(t)).copied().unwrap_or(NO_TWIN))
        .collect();
    let mut backward = vec![NO_TWIN; b.len()];
    for (i, &f) in forward.iter().enumerate() {
        if let Some(slot) = backward.get_mut(f as usize) {
            *slot = i as u32;
        }
    }
    forward
        .iter()
        .any(|&f| f != NO_TWIN)
        .then_some((forward, backward))
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
    let (forward, backward) = both_ways(a, b, plans, cache, one_sided)?;
    Ok(FrameDistance { forward, backward })
}

/// `one_side(samples of a, a, b's index, same triangles, a's twins)` from the first surface to
/// the second and back, the samples placed by `plans` and the indexes refitted in `cache`.
fn both_ways<T>(
    a: Surface<'_>,
    b: Surface<'_>,
    plans: &SurfacePlans,
    cache: &mut IndexCache,
    mut one_side: impl FnMut(&[Sample], Surface<'_>, &mut TriangleBvh, bool, Option<&[u32]>) -> Result<T>,
) -> Result<(T, T)> {
    let same = a.triangles == b.triangles;
    let a_index = refit_or_build(&mut cache.first, a, "first")?;
    let b_index = refit_or_build(&mut cache.second, b, "second")?;
    plans
        .first
        .apply(a.triangles, a.positions, &mut cache.samples);
    let (a_twins, b_twins) = match &plans.twins {
        Some((f, b)) => (Some(f.as_slice()), Some(b.as_slice())),
        None => (None, None),
    };
    let forward = one_side(&cache.samples, a, b_index, same, a_twins)?;
    plans
        .second
        .apply(b.triangles, b.positions, &mut cache.samples);
    let backward = one_side(&cache.samples, b, a_index, same, b_twins)?;
    Ok((forward, backward))
}

/// What a frame not measured in full still gives: see [`frame_bound_planned`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameBound {
    /// The larger of the two one-sided [`OneSided::bound_rms`]: an upper bound on the frame's
    /// symmetric RMS, and the quantity an estimate of that RMS scales.
    pub bound_rms: f64,
    /// The frame's largest sampled distance when it exceeds the `floor` asked for, else 0.
    pub max: f64,
}

/// [`frame_distance_planned`] at a fraction of the cost: each sample's distance to its hint
/// only, and exact distances only where that bound exceeds `floor` (so the Hausdorff distance
/// stays exact when `floor` is one already found).
pub fn frame_bound_planned(
    a: Surface<'_>,
    b: Surface<'_>,
    plans: &SurfacePlans,
    cache: &mut IndexCache,
    floor: f64,
) -> Result<FrameBound> {
    let (forward, backward) = both_ways(a, b, plans, cache, |samples, a, b, same, twins| {
        one_sided_bound(samples, a, b, same, twins, floor)
    })?;
    Ok(FrameBound {
        bound_rms: forward.0.max(backward.0),
        max: forward.1.max(backward.1),
    })
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
    fn renumbered_faces_pair_up_and_measure_alike() {
        // A bumpy sheet, and a copy whose faces are listed backwards with their corners rotated
        // (as a decoded stream's are): the faces pair up, and the distances do not change.
        let n = 6u32;
        let mut t: Vec<Triangle> = Vec::new();
        for i in 0..n - 1 {
            for j in 0..n - 1 {
                let v = i * n + j;
                t.extend([[v, v + 1, v + n], [v + 1, v + n + 1, v + n]]);
            }
        }
        let at = |z: f32| -> Vec<Point> {
            (0..n * n)
                .map(|v| {
                    let (x, y) = ((v % n) as f32, (v / n) as f32);
                    [x, y, z * (x * 0.7).sin() * y]
                })
                .collect()
        };
        let (a, b) = (at(0.1), at(0.12));
        let renumbered: Vec<Triangle> = t.iter().rev().map(|f| [f[1], f[2], f[0]]).collect();
        let Some((forward, backward)) = twins(&t, &renumbered) else {
            panic!("no face paired");
        };
        let last = t.len() as u32 - 1;
        assert!(forward.iter().enumerate().all(|(i, &f)| f == last - i as u32));
        assert!(backward.iter().enumerate().all(|(i, &f)| f == last - i as u32));
        assert_eq!(twins(&t, &[[0, 0, 0]]), None);
        let measure = |bt: &[Triangle]| {
            let s = |tri, pos| Surface {
                triangles: tri,
                positions: pos,
            };
            let plans = SurfacePlans::new(s(&t, &a), s(bt, &b), 0.5);
            frame_distance_planned(s(&t, &a), s(bt, &b), &plans, &mut IndexCache::default())
                .unwrap_or_else(|e| panic!("{e}"))
        };
        let (same, other) = (measure(&t), measure(&renumbered));
        assert!(same.rms() > 0.0);
        // Rotated corners round differently in the last bits, nothing more.
        for (x, y) in [(same.forward, other.forward), (same.backward, other.backward)] {
            assert!((x.rms - y.rms).abs() <= 1e-12 * x.rms, "{x:?} {y:?}");
            assert!((x.max - y.max).abs() <= 1e-12 * x.max, "{x:?} {y:?}");
        }
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
