//! Step 3 of the build, vertex ownership: each vertex shared by several charts is owned by one of
//! them, then charts owning too few vertices hand them to a neighbouring chart.

use crate::unwrap::Flattening;

/// Each vertex goes to one chart: among the charts with a face on it, the
/// one with most faces among those whose faces are in the vertex's own
/// cluster, else the one with most faces; ties go to the lower chart id.
/// Preferring big charts empties the slivers uvunwrap leaves along seams,
/// which are then dropped instead of each costing a block.
pub(crate) fn assign_owners(
    triangles: &[[u32; 3]],
    partition: &[u32],
    face_cluster: &[u32],
    flat: &Flattening,
    vertices: usize,
) -> Vec<Option<(u32, [f64; 2])>> {
    let mut chart_faces = vec![0usize; flat.charts as usize];
    for c in flat.face_chart.iter().flatten() {
        chart_faces[*c as usize] += 1;
    }
    // Rank: (own cluster, faces in chart, lower id first).
    type Rank = (bool, usize, std::cmp::Reverse<u32>);
    let mut owner: Vec<Option<(Rank, u32, [f64; 2])>> = vec![None; vertices];
    for (f, tri) in triangles.iter().enumerate() {
        let Some(chart) = flat.face_chart[f] else {
            continue;
        };
        for (k, &v) in tri.iter().enumerate() {
            let own_cluster = partition.get(v as usize) == face_cluster.get(f);
            let rank = (
                own_cluster,
                chart_faces[chart as usize],
                std::cmp::Reverse(chart),
            );
            let slot = &mut owner[v as usize];
            if slot.as_ref().is_none_or(|(r, _, _)| rank > *r) {
                *slot = Some((rank, chart, flat.corner_uv[f][k]));
            }
        }
    }
    owner
        .into_iter()
        .map(|o| o.map(|(_, c, uv)| (c, uv)))
        .collect()
}

/// Hands the vertices of charts owning fewer than `min` vertices to the
/// neighbouring chart that owns most of their mesh neighbours, placed at the
/// mean of those neighbours' 2D positions: a chart of a few vertices would
/// otherwise hold a whole block alone. A chart takes in at most as many
/// vertices as it owns, so that on coarse meshes made of small charts one
/// chart does not swallow the rest onto a few pixels
/// (docs/design.md, "Atlas: whole-piece charts and packing"). Returns how many
/// vertices changed chart.
pub(crate) fn absorb_small_charts(
    triangles: &[[u32; 3]],
    owner: &mut [Option<(u32, [f64; 2])>],
    charts: u32,
    min: usize,
) -> usize {
    let mut count = vec![0usize; charts as usize];
    for (c, _) in owner.iter().flatten() {
        count[*c as usize] += 1;
    }
    let small: Vec<bool> = count.iter().map(|&n| n > 0 && n < min).collect();
    let mut room = count.clone();
    if !small.iter().any(|&s| s) {
        return 0;
    }
    let neighbours = mesh_neighbours(triangles, owner.len());
    let mut absorbed = 0;
    loop {
        let mut changed = false;
        for v in 0..owner.len() {
            let Some((c, _)) = owner[v] else { continue };
            if !small[c as usize] {
                continue;
            }
            let takes = |d: u32| !small[d as usize] && room[d as usize] > 0;
            if let Some((d, n, sum)) = best_absorber(&neighbours[v], owner, takes) {
                room[d as usize] -= 1;
                owner[v] = Some((d, [sum[0] / n as f64, sum[1] / n as f64]));
                absorbed += 1;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    absorbed
}

/// Each vertex's neighbours through mesh edges (repeated once per edge side).
fn mesh_neighbours(triangles: &[[u32; 3]], vertices: usize) -> Vec<Vec<u32>> {
    let mut neighbours = vec![Vec::new(); vertices];
    for tri in triangles {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            if a != b {
                neighbours[a as usize].push(b);
                neighbours[b as usize].push(a);
            }
        }
    }
    neighbours
}

/// Among the charts that `takes` and that own some of `neighbours`, the one owning most of them
/// (ties: lower chart id), with that count and the sum of those neighbours' 2D positions.
fn best_absorber(
    neighbours: &[u32],
    owner: &[Option<(u32, [f64; 2])>],
    takes: impl Fn(u32) -> bool,
) -> Option<(u32, usize, [f64; 2])> {
    let mut tally: Vec<(u32, usize, [f64; 2])> = Vec::new();
    for &w in neighbours {
        let Some((d, uv)) = owner[w as usize] else {
            continue;
        };
        if !takes(d) {
            continue;
        }
        match tally.iter_mut().find(|t| t.0 == d) {
            Some(t) => {
                t.1 += 1;
                t.2 = [t.2[0] + uv[0], t.2[1] + uv[1]];
            }
            None => tally.push((d, 1, uv)),
        }
    }
    tally
        .into_iter()
        .max_by_key(|t| (t.1, std::cmp::Reverse(t.0)))
}
