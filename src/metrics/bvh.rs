//! A bounding-volume hierarchy over one frame's triangles, for nearest-triangle queries.
//!
//! Written here rather than taken from a crate: the `bvh` crate's `nearest_to` starts every query
//! from an unbounded search and stores `f32` shapes of its own type, and `parry3d` brings a second math
//! stack (glam) and `f32` only. The surface measures make tens of millions of queries whose answer is
//! almost always the triangle the previous sample hit (or the same-numbered triangle, when the
//! connectivity is shared), so the query takes a *hint* triangle whose distance bounds the search from
//! the start; that bound is what makes a 200-frame sequence take seconds. A uniform grid
//! ([`super::grid`]) settles almost every such query; the tree, a plain median split, takes the
//! rest. It is built in O(n log n) when a query first needs it and refitted in O(n) when one needs
//! it in a later frame, so the frames the grid settles whole never pay for it.

use super::grid::TriangleGrid;
use super::triangle::{PreparedTriangle, Vec3};
use crate::mesh::{Point, Triangle};

/// Triangles per leaf: a few exact distance tests are cheaper than another level of boxes.
const LEAF_SIZE: usize = 4;

#[cfg(any(test, feature = "internals"))]
/// Room for the traversal stack of any tree: median splits halve the count, so 2³² triangles need
/// at most 32 levels.
const MAX_DEPTH: usize = 64;

#[derive(Debug, Clone, Copy)]
struct Node {
    lo: Vec3,
    hi: Vec3,
    /// Leaf: first triangle slot in `order`; inner: index of the left child (the right one follows
    /// the left subtree, at `right`).
    first: u32,
    /// Leaf: number of triangles (> 0); inner: 0.
    count: u32,
    /// Inner: index of the right child.
    right: u32,
    /// Index of the parent ([`NO_NODE`] at the root).
    parent: u32,
}

/// The root's parent.
const NO_NODE: u32 = u32::MAX;

impl Node {
    fn distance_squared(&self, p: Vec3) -> f64 {
        let mut d2 = 0.0;
        for ((lo, hi), x) in self.lo.iter().zip(&self.hi).zip(&p) {
            let d = (lo - x).max(x - hi).max(0.0);
            d2 += d * d;
        }
        d2
    }
}

/// The nearest triangle to a query point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Nearest {
    /// Index of the triangle in the slice the tree was built from.
    pub triangle: u32,
    /// Squared distance from the query point to that triangle.
    pub distance_squared: f64,
}

/// Nearest-triangle index over one set of triangle positions.
#[derive(Debug, Clone)]
pub struct TriangleBvh {
    /// The triangles, indexed by the caller's triangle number.
    triangles: Vec<PreparedTriangle>,
    /// Settles most hinted queries without the tree (see [`super::grid`]).
    grid: TriangleGrid,
    /// Whether the grid holds the triangles as they are now (false after a refit, until a query
    /// needs it: a frame `eval` only bounds may never do).
    gridded: bool,
    /// The tree, built when a query first needs it: most measures never do.
    tree: Option<Tree>,
    /// Whether the tree's boxes hold the triangles as they are now (false after a refit, until a
    /// query needs the tree).
    fitted: bool,
}

/// The hierarchy of boxes.
#[derive(Debug, Clone)]
struct Tree {
    nodes: Vec<Node>,
    /// Triangle numbers in leaf order.
    order: Vec<u32>,
    /// The leaf holding each triangle.
    leaf_of: Vec<u32>,
}

/// The triangles at `positions`, prepared for distance queries.
fn prepared<'a>(
    triangles: &'a [Triangle],
    positions: &'a [Point],
) -> impl Iterator<Item = PreparedTriangle> + 'a {
    let at = |i: u32| -> Vec3 {
        positions
            .get(i as usize)
            .map_or([0.0; 3], |p| [p[0] as f64, p[1] as f64, p[2] as f64])
    };
    triangles
        .iter()
        .map(move |t| PreparedTriangle::new([at(t[0]), at(t[1]), at(t[2])]))
}

