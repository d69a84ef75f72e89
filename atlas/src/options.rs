//! How an atlas is built.

/// What happens to the chart pixels between vertex pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Interior {
    /// Chart triangles are rasterised: interior pixels are fixed and carry
    /// values interpolated from the corners (the paper's choice).
    #[default]
    Rasterised,
    /// Only vertex pixels are fixed; everything else is left to padding.
    Free,
}

/// Parameters of [`crate::build`].
#[derive(Clone, Debug, PartialEq)]
pub struct AtlasOptions {
    /// Lattice width in pixels (a multiple of `block`).
    pub width: u32,
    /// Lattice height in pixels (a multiple of `block`).
    pub height: u32,
    /// Side of the square blocks no two charts may share (8 for JPEG/MPEG DCT blocks).
    pub block: u32,
    /// Largest normalised L2 stretch (Sander et al. 2001; 1 is isometric) a
    /// chart may keep; stretchier charts are split and unwrapped again.
    pub max_stretch: f64,
    /// Interior pixel mode.
    pub interior: Interior,
    /// Charts owning fewer vertices than this give them to neighbouring
    /// charts (0 or 1: never).
    pub min_chart_vertices: usize,
    /// Rounds of stretch-driven splitting at most.
    pub max_split_rounds: u32,
    /// Grow and flatten charts on the mesh with vertices at bit-identical positions welded (glTF
    /// meshes split at UV seams, or not indexed). Off by default: far fewer charts, but the copies
    /// of a position are coded apart and crack apart, worse at equal rate on some meshes
    /// (docs/design.md, "Chart interiors and seams").
    pub weld: bool,
}

impl Default for AtlasOptions {
    fn default() -> Self {
        AtlasOptions {
            width: 256,
            height: 256,
            block: 8,
            max_stretch: 1.25,
            interior: Interior::Rasterised,
            max_split_rounds: 3,
            min_chart_vertices: 8,
            weld: false,
        }
    }
}

impl AtlasOptions {
    /// Checks that the lattice is made of whole blocks and fits `u16` coordinates.
    pub fn validate(&self) -> Result<(), crate::AtlasError> {
        let bad = |m: String| Err(crate::AtlasError::InvalidOptions(m));
        if self.block == 0 {
            return bad("block must be at least 1".into());
        }
        if self.width == 0 || self.height == 0 {
            return bad("lattice must be at least one block".into());
        }
        if self.width % self.block != 0 || self.height % self.block != 0 {
            return bad(format!(
                "lattice {}×{} is not a whole number of {}×{} blocks",
                self.width, self.height, self.block, self.block
            ));
        }
        if self.width > 16384 || self.height > 16384 {
            return bad("lattice sides must be at most 16384".into());
        }
        if !(self.max_stretch >= 1.0) {
            return bad(format!(
                "max_stretch {} must be at least 1",
                self.max_stretch
            ));
        }
        Ok(())
    }
}
