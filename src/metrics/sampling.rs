//! Deterministic area-weighted samples of a triangle surface, for integrating a distance over it.
//!
//! Each face is cut into `n²` similar sub-triangles (`n` from the face's longest edge and a spacing
//! relative to the bounding-box diagonal, see [`sample_spacing`]); each sub-triangle is integrated
//! with the 3-point edge-midpoint rule (a third of its area at each edge midpoint), exact for
//! quadratics. The squared distance from a face to the plane of a nearby face is exactly quadratic
//! across it, so the RMS converges far faster than with random samples, and no seed is needed.
//! Points shared by neighbouring faces (points on shared edges) are one sample carrying all their
//! weights. The sub-triangles' corners, the mesh vertices among them, where a displaced surface's
//! distance often peaks, are samples of no weight: they count for the maximum only, and come after
//! the weighted samples, so that most of them are settled by the maximum already found.

use super::triangle::{triangle_area, Vec3};
use crate::mesh::{Point, Triangle};
use rustc_hash::FxHashMap;

/// Samples per bounding-box diagonal: faces longer than `diagonal / SAMPLES_PER_DIAGONAL` are
/// subdivided. 50 agrees with Metro within the reference test's tolerance
/// (`tests/it/metrics_reference.rs`); denser sampling gains little for several times the work
/// (docs/design.md, "Surface RMSE: 50 samples per diagonal").
pub const SAMPLES_PER_DIAGONAL: f64 = 50.0;

/// Finest subdivision of one face: caps the work a single huge triangle can cause (16² sub-triangles).
pub const MAX_LEVEL: usize = 16;

/// Sample spacing for a surface whose reference bounding-box diagonal is `diagonal`.
pub fn sample_spacing(diagonal: f64) -> f64 {
    diagonal / SAMPLES_PER_DIAGONAL
}

/// A sample point: where, how much surface it stands for, and a face it lies on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Position.
    pub point: Vec3,
    /// Area it stands for.
    pub weight: f64,
    /// A face it lies on (the first one that produced it).
    pub face: u32,
    /// Another face it stands for (across the edge it lies on), or [`NO_FACE`].
    pub other_face: u32,
}

/// No other face.
pub const NO_FACE: u32 = u32::MAX;

fn position(positions: &[Point], i: u32) -> Vec3 {
    positions
        .get(i as usize)
        .map_or([0.0; 3], |p| [p[0] as f64, p[1] as f64, p[2] as f64])
}

fn longest_edge(c: &[Vec3; 3]) -> f64 {
    let len = |a: Vec3, b: Vec3| {
        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
    };
    len(c[0], c[1]).max(len(c[1], c[2])).max(len(c[2], c[0]))
}

/// Subdivision level for a face whose longest edge is `edge`.
fn level(edge: f64, spacing: f64) -> usize {
    if spacing > 0.0 && edge.is_finite() {
        ((edge / spacing).ceil() as usize).clamp(1, MAX_LEVEL)
    } else {
        1
    }
}

/// Where a lattice point of a face lies, as a key shared with the neighbouring faces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Shared {
    /// A mesh vertex.
    Vertex(u32),
    /// A point on the edge (lower vertex, higher vertex) of a face cut `2n` times, at lattice
    /// weight `k` of the lower vertex.
    Edge(u32, u32, usize, usize),
}

/// One planned sample: where on which face, and which faces' areas make up its weight.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Planned {
    face: u32,
    bary: [f64; 3],
    /// Range in [`SamplingPlan::shares`].
    shares: (u32, u32),
}

/// Where a surface is sampled, fixed once for every frame of an animation: per sample a face,
/// barycentric coordinates, and the fractions of the faces' areas it stands for. Making the plan
/// (the subdivision levels, the merging of shared points) is the costly part of sampling; applying
/// it to a frame is a few multiply-adds per sample.
#[derive(Debug, Clone, PartialEq)]
pub struct SamplingPlan {
    samples: Vec<Planned>,
    /// (face, fraction of its area).
    shares: Vec<(u32, f64)>,
}

/// The edge-midpoint rule's weight, as a fraction of a sub-triangle's area. (The 7-point rule,
/// exact for cubics, took twice the full queries on pdance for RMS values within 0.03 %:
/// docs/design.md, "Surface RMSE: 50 samples per diagonal".)
const MIDPOINT: f64 = 1.0 / 3.0;

impl SamplingPlan {
    /// Plans the samples of `triangles`, choosing each face's subdivision from its size at
    /// `positions` (the reference frame) and the `spacing`.
    pub fn new(triangles: &[Triangle], positions: &[Point], spacing: f64) -> Self {
        let mut planner = Planner {
            samples: Vec::with_capacity(4 * triangles.len()),
            shares: Vec::with_capacity(4 * triangles.len()),
            shared: FxHashMap::default(),
        };
        planner
            .shared
            .reserve(2 * triangles.len() + positions.len());
        for (f, t) in triangles.iter().enumerate() {
            let c = [
                position(positions, t[0]),
                position(positions, t[1]),
                position(positions, t[2]),
            ];
            let n = level(longest_edge(&c), spacing);
            let sub = 1.0 / (n * n) as f64;
            let face = f as u32;
            planner.add_lattice(face, t, n, sub);
        }
        planner.finish()
    }

