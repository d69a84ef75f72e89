//! The half-edge collapses (`hecol`, eq. 3–4) on the coarse vertex graph: sets kept by union-find,
//! candidate merges in a heap ordered by the merged set's error, and the stopping rule at the error
//! budget or the cluster cap.

use super::normal_equations::Sums;
use crate::error::Result;
use crate::mesh::topology::VertexAdjacency;
use crate::motion::partition::{compact, Partition};
use rayon::prelude::*;
use std::cmp::{Ordering, Reverse};
use std::collections::BinaryHeap;

/// When collapses stop: at the error budget E0² F V (unit coordinates), unless above the cluster cap.
pub(super) struct Limits {
    pub(super) budget: f64,
    /// Sampled-frame errors × `scale` = errors over all frames.
    pub(super) scale: f64,
    pub(super) max_clusters: usize,
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
pub(super) struct State {
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
    pub(super) total: f64,
    /// Number of sets.
    live: usize,
}

impl State {
    /// The coarse mesh whose vertices are the sets of equal `labels` (any values below the vertex
    /// count), with the cost of every collapse between adjacent sets queued.
    pub(super) fn new(sums: &Sums, adjacency: &VertexAdjacency, labels: &[usize]) -> Self {
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
    pub(super) fn collapse_within(&mut self, sums: &Sums, limits: &Limits) -> usize {
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
    pub(super) fn partition(&mut self) -> Result<Partition> {
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
