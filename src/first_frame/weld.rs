//! Vertices at the same position, coded once.
//!
//! glTF meshes duplicate a vertex wherever a UV or normal seam passes, and some are triangle
//! soups (every triangle with its own three vertices): coded as they are, each copy is a new
//! vertex of a new component, predicted from nothing. So the traversal and the geometry run on
//! the *welded* mesh (one vertex per distinct position), and this module codes how the input's
//! vertices sit on it: the number of copies of each welded vertex ("one per corner?", which a
//! soup answers yes everywhere, else a unary count, one decision per copy), then, for each corner
//! of each triangle in coding order, which copy it uses. A corner most often uses the copy its
//! neighbour across an edge uses (the seam is elsewhere: asked knowing whether the edge's other
//! end changed copy, and how sharply the surface folds there, see `creases`), else a copy not
//! used yet (a soup), else one named among those used. Copies no triangle uses come last. Output
//! vertices are numbered in order of first use, which is what the vertex order stream and
//! `reorder` see.

use std::collections::HashMap;

use super::creases;
use super::quantise::Cell;
use super::traversal::{undirected, UNASSIGNED};
use crate::error::{Error, Result};
use crate::mesh::topology::VertexAdjacency;
use crate::mesh::Triangle;
use crate::stream::entropy::{BitModel, SymbolCoder, UIntModel};

/// The welded vertices of quantised positions.
pub(super) struct Weld {
    /// Input vertex → welded vertex.
    pub(super) welded_of: Vec<u32>,
    /// Welded vertex → its first input vertex (welded vertices follow first appearance).
    pub(super) first: Vec<u32>,
}

impl Weld {
    /// Welds vertices with equal keys (equal positions: they decode to the same position).
    pub(super) fn new<K: Copy + Eq + std::hash::Hash>(cells: &[K]) -> Self {
        let mut by_cell: HashMap<K, u32> = HashMap::with_capacity(cells.len());
        let mut first = Vec::new();
        let welded_of = cells
            .iter()
            .enumerate()
            .map(|(v, &c)| {
                *by_cell.entry(c).or_insert_with(|| {
                    first.push(v as u32);
                    (first.len() - 1) as u32
                })
            })
            .collect();
        Self { welded_of, first }
    }
}

/// What only the encoder knows.
#[derive(Clone, Copy)]
pub(super) struct Actual<'a> {
    /// Input vertices of each welded vertex (traversal numbering), in input order.
    pub(super) copies_of: &'a [Vec<u32>],
    /// The input vertex at each corner of each coded triangle.
    pub(super) corners: &'a [Triangle],
}

/// The output vertices.
pub(super) struct Numbering {
    /// The coded triangles in output vertex indices.
    pub(super) triangles: Vec<Triangle>,
    /// Output vertex → welded vertex (traversal numbering).
    pub(super) welded: Vec<u32>,
    /// Output vertex → input vertex (encoder only).
    pub(super) inputs: Vec<u32>,
}

#[derive(Default)]
struct Models {
    /// "a copy for each of its corners?" (a triangle soup), asked of vertices in two or more
    /// triangles, by how many coded neighbours had one (0, 1, 2+).
    own_copies: [BitModel; 3],
    /// "another copy?", by how many coded neighbours have copies (0, 1, 2+), the sharpest fold of
    /// the vertex's edges ([`creases`]) and how many copies there are already (1, 2, 3, 4+):
    /// seams are lines, copies come in runs along them, and hard edges split normals.
    more: [[[BitModel; 4]; creases::CLASSES]; 3],
    /// "the copy the neighbour across the edge uses?", by what the edge's other end did in this
    /// triangle ([`Seam`]: a seam cuts both ends of an edge) and how sharply the edge folds.
    same_as_neighbour: [[BitModel; creases::CLASSES]; 3],
    /// "a copy not used yet?", by whether a neighbour's copy was offered first.
    fresh: [BitModel; 2],
    which: UIntModel,
}

fn corrupt(what: &str) -> Error {
    Error::Stream(format!("first frame copies: {what}"))
}

