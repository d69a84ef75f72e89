//! Welding for charting: the triangles with every vertex replaced by the first vertex at the
//! same position (bit-identical, −0 and 0 alike).
//!
//! Meshes read from glTF are often split at UV seams and hard edges, or not indexed at all (Fox:
//! 1728 vertices for 576 separate triangles). Charting on the split connectivity makes every
//! seam a chart border and every loose triangle a chart. With `AtlasOptions::weld` the charts are
//! grown, cut and flattened on the welded triangles instead; every vertex still gets its own pixel
//! (the copies of a position share its 2D point, and the lattice moves all but one to the nearest
//! free pixels of their chart).

use std::collections::HashMap;

/// The triangles on welded vertex ids.
pub(crate) fn welded(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let key = |p: &[f32; 3]| p.map(|c| if c == 0.0 { 0 } else { c.to_bits() });
    let mut first: HashMap<[u32; 3], u32> = HashMap::with_capacity(positions.len());
    let canonical: Vec<u32> = positions
        .iter()
        .enumerate()
        .map(|(v, p)| *first.entry(key(p)).or_insert(v as u32))
        .collect();
    triangles
        .iter()
        .map(|t| t.map(|v| canonical.get(v as usize).copied().unwrap_or(v)))
        .collect()
}

#[cfg(test)]
mod tests {
    #[test]
    fn copies_of_a_position_become_its_first_vertex() {
        let p = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [-0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
        ];
        assert_eq!(super::welded(&p, &[[2, 3, 1]]), vec![[0, 1, 1]]);
    }
}
