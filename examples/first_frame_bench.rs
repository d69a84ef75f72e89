//! Bits per vertex of the first-frame coder on OBJ or glTF meshes, with and without `reorder`.
//!
//! `cargo run --release --example first_frame_bench -- [--bits N] [--dump DIR] MESH...`
//! prints one JSON object per mesh; `--dump DIR` also writes each mesh as `NAME.mesh`
//! (u32 V, u32 F, V×3 f32, F×3 u32, little endian) for `scripts/draco_compare.py`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use mcgv_video::first_frame::{decode, encode, FirstFrameOptions};
use mcgv_video::mesh::{Point, Triangle};
use mcgv_video::{Error, Result};

/// Positions and position-index triangles of every model in an OBJ file, concatenated.
fn read_obj(path: &Path) -> Result<(Vec<Point>, Vec<Triangle>)> {
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ..Default::default()
    };
    let (models, _) =
        tobj::load_obj(path, &opts).map_err(|e| Error::Mesh(format!("{}: {e}", path.display())))?;
    let (mut positions, mut triangles) = (Vec::new(), Vec::new());
    for m in models {
        let base = positions.len() as u32;
        positions.extend(m.mesh.positions.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
        triangles.extend(
            m.mesh
                .indices
                .chunks_exact(3)
                .map(|c| [c[0] + base, c[1] + base, c[2] + base]),
        );
    }
    Ok((positions, triangles))
}

/// Frame 0 and the triangles of a glTF file, through the project's reader.
fn read_gltf(path: &Path) -> Result<(Vec<Point>, Vec<Triangle>)> {
    let mesh = mcgv_video::mesh::read_animation(&path.to_string_lossy(), &Default::default())?;
    Ok((mesh.frame(0).to_vec(), mesh.triangles().to_vec()))
}

fn dump(dir: &Path, name: &str, positions: &[Point], triangles: &[Triangle]) -> Result<()> {
    let mut out = Vec::new();
    out.extend_from_slice(&(positions.len() as u32).to_le_bytes());
    out.extend_from_slice(&(triangles.len() as u32).to_le_bytes());
    for c in positions.iter().flatten() {
        out.extend_from_slice(&c.to_le_bytes());
    }
    for v in triangles.iter().flatten() {
        out.extend_from_slice(&v.to_le_bytes());
    }
    let path = dir.join(format!("{name}.mesh"));
    std::fs::write(&path, out).map_err(|e| Error::io(path, e))
}

fn main() -> Result<()> {
    let mut args = std::env::args().skip(1);
    let (mut bits, mut dump_dir, mut inputs) = (12u8, None::<PathBuf>, Vec::new());
    while let Some(a) = args.next() {
        match a.as_str() {
            "--bits" => {
                bits = args
                    .next()
                    .and_then(|b| b.parse().ok())
                    .ok_or(Error::Usage("--bits N".into()))?
            }
            "--dump" => dump_dir = args.next().map(PathBuf::from),
            _ => inputs.push(PathBuf::from(a)),
        }
    }
    for path in inputs {
        let is_obj = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("obj"));
        let (positions, triangles) = if is_obj {
            read_obj(&path)?
        } else {
            read_gltf(&path)?
        };
        // Sequences live in folders named after them (walking_cat one level deeper, in OBJ/).
        let name = path
            .ancestors()
            .skip(1)
            .filter_map(|p| p.file_name())
            .map(|n| n.to_string_lossy().into_owned())
            .find(|n| n != "OBJ")
            .unwrap_or_default();
        if let Some(dir) = &dump_dir {
            dump(dir, &name, &positions, &triangles)?;
        }
        let v = positions.len().max(1) as f64;
        let mut row = serde_json::json!({ "mesh": name, "vertices": positions.len(), "triangles": triangles.len() });
        for reorder in [false, true] {
            let start = Instant::now();
            let coded = encode(&positions, &triangles, &FirstFrameOptions { bits, reorder })?;
            let encode_ms = start.elapsed().as_secs_f64() * 1e3;
            let start = Instant::now();
            let (tris, _) = decode(&coded.bytes)?;
            let decode_ms = start.elapsed().as_secs_f64() * 1e3;
            if tris.len() != triangles.len() {
                return Err(Error::Codec(format!(
                    "{name}: decoded {} of {} triangles",
                    tris.len(),
                    triangles.len()
                )));
            }
            let s = coded.sizes;
            let key = if reorder { "reorder" } else { "keep_order" };
            row[key] = serde_json::json!({
                "bytes": coded.bytes.len(),
                "bpv_total": coded.bytes.len() as f64 * 8.0 / v,
                "bpv_connectivity": s.connectivity as f64 * 8.0 / v,
                "bpv_geometry": s.geometry as f64 * 8.0 / v,
                "bpv_order": s.order as f64 * 8.0 / v,
                "encode_ms": encode_ms,
                "decode_ms": decode_ms,
            });
        }
        println!("{row}");
    }
    Ok(())
}
