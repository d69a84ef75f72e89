//! `mcgv-video encode`.

use crate::cli::EncodeArgs;
use crate::error::{Error, Result};

/// Runs `encode`.
pub fn run(_args: &EncodeArgs, _quiet: bool) -> Result<()> {
    Err(Error::Usage("`encode` is not available yet".into()))
}
