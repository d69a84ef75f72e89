//! Exact distance from a point to a triangle in 3D, in `f64`.
//!
//! Written here rather than taken from a crate because it is a few lines (the Voronoi-region walk of
//! Ericson, *Real-Time Collision Detection* §5.1.5) and the hot loop of every surface measure: it must
//! take plain arrays, stay in `f64`, and never divide by zero on the degenerate triangles real meshes
//! contain.

pub use crate::mesh::vector::Vec3;
use crate::mesh::vector::{cross, sub};

fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a + s·u + t·v`.
fn affine(a: Vec3, u: Vec3, s: f64, v: Vec3, t: f64) -> Vec3 {
    [
        a[0] + s * u[0] + t * v[0],
        a[1] + s * u[1] + t * v[1],
        a[2] + s * u[2] + t * v[2],
    ]
}

/// Squared distance between two points.
pub fn distance_squared(a: Vec3, b: Vec3) -> f64 {
    let d = sub(a, b);
    dot(d, d)
}

/// Area of the triangle `abc`.
pub fn triangle_area(a: Vec3, b: Vec3, c: Vec3) -> f64 {
    let n = cross(sub(b, a), sub(c, a));
    0.5 * dot(n, n).sqrt()
}

/// The point of segment `ab` closest to `p` (a zero-length segment is its one point).
pub fn closest_point_on_segment(p: Vec3, a: Vec3, b: Vec3) -> Vec3 {
    let ab = sub(b, a);
    let len2 = dot(ab, ab);
    if len2 <= 0.0 {
        return a;
    }
    let t = (dot(sub(p, a), ab) / len2).clamp(0.0, 1.0);
    affine(a, ab, t, ab, 0.0)
}

/// Relative size of `|ab × ac|²` against `|ab|²·|ac|²` below which a triangle is treated as a segment:
/// the face-region formulas divide by `|ab × ac|²`, which loses every digit near zero.
const DEGENERATE_SINE_SQUARED: f64 = 1e-14;

#[cfg(any(test, feature = "internals"))]
/// The point of triangle `abc` (edges and interior included) closest to `p`.
///
/// Every Voronoi region (three vertices, three edges, the face) is handled; a degenerate triangle
/// (collinear or coincident corners) is treated as the union of its three edges.
pub fn closest_point_on_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    PreparedTriangle::new([a, b, c]).closest_point(p)
}

/// A triangle with what every distance query to it needs computed once (two edge vectors and
/// whether it is degenerate): the surface measures ask each triangle of a frame for the distance
/// to several points. The answers are those of [`closest_point_on_triangle`] to the last bit.
#[derive(Debug, Clone, Copy)]
pub struct PreparedTriangle {
    /// The corners.
    pub corners: [Vec3; 3],
    ab: Vec3,
    ac: Vec3,
    /// Collinear or coincident corners: the triangle is its three edges.
    degenerate: bool,
}

impl PreparedTriangle {
    /// Prepares the triangle with `corners`.
    pub fn new(corners: [Vec3; 3]) -> Self {
        let [a, b, c] = corners;
        let ab = sub(b, a);
        let ac = sub(c, a);
        let n = cross(ab, ac);
        let n2 = dot(n, n);
        Self {
            corners,
            ab,
            ac,
            degenerate: n2 <= DEGENERATE_SINE_SQUARED * dot(ab, ab) * dot(ac, ac) || n2 == 0.0,
        }
    }

    /// Whether the triangle's plane alone puts `p` beyond `bound` (a squared distance), so that
    /// the triangle is no nearer: a dozen multiplications against the Voronoi walk. The margin
    /// covers the rounding of both computations; a degenerate triangle is never judged so.
    pub fn plane_beyond(&self, p: Vec3, bound: f64) -> bool {
        if self.degenerate {
            return false;
        }
        let n = cross(self.ab, self.ac);
        let d = dot(n, sub(p, self.corners[0]));
        d * d * (1.0 - 1e-6) > bound * dot(n, n)
    }

    /// Squared distance from `p` to the triangle.
    pub fn distance_squared(&self, p: Vec3) -> f64 {
        distance_squared(p, self.closest_point(p))
    }

    /// The point of the triangle closest to `p` (Ericson's Voronoi-region walk).
    pub fn closest_point(&self, p: Vec3) -> Vec3 {
        let [a, b, c] = self.corners;
        if self.degenerate {
            return closest_on_edges(p, a, b, c);
        }
        let (ab, ac) = (self.ab, self.ac);
        let ap = sub(p, a);
        let d1 = dot(ab, ap);
        let d2 = dot(ac, ap);
        if d1 <= 0.0 && d2 <= 0.0 {
            return a;
        }
        let bp = sub(p, b);
        let d3 = dot(ab, bp);
        let d4 = dot(ac, bp);
        if d3 >= 0.0 && d4 <= d3 {
            return b;
        }
        let vc = d1 * d4 - d3 * d2;
        if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
            return affine(a, ab, d1 / (d1 - d3), ac, 0.0);
        }
        let cp = sub(p, c);
        let d5 = dot(ab, cp);
        let d6 = dot(ac, cp);
        if d6 >= 0.0 && d5 <= d6 {
            return c;
        }
        let vb = d5 * d2 - d1 * d6;
        if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
            return affine(a, ab, 0.0, ac, d2 / (d2 - d6));
        }
        let va = d3 * d6 - d5 * d4;
        if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
            let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
            let bc = sub(c, b);
            return affine(b, bc, w, bc, 0.0);
        }
        // Face region: va + vb + vc = |ab × ac|², which the degeneracy test keeps away from zero.
        let inv = 1.0 / (va + vb + vc);
        affine(a, ab, vb * inv, ac, vc * inv)
    }
}

fn closest_on_edges(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    let candidates = [
        closest_point_on_segment(p, a, b),
        closest_point_on_segment(p, b, c),
        closest_point_on_segment(p, c, a),
    ];
    let mut best = candidates[0];
    let mut best_d = distance_squared(p, best);
    for q in &candidates[1..] {
        let d = distance_squared(p, *q);
        if d < best_d {
            best = *q;
            best_d = d;
        }
    }
    best
}

#[cfg(any(test, feature = "internals"))]
/// Squared distance from `p` to triangle `abc`.
pub fn point_triangle_distance_squared(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> f64 {
    distance_squared(p, closest_point_on_triangle(p, a, b, c))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_xoshiro::rand_core::{RngCore, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    fn uniform(rng: &mut Xoshiro256PlusPlus) -> f64 {
        (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }

    fn random_point(rng: &mut Xoshiro256PlusPlus) -> Vec3 {
        [uniform(rng), uniform(rng), uniform(rng)]
    }

    /// An independent answer: the plane projection when it falls inside (by barycentric signs),
    /// else the nearest of the three edges.
    fn brute_force(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> f64 {
        let mut best = [(a, b), (b, c), (c, a)]
            .iter()
            .map(|&(s, t)| distance_squared(p, closest_point_on_segment(p, s, t)))
            .fold(f64::INFINITY, f64::min);
        let n = cross(sub(b, a), sub(c, a));
        let n2 = dot(n, n);
        if n2 > 1e-20 {
            let h = dot(sub(p, a), n) / n2;
            let q = affine(p, n, -h, n, 0.0);
            let inside = [(a, b), (b, c), (c, a)]
                .iter()
                .all(|&(s, t)| dot(cross(sub(t, s), sub(q, s)), n) >= 0.0);
            if inside {
                best = best.min(distance_squared(p, q));
            }
        }
        best
    }

    #[test]
    fn matches_brute_force_on_random_triangles() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
        for _ in 0..20_000 {
            let (a, b, c, p) = (
                random_point(&mut rng),
                random_point(&mut rng),
                random_point(&mut rng),
                [
                    3.0 * uniform(&mut rng),
                    3.0 * uniform(&mut rng),
                    3.0 * uniform(&mut rng),
                ],
            );
            let got = point_triangle_distance_squared(p, a, b, c);
            let want = brute_force(p, a, b, c);
            assert!(
                (got - want).abs() <= 1e-9 * (1.0 + want),
                "p={p:?} abc={a:?} {b:?} {c:?}: {got} vs {want}"
            );
        }
    }

    #[test]
    fn never_farther_than_dense_samples_of_the_triangle() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
        let n = 40;
        for _ in 0..200 {
            let (a, b, c, p) = (
                random_point(&mut rng),
                random_point(&mut rng),
                random_point(&mut rng),
                random_point(&mut rng),
            );
            let got = point_triangle_distance_squared(p, a, b, c).sqrt();
            let mut sampled = f64::INFINITY;
            for i in 0..=n {
                for j in 0..=(n - i) {
                    let (s, t) = (i as f64 / n as f64, j as f64 / n as f64);
                    let q = affine(a, sub(b, a), s, sub(c, a), t);
                    sampled = sampled.min(distance_squared(p, q).sqrt());
                }
            }
            assert!(got <= sampled + 1e-12, "{got} > sampled {sampled}");
            // The lattice is at most one cell (≤ 2·√3 / n for corners in [-1,1]³) from any point.
            assert!(sampled - got <= 2.0 * 3f64.sqrt() / n as f64);
        }
    }

    #[test]
    fn every_voronoi_region_of_a_unit_triangle() {
        let (a, b, c) = ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        let cases: [(Vec3, Vec3); 7] = [
            ([-1.0, -1.0, 0.0], a),
            ([2.0, -0.5, 0.0], b),
            ([-0.5, 2.0, 1.0], c),
            ([0.5, -1.0, 0.0], [0.5, 0.0, 0.0]),
            ([-1.0, 0.5, 0.0], [0.0, 0.5, 0.0]),
            ([1.0, 1.0, 0.0], [0.5, 0.5, 0.0]),
            ([0.25, 0.25, 3.0], [0.25, 0.25, 0.0]),
        ];
        for (p, want) in cases {
            let got = closest_point_on_triangle(p, a, b, c);
            assert!(distance_squared(got, want) < 1e-24, "{p:?}: {got:?}");
        }
    }

    #[test]
    fn degenerate_triangles_are_their_edges() {
        let p = [0.5, 1.0, 0.0];
        // Collinear corners.
        let d = point_triangle_distance_squared(p, [0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]);
        assert!((d - 1.0).abs() < 1e-12);
        // Two coincident corners.
        let d = point_triangle_distance_squared(p, [0.0; 3], [0.0; 3], [1.0, 0.0, 0.0]);
        assert!((d - 1.0).abs() < 1e-12);
        // All three coincide.
        let d =
            point_triangle_distance_squared(p, [1.0, 1.0, 0.0], [1.0, 1.0, 0.0], [1.0, 1.0, 0.0]);
        assert!((d - 0.25).abs() < 1e-12);
        assert!(d.is_finite());
    }
}
