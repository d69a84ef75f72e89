//! Motion segmentation by decimation (skinning paper, Mamou et al., §3.1, eq. 1–6): the vertex graph
//! is simplified by half-edge collapses that merge vertices moving with the same affine motion, and
//! the vertices of the coarse mesh, each with its ancestor set, become the clusters. K is not asked
//! for; it falls out of the error threshold E0.
//!
//! # Reading of the paper
//! - A set `v ∪ v*` has the error `E(v)` of its least-squares affine fit, frame 0 → frame i, summed
//!   over the frames and the set's vertices (eq. 1–2). The cost `C(v, w)` of `hecol(v, w)` is that
//!   error for the merged set `v* ∪ w* ∪ {v, w}` (eq. 3–4) — the merged set's total error, not the
//!   increase over `E(v) + E(w)`; the collapse with the lowest cost goes first, and only the costs of
//!   pairs touching the merged set are recomputed.
//! - `E_l = (Σ_v E(v) / (D² F V))^½` (eq. 5): the RMS affine-fit error per vertex and frame, over the
//!   diagonal D of frame 0's bounding box. Collapses stop before the one that would take `E_l` above
//!   E0 (0.003 in the paper: an RMS misfit of 0.3 % of the diagonal). `E_l` never decreases (a union's
//!   least-squares error is at least the sum of its parts'), so this is the paper's "until E_l reaches E0".
//! - Collapses follow edges, so a cluster never spans two connected components: each component is
//!   segmented on its own, and a component too small for a determined affine map (fewer than four
//!   non-coplanar vertices) is fitted exactly and stays a cluster of its own — the paper's observation
//!   that models with many components get many clusters (Chicken: 41 components, K = 85).
//!
//! # Choices of this implementation
//! - The graph is the vertex adjacency, plus edges between copies of one position that move together
//!   (the seam welding of the k-means segmentation): a collapse on the vertex graph is a union of two
//!   sets, so non-manifold input needs nothing special, and glTF meshes split along UV seams are not
//!   taken for dozens of separate parts.
//! - Each set keeps its normal equations — `Σ χ₀χ₀ᵀ`, and per frame `Σ xᵢχ₀ᵀ` — plus `Σ‖xᵢ‖²`, so a
//!   merge adds two sets' sums and a cost costs O(frames), whatever the sets' sizes. The fit's error
//!   is the least-squares minimum, computed with the pseudo-inverse of the centred scatter: coplanar
//!   or tiny sets get their exact (possibly zero) minimum, not a regularised guess.
//! - Ties (sets of up to three vertices fit exactly: cost 0) go to the smaller merged set, so sets
//!   grow evenly instead of one set sweeping a rigid part vertex by vertex; then to the lower ids, so
//!   the result is deterministic.
//! - Border refinement (beyond the paper; `refine_passes`, 0 = the paper's plain decimation): sets
//!   of up to four vertices fit any motion exactly, so early zero-cost collapses can join vertices
//!   across the border of two parts; such a set later fits neither part and stays a cluster of its
//!   own (a two-part triangle soup gave 3 clusters). Each round moves every border vertex to the
//!   neighbouring cluster whose affine maps predict its trajectory best (as after k-means), then
//!   resumes the collapses on the clusters so refined with the budget left — a band now fitting
//!   one part exactly merges into it for free. Whole components never move, so each stays
//!   segmented on its own; a round that would raise the error is dropped, so `E_l` ≤ E0 holds.
//! - Memory is 12 numbers per set and frame; past `max_vertex_frames` vertices × frames, the frames
//!   are subsampled evenly (as the k-means features are) and `E_l` is estimated from them.
//!
//! # Measured (release build, 2 shared cores, E0 = 0.003, `cargo bench --bench motion`)
//! K0 is the paper's plain decimation (`refine_passes: 0`), K the default; "paper" is the
//! skinning paper's Table 1 (same E0). resid/motion is the bench's residual energy of the 17-bit
//! piecewise affine predictor over the raw motion energy; k-means is the default K = 20.
//!
//! | sequence | V × F | paper K | K0 | K | seconds | resid/motion | k-means K=20 (seconds) |
//! |---|---|---|---|---|---|---|---|
//! | chickenCrossing | 3030 × 400 | 85 | 82 | 70 | 0.79 | 2.27e-6 | 5.18e-5 (1.68) |
//! | pdance | 7061 × 201 | 21 | 18 | 15 | 1.00 | 7.49e-5 | 6.88e-5 (5.32) |
//! | pcow | 2904 × 204 | 64 | 66 | 46 | 0.37 | 2.23e-5 | 8.28e-5 (1.86) |
//! | horse-gallop | 8431 × 48 | 39 | 33 | 25 | 0.52 | 8.63e-4 | 3.06e-3 (4.30) |
//! | horse-collapse | 8431 × 53 | 135 | 96 | 67 | 0.55 | 1.64e-4 | 1.32e-3 (6.17) |
//!
//! At the K decimation found, k-means (`CLUSTERS=K`) predicts worse on all five: 7.76e-6 (chicken,
//! K = 65 after dissolving), 9.35e-5, 2.79e-5, 2.51e-3, 3.06e-4 (horse-collapse, 32.7 s).
//! BrainStem (34159 × 1310, frames subsampled to 58): K = 391, its welded components (each moves
//! rigidly, E_l ≈ 0), in 2.5 s (segmentation only: not encoded, so the partition coder's path for
//! more than 256 clusters is untested by this).

