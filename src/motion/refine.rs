//! Cluster refinement by what the predictor is judged on: how well a cluster's affine maps
//! predict a vertex's trajectory over the sampled frames.

use super::fit::{apply, AffineCoefficients, AffineSolver};
use super::sampled_motion::{SampledMotion, SAMPLED_FIT_LAMBDA};
use crate::mesh::topology::VertexAdjacency;
use rayon::prelude::*;

/// Per cluster, the affine maps (eq. 2) of its `members` over the sampled frames; `None` when empty.
fn cluster_tracks(
    members: &[Vec<usize>],
    motion: &SampledMotion,
) -> Vec<Option<Vec<AffineCoefficients>>> {
    members
        .par_iter()
        .map(|m| {
            if m.is_empty() {
                return None;
            }
            let source: Vec<[f64; 3]> = m.iter().map(|&v| motion.rest[v]).collect();
            let solver = AffineSolver::new(&source, SAMPLED_FIT_LAMBDA);
            Some(
                motion
                    .frames
                    .iter()
                    .map(|f| solver.solve(m.iter().map(|&v| f[v])))
                    .collect(),
            )
        })
        .collect()
}

/// Squared error of predicting vertex `v`'s sampled trajectory with `track`; infinite for no track.
fn trajectory_cost(
    track: Option<&Vec<AffineCoefficients>>,
    motion: &SampledMotion,
    v: usize,
) -> f64 {
    let Some(track) = track else {
        return f64::INFINITY;
    };
    track
        .iter()
        .zip(&motion.frames)
        .map(|(h, f)| {
            let q = apply(h, motion.rest[v]);
            (0..3).map(|a| (q[a] - f[v][a]).powi(2)).sum::<f64>()
        })
        .sum()
}

fn group(labels: &[usize], vertices: impl Iterator<Item = usize>, k: usize) -> Vec<Vec<usize>> {
    let mut members = vec![Vec::new(); k];
    for v in vertices {
        if let Some(m) = members.get_mut(labels[v]) {
            m.push(v);
        }
    }
    members
}

/// Gives each vertex outside `inliers` the cluster whose affine maps (fitted on that cluster's
/// inliers, eq. 2) predict its sampled trajectory best: the criterion the predictor will be judged by.
pub(super) fn assign_by_trajectory(
    labels: &mut [usize],
    inliers: &[usize],
    motion: &SampledMotion,
    k: usize,
) {
    let tracks = cluster_tracks(&group(labels, inliers.iter().copied(), k), motion);
    let mut is_inlier = vec![false; labels.len()];
    inliers.iter().for_each(|&v| is_inlier[v] = true);
    labels
        .par_iter_mut()
        .enumerate()
        .filter(|(v, _)| !is_inlier[*v])
        .for_each(|(v, label)| {
            if let Some((best, _)) = (0..k)
                .map(|c| (c, trajectory_cost(tracks[c].as_ref(), motion, v)))
                .min_by(|a, b| a.1.total_cmp(&b.1))
            {
                *label = best;
            }
        });
}

/// Moves cluster borders to lower the prediction error, keeping clusters spatially coherent: a
/// vertex may only join a cluster one of its neighbours is in, and (with `move_components`) a
/// connected component lying wholly in one cluster may move as a whole to any cluster.
pub(super) fn refine_borders(
    labels: &mut Vec<usize>,
    adjacency: &VertexAdjacency,
    motion: &SampledMotion,
    k: usize,
    passes: usize,
    move_components: bool,
) {
    let (component, component_count) = adjacency.components();
    for _ in 0..passes {
        let tracks = cluster_tracks(&group(labels, 0..labels.len(), k), motion);
        let current: &[usize] = labels;
        let mut next: Vec<usize> = (0..current.len())
            .into_par_iter()
            .map(|v| {
                let own = current[v];
                let mut best = (own, trajectory_cost(tracks[own].as_ref(), motion, v));
                for &u in adjacency.neighbours(v) {
                    let c = current[u as usize];
                    if c != best.0 {
                        let cost = trajectory_cost(tracks[c].as_ref(), motion, v);
                        if cost < best.1 {
                            best = (c, cost);
                        }
                    }
                }
                best.0
            })
            .collect();
        let mut single = vec![Some(usize::MAX); component_count];
        for (v, &c) in component.iter().enumerate() {
            let s = &mut single[c as usize];
            *s = match *s {
                Some(usize::MAX) => Some(next[v]),
                Some(l) if l == next[v] => Some(l),
                _ => None,
            };
        }
        let members = group(
            &component.iter().map(|&c| c as usize).collect::<Vec<_>>(),
            0..labels.len(),
            component_count,
        );
        for (c, vertices) in members.iter().enumerate() {
            if !move_components || single[c].is_none() || vertices.is_empty() {
                continue;
            }
            let best = (0..k)
                .map(|l| {
                    let cost: f64 = vertices
                        .iter()
                        .map(|&v| trajectory_cost(tracks[l].as_ref(), motion, v))
                        .sum();
                    (l, cost)
                })
                .min_by(|a, b| a.1.total_cmp(&b.1));
            if let Some((l, _)) = best {
                vertices.iter().for_each(|&v| next[v] = l);
            }
        }
        if next == *labels {
            break;
        }
        *labels = next;
    }
}
