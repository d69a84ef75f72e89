//! PC2 point caches (Blender, 3ds Max): positions only, so the connectivity comes from a base OBJ.
//!
//! Layout, all little-endian: `"POINTCACHE2\0"`, i32 version (1), i32 point count, f32 start frame,
//! f32 sample rate, i32 sample count, then sample count × point count × 3 f32. So small and fixed a
//! format needs no crate; none of the PC2 crates on crates.io is kept up.

use super::obj::{parse_obj, read_obj, ObjFrame};
use super::{AnimatedMesh, Point};
use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

const MAGIC: &[u8; 12] = b"POINTCACHE2\0";
const HEADER_LEN: usize = 32;

/// The frames stored in a PC2 file.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PointCache {
    /// Sample count × point count positions.
    pub frames: Vec<Vec<Point>>,
}

/// Reads a PC2 file and takes the triangles from `base` (default: the `.obj` with the same stem
/// beside it); the base's vertex count must equal the cache's point count.
pub(crate) fn read_pc2_animation(path: &Path, base: Option<&Path>) -> Result<AnimatedMesh> {
    let cache = read_pc2(path)?;
    let base = base_path(path, base)?;
    with_base(cache, read_obj(&base)?, path, &base)
}

/// The base OBJ of the PC2 cache at `path`: `base`, else the `.obj` of the same stem beside it.
pub(crate) fn base_path(path: &Path, base: Option<&Path>) -> Result<PathBuf> {
    Ok(match base {
        Some(b) => b.to_path_buf(),
        None => {
            let beside = path.with_extension("obj");
            if !beside.is_file() {
                return Err(Error::option(
                    "base",
                    format!(
                        "needed for {}: a PC2 cache holds no faces, and no base mesh is beside it (looked for {})",
                        path.display(),
                        beside.display()
                    ),
                ));
            }
            beside
        }
    })
}

/// Parses PC2 bytes held in memory with the base mesh's OBJ text; the paths only name errors.
pub(crate) fn parse_pc2_animation(
    bytes: &[u8],
    base_text: &str,
    path: &Path,
    base: &Path,
) -> Result<AnimatedMesh> {
    let cache =
        parse_pc2(bytes).map_err(|what| Error::Mesh(format!("{}: {what}", path.display())))?;
    let mesh = parse_obj(base_text, base)?;
    with_base(cache, mesh, path, base)
}

/// The animation of `cache`'s frames on `mesh`'s triangles; their vertex counts must agree.
fn with_base(cache: PointCache, mesh: ObjFrame, path: &Path, base: &Path) -> Result<AnimatedMesh> {
    let points = cache.frames.first().map_or(0, Vec::len);
    check_base(points, &mesh, path, base)?;
    AnimatedMesh::new(mesh.triangles, cache.frames)
        .and_then(|m| m.with_attributes(mesh.attributes))
        .map_err(|e| match e {
            Error::Mesh(m) => Error::Mesh(format!("{}: {m}", path.display())),
            other => other,
        })
}

/// The base mesh must have a vertex per point of the cache at `path`.
pub(crate) fn check_base(points: usize, mesh: &ObjFrame, path: &Path, base: &Path) -> Result<()> {
    if mesh.positions.len() == points {
        return Ok(());
    }
    Err(Error::Mesh(format!(
        "{} has {points} points per frame but its base mesh {} has {} vertices",
        path.display(),
        base.display(),
        mesh.positions.len()
    )))
}

/// Reads and checks a PC2 file: magic, version, counts and exact length.
pub(crate) fn read_pc2(path: &Path) -> Result<PointCache> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    parse_pc2(&bytes).map_err(|what| Error::Mesh(format!("{}: {what}", path.display())))
}

/// Parses PC2 bytes; the error says what is wrong.
fn parse_pc2(bytes: &[u8]) -> std::result::Result<PointCache, String> {
    let (points, _) = parse_header(bytes, bytes.len() as u64)?;
    let frames = bytes[HEADER_LEN..]
        .chunks_exact(points * 12)
        .map(parse_frame)
        .collect();
    Ok(PointCache { frames })
}