use super::partition::{compact, Partition};
use super::refine::refine_borders;
use super::sampled_motion::{feature_frames, welded_adjacency, SampledMotion};
use crate::error::{Error, Result};
use crate::mesh::topology::VertexAdjacency;
use crate::mesh::AnimatedMesh;
use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;
use std::cmp::{Ordering, Reverse};
use std::collections::BinaryHeap;

/// The paper's error threshold E0 (used for all its sequences).
pub const DEFAULT_E0: f64 = 0.003;

/// Default cap on the clusters decimation may leave. The stream itself takes up to one cluster per
/// vertex, but every cluster costs 12 affine coefficients per frame and seeds at least one chart:
/// 1024 clusters × 12 × 17 bits is 209 kbit per frame, more than the residual images of any sample here.
pub const MAX_DECIMATION_CLUSTERS: usize = 1024;

/// How to decimate.
#[derive(Debug, Clone, PartialEq)]
pub struct DecimateOptions {
    /// Error threshold E0 on `E_l` (eq. 5), a fraction of the bounding-box diagonal (default 0.003).
    pub e0: f64,
    /// Most clusters to leave: when E0 stops the collapses above it, they continue (past E0) down to
    /// the cap, and more connected components than the cap is an error.
    pub max_clusters: usize,
    /// Vertices × frames above which frames are subsampled (default 2 000 000, about 100 MB of sums).
    pub max_vertex_frames: usize,
    /// Rounds of border refinement after the collapses (default 4; 0 = the paper's plain
    /// decimation): each vertex may move to a neighbouring cluster whose affine maps predict it
    /// better, then the collapses resume within the budget (see the module documentation).
    pub refine_passes: usize,
}

impl Default for DecimateOptions {
    fn default() -> Self {
        Self {
            e0: DEFAULT_E0,
            max_clusters: MAX_DECIMATION_CLUSTERS,
            max_vertex_frames: 2_000_000,
            refine_passes: 4,
        }
    }
}

/// What decimation found.
#[derive(Debug, Clone)]
pub struct Decimation {
    /// The clusters: one per vertex of the coarse mesh (eq. 6).
    pub partition: Partition,
    /// `E_l` at the end (eq. 5): RMS affine-fit error per vertex and frame over the bbox diagonal.
    pub error: f64,
    /// Connected components of the (seam-welded) vertex graph: a lower bound on K.
    pub components: usize,
    /// Frames the errors were measured on (all but frame 0, which every affine map fits exactly,
    /// unless subsampled).
    pub frames_used: usize,
    /// Half-edge collapses done.
    pub collapses: usize,
    /// K of the paper's plain decimation: the clusters the first collapses left, before refinement.
    pub decimated_clusters: usize,
    /// `E_l` of the paper's plain decimation, before refinement.
    pub decimated_error: f64,
}

