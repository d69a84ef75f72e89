//! The Rust API's encode and decode times of one input, the baseline of the Python package's
//! overhead (scripts/python_overhead.py): reads INPUT once, then REPEAT times encodes it with the
//! default options and decodes every frame, printing one line per repetition:
//!
//! ```text
//! cargo run --release --example api_timing -- INPUT [REPEAT]
//! encode 12.345678 decode 0.123456 bytes 123456
//! ```
//! Only the calls are timed (`encode` + `to_bytes`; `Decoder::new` + `decode_all`), as the Python
//! script times its own calls.

use mcgv_video::{encode, read_animation, Decoder, EncodeOptions, ReadOptions};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (input, repeat) = match args.as_slice() {
        [input] => (input.as_str(), 1),
        [input, repeat] => (input.as_str(), repeat.parse()?),
        _ => return Err("usage: api_timing INPUT [REPEAT]".into()),
    };
    let mesh = read_animation(input, &ReadOptions::default())?;
    for _ in 0..repeat {
        let start = Instant::now();
        let bytes = encode(&mesh, &EncodeOptions::default())?.to_bytes();
        let encoded = start.elapsed().as_secs_f64();
        let start = Instant::now();
        let all = Decoder::new(&bytes)?.decode_all()?;
        let decoded = start.elapsed().as_secs_f64();
        assert_eq!(all.frame_count(), mesh.frame_count());
        println!(
            "encode {encoded:.6} decode {decoded:.6} bytes {}",
            bytes.len()
        );
    }
    Ok(())
}
