//! What can go wrong when padding: only malformed inputs; the solvers themselves never fail.

/// Why [`crate::pad`] refused its inputs.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PaddingError {
    /// Width or height is zero.
    #[error("image size {width}x{height} is empty")]
    EmptyImage {
        /// Image width in pixels.
        width: usize,
        /// Image height in pixels.
        height: usize,
    },
    /// A buffer's length does not match width × height.
    #[error("{what} has {got} values, expected {expected} (width x height)")]
    SizeMismatch {
        /// Which buffer: "image", "mask" or "previous".
        what: &'static str,
        /// Its length.
        got: usize,
        /// width × height.
        expected: usize,
    },
    /// The block size is zero, or the method needs a specific block size.
    #[error("block size {block} is not supported by {method}: {why}")]
    BadBlock {
        /// The requested block size.
        block: usize,
        /// The padding method.
        method: String,
        /// The constraint that was violated.
        why: &'static str,
    },
    /// A fixed pixel (or a pixel of the previous frame) is NaN or infinite.
    #[error("{what} pixel {index} is not finite")]
    NonFinite {
        /// "image" or "previous".
        what: &'static str,
        /// Row-major pixel index.
        index: usize,
    },
    /// A `--padding` name that no method answers to.
    #[error("unknown padding method '{0}' (expected one of: {names})", names = crate::Method::NAMES.join(", "))]
    UnknownMethod(String),
}