/// Segments the vertices by decimation (skinning paper §3.1): see the module documentation.
pub fn decimate(mesh: &AnimatedMesh, opts: &DecimateOptions) -> Result<Decimation> {
    if !(opts.e0.is_finite() && opts.e0 > 0.0) {
        return Err(Error::Usage(format!(
            "the decimation error threshold E0 must be a positive number, not {}",
            opts.e0
        )));
    }
    if opts.max_clusters == 0 {
        return Err(Error::Usage(
            "the decimation cluster cap must be at least 1".into(),
        ));
    }
    let v_count = mesh.vertex_count();
    let f_count = mesh.frame_count();
    if v_count == 0 || f_count == 0 {
        return Err(Error::Mesh(
            "decimation: the animation has no vertices or no frames".into(),
        ));
    }
    let wanted = (opts.max_vertex_frames / v_count.max(1)).clamp(1, f_count.max(2) - 1);
    let sampled = SampledMotion::new(mesh, wanted);
    let adjacency = welded_adjacency(mesh, &sampled);
    let (_, components) = adjacency.components();
    if components > opts.max_clusters {
        return Err(Error::Usage(format!(
            "decimation: the mesh has {components} connected components (seams welded) and each needs \
             its own cluster, more than the cap of {}; use --segmentation kmeans",
            opts.max_clusters
        )));
    }
    let frames_used = if f_count > 1 {
        feature_frames(f_count, wanted).len()
    } else {
        0
    };
    let sums = Sums::new(&sampled, frames_used);
    // The budget is E0² D² F V in unit coordinates (D = 1), for the sampled frames: frame 0 adds
    // nothing to any error, and the sampled frames stand for the F − 1 others.
    let scale = if frames_used > 0 {
        (f_count - 1) as f64 / frames_used as f64
    } else {
        0.0
    };
    let limits = Limits {
        budget: opts.e0 * opts.e0 * f_count as f64 * v_count as f64,
        scale,
        max_clusters: opts.max_clusters,
    };
    let rms = |total: f64| (total * scale / (f_count as f64 * v_count as f64)).sqrt();

    let singletons: Vec<usize> = (0..v_count).collect();
    let mut state = State::new(&sums, &adjacency, &singletons);
    let mut collapses = state.collapse_within(&sums, &limits);
    let mut partition = state.partition()?;
    let (decimated_clusters, decimated_total) = (partition.clusters(), state.total);
    let mut total = state.total;
    drop(state);
    // Sets of up to four vertices fit any motion exactly, so early collapses can pair vertices
    // across a border between parts; such a set later fits neither part and survives as a cluster
    // of its own. Each round moves border vertices to the neighbouring cluster that predicts them
    // best (components stay apart: only moves to a neighbour's cluster), then resumes the collapses
    // on the clusters so refined, with what is left of the budget.
    for _ in 0..opts.refine_passes {
        if partition.clusters() <= components || frames_used == 0 {
            break;
        }
        let k = partition.clusters();
        let mut labels: Vec<usize> = partition.labels().iter().map(|&l| l as usize).collect();
        refine_borders(&mut labels, &adjacency, &sampled, k, 1, false);
        let mut state = State::new(&sums, &adjacency, &labels);
        if state.total > total {
            // The refinement's (regularised) fits misjudged: keep what the collapses found.
            break;
        }
        let more = state.collapse_within(&sums, &limits);
        let refined = state.partition()?;
        let unchanged = more == 0 && refined.labels() == partition.labels();
        collapses += more;
        total = state.total;
        partition = refined;
        if unchanged {
            break;
        }
    }
    if partition.clusters() > opts.max_clusters {
        // Unreachable while components ≤ cap (collapses continue until one set per component), but
        // a wrong answer here would only show up as a huge stream.
        return Err(Error::Usage(format!(
            "decimation left {} clusters, more than the cap of {}",
            partition.clusters(),
            opts.max_clusters
        )));
    }
    Ok(Decimation {
        error: rms(total),
        decimated_clusters,
        decimated_error: rms(decimated_total),
        partition,
        components,
        frames_used,
        collapses,
    })
}

