//! Any bytes as a `.mcgv` stream, checksums repaired so that damage reaches the part decoders.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // Errors are the expected outcome; only a panic, an abort or running out of memory is a finding.
    let _ = mcgv_video_fuzz::harness::decode_stream(data);
});