impl TriangleBvh {
    /// Indexes `triangles` placed at `positions`; `None` when there are no triangles.
    ///
    /// Every index must be in range of `positions` (as [`crate::AnimatedMesh`] guarantees);
    /// a triangle with an out-of-range index is placed at the origin rather than panicking.
    pub fn new(triangles: &[Triangle], positions: &[Point]) -> Option<Self> {
        if triangles.is_empty() {
            return None;
        }
        let triangles: Vec<PreparedTriangle> = prepared(triangles, positions).collect();
        Some(Self {
            triangles,
            grid: TriangleGrid::default(),
            gridded: false,
            tree: None,
            fitted: false,
        })
    }

    /// Moves the index's triangles to `positions` (the same `triangles` it was built from, in a
    /// later frame). The tree, when there is one, keeps its shape and has its boxes refitted when
    /// a query next needs it: far cheaper than a rebuild, and as good while the motion keeps
    /// neighbouring triangles together (the answer is exact either way). Returns false, changing
    /// nothing, when `triangles` is not the size the index was built for.
    pub fn refit(&mut self, triangles: &[Triangle], positions: &[Point]) -> bool {
        if triangles.len() != self.triangles.len() {
            return false;
        }
        for (slot, t) in self.triangles.iter_mut().zip(prepared(triangles, positions)) {
            *slot = t;
        }
        self.gridded = false;
        self.fitted = false;
        true
    }

    /// Makes the tree hold the triangles as they are now: built on first use, refitted after
    /// a move.
    fn fit_tree(&mut self) {
        match &mut self.tree {
            Some(tree) if !self.fitted => tree.refit(&self.triangles),
            Some(_) => {}
            None => self.tree = Some(Tree::new(&self.triangles)),
        }
        self.fitted = true;
    }

    /// The corner positions of triangle `t` as the index holds them.
    pub fn corners(&self, t: u32) -> Option<&[Vec3; 3]> {
        self.triangles.get(t as usize).map(|t| &t.corners)
    }

    #[cfg(any(test, feature = "internals"))]
    /// Number of triangles in the index.
    pub fn len(&self) -> usize {
        self.triangles.len()
    }

    #[cfg(any(test, feature = "internals"))]
    /// Always false: an index is never built over no triangles.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    fn triangle_distance_squared(&self, t: u32, p: Vec3) -> f64 {
        self.triangles
            .get(t as usize)
            .map_or(f64::INFINITY, |t| t.distance_squared(p))
    }

    #[cfg(any(test, feature = "internals"))]
    /// The triangle nearest to `p`. `hint`, a triangle likely to be near (out-of-range hints are
    /// ignored), only speeds the search up: the answer is exact either way.
    pub fn nearest(&mut self, p: Vec3, hint: Option<u32>) -> Nearest {
        let best = self.nearest_hint(p, hint);
        self.nearest_from(p, best, &mut Vec::with_capacity(MAX_DEPTH))
    }

    /// The nearest of the `hints` to `p` (infinitely far when there is none): an upper bound on
    /// the distance to the surface, which is all a sample that only counts for the maximum may
    /// need.
    pub fn nearest_hint(&self, p: Vec3, hints: impl IntoIterator<Item = u32>) -> Nearest {
        let mut best = Nearest {
            triangle: 0,
            distance_squared: f64::INFINITY,
        };
        for h in hints {
            let d = self.triangle_distance_squared(h, p);
            if d < best.distance_squared {
                best = Nearest {
                    triangle: h,
                    distance_squared: d,
                };
            }
        }
        best
    }

    /// The triangle nearest to `p`, searching from `best` (a triangle of this index and its
    /// distance, or an infinite distance; see [`Self::nearest_hint`]), which only bounds the
    /// search; a caller-kept traversal `stack` spares a run of queries any allocation.
    pub fn nearest_from(
        &mut self,
        p: Vec3,
        mut best: Nearest,
        stack: &mut Vec<(u32, f64)>,
    ) -> Nearest {
        // A near hint bounds the search to a few grid cells.
        let mut found = (best.distance_squared, best.triangle);
        if !self.gridded {
            self.grid.rebuild(&self.triangles);
            self.gridded = true;
        }
        if self.grid.improve(p, &self.triangles, &mut found) {
            return Nearest {
                triangle: found.1,
                distance_squared: found.0,
            };
        }
        self.fit_tree();
        if let Some(tree) = &self.tree {
            tree.nearest_from(p, &mut best, &self.triangles, stack);
        }
        best
    }
}

