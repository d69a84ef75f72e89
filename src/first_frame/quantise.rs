//! Uniform quantisation of positions over their bounding cube.

use crate::error::{Error, Result};
use crate::mesh::Point;

/// Quantised coordinates: each axis in `0..=max_level()`.
pub type Cell = [i32; 3];

/// The grid positions are snapped to: 2^`bits` levels from `lo` over `extent` on every axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    /// Bits per coordinate (1..=24, so every level is exact in f32 arithmetic).
    pub bits: u8,
    /// Lower corner of the bounding box.
    pub lo: Point,
    /// The bounding box's largest extent (the step is the same on every axis, so the other
    /// corner is not needed).
    pub extent: f32,
}

impl Grid {
    /// Largest accepted `bits`.
    pub const MAX_BITS: u8 = 24;

    /// The grid over `positions`' bounding box; positions must be finite.
    pub fn fit(positions: &[Point], bits: u8) -> Result<Self> {
        if !(1..=Self::MAX_BITS).contains(&bits) {
            return Err(Error::Usage(format!(
                "position bits must be 1..={}, got {bits}",
                Self::MAX_BITS
            )));
        }
        let mut lo = [0.0f32; 3];
        let mut hi = [0.0f32; 3];
        for (k, p) in positions.iter().enumerate() {
            if p.iter().any(|c| !c.is_finite()) {
                return Err(Error::Mesh(format!(
                    "vertex {k} has a non-finite coordinate"
                )));
            }
            for a in 0..3 {
                if k == 0 || p[a] < lo[a] {
                    lo[a] = p[a];
                }
                if k == 0 || p[a] > hi[a] {
                    hi[a] = p[a];
                }
            }
        }
        let extent = (0..3).map(|a| hi[a] - lo[a]).fold(0.0f32, f32::max);
        Ok(Self { bits, lo, extent })
    }

    /// The largest level on an axis.
    pub fn max_level(&self) -> i32 {
        (1i32 << self.bits) - 1
    }

    /// One step for every axis (the largest extent over the levels), as Draco does: the error
    /// is isotropic, and short axes do not pay for precision nobody asked for.
    fn step(&self) -> f32 {
        self.extent / self.max_level() as f32
    }

    /// The cell nearest to `p`.
    pub fn quantise(&self, p: Point) -> Cell {
        let mut cell = [0; 3];
        for (a, c) in cell.iter_mut().enumerate() {
            let step = self.step();
            if step > 0.0 {
                let level = ((p[a] - self.lo[a]) / step).round();
                *c = (level as i32).clamp(0, self.max_level());
            }
        }
        cell
    }

    /// The position the decoder outputs for `cell`.
    pub fn dequantise(&self, cell: Cell) -> Point {
        let mut p = [0.0; 3];
        for (a, c) in p.iter_mut().enumerate() {
            *c = self.lo[a] + cell[a] as f32 * self.step();
        }
        p
    }

    /// Whether `cell` lies on the grid.
    pub fn contains(&self, cell: Cell) -> bool {
        cell.iter().all(|&c| (0..=self.max_level()).contains(&c))
    }
}