    #[cfg(any(test, feature = "internals"))]
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    #[cfg(any(test, feature = "internals"))]
    /// True when the surface has no faces.
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// The samples of `triangles` (those the plan was made for) at `positions`, into `out`;
    /// the weights sum to the frame's total area.
    pub fn apply(&self, triangles: &[Triangle], positions: &[Point], out: &mut Vec<Sample>) {
        let corners = |f: u32| -> [Vec3; 3] {
            triangles.get(f as usize).map_or([[0.0; 3]; 3], |t| {
                [
                    position(positions, t[0]),
                    position(positions, t[1]),
                    position(positions, t[2]),
                ]
            })
        };
        let areas: Vec<f64> = (0..triangles.len() as u32)
            .map(|f| {
                let c = corners(f);
                triangle_area(c[0], c[1], c[2])
            })
            .collect();
        out.clear();
        out.extend(self.samples.iter().map(|s| {
            let c = corners(s.face);
            let mut point = [0.0; 3];
            for (a, x) in point.iter_mut().enumerate() {
                *x = s.bary[0] * c[0][a] + s.bary[1] * c[1][a] + s.bary[2] * c[2][a];
            }
            let shares = self
                .shares
                .get(s.shares.0 as usize..s.shares.1 as usize)
                .unwrap_or(&[]);
            let weight = shares
                .iter()
                .map(|&(f, fraction)| fraction * areas.get(f as usize).copied().unwrap_or(0.0))
                .sum();
            let other_face = shares
                .iter()
                .map(|&(f, _)| f)
                .find(|&f| f != s.face)
                .unwrap_or(NO_FACE);
            Sample {
                point,
                weight,
                face: s.face,
                other_face,
            }
        }));
    }
}

#[cfg(any(test, feature = "internals"))]
/// Samples the surface of `triangles` at `positions` with the given `spacing`; the weights sum to
/// the total area. (A plan made and applied at once; see [`SamplingPlan`] to reuse one.)
pub fn sample_surface(triangles: &[Triangle], positions: &[Point], spacing: f64) -> Vec<Sample> {
    let mut out = Vec::new();
    SamplingPlan::new(triangles, positions, spacing).apply(triangles, positions, &mut out);
    out
}

/// [`SamplingPlan::new`] under way: the samples so far, the faces each stands for, and the
/// sample at each point shared between faces.
struct Planner {
    samples: Vec<Planned>,
    shares: Vec<Vec<(u32, f64)>>,
    shared: FxHashMap<Shared, usize>,
}

impl Planner {
    /// Corners and edge midpoints of the sub-triangles of `face` (`t`) cut `n` times: the lattice
    /// of step 1/(2n); a point on a mesh vertex or edge joins the sample already there.
    fn add_lattice(&mut self, face: u32, t: &Triangle, n: usize, sub: f64) {
        let m = 2 * n;
        for i in 0..=m {
            for j in 0..=(m - i) {
                let k = m - i - j;
                let fraction = lattice_fraction(i, j, k) * sub;
                let key = lattice_key(t, i, j, k, m);
                if let Some(list) = key
                    .as_ref()
                    .and_then(|k| self.shared.get(k))
                    .and_then(|&s| self.shares.get_mut(s))
                {
                    list.push((face, fraction));
                    continue;
                }
                if let Some(key) = key {
                    self.shared.insert(key, self.samples.len());
                }
                let bary = [i, j, k].map(|x| x as f64 / m as f64);
                self.samples.push(Planned {
                    face,
                    bary,
                    shares: (0, 0),
                });
                self.shares.push(vec![(face, fraction)]);
            }
        }
    }

    /// Flattens the shares into one list the samples index, the weighted samples first (in the
    /// order planned, so neighbours stay neighbours), then those of no weight.
    fn finish(self) -> SamplingPlan {
        let Self {
            samples, shares, ..
        } = self;
        let weighted = |list: &Vec<(u32, f64)>| list.iter().any(|&(_, f)| f > 0.0);
        let mut flat = Vec::with_capacity(shares.iter().map(Vec::len).sum());
        let mut ordered = Vec::with_capacity(samples.len());
        for want in [true, false] {
            for (s, list) in samples.iter().zip(&shares) {
                if weighted(list) != want {
                    continue;
                }
                let start = flat.len() as u32;
                flat.extend(list.iter().filter(|&&(_, f)| f > 0.0));
                ordered.push(Planned {
                    shares: (start, flat.len() as u32),
                    ..*s
                });
            }
        }
        SamplingPlan {
            samples: ordered,
            shares: flat,
        }
    }
}

/// The fraction of a sub-triangle's area that lattice point (i, j, k) stands for.
fn lattice_fraction(i: usize, j: usize, k: usize) -> f64 {
    let zeros = [i, j, k].iter().filter(|&&x| x == 0).count();
    let corner = i % 2 == 0 && j % 2 == 0 && k % 2 == 0;
    // A corner has no weight; a midpoint belongs to 1 sub-triangle on a face edge, 2 inside.
    match (corner, zeros) {
        (true, _) => 0.0,
        (false, 1) => MIDPOINT,
        (false, _) => 2.0 * MIDPOINT,
    }
}