/// When collapses stop: at the error budget E0² F V (unit coordinates), unless above the cluster cap.
struct Limits {
    budget: f64,
    /// Sampled-frame errors × `scale` = errors over all frames.
    scale: f64,
    max_clusters: usize,
}

/// Numbers kept per set before the per-frame ones: n, Σp (3), Σppᵀ (6, upper triangle), Σ‖x‖².
const HEAD: usize = 11;
/// Numbers per frame: Σ x pᵀ (3 × 3, row-major), Σ x (3).
const PER_FRAME: usize = 12;

/// Vertex trajectories in unit coordinates, vertex-major, and the layout of a set's sums.
struct Sums {
    rest: Vec<[f64; 3]>,
    /// `trajectories[v * frames + i]`: vertex v at sampled frame i.
    trajectories: Vec<[f64; 3]>,
    frames: usize,
}

impl Sums {
    fn new(motion: &SampledMotion, frames: usize) -> Self {
        let v_count = motion.rest.len();
        let mut trajectories = Vec::with_capacity(v_count * frames);
        for v in 0..v_count {
            trajectories.extend(motion.frames.iter().take(frames).map(|f| f[v]));
        }
        Self {
            rest: motion.rest.clone(),
            trajectories,
            frames,
        }
    }

    fn len(&self) -> usize {
        HEAD + PER_FRAME * self.frames
    }

    /// Adds vertex `v`'s terms of the normal equations to `sums`.
    fn add_vertex(&self, sums: &mut [f64], v: usize) {
        let p = self.rest[v];
        sums[0] += 1.0;
        for a in 0..3 {
            sums[1 + a] += p[a];
        }
        let mut k = 4;
        for a in 0..3 {
            for b in a..3 {
                sums[k] += p[a] * p[b];
                k += 1;
            }
        }
        let trajectory = &self.trajectories[v * self.frames..(v + 1) * self.frames];
        let mut energy = 0.0;
        for (slot, x) in sums[HEAD..].chunks_exact_mut(PER_FRAME).zip(trajectory) {
            for r in 0..3 {
                energy += x[r] * x[r];
                for c in 0..3 {
                    slot[3 * r + c] += x[r] * p[c];
                }
                slot[9 + r] += x[r];
            }
        }
        sums[10] += energy;
    }

    /// The least-squares error of the best affine map per frame (eq. 1–2) of the set whose sums these are.
    fn error(&self, sums: &[f64]) -> f64 {
        let n = sums[0];
        if n <= 1.0 {
            return 0.0;
        }
        let s = Vector3::new(sums[1], sums[2], sums[3]);
        let m = Matrix3::new(
            sums[4], sums[5], sums[6], sums[5], sums[7], sums[8], sums[6], sums[8], sums[9],
        );
        let scatter = m - s * s.transpose() / n;
        let pinv = pseudo_inverse(&scatter, m.trace());
        let mut fitted = 0.0;
        for slot in sums[HEAD..].chunks_exact(PER_FRAME) {
            let sx = Vector3::new(slot[9], slot[10], slot[11]);
            let cross = Matrix3::from_row_slice(&slot[..9]) - sx * s.transpose() / n;
            // The energy the best map explains: the translation part, then the linear part.
            fitted += sx.norm_squared() / n + (cross * pinv * cross.transpose()).trace();
        }
        let energy = sums[10];
        let error = energy - fitted;
        // Below float noise on the uncentred energy the fit is exact: say 0, so ties go to size.
        if error < 1e-13 * energy {
            0.0
        } else {
            error
        }
    }
}

/// Pseudo-inverse of a symmetric positive semi-definite 3 × 3 matrix. Directions below the noise of
/// forming it from uncentred sums (`magnitude` = trace of Σppᵀ) or far below its largest eigenvalue
/// are dropped: the fit is free along them, as the least-squares minimum of a flat set is.
fn pseudo_inverse(scatter: &Matrix3<f64>, magnitude: f64) -> Matrix3<f64> {
    let eigen = scatter.symmetric_eigen();
    let largest = eigen.eigenvalues.max();
    let floor = (1e-10 * largest)
        .max(1e-14 * magnitude)
        .max(f64::MIN_POSITIVE);
    let mut out = Matrix3::zeros();
    for k in 0..3 {
        let lambda = eigen.eigenvalues[k];
        if lambda > floor {
            let e = eigen.eigenvectors.column(k);
            out += e * e.transpose() / lambda;
        }
    }
    out
}

