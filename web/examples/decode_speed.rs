//! The native side of docs/web.md's speed comparison: decodes every frame of a `.mcgv` with the
//! same library build the WebAssembly decoder wraps (no default features), `RUNS` times, and
//! prints the best frames per second.
//!
//!   cargo run --release -p mcgv-web --example decode_speed -- FILE.mcgv [RUNS]

use mcgv_video::{Decoder, Silent};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let path = args.next().ok_or("usage: decode_speed FILE.mcgv [RUNS]")?;
    let runs: usize = args.next().map_or(Ok(5), |r| r.parse())?;
    let bytes = std::fs::read(&path)?;
    let mut best = f64::INFINITY;
    let mut frames = 0;
    for _ in 0..runs {
        let clock = Instant::now();
        let mut decoder = Decoder::new(&bytes)?;
        let mut out: Vec<f32> = Vec::new();
        decoder.for_each_frame(&Silent, |_, frame| {
            out.extend(frame.into_iter().flatten());
            Ok(())
        })?;
        best = best.min(clock.elapsed().as_secs_f64());
        frames = decoder.header().frames as usize;
    }
    println!(
        "{path}: {frames} frames, best of {runs}: {:.1} ms, {:.0} frames/s",
        best * 1e3,
        frames as f64 / best
    );
    Ok(())
}
