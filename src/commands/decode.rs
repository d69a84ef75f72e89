//! `mcgv-video decode`.

use crate::cli::DecodeArgs;
use crate::error::{Error, Result};

/// Runs `decode`.
pub fn run(_args: &DecodeArgs, _quiet: bool) -> Result<()> {
    Err(Error::Usage("`decode` is not available yet".into()))
}
