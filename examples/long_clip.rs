//! A long generated clip for the memory bench of temporal segments (issue 20): a square cloth of
//! about `V` vertices waving for `F` frames, written as a base OBJ and a PC2 cache one frame at a
//! time (the clip never exists whole in memory, here or in a streaming encoder).
//!
//! ```text
//! cargo run --release --example long_clip -- OUT_DIR VERTICES FRAMES
//! ```
//! Writes OUT_DIR/cloth.obj and OUT_DIR/cloth.pc2.

use std::error::Error;
use std::io::{BufWriter, Write};

type Res<T> = Result<T, Box<dyn Error>>;

/// Position of grid vertex (`i`, `j`) of an `n`×`n` cloth at frame `f`: two travelling waves and
/// a slow sway, so that motion is smooth in time and varies over the surface.
fn position(i: usize, j: usize, n: usize, f: usize) -> [f32; 3] {
    let (u, v) = (i as f32 / (n - 1) as f32, j as f32 / (n - 1) as f32);
    let t = f as f32 / 30.0;
    let wave = 0.08 * (6.0 * u - 2.0 * t).sin() * v + 0.03 * (9.0 * v + 3.1 * t).sin() * u;
    let sway = 0.2 * (0.5 * t).sin() * v * v;
    [u + sway, -v, wave + 0.5 * sway]
}

fn main() -> Res<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [dir, vertices, frames] = args.as_slice() else {
        return Err("usage: long_clip OUT_DIR VERTICES FRAMES".into());
    };
    let (vertices, frames): (usize, usize) = (vertices.parse()?, frames.parse()?);
    let n = ((vertices as f64).sqrt().round() as usize).max(2);
    let dir = std::path::Path::new(dir);
    std::fs::create_dir_all(dir)?;
    let mut obj = BufWriter::new(std::fs::File::create(dir.join("cloth.obj"))?);
    for j in 0..n {
        for i in 0..n {
            let [x, y, z] = position(i, j, n, 0);
            writeln!(obj, "v {x} {y} {z}")?;
        }
    }
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let a = j * n + i + 1;
            writeln!(obj, "f {} {} {}", a, a + 1, a + n + 1)?;
            writeln!(obj, "f {} {} {}", a, a + n + 1, a + n)?;
        }
    }
    obj.flush()?;
    let mut pc2 = BufWriter::new(std::fs::File::create(dir.join("cloth.pc2"))?);
    pc2.write_all(b"POINTCACHE2\0")?;
    pc2.write_all(&1i32.to_le_bytes())?;
    pc2.write_all(&i32::try_from(n * n)?.to_le_bytes())?;
    pc2.write_all(&0f32.to_le_bytes())?;
    pc2.write_all(&1f32.to_le_bytes())?;
    pc2.write_all(&i32::try_from(frames)?.to_le_bytes())?;
    for f in 0..frames {
        for j in 0..n {
            for i in 0..n {
                for c in position(i, j, n, f) {
                    pc2.write_all(&c.to_le_bytes())?;
                }
            }
        }
    }
    pc2.flush()?;
    eprintln!("{} vertices x {frames} frames in {}", n * n, dir.display());
    Ok(())
}
