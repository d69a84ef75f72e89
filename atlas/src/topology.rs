//! Topology of a seed piece: its boundary loops and Euler characteristic, which say whether the
//! piece is a disk (it can flatten as one chart), a genus-0 surface with several boundary loops
//! (an annulus, such as a band of a tube: a disk once cuts join its loops), closed, or anything
//! else (higher genus, non-manifold), which is left to the unwrapper's own segmentation.

use crate::seed::Dsu;
use std::collections::HashMap;

/// What a piece is, topologically.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    /// One boundary loop, genus 0.
    Disk,
    /// Genus 0 with two or more boundary loops, each given as its vertices.
    Holed(Vec<Vec<u32>>),
    /// No boundary, genus 0 (a sphere).
    Closed,
    /// Higher genus, non-manifold edges or pinched boundaries.
    Other,
}

/// The kind of surface the faces `faces` of `triangles` make. Faces with a repeated corner are
/// ignored (they carry no surface and the unwrapper drops them).
pub(crate) fn classify(triangles: &[[u32; 3]], faces: &[usize]) -> Kind {
    let mut edge_use: HashMap<(u32, u32), u32> = HashMap::new();
    let mut vertices: HashMap<u32, ()> = HashMap::new();
    let mut face_count = 0i64;
    for &f in faces {
        let t = triangles[f];
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            continue;
        }
        face_count += 1;
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *edge_use.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            vertices.insert(a, ());
        }
    }
    if edge_use.values().any(|&n| n > 2) {
        return Kind::Other;
    }
    let boundary: Vec<(u32, u32)> = edge_use
        .iter()
        .filter(|(_, &n)| n == 1)
        .map(|(&e, _)| e)
        .collect();
    let loops = boundary_loops(&boundary);
    let chi = vertices.len() as i64 - edge_use.len() as i64 + face_count;
    // χ = 2 − 2g − b on a manifold surface; a pinched vertex (two loops meeting, or a fan that
    // is not a disk) breaks the count, which then matches no genus-0 case below or gives a
    // kind whose flattening fails and falls back.
    let b = loops.len() as i64;
    if 2 - b - chi != 0 {
        return Kind::Other;
    }
    match loops.len() {
        0 => Kind::Closed,
        1 => Kind::Disk,
        _ => Kind::Holed(loops),
    }
}

/// The connected components of the boundary edges, as vertex lists (sorted, for determinism);
/// a loop whose vertices do not each have exactly two boundary edges (a pinched boundary) makes
/// the whole answer an empty-loop marker that [`classify`] rejects through the Euler count.
fn boundary_loops(boundary: &[(u32, u32)]) -> Vec<Vec<u32>> {
    let mut index: HashMap<u32, u32> = HashMap::new();
    let mut degree: Vec<u32> = Vec::new();
    let mut id = |v: u32, degree: &mut Vec<u32>| {
        let next = index.len() as u32;
        let i = *index.entry(v).or_insert(next);
        if i as usize == degree.len() {
            degree.push(0);
        }
        degree[i as usize] += 1;
        i
    };
    let ends: Vec<(u32, u32)> = boundary
        .iter()
        .map(|&(a, b)| (id(a, &mut degree), id(b, &mut degree)))
        .collect();
    let mut dsu = Dsu::new(index.len());
    for &(a, b) in &ends {
        dsu.union(a, b);
    }
    let mut by_root: HashMap<u32, Vec<u32>> = HashMap::new();
    for (&v, &i) in &index {
        by_root.entry(dsu.find(i)).or_default().push(v);
    }
    let mut loops: Vec<Vec<u32>> = by_root.into_values().collect();
    if degree.iter().any(|&d| d != 2) {
        // A pinched boundary: report one loop more than there are, so that χ never matches.
        loops.push(Vec::new());
    }
    loops.iter_mut().for_each(|l| l.sort_unstable());
    loops.sort();
    loops
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tube of `around` × `rows` quads, open at both ends (an annulus).
    fn tube(around: u32, rows: u32) -> Vec<[u32; 3]> {
        let mut t = Vec::new();
        for i in 0..rows {
            for j in 0..around {
                let a = i * around + j;
                let b = i * around + (j + 1) % around;
                let (c, d) = (a + around, b + around);
                t.push([a, b, d]);
                t.push([a, d, c]);
            }
        }
        t
    }

    #[test]
    fn kinds_of_simple_surfaces() {
        let all = |t: &[[u32; 3]]| (0..t.len()).collect::<Vec<_>>();
        let band = tube(6, 3);
        match classify(&band, &all(&band)) {
            Kind::Holed(loops) => assert_eq!(loops.len(), 2),
            k => panic!("band is {k:?}"),
        }
        // Half the band (three quads around) is a disk.
        let strip: Vec<usize> = (0..band.len()).filter(|f| (f / 2) % 6 < 3).collect();
        assert_eq!(classify(&band, &strip), Kind::Disk);
        // A tetrahedron is closed.
        let tet = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]];
        assert_eq!(classify(&tet, &all(&tet)), Kind::Closed);
        // Three faces on one edge: not a manifold.
        let fan = [[0, 1, 2], [1, 0, 3], [0, 1, 4]];
        assert_eq!(classify(&fan, &all(&fan)), Kind::Other);
    }

    #[test]
    fn a_torus_is_other() {
        // A 4×4 torus: the tube with its last row glued to the first.
        let t: Vec<[u32; 3]> = tube(4, 4).into_iter().map(|f| f.map(|v| v % 16)).collect();
        assert_eq!(classify(&t, &(0..t.len()).collect::<Vec<_>>()), Kind::Other);
    }
}
