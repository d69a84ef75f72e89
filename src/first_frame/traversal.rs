//! The connectivity traversal, written once for encoder and decoder (see [`SymbolCoder`]).
//!
//! A cut-border region growing in the spirit of Edgebreaker, generalised so that it needs no
//! manifold input: each undirected edge of a coded triangle becomes a *gate*, processed once
//! (depth first). Processing a gate codes, one by one, every not-yet-coded triangle on that edge
//! (so non-manifold edges just carry more than one) followed by a stop flag. A triangle is its
//! orientation bit (consistent with its neighbour or not) and a reference to its third vertex:
//! - `New`: first appearance (its position is coded afterwards, see `geometry`);
//! - `Left` / `Right`: the neighbour of the gate's ends along the open border (Edgebreaker's
//!   L, R and E cases);
//! - `Walk`: further along the open border (up to [`WALK_LIMIT`] steps), which covers most of
//!   Edgebreaker's S case without its offsets;
//! - `Explicit`: anything else (handles, components meeting at a vertex, non-manifold vertices)
//!   by its distance to the newest vertex in traversal order.
//!
//! When no gate is left, a new seed triangle starts the next component. Vertices are numbered
//! by first appearance ("traversal order"); the caller maps them back to the input's order.

use std::collections::{HashMap, HashSet};

use crate::error::{Error, Result};
use crate::mesh::Triangle;
use crate::stream::entropy::{BitModel, SymbolCoder, SymbolModel, UIntModel};

/// How far along the open border a `Walk` reference looks on each side.
const WALK_LIMIT: usize = 16;
/// Marks a vertex of the input not yet given a traversal index.
pub(super) const UNASSIGNED: u32 = u32::MAX;

const REF_NEW: usize = 0;
const REF_LEFT: usize = 1;
const REF_RIGHT: usize = 2;
const REF_WALK: usize = 3;
const REF_EXPLICIT: usize = 4;
const REF_KINDS: usize = 5;
const REFERENCE_CONTEXTS: usize = REF_KINDS * 2 * 3 * 3;

/// Context of a reference: the previous kind, whether both border neighbours are one vertex
/// (a closing triangle is likely) and how many coded triangles already surround each gate end
/// (a nearly full fan is likely to close, as in valence-driven coders).
fn reference_context(
    t: &Traversal,
    previous: usize,
    [a, b, _]: [u32; 3],
    left: Option<u32>,
    right: Option<u32>,
) -> usize {
    let fan = |v: u32| match t.outgoing.get(v as usize).map_or(0, Vec::len) {
        0..=3 => 0,
        4 => 1,
        _ => 2,
    };
    let closing = usize::from(left.is_some() && left == right);
    ((previous.min(REF_KINDS - 1) * 2 + closing) * 3 + fan(a)) * 3 + fan(b)
}

/// Adaptive contexts of the traversal.
pub(super) struct Models {
    /// "another triangle on this edge?", by how many coded triangles the edge has (0, 1, 2+).
    more: [BitModel; 3],
    flipped: BitModel,
    /// The kind of vertex reference, by [`reference_context`].
    reference: Vec<SymbolModel>,
    walk_side: BitModel,
    walk_step: UIntModel,
    explicit: UIntModel,
    seed_new: BitModel,
    previous_kind: usize,
}

impl Default for Models {
    fn default() -> Self {
        Self {
            more: Default::default(),
            flipped: BitModel::default(),
            reference: vec![SymbolModel::new(REF_KINDS); REFERENCE_CONTEXTS],
            walk_side: BitModel::default(),
            walk_step: UIntModel::default(),
            explicit: UIntModel::default(),
            seed_new: BitModel::default(),
            previous_kind: REF_NEW,
        }
    }
}

/// What only the encoder knows: the input mesh and how far it has been coded.
pub(super) struct Oracle<'a> {
    triangles: &'a [Triangle],
    by_edge: HashMap<u64, Vec<u32>>,
    coded: Vec<bool>,
    next_seed: usize,
    /// Input index → traversal index.
    pub(super) to_traversal: Vec<u32>,
    /// Traversal index → input index.
    pub(super) from_traversal: Vec<u32>,
    /// Indices of the input triangles in coding order.
    pub(super) coded_order: Vec<u32>,
}

