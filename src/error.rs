//! The crate-wide error type: every failure a user can cause ends here, with a message naming the culprit.

use std::path::PathBuf;

/// Anything that can go wrong in mcgv-video.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file involved.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// A mesh or mesh sequence is malformed.
    #[error("{0}")]
    Mesh(String),
    /// A `.mcgv` stream is malformed, truncated or corrupt.
    #[error("corrupt stream: {0}")]
    Stream(String),
    /// An image or video codec failed.
    #[error("codec: {0}")]
    Codec(String),
    /// The user asked for something that cannot be done.
    #[error("{0}")]
    Usage(String),
}

impl Error {
    /// An I/O error tied to the path it happened on.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }
}

/// Result with the crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;