impl Tree {
    /// A median-split tree over `triangles`.
    fn new(triangles: &[PreparedTriangle]) -> Self {
        let centroids: Vec<Vec3> = triangles
            .iter()
            .map(|t| {
                let c = &t.corners;
                let mut m = [0.0; 3];
                for (a, v) in m.iter_mut().enumerate() {
                    *v = (c[0][a] + c[1][a] + c[2][a]) / 3.0;
                }
                m
            })
            .collect();
        let mut order: Vec<u32> = (0..triangles.len() as u32).collect();
        let mut nodes = Vec::with_capacity(2 * triangles.len() / LEAF_SIZE + 1);
        build(&mut nodes, &mut order, 0, NO_NODE, triangles, &centroids);
        let mut leaf_of = vec![0u32; triangles.len()];
        for (i, n) in nodes.iter().enumerate().filter(|(_, n)| n.count > 0) {
            let held = order
                .get(n.first as usize..(n.first + n.count) as usize)
                .unwrap_or(&[]);
            for &t in held {
                if let Some(slot) = leaf_of.get_mut(t as usize) {
                    *slot = i as u32;
                }
            }
        }
        Self {
            nodes,
            order,
            leaf_of,
        }
    }

    /// Refits every box to `triangles`, keeping the tree's shape.
    fn refit(&mut self, triangles: &[PreparedTriangle]) {
        // Children follow their parent in `nodes`, so a backward sweep sees children first.
        for i in (0..self.nodes.len()).rev() {
            let Some(&n) = self.nodes.get(i) else {
                continue;
            };
            let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
            let mut grow = |p: &Vec3| {
                for a in 0..3 {
                    lo[a] = lo[a].min(p[a]);
                    hi[a] = hi[a].max(p[a]);
                }
            };
            if n.count > 0 {
                for &t in self.leaf(&n) {
                    if let Some(t) = triangles.get(t as usize) {
                        t.corners.iter().for_each(&mut grow);
                    }
                }
            } else {
                for child in [n.first, n.right] {
                    if let Some(c) = self.nodes.get(child as usize) {
                        grow(&c.lo);
                        grow(&c.hi);
                    }
                }
            }
            if let Some(node) = self.nodes.get_mut(i) {
                node.lo = lo;
                node.hi = hi;
            }
        }
    }

    /// Lowers `best` to the triangle nearest to `p`.
    fn nearest_from(
        &self,
        p: Vec3,
        best: &mut Nearest,
        triangles: &[PreparedTriangle],
        stack: &mut Vec<(u32, f64)>,
    ) {
        // Climb from the hint's leaf: every other subtree is the sibling of a node on that path,
        // and the siblings far from `p` are dismissed by one box test each. That skips the
        // descent from the root, which was most of the cost of a well-hinted query.
        let Some(&start) = self
            .leaf_of
            .get(best.triangle as usize)
            .filter(|_| best.distance_squared.is_finite())
        else {
            self.descend(0, p, best, triangles, stack);
            return;
        };
        self.descend(start, p, best, triangles, stack);
        let (mut child, mut node) = (
            start,
            self.nodes.get(start as usize).map_or(NO_NODE, |n| n.parent),
        );
        while let Some(n) = self.nodes.get(node as usize) {
            let sibling = if n.first == child { n.right } else { n.first };
            if self.box_distance(sibling, p) < best.distance_squared {
                self.descend(sibling, p, best, triangles, stack);
            }
            child = node;
            node = n.parent;
        }
    }

