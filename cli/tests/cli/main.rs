//! The command line's integration tests, one module per subject, in one test binary: each runs
//! the `mcgv-video` binary built for the tests and checks its output, files and exit codes.

mod browser;
mod common;

mod auto;
mod budget;
mod codec;
mod convert;
mod determinism;
mod eval;
mod frictions;
mod gltf;
mod info;
mod limits;
mod outputs;
mod report;
mod safety;
mod segmentation;
mod segments;
mod shell;
mod skinning;