/// Codes the copies of `welded_count` welded vertices, `vertex_count` in all, and which copy
/// each corner of `triangles` (welded traversal indices) uses.
pub(super) fn code_copies<C: SymbolCoder>(
    coder: &mut C,
    (triangles, cells): (&[Triangle], &[Cell]),
    welded_count: usize,
    vertex_count: usize,
    actual: Option<Actual>,
) -> Result<Numbering> {
    let mut models = Models::default();
    let adjacency = VertexAdjacency::new(welded_count, triangles);
    // Only a mesh with copies reads the folds (the others' counts are all 1).
    let folds = if vertex_count > welded_count {
        creases::classify(triangles, cells)
    } else {
        HashMap::new()
    };
    let fold = |a: u32, b: u32| folds.get(&undirected(a, b)).map_or(0, |&c| usize::from(c));
    let mut corners_of = vec![0usize; welded_count];
    for &w in triangles.iter().flatten() {
        if let Some(n) = corners_of.get_mut(w as usize) {
            *n += 1;
        }
    }
    let sharpest: Vec<usize> = (0..welded_count)
        .map(|w| {
            let around = adjacency.neighbours(w).iter();
            around.map(|&n| fold(w as u32, n)).max().unwrap_or(0)
        })
        .collect();
    let counts = code_counts(
        coder,
        &mut models,
        (&adjacency, &corners_of, &sharpest),
        vertex_count,
        actual,
    )?;
    let mut state = State {
        used: vec![Vec::new(); welded_count],
        out: Numbering {
            triangles: Vec::with_capacity(triangles.len()),
            welded: Vec::new(),
            inputs: Vec::new(),
        },
        output_of: actual.map_or_else(Vec::new, |_| vec![UNASSIGNED; vertex_count]),
    };
    let mut first_on_edge: HashMap<u64, u32> = HashMap::new();
    for (t, tri) in triangles.iter().enumerate() {
        let mut corners = [0u32; 3];
        for k in 0..3 {
            let w = tri[k] as usize;
            let count = *counts.get(w).ok_or_else(|| corrupt("vertex out of range"))?;
            let input = actual.and_then(|a| a.corners.get(t)).map(|c| c[k]);
            corners[k] = if count == 1 {
                match state.used[w].first() {
                    Some(&o) => o,
                    None => state.fresh(w, input),
                }
            } else {
                let across = neighbour_copy(tri, k, &first_on_edge, triangles, &state.out);
                let seam = across.map_or(Seam::Unknown, |a| {
                    Seam::at_other_end(a, (tri, k, &corners), &counts)
                });
                let pred = across.map(|a| a.copy);
                let crease = across.map_or(0, |a| fold(tri[k], tri[a.other]));
                let corner = Corner {
                    w,
                    count,
                    pred,
                    context: (seam, crease),
                };
                choose(coder, &mut models, &mut state, corner, input)?
            };
        }
        state.out.triangles.push(corners);
        for k in 0..3 {
            first_on_edge
                .entry(undirected(tri[k], tri[(k + 1) % 3]))
                .or_insert(t as u32);
        }
    }
    // Copies no triangle uses, welded vertex by welded vertex.
    for (w, &count) in counts.iter().enumerate() {
        let mut spare = actual.map(|a| a.copies_of[w].iter());
        while state.used[w].len() < count {
            let input = spare.as_mut().and_then(|s| {
                s.find(|&&v| state.output_of.get(v as usize) == Some(&UNASSIGNED))
                    .copied()
            });
            state.fresh(w, input);
        }
    }
    Ok(state.out)
}

/// The number of copies of each welded vertex, checked to add up to `vertex_count`: first, for a
/// vertex of two or more corners (`corners_of`, from the triangles), whether it has one copy per
/// corner, as every vertex of a triangle soup has; else the count in unary.
fn code_counts<C: SymbolCoder>(
    coder: &mut C,
    models: &mut Models,
    (adjacency, corners_of, sharpest): (&VertexAdjacency, &[usize], &[usize]),
    vertex_count: usize,
    actual: Option<Actual>,
) -> Result<Vec<usize>> {
    let welded_count = corners_of.len();
    let mut counts = Vec::with_capacity(welded_count);
    let mut total = 0usize;
    for (w, &corners) in corners_of.iter().enumerate() {
        let want = actual.map_or(1, |a| a.copies_of[w].len());
        let coded = |n: &u32| counts.get(*n as usize).map(|&c| (c, corners_of[*n as usize]));
        let neighbours = adjacency.neighbours(w).iter().filter_map(coded);
        let (mut seamed, mut soup) = (0usize, 0usize);
        for (count, corners) in neighbours {
            seamed += usize::from(count > 1);
            soup += usize::from(corners > 1 && count == corners);
        }
        let (seamed, soup) = (seamed.min(2), soup.min(2));
        if corners > 1 && coder.bit(want == corners, &mut models.own_copies[soup])? {
            if total + corners > vertex_count {
                return Err(corrupt("more copies than vertices"));
            }
            total += corners;
            counts.push(corners);
            continue;
        }
        let mut count = 1;
        let more = &mut models.more[seamed][sharpest[w].min(creases::CLASSES - 1)];
        while coder.bit(count < want, &mut more[(count - 1).min(3)])? {
            count += 1;
            if total + count > vertex_count {
                return Err(corrupt("more copies than vertices"));
            }
        }
        total += count;
        counts.push(count);
    }
    if total != vertex_count {
        return Err(corrupt("copies do not add up to the vertices"));
    }
    Ok(counts)
}

