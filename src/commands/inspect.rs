//! `mcgv-video inspect`.

use crate::cli::InspectArgs;
use crate::error::{Error, Result};

/// Runs `inspect`.
pub fn run(_args: &InspectArgs, _quiet: bool) -> Result<()> {
    Err(Error::Usage("`inspect` is not available yet".into()))
}
