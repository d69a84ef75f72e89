//! A uniform grid over one frame's triangles that settles a hinted nearest-triangle query locally.
//!
//! The surface measures query points that lie a tiny distance from their hint (the same-numbered
//! face of a decoded frame is usually a fraction of an edge away). In the [`super::bvh`] tree such a
//! query still climbs from the hint's leaf to the root, testing a sibling box at every level and
//! descending into the many overlapping boxes a point on the surface lies in: on pdance 29 node
//! boxes, 11 triangle boxes and 5 exact distances per query. Grid cells do not overlap, so the cube
//! of half-side `d` around the query meets one to a few cells (1.1 on pdance), and only the
//! triangles listed there can be nearer than `d` (24 boxes, 2.7 exact distances per query beyond
//! the hint's). The grid is rebuilt per frame in O(triangles). Cells are hashed into a table of
//! about two buckets per triangle, so empty space costs nothing; a collision only adds candidates.
//! The buckets' lists lie in memory in the order the triangles first join them, so that
//! neighbouring cells share cache lines. A triangle too large for 64 cells is tested by every
//! query; past 32 of them (meshes of small and large triangles) they get a coarser grid of their
//! own, sized by their extents, up to four levels deep.
//!
//! Written here rather than taken from a crate: the spatial crates (`parry3d-f64`'s QBVH, `rstar`,
//! `kiddo`) answer unbounded nearest queries over their own shapes and distance code; this one
//! takes the hint's distance as the bound and reuses [`super::triangle`]'s exact distance, so the
//! measures stay those of the tree to the last bit.

use super::triangle::{PreparedTriangle, Vec3};

/// Cells one triangle may span before it is kept aside and tested by every query instead.
const MAX_CELLS_PER_TRIANGLE: usize = 64;

/// Triangles kept aside beyond which they get a coarser grid of their own (every query would
/// test them all).
const MAX_OVERSIZED: usize = 32;

/// Coarser grids under the first at most, before the grid gives up (every query to the tree).
const MAX_COARSER: u8 = 4;

/// Cells a query may visit before it is left to the tree.
const MAX_QUERY_CELLS: usize = 27;

/// Cell edge over the mean triangle extent: smaller cells list fewer triangles each, but each
/// triangle joins more cells and a query crosses more cell walls. On pdance 1 took 7.0-7.4 CPU-s
/// for `eval`; 0.7 and 0.5 took 9-11 (with 2 to 8 buckets per triangle), 1.5 and 2 took 7.6-8.
const CELL_OVER_EXTENT: f64 = 1.0;

/// Cell edge over the mean extent in the coarser grids: their triangles are large and overlap
/// (BrainStem's coarser grid listed 46 of them a query at 1, 28 at 0.5; 0.25 and below were
/// slower, their triangles joining too many cells). BrainStem at 1 frame/s, `--threads 1`: 8.34-8.40
/// CPU-s at 1, 7.73-7.77 at 0.5.
const COARSER_CELL_OVER_EXTENT: f64 = 0.5;

/// The grid; empty (every query left to the tree) until built over finite triangles.
#[derive(Debug, Clone, Default)]
pub struct TriangleGrid {
    /// Corner of cell (0, 0, 0).
    min: Vec3,
    /// One over the cell edge.
    inv_cell: f64,
    /// Cells along each axis.
    dims: [i64; 3],
    /// Bucket `b` lists `entries[spans[b][0]..spans[b][1]]`; no buckets when the grid is off.
    spans: Vec<[u32; 2]>,
    entries: Vec<Entry>,
    /// Triangles too large for cells, tested by every query.
    oversized: Vec<u32>,
    /// Past [`MAX_OVERSIZED`] of them, a grid of the triangles too large for this one's cells:
    /// a mesh of small and large triangles (BrainStem: 61 666 faces, 330-920 a frame over 64
    /// cells) is then still queried by grid instead of by the tree (its `eval`: 750 → 263 CPU s).
    coarser: Option<Box<TriangleGrid>>,
    /// Bounding box (low, high corner) of each triangle.
    boxes: Vec<[Vec3; 2]>,
    /// (bucket, triangle) of each entry, in triangle order: kept for its memory.
    listed: Vec<(u32, u32)>,
}

/// A triangle listed in a bucket, with its bounding box widened to `f32` (a query tests the box
/// where it is listed: half the bytes of `f64`, and no jump to a per-triangle table).
#[derive(Debug, Clone, Copy, Default)]
struct Entry {
    lo: [f32; 3],
    hi: [f32; 3],
    triangle: u32,
}

