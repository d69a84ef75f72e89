//! The traversal → input vertex permutation, when the input's vertex order is kept.
//!
//! Coded in the input's order: for input vertex i, which decoded (traversal) vertex it is. Input
//! orders follow faces — on every mesh of `../shared/media` but the three.js Horse, the vertices
//! are numbered exactly in order of first use by the input's triangles — so input vertex i is most
//! often the free corner of a triangle whose other corners were numbered last, or another copy of
//! a recent position (a soup, a seam). Each vertex names one of those candidates with an adaptive
//! symbol, or escapes to its rank among the vertices not numbered yet, as a signed difference from
//! the rank of the traversal vertex after i − 1's.
//!
//! The candidates are the free corners of the triangles around the last [`RECENT`] input vertices
//! and the free copies of their positions, ranked as a triangle list would use them next: by the
//! newest numbered corner of their triangle (a copy: the vertex it copies), then by the other
//! corner (a triangle two of whose corners are numbered is closed by its third), then the corner
//! that follows the newest in the triangle's orientation (corners are used in their listed order),
//! then by traversal index. Version 3 listed the previous vertex's neighbours, the recent copies,
//! then the other recent vertices' neighbours, each by traversal index, and coded an escape as a
//! difference of traversal indices: 3.9 % more bytes for the kept-order first frames of
//! `../shared/media` (docs/history.md).

use super::free_ranks::FreeRanks;
use crate::error::{Error, Result};
use crate::mesh::Triangle;
use crate::stream::entropy::{IntModel, SymbolCoder, SymbolModel};

/// Candidates a vertex may name; the symbol after them is the escape.
const CANDIDATES: usize = 127;
/// Earlier input vertices whose triangles and copies give the candidates, the latest first. 8
/// and 16 cost 0.2-0.5 % more bytes than 32, 64 and 128 saved 0.1-0.2 % for up to twice the work.
const RECENT: usize = 32;
/// What the best candidate is ([`Candidates::lead`]): none, only from an older vertex's triangle,
/// the third corner of a triangle two of whose corners are numbered, or one numbered corner or a
/// copy; each whether it follows its newest corner. One model each, after a named vertex and after
/// an escape.
const LEADS: usize = 8;

fn corrupt(what: &str) -> Error {
    Error::Stream(format!("first frame vertex order: {what}"))
}

/// The triangles around each vertex (traversal indices), in one array.
struct Incidence {
    starts: Vec<u32>,
    triangles: Vec<u32>,
}

impl Incidence {
    fn new(triangles: &[Triangle], vertex_count: usize) -> Self {
        let mut starts = vec![0u32; vertex_count + 1];
        for &v in triangles.iter().flatten() {
            if let Some(n) = starts.get_mut(v as usize + 1) {
                *n += 1;
            }
        }
        for v in 0..vertex_count {
            starts[v + 1] += starts[v];
        }
        let mut next = starts.clone();
        let mut list = vec![0u32; starts[vertex_count] as usize];
        for (k, tri) in triangles.iter().enumerate() {
            for &v in tri {
                if let Some(slot) = next.get_mut(v as usize) {
                    list[*slot as usize] = k as u32;
                    *slot += 1;
                }
            }
        }
        Self {
            starts,
            triangles: list,
        }
    }

    fn of(&self, v: u32) -> &[u32] {
        let at = |i: usize| self.starts.get(i).map_or(0, |&s| s as usize);
        let v = v as usize;
        self.triangles.get(at(v)..at(v + 1)).unwrap_or(&[])
    }
}

