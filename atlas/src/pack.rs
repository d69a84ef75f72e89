//! Block-aligned packing of chart footprints: every chart owns a set of
//! whole blocks (the blocks its triangles and vertices touch), no block is
//! shared, one common scale for all charts.
//!
//! Written here because the footprints live on a tiny grid (32×32 blocks for
//! a 256 lattice) and are re-packed at each step of the scale search; the
//! packing crates work on pixel rectangles with padding, which this does not
//! need, and cannot nest a chart into another's empty blocks.

/// One of the four orientations tried for a chart: a half turn and/or a
/// transposition (mirroring is harmless: only the vertex → pixel map matters).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub(crate) struct Orientation {
    /// Coordinates reversed on both axes first.
    pub half_turn: bool,
    /// Then x and y swapped.
    pub transposed: bool,
}

impl Orientation {
    const ALL: [Orientation; 4] = [
        Orientation {
            half_turn: false,
            transposed: false,
        },
        Orientation {
            half_turn: false,
            transposed: true,
        },
        Orientation {
            half_turn: true,
            transposed: false,
        },
        Orientation {
            half_turn: true,
            transposed: true,
        },
    ];

    /// Maps a point of a `w × h` local frame (cells or pixels, where the
    /// last one is `w - 1`) into the oriented frame.
    pub(crate) fn apply(&self, p: [f64; 2], w: f64, h: f64) -> [f64; 2] {
        let p = if self.half_turn {
            [w - 1.0 - p[0], h - 1.0 - p[1]]
        } else {
            p
        };
        if self.transposed {
            [p[1], p[0]]
        } else {
            p
        }
    }

    fn cell(&self, c: (u32, u32), w: u32, h: u32) -> (u32, u32) {
        let c = if self.half_turn {
            (w - 1 - c.0, h - 1 - c.1)
        } else {
            c
        };
        if self.transposed {
            (c.1, c.0)
        } else {
            c
        }
    }
}

/// A chart's blocks in its own `width × height` block frame.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Footprint {
    pub width: u32,
    pub height: u32,
    /// Occupied cells `(x, y)`, each once.
    pub cells: Vec<(u32, u32)>,
}

/// Where a chart went: top-left of its oriented frame, in blocks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub(crate) struct Placement {
    pub bx: u32,
    pub by: u32,
    pub orientation: Orientation,
}

impl Placement {
    /// Lattice blocks a footprint covers when placed here.
    pub(crate) fn cells<'a>(&'a self, f: &'a Footprint) -> impl Iterator<Item = (u32, u32)> + 'a {
        f.cells.iter().map(move |&c| {
            let (x, y) = self.orientation.cell(c, f.width, f.height);
            (self.bx + x, self.by + y)
        })
    }
}

/// Packs footprints into a `grid_w × grid_h` block grid, biggest first, each
/// at the top-most then left-most spot where one of its orientations fits
/// (bottom-left fill, so small charts drop into the gaps of big ones).
/// `None` if one does not fit.
pub(crate) fn pack(footprints: &[Footprint], grid_w: u32, grid_h: u32) -> Option<Vec<Placement>> {
    let by_blocks = |f: &Footprint| (f.cells.len(), f.width.max(f.height));
    let by_side = |f: &Footprint| (f.width.max(f.height) as usize, f.cells.len() as u32);
    [by_blocks, by_side]
        .iter()
        .find_map(|key| pack_in_order(footprints, grid_w, grid_h, key))
}

/// [`pack`] with one order: decreasing `key`.
fn pack_in_order(
    footprints: &[Footprint],
    grid_w: u32,
    grid_h: u32,
    key: &dyn Fn(&Footprint) -> (usize, u32),
) -> Option<Vec<Placement>> {
    let mut order: Vec<usize> = (0..footprints.len()).collect();
    order.sort_by_key(|&i| (std::cmp::Reverse(key(&footprints[i])), i));
    let mut used = vec![false; (grid_w * grid_h) as usize];
    let mut placed = vec![Placement::default(); footprints.len()];
    for i in order {
        let f = &footprints[i];
        let mut best: Option<((u32, u32), u32, u32, Orientation)> = None;
        for o in Orientation::ALL {
            let full = f.cells.len() == (f.width * f.height) as usize;
            // A full rectangle looks the same turned; a full square also transposed.
            if full && (o.half_turn || (o.transposed && f.width == f.height)) {
                continue;
            }
            let (ow, oh) = if o.transposed {
                (f.height, f.width)
            } else {
                (f.width, f.height)
            };
            if ow > grid_w || oh > grid_h {
                continue;
            }
            let cells: Vec<(u32, u32)> = f
                .cells
                .iter()
                .map(|&c| o.cell(c, f.width, f.height))
                .collect();
            // Score: bottom edge, then left edge, so tall shapes lie down.
            'search: for y in 0..=grid_h - oh {
                for x in 0..=grid_w - ow {
                    if best.is_some_and(|(score, _, _, _)| (y + oh, x) >= score) {
                        if x == 0 {
                            break 'search;
                        }
                        break;
                    }
                    if cells
                        .iter()
                        .all(|&(cx, cy)| !used[((y + cy) * grid_w + x + cx) as usize])
                    {
                        best = Some(((y + oh, x), y, x, o));
                        break 'search;
                    }
                }
            }
        }
        let (_, by, bx, orientation) = best?;
        let p = Placement {
            bx,
            by,
            orientation,
        };
        for (x, y) in p.cells(f) {
            used[(y * grid_w + x) as usize] = true;
        }
        placed[i] = p;
    }
    Some(placed)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rect(w: u32, h: u32) -> Footprint {
        Footprint {
            width: w,
            height: h,
            cells: (0..h).flat_map(|y| (0..w).map(move |x| (x, y))).collect(),
        }
    }

    #[test]
    fn packs_without_overlap_and_refuses_overflow() {
        let l_shape = Footprint {
            width: 3,
            height: 3,
            cells: vec![(0, 0), (0, 1), (0, 2), (1, 2), (2, 2)],
        };
        let shapes = [
            rect(3, 2),
            rect(2, 2),
            rect(4, 1),
            rect(1, 1),
            rect(1, 3),
            l_shape,
        ];
        let Some(placed) = pack(&shapes, 5, 5) else {
            panic!("21 blocks fit a 5×5 grid");
        };
        let mut used = [[false; 5]; 5];
        for (p, f) in placed.iter().zip(&shapes) {
            for (x, y) in p.cells(f) {
                assert!(!used[y as usize][x as usize], "overlap at {x},{y}");
                used[y as usize][x as usize] = true;
            }
        }
        assert!(pack(&[rect(3, 3), rect(3, 3)], 4, 5).is_none());
    }

    #[test]
    fn a_small_chart_nests_in_an_l_shape() {
        let l_shape = Footprint {
            width: 2,
            height: 2,
            cells: vec![(0, 0), (0, 1), (1, 1)],
        };
        assert!(pack(&[l_shape, rect(1, 1)], 2, 2).is_some());
    }
}