impl Entry {
    fn new(b: &[Vec3; 2], triangle: u32) -> Self {
        // The nearest f32 on the outer side (`f32::next_down` needs a newer Rust than the MSRV).
        let down = |x: f64| {
            let y = x as f32;
            if f64::from(y) > x {
                step(y, -1)
            } else {
                y
            }
        };
        let up = |x: f64| {
            let y = x as f32;
            if f64::from(y) < x {
                step(y, 1)
            } else {
                y
            }
        };
        Self {
            lo: [down(b[0][0]), down(b[0][1]), down(b[0][2])],
            hi: [up(b[1][0]), up(b[1][1]), up(b[1][2])],
            triangle,
        }
    }

    /// Squared distance from `p` to the (widened) box: never more than to the triangle's box.
    fn distance_squared(&self, p: Vec3) -> f64 {
        let mut d2 = 0.0;
        for ((lo, hi), x) in self.lo.iter().zip(&self.hi).zip(&p) {
            // Comparisons rather than `f64::max`, whose NaN rule costs instructions in this, the
            // grid's innermost test: the same value for every finite input (a NaN corner only
            // changes which triangles are measured exactly, and those measure NaN anyway).
            let (below, above) = (f64::from(*lo) - x, x - f64::from(*hi));
            let d = if below > above { below } else { above };
            let d = if d > 0.0 { d } else { 0.0 };
            d2 += d * d;
        }
        d2
    }
}

/// The next `f32` after finite or infinite `y` towards +∞ (`dir` 1) or −∞ (−1); NaN stays NaN.
fn step(y: f32, dir: i32) -> f32 {
    if y.is_nan() || (y == f32::INFINITY && dir > 0) || (y == f32::NEG_INFINITY && dir < 0) {
        return y;
    }
    if y == 0.0 {
        let tiny = f32::from_bits(1);
        return if dir > 0 { tiny } else { -tiny };
    }
    // Away from zero is one more in the bit pattern, towards zero one less, whatever the sign.
    let away = (y > 0.0) == (dir > 0);
    let bits = y.to_bits();
    f32::from_bits(if away { bits + 1 } else { bits - 1 })
}

/// The cell range `lo..=hi` along each axis.
type CellRange = ([i64; 3], [i64; 3]);

impl TriangleGrid {
    /// Rebuilds the grid over `triangles`, reusing its memory.
    pub fn rebuild(&mut self, triangles: &[PreparedTriangle]) {
        self.build(triangles, None, 0);
    }

    /// Builds the grid over `triangles`, or only those numbered in `subset`; `level` grids lie
    /// above this one.
    fn build(&mut self, triangles: &[PreparedTriangle], subset: Option<&[u32]>, level: u8) {
        self.spans.clear();
        self.entries.clear();
        self.oversized.clear();
        self.boxes.clear();
        match subset {
            None => self
                .boxes
                .extend(triangles.iter().map(|t| corner_box(&t.corners))),
            Some(ids) => self.boxes.extend(
                ids.iter()
                    .filter_map(|&t| triangles.get(t as usize))
                    .map(|t| corner_box(&t.corners)),
            ),
        }
        let count = self.boxes.len();
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        let mut extent = 0.0;
        for b in &self.boxes {
            for a in 0..3 {
                lo[a] = lo[a].min(b[0][a]);
                hi[a] = hi[a].max(b[1][a]);
            }
            extent += (0..3).map(|a| b[1][a] - b[0][a]).fold(0.0, f64::max);
        }
        let over_extent = if level == 0 {
            CELL_OVER_EXTENT
        } else {
            COARSER_CELL_OVER_EXTENT
        };
        let cell = over_extent * extent / count.max(1) as f64;
        if !(cell > 0.0 && cell.is_finite() && lo.iter().chain(&hi).all(|x| x.is_finite())) {
            return;
        }
        self.min = lo;
        self.inv_cell = 1.0 / cell;
        // Cells beyond 2²⁰ per axis would overflow the hash's range; a clip that wide against its
        // triangles is left to the tree.
        let dims = [0, 1, 2].map(|a| ((hi[a] - lo[a]) * self.inv_cell).floor() as i64 + 1);
        if dims.iter().any(|&n| n > 1 << 20) {
            return;
        }
        self.dims = dims;
        let number = |t: usize| subset.and_then(|ids| ids.get(t).copied()).unwrap_or(t as u32);
        self.fill(count, number);
        if self.oversized.len() > MAX_OVERSIZED && level < MAX_COARSER {
            let ids = std::mem::take(&mut self.oversized);
            let coarser = self.coarser.get_or_insert_with(Box::default);
            coarser.build(triangles, Some(&ids), level + 1);
            if coarser.spans.is_empty() {
                self.spans.clear();
            }
        } else {
            self.coarser = None;
            if self.oversized.len() > MAX_OVERSIZED {
                self.oversized.clear();
                self.spans.clear();
            }
        }
    }

