//! The library's error type: every failure a caller can cause ends here, with a message naming the
//! culprit and, where another crate failed, that crate's error as the [`source`](std::error::Error::source).

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
    /// An option (a field of [`EncodeOptions`](crate::EncodeOptions),
    /// [`DecodeOptions`](crate::DecodeOptions) or [`ReadOptions`](crate::ReadOptions)) is out of
    /// range or does not apply; `option` is the field's name, which a command line renders as its flag.
    #[error("{option}: {message}")]
    InvalidOption {
        /// The option's field name, e.g. `clusters`.
        option: &'static str,
        /// What is wrong with it.
        message: String,
    },
    /// The caller asked for something the input cannot give (a frame past the end, images of a
    /// stream that has none).
    #[error("{0}")]
    Usage(String),
    /// The atlas could not be built.
    #[cfg(feature = "encode")]
    #[error("atlas: {0}")]
    Atlas(#[from] atlas::AtlasError),
    /// Padding the free pixels of a geometry image failed.
    #[error("padding: {0}")]
    Padding(#[from] padding::PaddingError),
}

impl Error {
    /// An I/O error tied to the path it happened on.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }

    /// An invalid option, by its field name.
    pub fn option(option: &'static str, message: impl Into<String>) -> Self {
        Error::InvalidOption {
            option,
            message: message.into(),
        }
    }
}

/// Result with the crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;
