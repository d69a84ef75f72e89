//! `mcgv-video info`.

use crate::cli::InfoArgs;
use crate::error::{Error, Result};

/// Runs `info`.
pub fn run(_args: &InfoArgs, _quiet: bool) -> Result<()> {
    Err(Error::Usage("`info` is not available yet".into()))
}