struct State {
    /// Output vertices of each welded vertex so far.
    used: Vec<Vec<u32>>,
    out: Numbering,
    /// Input → output vertex (encoder only).
    output_of: Vec<u32>,
}

impl State {
    /// A new output vertex for welded vertex `w` (input vertex `input` on the encoder).
    fn fresh(&mut self, w: usize, input: Option<u32>) -> u32 {
        let o = self.out.welded.len() as u32;
        self.out.welded.push(w as u32);
        self.used[w].push(o);
        if let Some(slot) = input.and_then(|v| self.output_of.get_mut(v as usize)) {
            *slot = o;
            self.out.inputs.push(input.unwrap_or(0));
        }
        o
    }
}

/// A corner's neighbour across an edge: the copy it uses there, the corner of this triangle at
/// the edge's other end, and the copy that end uses there.
#[derive(Clone, Copy)]
struct Across {
    copy: u32,
    other: usize,
    other_copy: Option<u32>,
}

/// The copy that corner `k` of `tri` uses in the first coded triangle sharing one of its edges
/// (the entry edge, corners 0 and 1, first).
fn neighbour_copy(
    tri: &Triangle,
    k: usize,
    first_on_edge: &HashMap<u64, u32>,
    triangles: &[Triangle],
    out: &Numbering,
) -> Option<Across> {
    (0..3).filter(|&j| j != k).find_map(|j| {
        let t = *first_on_edge.get(&undirected(tri[k], tri[j]))? as usize;
        let (there, copies) = (triangles.get(t)?, out.triangles.get(t)?);
        let copy_of = |v: u32| there.iter().position(|&x| x == v).map(|pos| copies[pos]);
        Some(Across {
            copy: copy_of(tri[k])?,
            other: j,
            other_copy: copy_of(tri[j]),
        })
    })
}

/// What the other end of the edge a corner's prediction comes across did in this triangle.
#[derive(Clone, Copy)]
enum Seam {
    /// Not coded yet, or it has one copy.
    Unknown,
    /// It uses the copy it uses across the edge: most likely no seam on the edge.
    Kept,
    /// It changed copy: most likely a seam on the edge.
    Cut,
}

impl Seam {
    /// For corner `k` of `tri`, predicted `across` an edge, with the `corners` of this triangle
    /// below `k` decided.
    fn at_other_end(
        across: Across,
        (tri, k, corners): (&Triangle, usize, &[u32; 3]),
        counts: &[usize],
    ) -> Seam {
        let j = across.other;
        if j >= k || counts.get(tri[j] as usize).is_none_or(|&c| c < 2) {
            return Seam::Unknown;
        }
        match across.other_copy {
            Some(copy) if copy == corners[j] => Seam::Kept,
            Some(_) => Seam::Cut,
            None => Seam::Unknown,
        }
    }
}

/// A corner of a welded vertex with copies, as [`choose`] codes it.
struct Corner {
    w: usize,
    count: usize,
    pred: Option<u32>,
    /// What the edge's other end did, and the edge's fold class.
    context: (Seam, usize),
}

/// Codes which of the copies of a welded vertex a corner uses.
fn choose<C: SymbolCoder>(
    coder: &mut C,
    models: &mut Models,
    state: &mut State,
    corner: Corner,
    input: Option<u32>,
) -> Result<u32> {
    let Corner {
        w,
        count,
        pred,
        context: (seam, crease),
    } = corner;
    let known = input
        .and_then(|v| state.output_of.get(v as usize).copied())
        .filter(|&o| o != UNASSIGNED);
    if let Some(p) = pred {
        let model = &mut models.same_as_neighbour[seam as usize][crease.min(creases::CLASSES - 1)];
        if coder.bit(known == Some(p), model)? {
            return Ok(p);
        }
    }
    let others: Vec<u32> = state.used[w]
        .iter()
        .copied()
        .filter(|&o| Some(o) != pred)
        .collect();
    let can_be_fresh = state.used[w].len() < count;
    let fresh = match (can_be_fresh, others.is_empty()) {
        (true, false) => coder.bit(known.is_none(), &mut models.fresh[usize::from(pred.is_some())])?,
        (true, true) => true,
        (false, false) => false,
        (false, true) => return Err(corrupt("no copy left")),
    };
    if fresh {
        return Ok(state.fresh(w, input));
    }
    let index = known
        .and_then(|o| others.iter().position(|&x| x == o))
        .unwrap_or(0);
    let index = if others.len() > 1 {
        coder.unsigned(index as u64, &mut models.which)?
    } else {
        0
    };
    usize::try_from(index)
        .ok()
        .and_then(|i| others.get(i).copied())
        .ok_or_else(|| corrupt("no such copy"))
}