    /// Lists each triangle in the buckets of its cells (counting pass, then placing pass);
    /// `number` gives the number of the `t`-th box's triangle. Leaves the triangles too large for
    /// cells in `oversized`.
    fn fill(&mut self, triangles: usize, number: impl Fn(usize) -> u32) {
        let buckets = (2 * triangles).next_power_of_two();
        let mut count = vec![0u32; buckets + 1];
        // Each (bucket, triangle) listing, found once: placing then needs no cell arithmetic.
        let mut listed = std::mem::take(&mut self.listed);
        listed.clear();
        for (t, b) in self.boxes.iter().enumerate() {
            let range = self.cells(b[0], b[1]);
            if cell_count(&range) > MAX_CELLS_PER_TRIANGLE {
                self.oversized.push(number(t));
                continue;
            }
            for_each_cell(&range, |c| {
                let k = bucket(c, buckets);
                if let Some(n) = count.get_mut(k + 1) {
                    *n += 1;
                    listed.push((k as u32, t as u32));
                }
            });
        }
        // Bucket b's entries are `entries[spans[b][0]..spans[b][1]]`, laid out in the order the
        // triangles first list them: neighbouring triangles' cells lie near each other in memory,
        // so a run of queries nearby reads from the cache.
        let mut spans = vec![[0u32; 2]; buckets];
        let mut next = 0u32;
        for &(k, _) in &listed {
            if let (Some(span), Some(&n)) = (spans.get_mut(k as usize), count.get(k as usize + 1)) {
                if span[1] == 0 {
                    *span = [next, next + n];
                    next = span[1];
                }
            }
        }
        self.entries.resize(next as usize, Entry::default());
        // `placed[b]`: where bucket b's next entry goes.
        let mut placed: Vec<u32> = spans.iter().map(|s| s[0]).collect();
        let mut current = (u32::MAX, Entry::default());
        for &(k, t) in &listed {
            if current.0 != t {
                let b = self.boxes.get(t as usize).copied().unwrap_or_default();
                current = (t, Entry::new(&b, number(t as usize)));
            }
            if let Some(slot) = placed.get_mut(k as usize) {
                if let Some(e) = self.entries.get_mut(*slot as usize) {
                    *e = current.1;
                }
                *slot += 1;
            }
        }
        self.listed = listed;
        self.spans = spans;
    }

    /// The cells a box `lo..hi` meets, clipped to the grid (empty along an axis it misses).
    fn cells(&self, lo: Vec3, hi: Vec3) -> CellRange {
        let at = |x: f64, a: usize| -> i64 {
            let c = (x - self.min[a]) * self.inv_cell;
            // Rounds down like `floor` (a library call on baseline x86-64) within the clipped
            // range; the conversion saturates, and clipping keeps indexes in range (a miss gives
            // lo > hi).
            let t = c.max(-1.0) as i64;
            (t - i64::from((t as f64) > c)).min(self.dims[a])
        };
        let lo = [
            at(lo[0], 0).max(0),
            at(lo[1], 1).max(0),
            at(lo[2], 2).max(0),
        ];
        let hi = [
            at(hi[0], 0).min(self.dims[0] - 1),
            at(hi[1], 1).min(self.dims[1] - 1),
            at(hi[2], 2).min(self.dims[2] - 1),
        ];
        (lo, hi)
    }