/// The mesh vertex or edge point that lattice point (i, j, k) of `t` lies on, if any.
fn lattice_key(t: &Triangle, i: usize, j: usize, k: usize, m: usize) -> Option<Shared> {
    match (i, j, k) {
        (_, 0, 0) => Some(Shared::Vertex(t[0])),
        (0, _, 0) => Some(Shared::Vertex(t[1])),
        (0, 0, _) => Some(Shared::Vertex(t[2])),
        (0, _, _) => Some(edge_key(t[1], j, t[2], k, m)),
        (_, 0, _) => Some(edge_key(t[0], i, t[2], k, m)),
        (_, _, 0) => Some(edge_key(t[0], i, t[1], j, m)),
        _ => None,
    }
}

/// The key of a lattice point on the edge between vertices `a` (lattice weight `wa`) and `b`.
fn edge_key(a: u32, wa: usize, b: u32, wb: usize, m: usize) -> Shared {
    if a <= b {
        Shared::Edge(a, b, m, wa)
    } else {
        Shared::Edge(b, a, m, wb)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_sum_to_the_area_at_every_level() {
        let positions = [[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [0.0, 4.0, 0.0]];
        for spacing in [10.0, 2.0, 0.7, 0.3, 0.01] {
            let s = sample_surface(&[[0, 1, 2]], &positions, spacing);
            let total: f64 = s.iter().map(|s| s.weight).sum();
            assert!((total - 6.0).abs() < 1e-12, "spacing {spacing}: {total}");
            assert!(s.iter().all(|s| s.weight >= 0.0));
            assert!(s.iter().filter(|s| s.weight > 0.0).count() >= 3);
        }
    }

    #[test]
    fn integrates_a_quadratic_exactly_and_a_cubic_ever_better() {
        // Over the triangle (0,0),(1,0),(0,1): ∫ x = 1/6, ∫ x² = 1/12, ∫ xy = 1/24, ∫ x³ = 1/20.
        let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        type Integrand = fn(Vec3) -> f64;
        let cases: [(Integrand, f64); 3] = [
            (|p| p[0], 1.0 / 6.0),
            (|p| p[0].powi(2), 1.0 / 12.0),
            (|p| p[0] * p[1], 1.0 / 24.0),
        ];
        let integral = |s: &[Sample], f: Integrand| -> f64 { s.iter().map(|s| s.weight * f(s.point)).sum() };
        let mut cubic_error = f64::INFINITY;
        for spacing in [2.0, 0.4, 0.1] {
            let s = sample_surface(&[[0, 1, 2]], &positions, spacing);
            for (f, want) in cases {
                let got = integral(&s, f);
                assert!((got - want).abs() < 1e-12, "{got} vs {want}");
            }
            // Not exact for a cubic, but converging as the sub-triangles shrink.
            let error = (integral(&s, |p| p[0].powi(3)) - 1.0 / 20.0).abs();
            assert!(error > 0.0 && error < cubic_error, "spacing {spacing}: {error}");
            cubic_error = error;
        }
        assert!(cubic_error < 1e-4, "{cubic_error}");
    }

    #[test]
    fn corners_come_last_with_no_weight() {
        let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let s = sample_surface(&[[0, 1, 2]], &positions, 0.5);
        let weighted = s.iter().take_while(|s| s.weight > 0.0).count();
        assert!(s[weighted..].iter().all(|s| s.weight == 0.0));
        // Level 3: 3² sub-triangles with 18 distinct edge midpoints, and 10 corners.
        assert_eq!((weighted, s.len() - weighted), (18, 10));
        // The mesh vertices are among the corners, for the maximum.
        for corner in positions {
            let c = corner.map(f64::from);
            assert!(s[weighted..].iter().any(|s| s.point == c), "{c:?}");
        }
    }

    #[test]
    fn points_on_a_shared_edge_are_one_sample() {
        // Two triangles sharing edge 1–2, walked in opposite directions.
        let positions = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
        ];
        let tris = [[0, 1, 2], [3, 2, 1]];
        for (spacing, level) in [(2.0, 1usize), (0.5, 3)] {
            let s = sample_surface(&tris, &positions, spacing);
            // Per face: the (2L+1)(2L+2)/2 lattice points; the shared edge holds 2L+1 of them.
            let per_face = (level + 1) * (2 * level + 1);
            assert_eq!(s.len(), 2 * per_face - (2 * level + 1), "level {level}");
            let total: f64 = s.iter().map(|s| s.weight).sum();
            assert!((total - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn finer_spacing_gives_more_samples() {
        let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let coarse = sample_surface(&[[0, 1, 2]], &positions, 2.0).len();
        let fine = sample_surface(&[[0, 1, 2]], &positions, 0.1).len();
        assert_eq!(coarse, 3 + 3);
        assert!(fine > 10 * coarse);
    }
}