impl<'a> Oracle<'a> {
    /// `triangles` must have three distinct indices below `vertex_count` each.
    pub(super) fn new(triangles: &'a [Triangle], vertex_count: usize) -> Self {
        Self {
            triangles,
            by_edge: by_edge(triangles),
            coded: vec![false; triangles.len()],
            next_seed: 0,
            to_traversal: vec![UNASSIGNED; vertex_count],
            from_traversal: Vec::new(),
            coded_order: Vec::new(),
        }
    }

    /// The next uncoded triangle on input edge {a, b}, preferring the consistently oriented
    /// one: its index, third vertex and whether it contains a→b (flipped) rather than b→a.
    fn next_on_edge(&self, a: u32, b: u32) -> Option<(usize, u32, bool)> {
        let list = self.by_edge.get(&undirected(a, b))?;
        let mut found = None;
        for &t in list {
            let t = t as usize;
            if self.coded.get(t).copied().unwrap_or(true) {
                continue;
            }
            let tri = self.triangles.get(t)?;
            let k = tri.iter().position(|&v| v != a && v != b)?;
            let x = tri[k];
            // With x at position k, the triangle reads (x, p, q) cyclically.
            let (p, q) = (tri[(k + 1) % 3], tri[(k + 2) % 3]);
            let flipped = (p, q) == (a, b);
            if !flipped {
                return Some((t, x, false));
            }
            found.get_or_insert((t, x, true));
        }
        found
    }

    fn next_seed(&mut self) -> Option<usize> {
        while self.coded.get(self.next_seed).copied()? {
            self.next_seed += 1;
        }
        Some(self.next_seed)
    }
}

/// The key of edge {a, b} whichever way round.
pub(super) fn undirected(a: u32, b: u32) -> u64 {
    directed(a.min(b), a.max(b))
}

/// The triangles on each undirected edge, by [`undirected`] key, in triangle order.
pub(super) fn by_edge(triangles: &[Triangle]) -> HashMap<u64, Vec<u32>> {
    let mut by_edge: HashMap<u64, Vec<u32>> = HashMap::new();
    for (t, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            by_edge
                .entry(undirected(tri[k], tri[(k + 1) % 3]))
                .or_default()
                .push(t as u32);
        }
    }
    by_edge
}

fn directed(a: u32, b: u32) -> u64 {
    (u64::from(a) << 32) | u64::from(b)
}

fn corrupt(what: &str) -> Error {
    Error::Stream(format!("first frame connectivity: {what}"))
}

/// The decoded (or, on the encoder, mirrored) state, all in traversal indices.
#[derive(Default)]
pub(super) struct Traversal {
    /// Triangles in coding order.
    pub(super) triangles: Vec<Triangle>,
    /// Number of vertices so far.
    pub(super) vertices: usize,
    half_edges: HashSet<u64>,
    edge_use: HashMap<u64, u8>,
    done: HashSet<u64>,
    incoming: Vec<Vec<u32>>,
    outgoing: Vec<Vec<u32>>,
    /// Gates: half-edge (a, b) of a coded triangle whose third vertex is c.
    gates: Vec<[u32; 3]>,
}

impl Traversal {
    fn is_open(&self, from: u32, to: u32) -> bool {
        self.half_edges.contains(&directed(from, to))
            && !self.half_edges.contains(&directed(to, from))
    }

    /// The first vertex u with an open border half-edge u→v (`backwards`) or v→u.
    fn border_neighbour(&self, v: u32, backwards: bool) -> Option<u32> {
        let list = if backwards {
            self.incoming.get(v as usize)?
        } else {
            self.outgoing.get(v as usize)?
        };
        list.iter().copied().find(|&u| {
            if backwards {
                self.is_open(u, v)
            } else {
                self.is_open(v, u)
            }
        })
    }

    /// Vertices along the open border before `a` (left) or after `b` (right), nearest first.
    fn walk(&self, a: u32, b: u32, left: bool) -> Vec<u32> {
        let mut out = Vec::new();
        let mut cur = if left { a } else { b };
        while out.len() < WALK_LIMIT {
            match self.border_neighbour(cur, left) {
                Some(u) if u != a && u != b && !out.contains(&u) => {
                    out.push(u);
                    cur = u;
                }
                _ => break,
            }
        }
        out
    }

    fn add_vertex(&mut self) -> u32 {
        self.vertices += 1;
        self.incoming.push(Vec::new());
        self.outgoing.push(Vec::new());
        (self.vertices - 1) as u32
    }