    /// Searches the subtree under `start` for anything nearer than `best`.
    fn descend(
        &self,
        start: u32,
        p: Vec3,
        best: &mut Nearest,
        triangles: &[PreparedTriangle],
        stack: &mut Vec<(u32, f64)>,
    ) {
        stack.clear();
        let mut node = start;
        while let Some(n) = self.nodes.get(node as usize) {
            if n.count > 0 {
                for &t in self.leaf(n) {
                    let Some(tri) = triangles.get(t as usize) else {
                        continue;
                    };
                    // The triangle's own box: a few comparisons that spare most exact tests.
                    if corner_box_distance_squared(&tri.corners, p) >= best.distance_squared {
                        continue;
                    }
                    let d = tri.distance_squared(p);
                    if d < best.distance_squared {
                        *best = Nearest {
                            triangle: t,
                            distance_squared: d,
                        };
                    }
                }
            } else {
                let (l, r) = (n.first, n.right);
                let dl = self.box_distance(l, p);
                let dr = self.box_distance(r, p);
                let (near, d_near, far, d_far) = if dl <= dr {
                    (l, dl, r, dr)
                } else {
                    (r, dr, l, dl)
                };
                if d_near < best.distance_squared {
                    if d_far < best.distance_squared {
                        stack.push((far, d_far));
                    }
                    node = near;
                    continue;
                }
            }
            // Pop the next subtree that can still hold something nearer than the best so far.
            let mut next = None;
            while let Some((candidate, d)) = stack.pop() {
                if d < best.distance_squared {
                    next = Some(candidate);
                    break;
                }
            }
            match next {
                Some(c) => node = c,
                None => break,
            }
        }
    }

    /// The triangles of leaf `n` (none for an inner node).
    fn leaf(&self, n: &Node) -> &[u32] {
        self.order
            .get(n.first as usize..(n.first + n.count) as usize)
            .unwrap_or(&[])
    }

    fn box_distance(&self, node: u32, p: Vec3) -> f64 {
        self.nodes
            .get(node as usize)
            .map_or(f64::INFINITY, |n| n.distance_squared(p))
    }
}

/// Squared distance from `p` to the bounding box of a triangle's corners.
fn corner_box_distance_squared(c: &[Vec3; 3], p: Vec3) -> f64 {
    let mut d2 = 0.0;
    for (a, x) in p.iter().enumerate() {
        let lo = c[0][a].min(c[1][a]).min(c[2][a]);
        let hi = c[0][a].max(c[1][a]).max(c[2][a]);
        let d = (lo - x).max(x - hi).max(0.0);
        d2 += d * d;
    }
    d2
}