/// Checks a PC2 header against the file's length `file_len`; returns the point and sample counts.
pub(crate) fn parse_header(
    bytes: &[u8],
    file_len: u64,
) -> std::result::Result<(usize, usize), String> {
    let header = bytes.get(..HEADER_LEN).ok_or_else(|| {
        format!("{file_len} bytes is too short for a PC2 header ({HEADER_LEN} bytes)")
    })?;
    if &header[..12] != MAGIC {
        return Err("not a PC2 point cache (no POINTCACHE2 signature)".into());
    }
    let word = |at: usize| [header[at], header[at + 1], header[at + 2], header[at + 3]];
    let version = i32::from_le_bytes(word(12));
    let points = i32::from_le_bytes(word(16));
    let samples = i32::from_le_bytes(word(28));
    if version != 1 {
        return Err(format!("PC2 version {version}, only version 1 is known"));
    }
    if points <= 0 || samples <= 0 {
        return Err(format!(
            "header says {points} points and {samples} samples; both must be positive"
        ));
    }
    let (points, samples) = (points as u64, samples as u64);
    let expected = points
        .checked_mul(samples)
        .and_then(|n| n.checked_mul(12))
        .and_then(|n| n.checked_add(HEADER_LEN as u64))
        .ok_or_else(|| format!("header counts {points} × {samples} are too large"))?;
    if file_len != expected {
        let state = if file_len < expected {
            "truncated"
        } else {
            "inconsistent"
        };
        return Err(format!(
            "{state}: {points} points × {samples} samples need {expected} bytes, the file has \
             {file_len}"
        ));
    }
    Ok((points as usize, samples as usize))
}

/// One sample's positions from its `points × 12` bytes.
pub(crate) fn parse_frame(frame: &[u8]) -> Vec<Point> {
    frame
        .chunks_exact(12)
        .map(|p| {
            let f = |k: usize| f32::from_le_bytes([p[k], p[k + 1], p[k + 2], p[k + 3]]);
            [f(0), f(4), f(8)]
        })
        .collect()
}

/// Bytes before the first sample.
pub(crate) const SAMPLES_START: u64 = HEADER_LEN as u64;

/// The PC2 bytes of an animation: start frame 0, one sample per frame.
pub(crate) fn pc2_bytes(mesh: &AnimatedMesh) -> Result<Vec<u8>> {
    let mut out = Vec::with_capacity(HEADER_LEN + mesh.frame_count() * mesh.vertex_count() * 12);
    out.extend_from_slice(&header_bytes(mesh.vertex_count(), mesh.frame_count())?);
    for frame in mesh.frames() {
        push_frame(&mut out, frame);
    }
    Ok(out)
}

/// The 32-byte header of a cache of `points` positions × `samples` frames (start 0, rate 1).
pub(crate) fn header_bytes(points: usize, samples: usize) -> Result<Vec<u8>> {
    let too_many =
        |what: &str, n: usize| Error::Usage(format!("{n} {what} do not fit in a PC2 file"));
    let points = i32::try_from(points).map_err(|_| too_many("vertices", points))?;
    let samples = i32::try_from(samples).map_err(|_| too_many("frames", samples))?;
    let mut out = Vec::with_capacity(HEADER_LEN);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&1i32.to_le_bytes());
    out.extend_from_slice(&points.to_le_bytes());
    out.extend_from_slice(&0f32.to_le_bytes());
    out.extend_from_slice(&1f32.to_le_bytes());
    out.extend_from_slice(&samples.to_le_bytes());
    Ok(out)
}

/// Appends one sample's bytes to `out`.
pub(crate) fn push_frame(out: &mut Vec<u8>, frame: &[Point]) {
    out.extend(
        frame
            .iter()
            .flat_map(|p| p.iter().flat_map(|c| c.to_le_bytes())),
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bytes_round_trip_and_every_cut_is_refused() {
        let mesh = AnimatedMesh::new(
            vec![[0, 1, 2]],
            vec![
                vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
                vec![[0.5, 0.0, 0.0], [1.5, 0.0, 0.0], [0.5, 1.0, -2.25]],
            ],
        )
        .unwrap();
        let bytes = pc2_bytes(&mesh).unwrap();
        assert_eq!(bytes.len(), 32 + 2 * 3 * 12);
        assert_eq!(parse_pc2(&bytes).unwrap().frames, mesh.frames());
        for cut in 0..bytes.len() {
            assert!(parse_pc2(&bytes[..cut]).is_err(), "cut at {cut} accepted");
        }
        let mut longer = bytes.clone();
        longer.push(0);
        assert!(parse_pc2(&longer).unwrap_err().contains("inconsistent"));
    }
}