    /// Lowers `best` (squared distance, triangle) to the nearest triangle to `p` when one is
    /// nearer than `best` already is. Returns false, changing nothing, when the grid cannot tell
    /// (no grid, or a bound too wide for few cells): the caller then searches otherwise.
    pub fn improve(&self, p: Vec3, triangles: &[PreparedTriangle], best: &mut (f64, u32)) -> bool {
        if self.spans.is_empty() || !best.0.is_finite() {
            return false;
        }
        // A little wider than the bound, so rounding in `p ± d` never drops a nearer triangle.
        let d = best.0.sqrt() * (1.0 + 1e-9) + 1e-9 / self.inv_cell;
        let range = self.cells(
            [p[0] - d, p[1] - d, p[2] - d],
            [p[0] + d, p[1] + d, p[2] + d],
        );
        if cell_count(&range) > MAX_QUERY_CELLS {
            return false;
        }
        // The coarser grid first: when it cannot tell, nothing has changed yet.
        if let Some(coarser) = &self.coarser {
            if !coarser.improve(p, triangles, best) {
                return false;
            }
        }
        let buckets = self.spans.len();
        let exact = |t: u32, best: &mut (f64, u32)| {
            if let Some(tri) = triangles.get(t as usize) {
                if tri.plane_beyond(p, best.0) {
                    return;
                }
                let d2 = tri.distance_squared(p);
                if d2 < best.0 {
                    *best = (d2, t);
                }
            }
        };
        for &t in &self.oversized {
            if t != best.1 {
                exact(t, best);
            }
        }
        for_each_cell(&range, |cell| {
            let b = bucket(cell, buckets);
            let Some(&[s, e]) = self.spans.get(b) else {
                return;
            };
            for entry in self.entries.get(s as usize..e as usize).unwrap_or(&[]) {
                if entry.triangle != best.1 && entry.distance_squared(p) < best.0 {
                    exact(entry.triangle, best);
                }
            }
        });
        true
    }
}