    /// Records a coded triangle and opens gates on its edges other than `entry`.
    fn add_triangle(&mut self, tri: Triangle, entry: Option<u64>) {
        self.triangles.push(tri);
        for k in 0..3 {
            let (p, q) = (tri[k], tri[(k + 1) % 3]);
            self.half_edges.insert(directed(p, q));
            if let Some(list) = self.outgoing.get_mut(p as usize) {
                list.push(q);
            }
            if let Some(list) = self.incoming.get_mut(q as usize) {
                list.push(p);
            }
            // Only 0, 1, 2 and "more" matter; an edge of 256+ triangles must not overflow the count.
            let uses = self.edge_use.entry(undirected(p, q)).or_insert(0);
            *uses = uses.saturating_add(1);
        }
        // Start from the entry edge so that the edge after it is explored first (pushed last).
        let start = (0..3)
            .find(|&k| Some(undirected(tri[k], tri[(k + 1) % 3])) == entry)
            .unwrap_or(2);
        for step in 1..=3 {
            let k = (start + step) % 3;
            let (p, q, r) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
            if Some(undirected(p, q)) != entry {
                self.gates.push([p, q, r]);
            }
        }
    }
}

/// Runs the traversal over `triangle_count` triangles and at most `vertex_limit` vertices.
pub(super) fn run<C: SymbolCoder>(
    coder: &mut C,
    mut oracle: Option<&mut Oracle>,
    triangle_count: usize,
    vertex_limit: usize,
    models: &mut Models,
) -> Result<Traversal> {
    let mut t = Traversal::default();
    while t.triangles.len() < triangle_count {
        let Some(gate) = t.gates.pop() else {
            seed(coder, oracle.as_deref_mut(), &mut t, vertex_limit, models)?;
            continue;
        };
        let [a, b, _] = gate;
        let edge = undirected(a, b);
        if !t.done.insert(edge) {
            continue;
        }
        loop {
            let next = match oracle.as_deref() {
                Some(o) => o.next_on_edge(input_of(o, a)?, input_of(o, b)?),
                None => None,
            };
            let use_count = t.edge_use.get(&edge).copied().unwrap_or(0).min(2) as usize;
            if !coder.bit(next.is_some(), &mut models.more[use_count])? {
                break;
            }
            if t.triangles.len() >= triangle_count {
                return Err(corrupt("more triangles than announced"));
            }
            let flipped = coder.bit(next.is_some_and(|n| n.2), &mut models.flipped)?;
            let x = code_third_vertex(
                coder,
                oracle.as_deref_mut(),
                next,
                &mut t,
                gate,
                vertex_limit,
                models,
            )?;
            if let (Some(o), Some((index, _, _))) = (oracle.as_deref_mut(), next) {
                if let Some(c) = o.coded.get_mut(index) {
                    *c = true;
                }
                o.coded_order.push(index as u32);
            }
            let tri = if flipped { [a, b, x] } else { [b, a, x] };
            t.add_triangle(tri, Some(edge));
        }
    }
    Ok(t)
}

/// The input index of traversal vertex `v` (encoder side).
fn input_of(o: &Oracle, v: u32) -> Result<u32> {
    o.from_traversal
        .get(v as usize)
        .copied()
        .ok_or_else(|| corrupt("traversal vertex without input vertex"))
}

impl Oracle<'_> {
    /// Gives input vertex `x` the next traversal index.
    pub(super) fn assign(&mut self, x: u32) {
        if let Some(slot) = self.to_traversal.get_mut(x as usize) {
            *slot = self.from_traversal.len() as u32;
        }
        self.from_traversal.push(x);
    }
}

/// Appends a new vertex (the encoder gives input vertex `input` the next traversal index).
fn new_vertex(
    oracle: Option<&mut Oracle>,
    input: u32,
    t: &mut Traversal,
    vertex_limit: usize,
) -> Result<u32> {
    if t.vertices >= vertex_limit {
        return Err(corrupt("more vertices than announced"));
    }
    if let Some(o) = oracle {
        o.assign(input);
    }
    Ok(t.add_vertex())
}

