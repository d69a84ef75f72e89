//! Motion segmentation by decimation (skinning paper, Mamou et al., §3.1, eq. 1–6): the vertex graph
//! is simplified by half-edge collapses that merge vertices moving with the same affine motion, and
//! the vertices of the coarse mesh, each with its ancestor set, become the clusters. K is not asked
//! for; it falls out of the error threshold E0.
//!
//! This module holds the options and the driver (plain decimation, then border refinement);
//! `normal_equations` the per-set sums and the closed-form fit error; `collapse` the collapse heap
//! and the merges.
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
//! # Measured
//! Border refinement leaves fewer clusters than plain decimation at the same E0, and k-means at
//! the K decimation finds predicts worse (`cargo bench --bench motion`;
//! docs/design.md, "Decimation: border refinement").

mod collapse;
mod normal_equations;

use super::partition::Partition;
use super::refine::refine_borders;
use super::sampled_motion::{feature_frames, welded_adjacency, SampledMotion};
use crate::error::{Error, Result};
use crate::mesh::topology::VertexAdjacency;
use crate::mesh::AnimatedMesh;
use collapse::{Limits, State};
use normal_equations::Sums;

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
    /// The diagnostics below are read by the motion bench and the tests.
    /// Frames the errors were measured on (all but frame 0, which every affine map fits exactly,
    /// unless subsampled).
    #[cfg_attr(not(feature = "internals"), allow(dead_code))]
    pub frames_used: usize,
    /// Half-edge collapses done.
    #[cfg_attr(not(feature = "internals"), allow(dead_code))]
    pub collapses: usize,
    /// K of the paper's plain decimation: the clusters the first collapses left, before refinement.
    #[cfg_attr(not(feature = "internals"), allow(dead_code))]
    pub decimated_clusters: usize,
    /// `E_l` of the paper's plain decimation, before refinement.
    #[cfg_attr(not(feature = "internals"), allow(dead_code))]
    pub decimated_error: f64,
}

/// Segments the vertices by decimation (skinning paper §3.1): see the module documentation.
pub fn decimate(mesh: &AnimatedMesh, opts: &DecimateOptions) -> Result<Decimation> {
    check_options(opts)?;
    let problem = Problem::new(mesh, opts)?;
    let singletons: Vec<usize> = (0..mesh.vertex_count()).collect();
    let plain = problem.collapse(problem.sets(&singletons))?;
    let refined = problem.refine(plain.clone(), opts.refine_passes)?;
    let partition = refined.partition;
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
        error: problem.rms(refined.total),
        decimated_clusters: plain.partition.clusters(),
        decimated_error: problem.rms(plain.total),
        partition,
        components: problem.components,
        frames_used: problem.frames_used,
        collapses: refined.collapses,
    })
}

/// Refuses a threshold E0 that is not a positive number and a cluster cap of 0.
fn check_options(opts: &DecimateOptions) -> Result<()> {
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
    Ok(())
}

/// One animation's decimation: its sampled motion, seam-welded vertex graph, trajectories laid
/// out for the normal equations, and when collapses stop.
struct Problem {
    sampled: SampledMotion,
    adjacency: VertexAdjacency,
    /// Connected components of `adjacency`.
    components: usize,
    /// Frames the errors are measured on.
    frames_used: usize,
    sums: Sums,
    limits: Limits,
    /// Vertices × frames of the whole animation, the denominator of `E_l` (eq. 5).
    vertex_frames: f64,
}

/// Where the collapses stand: the clusters, their total error over the sampled frames, and the
/// collapses done to get there.
#[derive(Clone)]
struct Outcome {
    partition: Partition,
    total: f64,
    collapses: usize,
}

impl Problem {
    fn new(mesh: &AnimatedMesh, opts: &DecimateOptions) -> Result<Self> {
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
                 its own cluster, more than the cap of {}; k-means segmentation takes any mesh",
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
        Ok(Self {
            sampled,
            adjacency,
            components,
            frames_used,
            sums,
            limits,
            vertex_frames: f_count as f64 * v_count as f64,
        })
    }

    /// `E_l` (eq. 5) of a total error over the sampled frames.
    fn rms(&self, total: f64) -> f64 {
        (total * self.limits.scale / self.vertex_frames).sqrt()
    }

    /// The coarse mesh whose vertices are the sets of equal `labels`.
    fn sets(&self, labels: &[usize]) -> State {
        State::new(&self.sums, &self.adjacency, labels)
    }

    /// Collapses the sets of `state` within the limits.
    fn collapse(&self, mut state: State) -> Result<Outcome> {
        let collapses = state.collapse_within(&self.sums, &self.limits);
        Ok(Outcome {
            partition: state.partition()?,
            total: state.total,
            collapses,
        })
    }

    /// Border refinement, up to `passes` rounds. Sets of up to four vertices fit any motion exactly,
    /// so early collapses can pair vertices across a border between parts; such a set later fits
    /// neither part and survives as a cluster of its own. Each round moves border vertices to the
    /// neighbouring cluster that predicts them best (components stay apart: only moves to a
    /// neighbour's cluster), then resumes the collapses on the clusters so refined, with what is
    /// left of the budget.
    fn refine(&self, mut outcome: Outcome, passes: usize) -> Result<Outcome> {
        for _ in 0..passes {
            if outcome.partition.clusters() <= self.components || self.frames_used == 0 {
                break;
            }
            let k = outcome.partition.clusters();
            let mut labels: Vec<usize> = outcome
                .partition
                .labels()
                .iter()
                .map(|&l| l as usize)
                .collect();
            refine_borders(&mut labels, &self.adjacency, &self.sampled, k, 1, false);
            let state = self.sets(&labels);
            if state.total > outcome.total {
                // The refinement's (regularised) fits misjudged: keep what the collapses found.
                break;
            }
            let refined = self.collapse(state)?;
            let unchanged =
                refined.collapses == 0 && refined.partition.labels() == outcome.partition.labels();
            outcome = Outcome {
                collapses: outcome.collapses + refined.collapses,
                ..refined
            };
            if unchanged {
                break;
            }
        }
        Ok(outcome)
    }
}
