//! Any bytes as an OBJ, a PC2 with its base OBJ, or a glTF/GLB (the first byte picks which).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // Errors are the expected outcome; only a panic, an abort or running out of memory is a finding.
    let _ = mcgv_video_fuzz::harness::read_mesh(data);
});