/// The vertices input vertex i is likely to be, not numbered yet, best first; at most
/// [`CANDIDATES`].
struct Candidates<'a> {
    triangles: &'a [Triangle],
    incidence: Incidence,
    /// Traversal vertices of each welded vertex, increasing.
    copies: Vec<Vec<u32>>,
    /// Per welded vertex, how many of its first copies are numbered: skipped at once, so that a
    /// position with thousands of copies is not scanned from its start for each of them.
    numbered_copies: Vec<usize>,
    welded: &'a [u32],
    /// (rank key, vertex) of every candidate found, duplicates included; sorted by key, highest
    /// first, then by vertex.
    found: Vec<(u64, u32)>,
    list: Vec<u32>,
    /// Per traversal vertex, the fill that last listed it (fills are counted from 1): whether a
    /// vertex is listed already, without searching the list.
    listed_in: Vec<u32>,
    /// Per triangle, the fill that last read it: each triangle is read once a fill.
    read_in: Vec<u32>,
    fills: u32,
    /// What the best candidate was in the last fill (see [`LEADS`]).
    lead: usize,
}

/// A candidate's rank key: the newest numbered corner's input index, then 2 + the other numbered
/// corner's (1 when the other corner is free or the candidate is a copy), then whether it follows
/// the newest corner in the triangle's orientation. Input indices are below 2²⁸.
fn key(newest: u32, other: Option<u32>, follows: bool) -> u64 {
    let other = other.map_or(1, |o| u64::from(o) + 2);
    (u64::from(newest) << 32) | (other << 1) | u64::from(follows)
}

impl<'a> Candidates<'a> {
    fn new(triangles: &'a [Triangle], welded: &'a [u32]) -> Self {
        let count = welded.iter().max().map_or(0, |&w| w as usize + 1);
        let mut copies = vec![Vec::new(); count];
        for (t, &w) in welded.iter().enumerate() {
            copies[w as usize].push(t as u32);
        }
        Self {
            triangles,
            incidence: Incidence::new(triangles, welded.len()),
            numbered_copies: vec![0; copies.len()],
            copies,
            welded,
            found: Vec::new(),
            list: Vec::with_capacity(CANDIDATES),
            listed_in: vec![0; welded.len()],
            read_in: vec![0; triangles.len()],
            fills: 0,
            lead: 0,
        }
    }

    /// Fills the list for the vertex after `recent` (traversal indices, the latest last);
    /// `input[t]` is the input index of every numbered traversal vertex t.
    fn fill(&mut self, recent: &[u32], numbered: &[bool], input: &[u32]) {
        self.found.clear();
        self.fills += 1;
        // Each triangle is read from its newest numbered corner (the latest recent vertex on it),
        // so the candidates come grouped by that corner, newest first: sorting each group sorts
        // them all.
        for &p in recent.iter().rev().take(RECENT) {
            let start = self.found.len();
            self.find_in_triangles(p, numbered, input);
            self.find_copies(p, numbered, input);
            self.found[start..].sort_unstable_by_key(|&(key, t)| (u64::MAX - key, t));
        }
        self.list.clear();
        for &(_, t) in &self.found {
            if self.list.len() == CANDIDATES {
                break;
            }
            let listed = &mut self.listed_in[t as usize];
            if *listed != self.fills {
                *listed = self.fills;
                self.list.push(t);
            }
        }
        let previous = recent.last().map(|&p| input[p as usize]);
        let kind = match self.found.first() {
            None => 0,
            Some(&(key, _)) if Some((key >> 32) as u32) != previous => 1,
            Some(&(key, _)) if (key >> 1) & 0x7fff_ffff >= 2 => 2,
            Some(_) => 3,
        };
        let follows = self.found.first().is_some_and(|&(key, _)| key & 1 == 1);
        self.lead = kind + 4 * usize::from(follows);
    }