/// Builds the subtree over `order[..]` (whose first slot is `offset` in the whole order) and returns
/// its node index.
fn build(
    nodes: &mut Vec<Node>,
    order: &mut [u32],
    offset: usize,
    parent: u32,
    triangles: &[PreparedTriangle],
    centroids: &[Vec3],
) -> u32 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    let mut clo = [f64::INFINITY; 3];
    let mut chi = [f64::NEG_INFINITY; 3];
    for &t in order.iter() {
        if let (Some(t), Some(m)) = (triangles.get(t as usize), centroids.get(t as usize)) {
            for a in 0..3 {
                for v in &t.corners {
                    lo[a] = lo[a].min(v[a]);
                    hi[a] = hi[a].max(v[a]);
                }
                clo[a] = clo[a].min(m[a]);
                chi[a] = chi[a].max(m[a]);
            }
        }
    }
    let index = nodes.len() as u32;
    nodes.push(Node {
        lo,
        hi,
        first: offset as u32,
        count: order.len() as u32,
        right: 0,
        parent,
    });
    if order.len() <= LEAF_SIZE {
        return index;
    }
    let extent = [chi[0] - clo[0], chi[1] - clo[1], chi[2] - clo[2]];
    let axis = if extent[0] >= extent[1] && extent[0] >= extent[2] {
        0
    } else if extent[1] >= extent[2] {
        1
    } else {
        2
    };
    let mid = order.len() / 2;
    let key = |t: &u32| centroids.get(*t as usize).map_or(0.0, |m| m[axis]);
    order.select_nth_unstable_by(mid, |x, y| key(x).total_cmp(&key(y)));
    let (left, right) = order.split_at_mut(mid);
    let l = build(nodes, left, offset, index, triangles, centroids);
    let r = build(nodes, right, offset + mid, index, triangles, centroids);
    if let Some(n) = nodes.get_mut(index as usize) {
        n.first = l;
        n.count = 0;
        n.right = r;
    }
    index
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_xoshiro::rand_core::{RngCore, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    fn uniform(rng: &mut Xoshiro256PlusPlus) -> f32 {
        (rng.next_u32() >> 8) as f32 / (1u32 << 24) as f32
    }

    #[test]
    fn nearest_matches_a_linear_scan() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
        let positions: Vec<Point> = (0..600)
            .map(|_| [uniform(&mut rng), uniform(&mut rng), uniform(&mut rng)])
            .collect();
        let triangles: Vec<Triangle> = (0..200u32)
            .map(|i| [3 * i, 3 * i + 1, (3 * i + 2) % 600])
            .chain([[0, 0, 1], [5, 5, 5]])
            .collect();
        let Some(mut bvh) = TriangleBvh::new(&triangles, &positions) else {
            panic!("no tree over 202 triangles");
        };
        assert_eq!(bvh.len(), 202);
        for k in 0..2000 {
            let p = [
                uniform(&mut rng) as f64 * 1.4 - 0.2,
                uniform(&mut rng) as f64 * 1.4 - 0.2,
                uniform(&mut rng) as f64 * 1.4 - 0.2,
            ];
            let want = (0..triangles.len() as u32)
                .map(|t| bvh.triangle_distance_squared(t, p))
                .fold(f64::INFINITY, f64::min);
            let hint = if k % 2 == 0 { Some(k % 202) } else { None };
            let got = bvh.nearest(p, hint);
            assert_eq!(got.distance_squared, want);
            assert_eq!(bvh.triangle_distance_squared(got.triangle, p), want);
        }
    }

    #[test]
    fn a_refitted_tree_answers_like_a_new_one() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
        let mut points = |n: usize| -> Vec<Point> {
            (0..n)
                .map(|_| [uniform(&mut rng), uniform(&mut rng), uniform(&mut rng)])
                .collect()
        };
        let (first, later, queries) = (points(300), points(300), points(500));
        let triangles: Vec<Triangle> = (0..100u32).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
        let (Some(mut tree), Some(mut fresh)) = (
            TriangleBvh::new(&triangles, &first),
            TriangleBvh::new(&triangles, &later),
        ) else {
            panic!("no tree");
        };
        // An unhinted query needs the tree: it is built over the first positions, then refitted.
        tree.nearest([0.5; 3], None);
        assert!(tree.tree.is_some() && tree.fitted);
        assert!(tree.refit(&triangles, &later));
        assert!(!tree.fitted);
        assert!(!tree.refit(&triangles[1..], &later));
        for q in queries {
            let p = [q[0] as f64, q[1] as f64, q[2] as f64];
            assert_eq!(
                tree.nearest(p, None).distance_squared,
                fresh.nearest(p, Some(7)).distance_squared
            );
        }
    }

    #[test]
    fn no_triangles_no_tree() {
        assert!(TriangleBvh::new(&[], &[[0.0; 3]]).is_none());
    }
}