/// A candidate collapse: merging the sets of representatives `a` and `b` at `cost` (eq. 3), valid
/// while both sets are as they were (`versions`).
#[derive(Debug, Clone, Copy)]
struct Candidate {
    cost: f64,
    size: u32,
    a: u32,
    b: u32,
    versions: (u32, u32),
}

impl Candidate {
    fn key(&self) -> (f64, u32, u32, u32) {
        (self.cost, self.size, self.a.min(self.b), self.a.max(self.b))
    }
}

impl PartialEq for Candidate {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl Eq for Candidate {}

impl PartialOrd for Candidate {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Candidate {
    fn cmp(&self, other: &Self) -> Ordering {
        let (x, y) = (self.key(), other.key());
        x.0.total_cmp(&y.0)
            .then(x.1.cmp(&y.1))
            .then(x.2.cmp(&y.2))
            .then(x.3.cmp(&y.3))
    }
}

/// The coarse mesh: sets by representative, their sums, errors, neighbours, and the candidates.
struct State {
    /// Union-find parent: a representative is its own parent.
    parent: Vec<u32>,
    size: Vec<u32>,
    version: Vec<u32>,
    /// A merged set's sums; `None` for a single vertex (computed from its trajectory when needed).
    sums: Vec<Option<Vec<f64>>>,
    error: Vec<f64>,
    /// Representatives of the adjacent sets, sorted.
    neighbours: Vec<Vec<u32>>,
    heap: BinaryHeap<Reverse<Candidate>>,
    scratch: Vec<f64>,
    /// Σ E over the sets (sampled frames).
    total: f64,
    /// Number of sets.
    live: usize,
}

impl State {
    /// The coarse mesh whose vertices are the sets of equal `labels` (any values below the vertex
    /// count), with the cost of every collapse between adjacent sets queued.
    fn new(sums: &Sums, adjacency: &VertexAdjacency, labels: &[usize]) -> Self {
        let v_count = adjacency.vertex_count();
        let mut rep_of = vec![u32::MAX; v_count];
        let mut parent = vec![0u32; v_count];
        let mut size = vec![0u32; v_count];
        for (v, &l) in labels.iter().enumerate() {
            let rep = &mut rep_of[l.min(v_count - 1)];
            if *rep == u32::MAX {
                *rep = v as u32;
            }
            parent[v] = *rep;
            size[*rep as usize] += 1;
        }
        let mut set_sums: Vec<Option<Vec<f64>>> = vec![None; v_count];
        for (v, &r) in parent.iter().enumerate() {
            let r = r as usize;
            if size[r] > 1 {
                let s = set_sums[r].get_or_insert_with(|| vec![0.0; sums.len()]);
                sums.add_vertex(s, v);
            }
        }
        let error: Vec<f64> = set_sums
            .par_iter()
            .map(|s| s.as_ref().map_or(0.0, |s| sums.error(s)))
            .collect();
        let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); v_count];
        for (v, &r) in parent.iter().enumerate() {
            for &u in adjacency.neighbours(v) {
                let q = parent[u as usize];
                if q != r {
                    neighbours[r as usize].push(q);
                }
            }
        }
        neighbours.par_iter_mut().for_each(|n| {
            n.sort_unstable();
            n.dedup();
        });
        let mut state = Self {
            parent,
            version: vec![0; v_count],
            sums: set_sums,
            total: error.iter().sum(),
            error,
            neighbours,
            heap: BinaryHeap::new(),
            scratch: vec![0.0; sums.len()],
            live: size.iter().filter(|&&n| n > 0).count(),
            size,
        };
        // The first costs, one per pair of adjacent sets, in parallel.
        let this = &state;
        let candidates: Vec<Candidate> = (0..v_count)
            .into_par_iter()
            .filter(|&a| this.parent[a] as usize == a)
            .flat_map_iter(|a| {
                let mut scratch = vec![0.0; sums.len()];
                this.neighbours[a]
                    .iter()
                    .filter(|&&b| (b as usize) > a)
                    .map(|&b| this.candidate(sums, &mut scratch, a, b as usize))
                    .collect::<Vec<_>>()
            })
            .collect();
        state.heap = candidates.into_iter().map(Reverse).collect();
        state
    }

