//! What the fuzz targets run, as plain functions so that `tests/it/fuzz_regressions.rs` replays the
//! crashers through exactly the same code (it includes [`harness`] by path).

pub mod harness;
