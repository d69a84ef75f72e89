//! `mcgv-video eval`.

use crate::cli::EvalArgs;
use crate::error::{Error, Result};

/// Runs `eval`.
pub fn run(_args: &EvalArgs, _quiet: bool) -> Result<()> {
    Err(Error::Usage("`eval` is not available yet".into()))
}
