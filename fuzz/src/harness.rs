//! The fuzz targets' bodies. Uses only `mcgv_video` and `crc32fast`, so the regression test
//! (`tests/fuzz_regressions.rs`) includes this file by path and replays crashers through the same code.

use mcgv_video::commands::info::Info;
use mcgv_video::decoder::Decoder;
use mcgv_video::mesh::{parse_gltf, parse_obj, parse_pc2, AnimatedMesh, Triangle};
use mcgv_video::stream::container::{ContainerReader, FILE_HEADER_LEN, PART_HEADER_LEN};
use mcgv_video::stream::first_frame::{self, FirstFrameOptions};
use mcgv_video::Result;
use std::io::Cursor;
use std::path::Path;

/// Bytes of the first-frame coder's own header; its CRC-32 is the header's last four bytes.
const FIRST_FRAME_HEADER_LEN: usize = 56;

/// Meshes larger than this skip the static mesh coder round trip: it would slow every execution
/// down without covering anything a small mesh does not.
const ROUND_TRIP_LIMIT: usize = 4096;

/// Decodes `data` as a `.mcgv` stream after repairing its checksums, then every frame in order and
/// the last one on its own (random access decodes from the previous key frame).
pub fn decode_stream(data: &[u8]) -> Result<()> {
    let mut bytes = data.to_vec();
    fix_checksums(&mut bytes);
    let mut decoder = Decoder::new(ContainerReader::new(Cursor::new(bytes))?)?;
    let mesh = decoder.decode_all(&mcgv_video::progress::bar(0, "", true))?;
    let last = mesh.frame_count() - 1;
    let alone = decoder.decode_frame(last)?;
    // Decoding is deterministic: the frame read alone is the one read in sequence.
    assert!(
        same_bits(&alone, mesh.frame(last)),
        "frame {last} decodes differently alone and in sequence"
    );
    Ok(())
}

/// Reads `data` as a mesh: the first byte picks OBJ (0), PC2 + base OBJ separated by a NUL byte
/// (1) or glTF/GLB (2). A mesh that reads is measured like `info` does and its first frame goes
/// through the static mesh coder, whose connectivity must come back unchanged.
pub fn read_mesh(data: &[u8]) -> Result<()> {
    let Some((&kind, rest)) = data.split_first() else {
        return Ok(());
    };
    let mesh = match kind % 3 {
        0 => parse_obj(&String::from_utf8_lossy(rest), Path::new("fuzz.obj"))?,
        1 => {
            let split = rest.iter().position(|&b| b == 0).unwrap_or(rest.len());
            let (base, pc2) = rest.split_at(split);
            let pc2 = pc2.get(1..).unwrap_or_default();
            parse_pc2(pc2, &String::from_utf8_lossy(base), Path::new("fuzz.pc2"))?
        }
        _ => parse_gltf(rest, Path::new("fuzz.glb"), None, None)?,
    };
    check_mesh(&mesh)
}

fn check_mesh(mesh: &AnimatedMesh) -> Result<()> {
    let info = Info::of(mesh, 0.0);
    assert_eq!(info.vertices, mesh.vertex_count());
    if mesh.vertex_count() > ROUND_TRIP_LIMIT || mesh.triangles().len() > 2 * ROUND_TRIP_LIMIT {
        return Ok(());
    }
    let coded = first_frame::encode(
        mesh.frame(0),
        mesh.triangles(),
        &FirstFrameOptions::default(),
    )?;
    let (triangles, positions) = first_frame::decode(&coded.bytes)?;
    assert_eq!(positions.len(), mesh.vertex_count());
    assert!(same_bits(&positions, &coded.decoded_positions));
    assert_eq!(canonical(&triangles), canonical(mesh.triangles()));
    Ok(())
}

/// Triangles rotated to start at their smallest index, sorted: equal for the same connectivity.
pub fn canonical(triangles: &[Triangle]) -> Vec<Triangle> {
    let mut out: Vec<Triangle> = triangles
        .iter()
        .map(|t| {
            let k = (0..3).min_by_key(|&k| t[k]).unwrap_or(0);
            [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
        })
        .collect();
    out.sort_unstable();
    out
}

fn same_bits(a: &[[f32; 3]], b: &[[f32; 3]]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(p, q)| (0..3).all(|k| p[k].to_bits() == q[k].to_bits()))
}

