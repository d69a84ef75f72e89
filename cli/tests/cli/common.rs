//! Helpers of the command-line tests: running the binary and reading what it printed, on top of
//! the helpers every integration test shares.
#![allow(dead_code, unused_imports)]

#[path = "../../../tests/common/mod.rs"]
mod shared;

pub use shared::*;

use std::path::Path;
use std::process::{Command, Output};

/// Runs the `mcgv-video` binary built for these tests; its status is the caller's to check.
pub fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mcgv-video"))
        .args(args)
        .output()
        .unwrap_or_else(|e| panic!("running mcgv-video: {e}"))
}

/// Asserts the run succeeded (showing its stderr when not) and returns its stdout.
pub fn ok(out: &Output) -> String {
    assert!(
        out.status.success(),
        "failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The single JSON object a successful `--json` run prints.
pub fn json(out: &Output) -> serde_json::Value {
    let stdout = ok(out);
    serde_json::from_str(stdout.trim())
        .unwrap_or_else(|e| panic!("not one JSON object ({e}): {stdout}"))
}

/// The names of the entries in `dir`, sorted.
pub fn file_names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{} lists: {e}", dir.display()))
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// The grey levels of an image file (a PNG the binary wrote).
pub fn grey(path: &Path) -> Vec<u8> {
    image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_luma8()
        .into_raw()
}
