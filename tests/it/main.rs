//! The library's integration tests, one module per subject, in one test binary (so FFmpeg is
//! linked once). `tests/forged_counts.rs` is its own binary: it installs a counting allocator.

#[path = "../common/mod.rs"]
mod common;

mod affine_coding;
mod attributes;
mod auto;
mod budget;
mod cloth;
mod codec;
mod decimate;
mod error_law;
mod first_frame;
mod first_frame_bits;
mod fuzz_regressions;
mod gltf_write;
mod hostile_meshes;
mod layering;
mod mesh_io;
mod metrics_reference;
mod motion;
mod partial;
mod roundtrip;
mod segments;
mod skinning;
mod tdct;
mod tdct_spatial;
