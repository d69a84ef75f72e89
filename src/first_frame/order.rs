//! The traversal → input vertex permutation, when the input's vertex order is kept.
//!
//! Coded in the input's order: for input vertex i, which decoded (traversal) vertex it is. Input
//! orders follow faces — on every mesh of `../shared/media` but the three.js Horse, the vertices
//! are numbered exactly in order of first use by the input's triangles — so input vertex i is most
//! often a neighbour of input vertex i − 1, or of one a few before it, or another copy of the same
//! position (a soup, a seam). Each vertex names one of those candidates (those not yet numbered,
//! in a fixed order the decoder rebuilds) with an adaptive symbol, or escapes to a signed
//! difference from the traversal vertex after i − 1's. Version 2 coded the traversal vertices in
//! turn against guesses of their input index (one past the largest so far, a neighbour's): 18–47 %
//! more bytes (docs/history.md).

use crate::error::{Error, Result};
use crate::mesh::topology::VertexAdjacency;
use crate::stream::entropy::{IntModel, SymbolCoder, SymbolModel};

/// Candidates a vertex may name; the symbol after them is the escape.
const CANDIDATES: usize = 127;
/// Earlier input vertices whose neighbours and copies are candidates, the latest first. The order
/// stream at 12 bits against 4 recent vertices and 15 candidates: 8 and 31 −6 to 0 %, 16 and 63
/// −11 to −1 %, 32 and 127 (kept) −15 to +0.4 % (pdance 2 640 → 2 252 bytes, BrainStem 15 052 →
/// 14 220, CesiumMan 2 812 → 2 800; the 160-vertex RiggedSimple 56 → 72), the first frame's
/// encoding 22 % slower in all (pdance 30 → 36 ms).
const RECENT: usize = 32;

fn corrupt(what: &str) -> Error {
    Error::Stream(format!("first frame vertex order: {what}"))
}

/// The traversal vertices input vertex i is likely to be, not numbered yet: the previous input
/// vertex's neighbours, the other copies of the last [`RECENT`] input vertices' positions, then
/// the neighbours of the others of them, the latest first, each list by increasing traversal
/// index; at most [`CANDIDATES`].
struct Candidates<'a> {
    adjacency: &'a VertexAdjacency,
    /// Traversal vertices of each welded vertex, increasing.
    copies: Vec<Vec<u32>>,
    /// Per welded vertex, how many of its first copies are numbered: skipped at once, so that a
    /// position with thousands of copies is not scanned from its start for each of them.
    numbered_copies: Vec<usize>,
    welded: &'a [u32],
    list: Vec<u32>,
    /// Per traversal vertex, the fill that last listed it (fills are counted from 1): whether a
    /// vertex is listed already, without searching the list.
    listed_in: Vec<u32>,
    fills: u32,
}

impl<'a> Candidates<'a> {
    fn new(adjacency: &'a VertexAdjacency, welded: &'a [u32]) -> Self {
        let count = welded.iter().max().map_or(0, |&w| w as usize + 1);
        let mut copies = vec![Vec::new(); count];
        for (t, &w) in welded.iter().enumerate() {
            copies[w as usize].push(t as u32);
        }
        Self {
            adjacency,
            numbered_copies: vec![0; copies.len()],
            copies,
            listed_in: vec![0; welded.len()],
            welded,
            list: Vec::with_capacity(CANDIDATES),
            fills: 0,
        }
    }

    /// Fills the list for the vertex after `recent` (traversal indices, the latest last).
    fn fill(&mut self, recent: &[u32], numbered: &[bool]) {
        self.list.clear();
        self.fills += 1;
        let Some(&last) = recent.last() else {
            return;
        };
        let latest = recent.iter().rev().take(RECENT);
        let mut siblings: Vec<&[u32]> = Vec::with_capacity(RECENT);
        for &p in latest.clone() {
            let Some(&w) = self.welded.get(p as usize) else {
                continue;
            };
            let (copies, skip) = (&self.copies[w as usize], &mut self.numbered_copies[w as usize]);
            while copies.get(*skip).is_some_and(|&t| numbered[t as usize]) {
                *skip += 1;
            }
            // Bounded: copies numbered out of order after the first free one are scanned again.
            let end = copies.len().min(*skip + 2 * CANDIDATES);
            siblings.push(&copies[*skip..end]);
        }
        // The previous vertex's neighbours (its triangle's other corners), the copies of the
        // recent ones' positions (a soup's next triangle shares a position), then the recent
        // ones' neighbours. Each vertex is among the recent ones RECENT times: its neighbours are
        // read as often.
        let first = self.adjacency.neighbours(last as usize).iter();
        let copies = siblings.into_iter().flatten();
        let others = latest.skip(1).flat_map(|&p| self.adjacency.neighbours(p as usize));
        let (siblings, neighbours) = (first.chain(copies), others);
        for &t in siblings.chain(neighbours) {
            if self.list.len() == CANDIDATES {
                break;
            }
            let listed = &mut self.listed_in[t as usize];
            if !numbered[t as usize] && *listed != self.fills {
                *listed = self.fills;
                self.list.push(t);
            }
        }
    }
}

/// Codes `order[t]` (the input index of traversal vertex t) for every t; `adjacency` is over
/// traversal indices, `welded` gives each traversal vertex's welded vertex. On the decoder
/// `order` is filled in and checked to be a permutation.
pub(super) fn code_order<C: SymbolCoder>(
    coder: &mut C,
    order: &mut [u32],
    adjacency: &VertexAdjacency,
    welded: &[u32],
) -> Result<()> {
    let vertex_count = order.len();
    if adjacency.vertex_count() != vertex_count || welded.len() != vertex_count {
        return Err(corrupt("adjacency does not match"));
    }
    // Input vertex → traversal vertex (the encoder's from `order`; the decoder's decoded).
    let mut traversal_of = vec![0u32; vertex_count];
    for (t, &input) in order.iter().enumerate() {
        if let Some(slot) = traversal_of.get_mut(input as usize) {
            *slot = t as u32;
        }
    }
    let mut choice = SymbolModel::new(CANDIDATES + 1);
    let mut jump = IntModel::default();
    let mut candidates = Candidates::new(adjacency, welded);
    let mut numbered = vec![false; vertex_count];
    for i in 0..vertex_count {
        candidates.fill(&traversal_of[..i], &numbered);
        let actual = traversal_of[i];
        let named = candidates.list.iter().position(|&t| t == actual);
        let pick = coder.symbol(named.unwrap_or(CANDIDATES), &mut choice)?;
        let t = match candidates.list.get(pick) {
            Some(&t) => i64::from(t),
            None if pick == CANDIDATES => {
                let after = i.checked_sub(1).map_or(0, |p| i64::from(traversal_of[p]) + 1);
                let delta = coder.signed(i64::from(actual) - after, &mut jump)?;
                after.checked_add(delta).ok_or_else(|| corrupt("index out of range"))?
            }
            None => return Err(corrupt("no such candidate")),
        };
        let t = usize::try_from(t)
            .ok()
            .filter(|&t| t < vertex_count)
            .ok_or_else(|| corrupt("index out of range"))?;
        if std::mem::replace(&mut numbered[t], true) {
            return Err(corrupt("repeated index"));
        }
        traversal_of[i] = t as u32;
        order[t] = i as u32;
    }
    Ok(())
}