/// The bounding box of a triangle's corners.
fn corner_box(c: &[Vec3; 3]) -> [Vec3; 2] {
    let (mut lo, mut hi) = (c[0], c[0]);
    for p in &c[1..] {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    [lo, hi]
}

/// Cells in a range (0 when it is empty along an axis).
fn cell_count((lo, hi): &CellRange) -> usize {
    (0..3)
        .map(|a| (hi[a] - lo[a] + 1).max(0) as usize)
        .product()
}

fn for_each_cell((lo, hi): &CellRange, mut f: impl FnMut([i64; 3])) {
    for i in lo[0]..=hi[0] {
        for j in lo[1]..=hi[1] {
            for k in lo[2]..=hi[2] {
                f([i, j, k]);
            }
        }
    }
}

/// The bucket of a cell: the classic spatial-hash primes, in a power-of-two table.
fn bucket(c: [i64; 3], buckets: usize) -> usize {
    let h = (c[0] as u64).wrapping_mul(73_856_093)
        ^ (c[1] as u64).wrapping_mul(19_349_663)
        ^ (c[2] as u64).wrapping_mul(83_492_791);
    (h as usize) & (buckets - 1)
}

#[cfg(test)]
mod tests {
    use super::super::triangle::point_triangle_distance_squared;
    use super::*;
    use rand_xoshiro::rand_core::{RngCore, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    fn uniform(rng: &mut Xoshiro256PlusPlus) -> f64 {
        (rng.next_u32() >> 8) as f64 / (1u32 << 24) as f64
    }

    /// A triangle with a corner at `o` and the others up to `size / 2` away on each axis.
    fn near(rng: &mut Xoshiro256PlusPlus, o: Vec3, size: f64) -> [Vec3; 3] {
        let mut c = [o; 3];
        for p in &mut c[1..] {
            for x in p.iter_mut() {
                *x += size * uniform(rng) - size / 2.0;
            }
        }
        c
    }

    /// Small triangles scattered in the unit cube, a clump of 60 tiny ones in one cell, and one
    /// triangle spanning the cube (kept aside).
    fn soup(rng: &mut Xoshiro256PlusPlus) -> Vec<[Vec3; 3]> {
        let mut corners: Vec<[Vec3; 3]> = (0..400)
            .map(|_| {
                let o = [uniform(rng), uniform(rng), uniform(rng)];
                near(rng, o, 0.1)
            })
            .collect();
        for _ in 0..60 {
            let o = [0.5 + 0.002 * uniform(rng), 0.5, 0.5];
            corners.push(near(rng, o, 0.002));
        }
        corners.push([[0.0; 3], [1.0, 0.0, 0.0], [1.0, 1.0, 1.0]]);
        corners
    }

    fn prepare(corners: &[[Vec3; 3]]) -> Vec<PreparedTriangle> {
        corners.iter().map(|c| PreparedTriangle::new(*c)).collect()
    }

    /// Queries `grid` at each (hint, point): a settled query must give the linear scan's minimum,
    /// an unsettled one change nothing. Returns how many were settled.
    fn check_queries(
        grid: &TriangleGrid,
        corners: &[[Vec3; 3]],
        queries: impl Iterator<Item = (usize, Vec3)>,
    ) -> usize {
        let triangles = prepare(corners);
        let distance = |t: usize, p: Vec3| {
            let c = corners[t];
            point_triangle_distance_squared(p, c[0], c[1], c[2])
        };
        let mut settled = 0;
        for (k, (hint, p)) in queries.enumerate() {
            let want = (0..corners.len())
                .map(|t| distance(t, p))
                .fold(f64::INFINITY, f64::min);
            let mut best = (distance(hint, p), hint as u32);
            if grid.improve(p, &triangles, &mut best) {
                settled += 1;
                assert_eq!(best.0, want, "query {k}");
                assert_eq!(distance(best.1 as usize, p), want);
            } else {
                assert_eq!(best, (distance(hint, p), hint as u32), "unchanged when unsure");
            }
        }
        settled
    }

    #[test]
    fn a_settled_query_is_the_linear_scan() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(9);
        let corners = soup(&mut rng);
        let mut grid = TriangleGrid::default();
        grid.rebuild(&prepare(&corners));
        assert_eq!(grid.oversized.len(), 1, "the spanning triangle is kept aside");
        let longest = grid.spans.iter().map(|s| s[1] - s[0]).max();
        assert!(longest >= Some(60), "the clump shares a bucket: {longest:?}");
        let n = corners.len();
        let queries = (0..3000).map(|k| {
            let hint = k % n;
            // Most queries lie near their hint, as the measures' do (some in the clump); a third
            // anywhere.
            if k % 3 == 0 {
                (hint, corners[hint][0].map(|x| x + 0.01 * uniform(&mut rng)))
            } else if k % 3 == 1 {
                let clump = n - 2 - k % 60;
                (hint, corners[clump][1].map(|x| x + 0.0001 * uniform(&mut rng)))
            } else {
                let p = [uniform(&mut rng), uniform(&mut rng), uniform(&mut rng)];
                (hint, p)
            }
        });
        // Far hints span too many cells and are left to the tree; near ones are settled.
        let settled = check_queries(&grid, &corners, queries);
        assert!(settled > 1000, "{settled}");
    }

    #[test]
    fn many_large_triangles_get_a_coarser_grid_of_their_own() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
        let mut corners = soup(&mut rng);
        // Forty large triangles, each over more cells than one triangle may join.
        for _ in 0..40 {
            let o = [uniform(&mut rng), uniform(&mut rng), uniform(&mut rng)];
            corners.push(near(&mut rng, o, 1.5));
        }
        let triangles = prepare(&corners);
        let mut grid = TriangleGrid::default();
        grid.rebuild(&triangles);
        assert!(grid.coarser.is_some(), "{} kept aside", grid.oversized.len());
        let n = corners.len();
        let queries = (0..2000).map(|k| {
            let hint = k % n;
            (hint, corners[hint][k % 3].map(|x| x + 0.003 * uniform(&mut rng)))
        });
        let settled = check_queries(&grid, &corners, queries);
        assert!(settled > 1000, "{settled}");
        // Back to few large triangles: the coarser grid goes.
        grid.rebuild(&triangles[..n - 40]);
        assert!(grid.coarser.is_none() && !grid.spans.is_empty());
    }

    #[test]
    fn widened_boxes_hold_the_exact_ones() {
        for x in [0.1f64, -0.1, 1e-40, -1e-40, 0.0, 3.0, 1e300, -1e300, 16777217.0] {
            let e = Entry::new(&[[x; 3], [x; 3]], 0);
            assert!(f64::from(e.lo[0]) <= x && f64::from(e.hi[0]) >= x, "{x}");
            assert!(e.hi[0] <= step(step(e.lo[0], 1), 1), "{x}: within two steps");
        }
        assert_eq!(step(1.0, 1), 1.0 + f32::EPSILON);
        assert_eq!(step(-1.0, -1), -1.0 - f32::EPSILON);
        assert_eq!(step(f32::MAX, 1), f32::INFINITY);
        assert!(step(0.0, -1) < 0.0 && step(-0.0, 1) > 0.0);
    }

    #[test]
    fn no_grid_or_no_bound_settles_nothing() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(4);
        let triangles = prepare(&soup(&mut rng));
        let mut best = (0.5, 0);
        assert!(!TriangleGrid::default().improve([0.5; 3], &triangles, &mut best));
        let mut grid = TriangleGrid::default();
        grid.rebuild(&triangles);
        let mut unbounded = (f64::INFINITY, 0);
        assert!(!grid.improve([0.5; 3], &triangles, &mut unbounded));
        // Non-finite corners switch the grid off rather than filling it with junk.
        grid.rebuild(&prepare(&[[[f64::NAN; 3]; 3]]));
        assert!(!grid.improve([0.5; 3], &triangles, &mut best));
    }
}