    /// The free corners of the triangles around numbered vertex `p`.
    fn find_in_triangles(&mut self, p: u32, numbered: &[bool], input: &[u32]) {
        let is_numbered = |v: u32| numbered.get(v as usize).copied().unwrap_or(false);
        for &k in self.incidence.of(p) {
            let (Some(&tri), Some(read)) =
                (self.triangles.get(k as usize), self.read_in.get_mut(k as usize))
            else {
                continue;
            };
            if std::mem::replace(read, self.fills) == self.fills {
                continue;
            }
            // The newest numbered corner (its place and input index) and the other one's index.
            let (mut newest, mut other): (Option<(usize, u32)>, Option<u32>) = (None, None);
            for (c, &v) in tri.iter().enumerate() {
                if !is_numbered(v) {
                    continue;
                }
                let i = input.get(v as usize).copied().unwrap_or(0);
                match newest {
                    Some((_, n)) if i < n => other = Some(other.map_or(i, |o| o.max(i))),
                    _ => {
                        other = newest.map(|(_, n)| n);
                        newest = Some((c, i));
                    }
                }
            }
            let Some((at, newest)) = newest else {
                continue;
            };
            for (c, &v) in tri.iter().enumerate() {
                if !is_numbered(v) {
                    let follows = c == (at + 1) % 3;
                    self.found.push((key(newest, other, follows), v));
                }
            }
        }
    }

    /// The free copies of numbered vertex `p`'s position.
    fn find_copies(&mut self, p: u32, numbered: &[bool], input: &[u32]) {
        let Some(&w) = self.welded.get(p as usize) else {
            return;
        };
        let (copies, skip) = (&self.copies[w as usize], &mut self.numbered_copies[w as usize]);
        while copies.get(*skip).is_some_and(|&t| numbered[t as usize]) {
            *skip += 1;
        }
        // Bounded: copies numbered out of order after the first free one are scanned again.
        let end = copies.len().min(*skip + 2 * CANDIDATES);
        let newest = input.get(p as usize).copied().unwrap_or(0);
        for &t in &copies[*skip..end] {
            if !numbered[t as usize] {
                self.found.push((key(newest, None, false), t));
            }
        }
    }
}

/// Codes `order[t]` (the input index of traversal vertex t) for every t; `triangles` are all the
/// triangles in traversal indices, `welded` gives each traversal vertex's welded vertex. On the
/// decoder `order` is filled in and checked to be a permutation.
pub(super) fn code_order<C: SymbolCoder>(
    coder: &mut C,
    order: &mut [u32],
    triangles: &[Triangle],
    welded: &[u32],
) -> Result<()> {
    let vertex_count = order.len();
    if welded.len() != vertex_count
        || triangles.iter().flatten().any(|&v| v as usize >= vertex_count)
    {
        return Err(corrupt("triangles do not match"));
    }
    // Input vertex → traversal vertex (the encoder's from `order`; the decoder's decoded).
    let mut traversal_of = vec![0u32; vertex_count];
    for (t, &input) in order.iter().enumerate() {
        if let Some(slot) = traversal_of.get_mut(input as usize) {
            *slot = t as u32;
        }
    }
    let mut choice = vec![SymbolModel::new(CANDIDATES + 1); 2 * LEADS];
    let mut jump = IntModel::default();
    let mut candidates = Candidates::new(triangles, welded);
    let mut numbered = vec![false; vertex_count];
    let mut free = FreeRanks::full(vertex_count);
    let mut escaped = false;
    for i in 0..vertex_count {
        candidates.fill(&traversal_of[..i], &numbered, order);
        let actual = traversal_of[i];
        let named = candidates.list.iter().position(|&t| t == actual);
        let context = 2 * candidates.lead + usize::from(escaped);
        let pick = coder.symbol(named.unwrap_or(CANDIDATES), &mut choice[context])?;
        escaped = pick == CANDIDATES;
        let t = match candidates.list.get(pick) {
            Some(&t) => t as usize,
            None if escaped => {
                let after = i.checked_sub(1).map_or(0, |p| traversal_of[p] as usize + 1);
                let from = free.below(after) as i64;
                let rank = from + coder.signed(free.below(actual as usize) as i64 - from, &mut jump)?;
                usize::try_from(rank)
                    .ok()
                    .and_then(|rank| free.select(rank))
                    .ok_or_else(|| corrupt("index out of range"))?
            }
            None => return Err(corrupt("no such candidate")),
        };
        if std::mem::replace(&mut numbered[t], true) {
            return Err(corrupt("repeated index"));
        }
        free.remove(t);
        traversal_of[i] = t as u32;
        order[t] = i as u32;
    }
    Ok(())
}