    /// The collapse of the sets of `a` and `b`, with its cost (eq. 3).
    fn candidate(&self, sums: &Sums, scratch: &mut [f64], a: usize, b: usize) -> Candidate {
        scratch.iter_mut().for_each(|x| *x = 0.0);
        self.add_set(sums, scratch, a);
        self.add_set(sums, scratch, b);
        Candidate {
            cost: sums.error(scratch),
            size: self.size[a] + self.size[b],
            a: a as u32,
            b: b as u32,
            versions: (self.version[a], self.version[b]),
        }
    }

    /// Collapses the cheapest pair (eq. 3) until the next would take the total error past the
    /// budget (unless there are more sets than the cap) or no pair is left; returns the collapses.
    fn collapse_within(&mut self, sums: &Sums, limits: &Limits) -> usize {
        let mut collapses = 0;
        while let Some(Reverse(c)) = self.heap.pop() {
            if !self.is_current(&c) {
                continue;
            }
            let (a, b) = (c.a as usize, c.b as usize);
            let increase = (c.cost - self.error[a] - self.error[b]).max(0.0);
            if (self.total + increase) * limits.scale > limits.budget
                && self.live <= limits.max_clusters
            {
                break;
            }
            self.total += increase;
            self.collapse(sums, a, b, c.cost);
            self.live -= 1;
            collapses += 1;
        }
        collapses
    }

    /// The sets as a partition, labels in order of first vertex.
    fn partition(&mut self) -> Result<Partition> {
        let labels = (0..self.parent.len())
            .map(|v| self.root(v) as usize)
            .collect();
        compact(labels)
    }

    fn is_current(&self, c: &Candidate) -> bool {
        let (a, b) = (c.a as usize, c.b as usize);
        self.parent[a] == c.a
            && self.parent[b] == c.b
            && self.version[a] == c.versions.0
            && self.version[b] == c.versions.1
    }

    /// The representative of `v`'s set (with path halving).
    fn root(&mut self, v: usize) -> u32 {
        let mut x = v;
        while self.parent[x] as usize != x {
            let grand = self.parent[self.parent[x] as usize];
            self.parent[x] = grand;
            x = grand as usize;
        }
        x as u32
    }

    /// Adds the sums of the set represented by `r` to `out`.
    fn add_set(&self, sums: &Sums, out: &mut [f64], r: usize) {
        match &self.sums[r] {
            Some(s) => out.iter_mut().zip(s).for_each(|(o, x)| *o += x),
            None => sums.add_vertex(out, r),
        }
    }

