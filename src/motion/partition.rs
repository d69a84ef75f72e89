//! The result of segmentation: one cluster id per vertex, checked to be compact (every cluster
//! used), plus the renumbering that makes raw labels compact.

use crate::error::{Error, Result};

/// A cluster id per vertex. Labels are compact: every cluster in `0..clusters()` has at least one vertex.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Partition {
    labels: Vec<u32>,
    clusters: usize,
}

impl Partition {
    /// Checks and wraps labels (e.g. read from a stream): at least one vertex, every label below
    /// `clusters`, and every cluster used.
    pub fn from_labels(labels: Vec<u32>, clusters: usize) -> Result<Self> {
        if labels.is_empty() {
            return Err(Error::Stream("partition has no vertices".into()));
        }
        let mut used = vec![false; clusters];
        for (v, &l) in labels.iter().enumerate() {
            match used.get_mut(l as usize) {
                Some(u) => *u = true,
                None => {
                    return Err(Error::Stream(format!(
                        "partition: vertex {v} has cluster {l}, but there are only {clusters}"
                    )))
                }
            }
        }
        if let Some(k) = used.iter().position(|&u| !u) {
            return Err(Error::Stream(format!(
                "partition: cluster {k} of {clusters} has no vertex"
            )));
        }
        Ok(Self { labels, clusters })
    }

    /// The cluster of each vertex.
    pub fn labels(&self) -> &[u32] {
        &self.labels
    }

    /// Number of clusters.
    pub fn clusters(&self) -> usize {
        self.clusters
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.labels.len()
    }

    /// The vertices of each cluster, in increasing order.
    pub fn members(&self) -> Vec<Vec<u32>> {
        let mut members = vec![Vec::new(); self.clusters];
        for (v, &l) in self.labels.iter().enumerate() {
            if let Some(m) = members.get_mut(l as usize) {
                m.push(v as u32);
            }
        }
        members
    }
}

/// Renumbers labels `0..n` in order of first appearance.
pub(super) fn compact(labels: Vec<usize>) -> Result<Partition> {
    let mut map = std::collections::HashMap::new();
    let compact: Vec<u32> = labels
        .into_iter()
        .map(|l| {
            let next = map.len() as u32;
            *map.entry(l).or_insert(next)
        })
        .collect();
    Partition::from_labels(compact, map.len())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn partition_rejects_bad_labels() {
        assert!(Partition::from_labels(vec![0, 2], 2).is_err());
        assert!(Partition::from_labels(vec![0, 0], 2).is_err());
        assert!(Partition::from_labels(vec![], 1).is_err());
        let p = Partition::from_labels(vec![1, 0, 1], 2).unwrap();
        assert_eq!(p.members(), vec![vec![1], vec![0, 2]]);
    }
}
