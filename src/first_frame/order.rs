//! The traversal → input vertex permutation, when the input's vertex order is kept.
//!
//! Each traversal vertex's input index is coded as a small correction to one of a few guesses,
//! the guess named by an adaptive symbol: one past the largest index so far (input orders often
//! follow face order), one past the previous vertex's, a coded neighbour's (modellers tend
//! to number neighbours close together), or one past the newest earlier copy of the same
//! position (see `weld`).

use std::collections::HashMap;

use crate::error::{Error, Result};
use crate::mesh::topology::VertexAdjacency;
use crate::stream::entropy::{IntModel, SymbolCoder, SymbolModel};

/// Guesses per vertex: the two sequential ones and up to this many minus two neighbours.
const GUESSES: usize = 8;

fn corrupt(what: &str) -> Error {
    Error::Stream(format!("first frame vertex order: {what}"))
}

/// Codes `order[t]` (the input index of traversal vertex t) for every t; `adjacency` is over
/// traversal indices. On the decoder `order` is filled in and checked to be a permutation.
pub(super) fn code_order<C: SymbolCoder>(
    coder: &mut C,
    order: &mut [u32],
    adjacency: &VertexAdjacency,
    welded: &[u32],
) -> Result<()> {
    let vertex_count = order.len();
    if adjacency.vertex_count() != vertex_count {
        return Err(corrupt("adjacency does not match"));
    }
    let mut choice = SymbolModel::new(GUESSES);
    let mut deltas: [IntModel; 4] = Default::default();
    let mut seen = vec![false; vertex_count];
    let (mut previous, mut largest) = (-1i64, -1i64);
    let mut guesses = Vec::with_capacity(GUESSES);
    let mut newest_copy: HashMap<u32, u32> = HashMap::new();
    for t in 0..vertex_count {
        guesses.clear();
        guesses.extend([largest + 1, previous + 1]);
        for &n in adjacency.neighbours(t) {
            if (n as usize) < t && guesses.len() < GUESSES - 1 {
                guesses.push(i64::from(order[n as usize]));
            }
        }
        // Last, the newest earlier copy of the same welded vertex: copies of a soup's or a seam's
        // vertex are often numbered near each other in the input, across the traversal's jumps.
        let w = welded.get(t).copied();
        let sibling = w.and_then(|w| newest_copy.get(&w).copied());
        if let Some(copy) = sibling {
            guesses.push(i64::from(order[copy as usize]) + 1);
        }
        if let Some(w) = w {
            newest_copy.insert(w, t as u32);
        }
        let actual = i64::from(order[t]);
        let best = (0..guesses.len())
            .min_by_key(|&g| (actual - guesses[g]).abs())
            .unwrap_or(0);
        let pick = coder.symbol(best, &mut choice)?;
        let base = *guesses.get(pick).ok_or_else(|| corrupt("no such guess"))?;
        let class = if sibling.is_some() && pick + 1 == guesses.len() {
            3
        } else {
            pick.min(2)
        };
        let value = base + coder.signed(actual - base, &mut deltas[class])?;
        let index = usize::try_from(value)
            .ok()
            .filter(|&v| v < vertex_count)
            .ok_or_else(|| corrupt("index out of range"))?;
        if std::mem::replace(&mut seen[index], true) {
            return Err(corrupt("repeated index"));
        }
        order[t] = index as u32;
        previous = value;
        largest = largest.max(value);
    }
    Ok(())
}