    /// `hecol`: merges the set of `b` into that of `a` (the larger keeps its representative), whose
    /// error becomes `cost`, and queues the new costs of the merged set with each of its neighbours.
    fn collapse(&mut self, sums: &Sums, a: usize, b: usize, cost: f64) {
        let (a, b) = if self.size[a] >= self.size[b] {
            (a, b)
        } else {
            (b, a)
        };
        let mut merged = self.sums[a].take().unwrap_or_else(|| vec![0.0; sums.len()]);
        if self.size[a] == 1 {
            sums.add_vertex(&mut merged, a);
        }
        self.add_set(sums, &mut merged, b);
        self.sums[a] = Some(merged);
        self.sums[b] = None;
        self.parent[b] = a as u32;
        self.size[a] += self.size[b];
        self.version[a] = self.version[a].wrapping_add(1);
        self.error[a] = cost;

        let from_b = std::mem::take(&mut self.neighbours[b]);
        for &n in &from_b {
            let list = &mut self.neighbours[n as usize];
            if let Ok(i) = list.binary_search(&(b as u32)) {
                list.remove(i);
            }
            if let Err(i) = list.binary_search(&(a as u32)) {
                if n as usize != a {
                    list.insert(i, a as u32);
                }
            }
        }
        let mut union: Vec<u32> = self.neighbours[a]
            .iter()
            .chain(&from_b)
            .copied()
            .filter(|&n| n as usize != a && n as usize != b)
            .collect();
        union.sort_unstable();
        union.dedup();
        self.neighbours[a] = union;

        let mut scratch = std::mem::take(&mut self.scratch);
        for i in 0..self.neighbours[a].len() {
            let n = self.neighbours[a][i] as usize;
            let c = self.candidate(sums, &mut scratch, a, n);
            self.heap.push(Reverse(c));
        }
        self.scratch = scratch;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sums_of(points: &[[f64; 3]], frames: &[Vec<[f64; 3]>]) -> (Sums, Vec<f64>) {
        let motion = SampledMotion {
            rest: points.to_vec(),
            frames: frames.to_vec(),
        };
        let sums = Sums::new(&motion, frames.len());
        let mut s = vec![0.0; sums.len()];
        for v in 0..points.len() {
            sums.add_vertex(&mut s, v);
        }
        (sums, s)
    }

    /// The closed form agrees with a direct least-squares fit, for a full-rank set and a flat one.
    #[test]
    fn error_matches_a_direct_fit() {
        let points = [
            [0.1, 0.0, 0.2],
            [0.3, 0.1, -0.1],
            [-0.2, 0.25, 0.05],
            [0.05, -0.3, 0.1],
            [0.2, 0.2, 0.3],
            [-0.1, -0.1, -0.2],
        ];
        let wobble = |p: [f64; 3], k: usize| {
            [
                0.9 * p[0] + 0.1 * p[1] + 0.02 * (k as f64 * 1.7).sin(),
                p[1] + 0.3 * p[2] * p[2],
                p[2] - 0.2 + 0.01 * (k as f64).cos(),
            ]
        };
        let frames: Vec<Vec<[f64; 3]>> = (0..2)
            .map(|f| {
                (0..points.len())
                    .map(|k| wobble(points[k], k + f))
                    .collect()
            })
            .collect();
        let (sums, s) = sums_of(&points, &frames);
        let direct: f64 = frames
            .iter()
            .map(|f| {
                let solver = super::super::fit::AffineSolver::new(&points, 0.0);
                let h = solver.solve(f.iter().copied());
                points
                    .iter()
                    .zip(f)
                    .map(|(&p, q)| {
                        let r = super::super::fit::apply(&h, p);
                        (0..3).map(|a| (r[a] - q[a]).powi(2)).sum::<f64>()
                    })
                    .sum::<f64>()
            })
            .sum();
        let closed = sums.error(&s);
        assert!(direct > 1e-6, "the test motion must not be affine");
        assert!(
            (closed - direct).abs() < 1e-9 * direct.max(1.0),
            "{closed} vs {direct}"
        );

        // Four coplanar points moving out of their plane non-affinely: the minimum is not zero,
        // and three of them alone (always exactly affine) have zero error.
        let flat = [
            [0.0, 0.0, 0.0],
            [0.2, 0.0, 0.0],
            [0.0, 0.2, 0.0],
            [0.2, 0.2, 0.0],
        ];
        let bent = vec![vec![
            [0.0, 0.0, 0.0],
            [0.2, 0.0, 0.0],
            [0.0, 0.2, 0.0],
            [0.2, 0.2, 0.1],
        ]];
        let (sums, s) = sums_of(&flat, &bent);
        // Best fit spreads the 0.1 offset: residuals ±0.025 on all four in z: 4 × 0.025².
        assert!(
            (sums.error(&s) - 4.0 * 0.025f64.powi(2)).abs() < 1e-12,
            "{}",
            sums.error(&s)
        );
        let (sums, s) = sums_of(&flat[..3], &[bent[0][..3].to_vec()]);
        assert_eq!(sums.error(&s), 0.0);
    }

    /// Coincident frame-0 points that part later cannot share an affine map.
    #[test]
    fn coincident_points_that_part_have_an_error() {
        let points = [[0.1, 0.1, 0.1], [0.1, 0.1, 0.1]];
        let frames = vec![vec![[0.1, 0.1, 0.1], [0.3, 0.1, 0.1]]];
        let (sums, s) = sums_of(&points, &frames);
        assert!((sums.error(&s) - 2.0 * 0.1f64.powi(2)).abs() < 1e-12);
    }
}
