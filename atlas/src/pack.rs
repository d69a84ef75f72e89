//! Block-aligned rectangle packing: every chart gets a rectangle of whole
//! blocks, no block is shared, one common scale for all charts.
//!
//! Written here because the rectangles live on a tiny grid (32×32 blocks for
//! a 256 lattice) and must be re-packed at each step of the scale search;
//! the packing crates work on pixels and pad, which this does not need.

/// A chart's rectangle in blocks, and where it went.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Placement {
    /// Left column, in blocks.
    pub bx: u32,
    /// Top row, in blocks.
    pub by: u32,
    /// Whether the chart is transposed (its u runs down, v runs across).
    pub transposed: bool,
}

/// Free-cell runs of a block grid, for quick "is this rectangle free" tests.
struct Grid {
    w: u32,
    h: u32,
    /// For each cell, free cells to its right including itself.
    run: Vec<u32>,
}

impl Grid {
    fn new(w: u32, h: u32) -> Self {
        let mut g = Grid {
            w,
            h,
            run: vec![0; (w * h) as usize],
        };
        for y in 0..h {
            for x in 0..w {
                g.run[(y * w + x) as usize] = w - x;
            }
        }
        g
    }

    fn fits(&self, x: u32, y: u32, rw: u32, rh: u32) -> bool {
        x + rw <= self.w
            && y + rh <= self.h
            && (y..y + rh).all(|row| self.run[(row * self.w + x) as usize] >= rw)
    }

    /// First fit scanning rows top to bottom, columns left to right.
    fn find(&self, rw: u32, rh: u32) -> Option<(u32, u32)> {
        if rw > self.w || rh > self.h {
            return None;
        }
        (0..=self.h - rh)
            .flat_map(|y| (0..=self.w - rw).map(move |x| (x, y)))
            .find(|&(x, y)| self.fits(x, y, rw, rh))
    }

    fn occupy(&mut self, x: u32, y: u32, rw: u32, rh: u32) {
        for row in y..y + rh {
            let base = (row * self.w) as usize;
            for cx in x..x + rw {
                self.run[base + cx as usize] = 0;
            }
            let mut next = 0;
            for cx in (0..self.w).rev() {
                let i = base + cx as usize;
                next = if self.run[i] == 0 { 0 } else { next + 1 };
                self.run[i] = next;
            }
        }
    }
}

/// Packs rectangles of `(width, height)` blocks into a `grid_w × grid_h`
/// block grid, trying both orientations, biggest first, each at the
/// top-most then left-most free spot (bottom-left fill, so small charts drop
/// into holes left by big ones). `None` if one does not fit.
pub(crate) fn pack(sizes: &[(u32, u32)], grid_w: u32, grid_h: u32) -> Option<Vec<Placement>> {
    let mut order: Vec<usize> = (0..sizes.len()).collect();
    order.sort_by_key(|&i| {
        let (w, h) = sizes[i];
        (std::cmp::Reverse(w.max(h)), std::cmp::Reverse(w * h), i)
    });
    let mut grid = Grid::new(grid_w, grid_h);
    let mut placed = vec![
        Placement {
            bx: 0,
            by: 0,
            transposed: false
        };
        sizes.len()
    ];
    for i in order {
        let (w, h) = sizes[i];
        let upright = grid.find(w, h).map(|(x, y)| (y, x, false));
        let turned = if w != h {
            grid.find(h, w).map(|(x, y)| (y, x, true))
        } else {
            None
        };
        let (by, bx, transposed) = match (upright, turned) {
            (Some(a), Some(b)) => a.min(b),
            (a, b) => a.or(b)?,
        };
        let (rw, rh) = if transposed { (h, w) } else { (w, h) };
        grid.occupy(bx, by, rw, rh);
        placed[i] = Placement { bx, by, transposed };
    }
    Some(placed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packs_without_overlap_and_refuses_overflow() {
        let sizes = [(3, 2), (2, 2), (4, 1), (1, 1), (1, 3)];
        let placed = pack(&sizes, 4, 5);
        let Some(placed) = placed else {
            panic!("16 blocks fit a 4×5 grid");
        };
        let mut used = [[false; 4]; 5];
        for (p, &(w, h)) in placed.iter().zip(&sizes) {
            let (w, h) = if p.transposed { (h, w) } else { (w, h) };
            for y in p.by..p.by + h {
                for x in p.bx..p.bx + w {
                    assert!(!used[y as usize][x as usize], "overlap at {x},{y}");
                    used[y as usize][x as usize] = true;
                }
            }
        }
        assert!(pack(&[(3, 3), (3, 3)], 4, 5).is_none());
    }
}
