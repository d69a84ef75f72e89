//! A simulated cloth: the soft body the temporal DCT's spatial prediction is for (issue 18).
//!
//! A square sheet of `n × n` particles joined by structural and shear springs (position-based, as
//! Jakobsen's Verlet cloth), pinned at two corners of one edge, starts horizontal and falls under
//! gravity with a gusting wind: every vertex moves, no two parts rigidly. Deterministic.

use mcgv_video::mesh::{AnimatedMesh, Point, Triangle};

/// Simulation steps per frame (30 frames per second, 1/240 s per step).
const SUBSTEPS: usize = 8;
/// Constraint relaxation passes per step.
const PASSES: usize = 6;

/// The cloth's animation: `n × n` vertices (n ≥ 2), `frames` frames of a 1 × 1 sheet.
pub fn cloth(n: usize, frames: usize) -> AnimatedMesh {
    let h = 1.0 / (n - 1) as f64;
    let index = |i: usize, j: usize| i * n + j;
    let mut pos: Vec<[f64; 3]> = (0..n * n)
        .map(|p| [(p / n) as f64 * h, 0.0, (p % n) as f64 * h])
        .collect();
    let mut old = pos.clone();
    let mut springs = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let neighbours = [
                (i + 1, j, 1.0),
                (i, j + 1, 1.0),
                (i + 1, j + 1, 2f64.sqrt()),
            ];
            for (a, b, length) in neighbours {
                if a < n && b < n {
                    springs.push((index(i, j), index(a, b), length * h));
                }
            }
            if i + 1 < n && j > 0 {
                springs.push((index(i, j), index(i + 1, j - 1), 2f64.sqrt() * h));
            }
        }
    }
    let pinned = [index(0, 0), index(0, n - 1)];
    let dt = 1.0 / (30 * SUBSTEPS) as f64;
    let mut out = Vec::with_capacity(frames);
    for f in 0..frames {
        for s in 0..SUBSTEPS {
            let t = (f * SUBSTEPS + s) as f64 * dt;
            let wind = [1.5 * (1.3 * t).sin().max(0.0), 0.0, 0.8 * (0.7 * t).cos()];
            for (p, q) in pos.iter_mut().zip(old.iter_mut()) {
                let now = *p;
                for a in 0..3 {
                    let gravity = if a == 1 { -9.81 } else { 0.0 };
                    p[a] += 0.99 * (now[a] - q[a]) + (gravity + wind[a]) * dt * dt;
                }
                *q = now;
            }
            relax(&mut pos, &springs, &pinned, h, n);
        }
        out.push(pos.iter().map(|p| p.map(|x| x as f32) as Point).collect());
    }
    AnimatedMesh::new(triangles(n), out).expect("a valid cloth")
}

/// Pulls every spring back towards its rest length and the pinned corners to their places.
fn relax(
    pos: &mut [[f64; 3]],
    springs: &[(usize, usize, f64)],
    pinned: &[usize],
    h: f64,
    n: usize,
) {
    for _ in 0..PASSES {
        for &(a, b, rest) in springs {
            let d = [0, 1, 2].map(|k| pos[b][k] - pos[a][k]);
            let length = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt().max(1e-12);
            let c = 0.5 * (length - rest) / length;
            for k in 0..3 {
                pos[a][k] += c * d[k];
                pos[b][k] -= c * d[k];
            }
        }
        for &p in pinned {
            pos[p] = [0.0, 0.0, (p % n) as f64 * h];
        }
    }
}

/// Two triangles per grid square.
fn triangles(n: usize) -> Vec<Triangle> {
    let mut t = Vec::with_capacity(2 * (n - 1) * (n - 1));
    for i in 0..n - 1 {
        for j in 0..n - 1 {
            let (a, b, c, d) = (
                i * n + j,
                i * n + j + 1,
                (i + 1) * n + j,
                (i + 1) * n + j + 1,
            );
            t.push([a as u32, c as u32, b as u32]);
            t.push([b as u32, c as u32, d as u32]);
        }
    }
    t
}

/// Writes the cloth as an OBJ sequence into `$CLOTH_DIR` (default `target/cloth`), for measuring
/// with the command line: `CLOTH_DIR=… cargo test --release --test it write_cloth -- --ignored`.
#[test]
#[ignore = "writes a fixture for measurements"]
fn write_cloth() {
    let dir = std::env::var("CLOTH_DIR").unwrap_or_else(|_| "target/cloth".into());
    let mesh = cloth(40, 90);
    mcgv_video::mesh::io::write_obj_sequence(&mesh, std::path::Path::new(&dir)).unwrap();
}
