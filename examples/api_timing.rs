//! The Rust API's encode and decode times of one input, the baseline of the Python package's
//! overhead (scripts/python_overhead.py): reads INPUT once, then REPEAT times encodes it with the
//! default options and decodes every frame DECODES times, printing one line per repetition with
//! wall and CPU seconds (the decode's: per decode):
//!
//! ```text
//! cargo run --release --example api_timing -- INPUT [REPEAT [DECODES]]
//! encode 12.345678 cpu 20.13 decode 0.123456 cpu 0.12 bytes 123456
//! ```
//! Only the calls are timed (`encode` + `to_bytes`; `Decoder::new` + `decode_all`), as the Python
//! script times its own calls. CPU seconds are the process's (every thread's), which on a machine
//! shared with other jobs vary far less than wall seconds.

use mcgv_video::{encode, read_animation, Decoder, EncodeOptions, ReadOptions};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (input, repeat, decodes) = match args.as_slice() {
        [input] => (input.as_str(), 1, 1),
        [input, repeat] => (input.as_str(), repeat.parse()?, 1),
        [input, repeat, decodes] => (input.as_str(), repeat.parse()?, decodes.parse()?),
        _ => return Err("usage: api_timing INPUT [REPEAT [DECODES]]".into()),
    };
    let mesh = read_animation(input, &ReadOptions::default())?;
    for _ in 0..repeat {
        let (start, cpu) = (Instant::now(), cpu_seconds()?);
        let bytes = encode(&mesh, &EncodeOptions::default())?.to_bytes();
        let (encoded, encoded_cpu) = (start.elapsed().as_secs_f64(), cpu_seconds()? - cpu);
        let (start, cpu) = (Instant::now(), cpu_seconds()?);
        for _ in 0..decodes {
            let all = Decoder::new(&bytes)?.decode_all()?;
            assert_eq!(all.frame_count(), mesh.frame_count());
        }
        let n = decodes.max(1) as f64;
        let decoded = start.elapsed().as_secs_f64() / n;
        let decoded_cpu = (cpu_seconds()? - cpu) / n;
        println!(
            "encode {encoded:.6} cpu {encoded_cpu:.2} decode {decoded:.6} cpu {decoded_cpu:.3} bytes {}",
            bytes.len()
        );
    }
    Ok(())
}

/// The process's user + system CPU seconds, from /proc/self/stat (Linux), whose fields 14 and 15
/// count clock ticks of USER_HZ, 100 per second on every Linux architecture: 10 ms steps, which
/// is why decodes are repeated.
fn cpu_seconds() -> Result<f64, Box<dyn std::error::Error>> {
    let stat = std::fs::read_to_string("/proc/self/stat")?;
    // The command name (field 2) may hold spaces; the fields after it follow its closing ')'.
    let after = stat.rsplit_once(')').ok_or("unexpected /proc/self/stat")?.1;
    let fields: Vec<&str> = after.split_whitespace().collect();
    let ticks = |i: usize| -> Result<f64, Box<dyn std::error::Error>> {
        Ok(fields
            .get(i)
            .ok_or("short /proc/self/stat")?
            .parse::<f64>()?)
    };
    // Field 3 (state) is fields[0] here, so utime (14) and stime (15) are fields[11] and [12].
    Ok((ticks(11)? + ticks(12)?) / 100.0)
}