/// Rewrites every checksum a `.mcgv` file carries (each part's, the first frame's own and each
/// frame chunk's from the frame index) to match the bytes, so that mutated files get past the
/// CRC checks, which would otherwise reject nearly every mutation before any decoder runs. Stops
/// quietly where the layout stops making sense: the decoder reports that itself.
pub fn fix_checksums(bytes: &mut [u8]) {
    let word = |b: &[u8], at: usize| -> Option<u32> {
        Some(u32::from_le_bytes(b.get(at..at + 4)?.try_into().ok()?))
    };
    let Some(count) = word(bytes, 12) else {
        return;
    };
    let mut pos = FILE_HEADER_LEN;
    let mut index: Option<(usize, usize)> = None;
    let mut frames: Option<(usize, usize)> = None;
    for _ in 0..count.min(64) {
        let Some(head) = bytes.get(pos..pos + PART_HEADER_LEN) else {
            return;
        };
        let tag: [u8; 4] = [head[0], head[1], head[2], head[3]];
        let whole = head[4] == 0;
        let Some((start, end)) = payload_span(bytes, pos) else {
            return;
        };
        if &tag == b"MESH" && end - start >= FIRST_FRAME_HEADER_LEN {
            let body = &bytes[start..end];
            let mut h = crc32fast::Hasher::new();
            h.update(&body[..FIRST_FRAME_HEADER_LEN - 4]);
            h.update(&body[FIRST_FRAME_HEADER_LEN..]);
            let crc = h.finalize().to_le_bytes();
            bytes[start + FIRST_FRAME_HEADER_LEN - 4..start + FIRST_FRAME_HEADER_LEN]
                .copy_from_slice(&crc);
        }
        match &tag {
            b"INDX" => index = Some((start, end)),
            b"FRMS" => frames = Some((start, end)),
            _ => {}
        }
        if whole {
            let crc = crc32fast::hash(&bytes[start..end]).to_le_bytes();
            bytes[pos + 13..pos + 17].copy_from_slice(&crc);
        }
        pos = end;
    }
    // Frame chunks: the index lists (length, CRC, key) per frame, chunks laid end to end.
    let (Some((i_start, i_end)), Some((f_start, f_end))) = (index, frames) else {
        return;
    };
    let mut offset = f_start;
    let mut at = i_start + 4;
    while at + 9 <= i_end {
        let Some(len) = word(bytes, at) else {
            return;
        };
        let Some(end) = offset.checked_add(len as usize).filter(|&e| e <= f_end) else {
            break;
        };
        let crc = crc32fast::hash(&bytes[offset..end]).to_le_bytes();
        bytes[at + 4..at + 8].copy_from_slice(&crc);
        offset = end;
        at += 9;
    }
    // The index is a whole-checked part written before the images: its CRC changed with the chunks'.
    refresh_part_crc(bytes, b"INDX");
}

/// Where the payload of the part whose header starts at `pos` lies, if it lies inside `bytes`.
fn payload_span(bytes: &[u8], pos: usize) -> Option<(usize, usize)> {
    let head = bytes.get(pos..pos + PART_HEADER_LEN)?;
    let len = u64::from_le_bytes(head[5..13].try_into().unwrap_or_default());
    let start = pos + PART_HEADER_LEN;
    let end = usize::try_from(len).ok()?.checked_add(start)?;
    (end <= bytes.len()).then_some((start, end))
}

/// Recomputes the part CRC of the (first) part tagged `tag`.
fn refresh_part_crc(bytes: &mut [u8], tag: &[u8; 4]) {
    let mut pos = FILE_HEADER_LEN;
    while let Some(head) = bytes.get(pos..pos + PART_HEADER_LEN) {
        let Some((start, end)) = payload_span(bytes, pos) else {
            return;
        };
        if &head[..4] == tag {
            if head[4] == 0 {
                let crc = crc32fast::hash(&bytes[start..end]).to_le_bytes();
                bytes[pos + 13..pos + 17].copy_from_slice(&crc);
            }
            return;
        }
        pos = end;
    }
}