/// Codes the third vertex of a triangle entering through `gate`; returns its traversal index.
#[allow(clippy::too_many_arguments)]
fn code_third_vertex<C: SymbolCoder>(
    coder: &mut C,
    oracle: Option<&mut Oracle>,
    next: Option<(usize, u32, bool)>,
    t: &mut Traversal,
    gate: [u32; 3],
    vertex_limit: usize,
    models: &mut Models,
) -> Result<u32> {
    let [a, b, _] = gate;
    let left1 = t.border_neighbour(a, true).filter(|&u| u != b);
    let right1 = t.border_neighbour(b, false).filter(|&u| u != a);
    let input = next.map_or(UNASSIGNED, |n| n.1);
    let known = oracle
        .as_deref()
        .and_then(|o| o.to_traversal.get(input as usize).copied())
        .filter(|&v| v != UNASSIGNED);
    // Encoder: classify the reference; the decoder's guesses are ignored by its coder.
    let mut walk_hit: Option<(bool, usize)> = None;
    let kind = match known {
        None => REF_NEW,
        Some(v) if Some(v) == left1 => REF_LEFT,
        Some(v) if Some(v) == right1 => REF_RIGHT,
        Some(v) => {
            for left in [true, false] {
                if walk_hit.is_none() {
                    walk_hit = t
                        .walk(a, b, left)
                        .iter()
                        .position(|&u| u == v)
                        .map(|k| (left, k));
                }
            }
            if walk_hit.is_some() {
                REF_WALK
            } else {
                REF_EXPLICIT
            }
        }
    };
    let context = reference_context(t, models.previous_kind, gate, left1, right1);
    let kind = coder.symbol(kind, &mut models.reference[context])?;
    models.previous_kind = kind;
    let x = match kind {
        REF_NEW => new_vertex(oracle, input, t, vertex_limit)?,
        REF_LEFT => left1.ok_or_else(|| corrupt("no left neighbour"))?,
        REF_RIGHT => right1.ok_or_else(|| corrupt("no right neighbour"))?,
        REF_WALK => {
            let (left, step) = walk_hit.unwrap_or((false, 0));
            let left = coder.bit(left, &mut models.walk_side)?;
            let step = coder.unsigned(step as u64, &mut models.walk_step)?;
            let walk = t.walk(a, b, left);
            usize::try_from(step)
                .ok()
                .and_then(|s| walk.get(s).copied())
                .ok_or_else(|| corrupt("border walk too short"))?
        }
        _ => explicit_reference(coder, known, t, models)?,
    };
    if x == a || x == b {
        return Err(corrupt("degenerate triangle"));
    }
    Ok(x)
}

/// An already-numbered vertex coded as its distance back from the newest one; `known` is the
/// encoder's vertex (the decoder passes `None` and reads the distance).
fn explicit_reference<C: SymbolCoder>(
    coder: &mut C,
    known: Option<u32>,
    t: &Traversal,
    models: &mut Models,
) -> Result<u32> {
    let newest = t.vertices as u64;
    let distance = known.map_or(0, |v| newest - 1 - u64::from(v));
    let distance = coder.unsigned(distance, &mut models.explicit)?;
    newest
        .checked_sub(1)
        .and_then(|n| n.checked_sub(distance))
        .and_then(|v| u32::try_from(v).ok())
        .ok_or_else(|| corrupt("vertex reference out of range"))
}

/// Starts a new component with the next uncoded triangle.
fn seed<C: SymbolCoder>(
    coder: &mut C,
    mut oracle: Option<&mut Oracle>,
    t: &mut Traversal,
    vertex_limit: usize,
    models: &mut Models,
) -> Result<()> {
    let input = match oracle.as_deref_mut() {
        Some(o) => {
            let s = o
                .next_seed()
                .ok_or_else(|| corrupt("no triangle left to seed"))?;
            if let Some(c) = o.coded.get_mut(s) {
                *c = true;
            }
            o.coded_order.push(s as u32);
            o.triangles.get(s).copied()
        }
        None => None,
    };
    let mut tri = [0u32; 3];
    for k in 0..3 {
        let x = input.map_or(UNASSIGNED, |i| i[k]);
        let known = oracle
            .as_deref()
            .and_then(|o| o.to_traversal.get(x as usize).copied())
            .filter(|&v| v != UNASSIGNED);
        tri[k] = if coder.bit(known.is_none(), &mut models.seed_new)? {
            new_vertex(oracle.as_deref_mut(), x, t, vertex_limit)?
        } else {
            explicit_reference(coder, known, t, models)?
        };
    }
    if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
        return Err(corrupt("degenerate seed triangle"));
    }
    t.add_triangle(tri, None);
    Ok(())
}
