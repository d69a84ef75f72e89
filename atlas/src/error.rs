//! What can go wrong while building or using an atlas.

/// Errors of [`crate::build`] and of the [`crate::Atlas`] methods.
#[derive(Debug, thiserror::Error)]
pub enum AtlasError {
    /// The partition does not give one cluster per vertex.
    #[error("partition has {partition} entries but the mesh has {vertices} vertices")]
    PartitionLength {
        /// Entries in the partition.
        partition: usize,
        /// Vertices in the mesh.
        vertices: usize,
    },
    /// A triangle names a vertex that does not exist.
    #[error("triangle {triangle} uses vertex {vertex}, but the mesh has {vertices} vertices")]
    VertexOutOfRange {
        /// Triangle index.
        triangle: usize,
        /// Offending vertex index.
        vertex: u32,
        /// Vertices in the mesh.
        vertices: usize,
    },
    /// A vertex position is NaN or infinite.
    #[error("vertex {0} has a non-finite position")]
    NonFinitePosition(usize),
    /// The options cannot describe a lattice.
    #[error("invalid atlas option: {0}")]
    InvalidOptions(String),
    /// The mesh has more vertices than the lattice has pixels.
    #[error("{vertices} vertices do not fit a {width}×{height} lattice; a {suggest}x{suggest} lattice would fit")]
    TooManyVertices {
        /// Vertices in the mesh.
        vertices: usize,
        /// Lattice width.
        width: u32,
        /// Lattice height.
        height: u32,
        /// A square lattice side that has room for them.
        suggest: u32,
    },
    /// Even at the smallest scale the charts' blocks do not fit.
    #[error("{charts} charts need at least {blocks} blocks of {block}×{block} but the {width}×{height} lattice has {available}; a {suggest}x{suggest} lattice would fit")]
    ChartsDoNotFit {
        /// Number of charts.
        charts: usize,
        /// Blocks they need at the smallest scale.
        blocks: usize,
        /// Blocks in the lattice.
        available: usize,
        /// Block side.
        block: u32,
        /// Lattice width.
        width: u32,
        /// Lattice height.
        height: u32,
        /// A square lattice side with room for them.
        suggest: u32,
    },
    /// The unwrapping library refused the mesh.
    #[error("parameterization failed: {0}")]
    Unwrap(#[from] uvunwrap::Error),
    /// The unwrapping library failed internally (a bug there, caught so it is an error here).
    #[error("the UV unwrapper failed internally: {0}")]
    UnwrapPanicked(String),
    /// A per-vertex array does not match the atlas.
    #[error("{what}: expected {expected} values, got {got}")]
    Length {
        /// Which array.
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Actual length.
        got: usize,
    },
    /// A vertex pixel lies outside the image.
    #[error("vertex {vertex} maps to pixel ({x}, {y}) outside the {width}-wide image of {pixels} pixels")]
    PixelOutside {
        /// Vertex index.
        vertex: usize,
        /// Column.
        x: u16,
        /// Row.
        y: u16,
        /// Image width.
        width: u32,
        /// Pixels in the image.
        pixels: usize,
    },
    /// Writing the picture failed.
    #[error("writing {path}: {source}")]
    Image {
        /// Output path.
        path: String,
        /// Cause.
        source: image::ImageError,
    },
}

#[cfg(test)]
mod tests {
    use super::AtlasError;
    use std::error::Error;

    #[test]
    fn wrapped_errors_are_sources() {
        let io = std::io::Error::other("disk full");
        let e = AtlasError::Image {
            path: "atlas.png".into(),
            source: image::ImageError::IoError(io),
        };
        assert!(e
            .source()
            .is_some_and(|s| s.to_string().contains("disk full")));
        assert!(AtlasError::NonFinitePosition(3).source().is_none());
    }
}
