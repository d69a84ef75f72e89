//! The fuzz targets' bodies. Uses only `mcgv_video` and `crc32fast`, so the regression test
//! (`tests/it/fuzz_regressions.rs`, through `tests/common/mod.rs`) includes this file by path and
//! replays crashers through the same code.

use mcgv_video::codec::tdct::index::BandIndex;
use mcgv_video::first_frame::{self, FirstFrameOptions};
use mcgv_video::mesh::{parse_gltf, parse_obj, parse_pc2, AnimatedMesh, Summary, Triangle};
use mcgv_video::stream::container::{FILE_HEADER_LEN, PART_HEADER_LEN};
use mcgv_video::stream::frame_index::FrameIndex;
use mcgv_video::Decoder;
use mcgv_video::Result;
use std::path::Path;

/// Bytes of the first-frame coder's own header; its CRC-32 is the header's last four bytes.
const FIRST_FRAME_HEADER_LEN: usize = first_frame::HEADER_LEN;

/// Meshes larger than this skip the static mesh coder round trip: it would slow every execution
/// down without covering anything a small mesh does not.
const ROUND_TRIP_LIMIT: usize = 4096;

/// Decodes `data` as a `.mcgv` stream after repairing its checksums, then every frame in order and
/// the last one on its own (random access decodes from the previous key frame). A temporal-DCT
/// stream is decoded a second time cut inside its coefficients part, as a file still downloading
/// would be: that prefix must decode or be refused like any other input.
pub fn decode_stream(data: &[u8]) -> Result<()> {
    let mut bytes = data.to_vec();
    fix_band_index(&mut bytes);
    fix_frame_index(&mut bytes);
    fix_checksums(&mut bytes);
    if let Some((start, end)) = part_span(&bytes, b"TDCT").filter(|&(s, e)| e > s) {
        // Where to cut follows the input, so that the corpus covers cuts at band boundaries and
        // inside bands alike; each input always cuts at the same place, so crashes replay.
        let cut = start + crc32fast::hash(data) as usize % (end - start);
        let _ = decode_and_check(&bytes[..cut]);
    }
    decode_and_check(&bytes)
}

fn decode_and_check(bytes: &[u8]) -> Result<()> {
    let mut decoder = Decoder::new(bytes)?;
    let mesh = decoder.decode_all()?;
    let last = mesh.frame_count() - 1;
    // The last frame reads the open (last) segment again; the first one, in a segmented stream,
    // reopens the first segment.
    for f in [last, 0] {
        let alone = decoder.decode_frame(f)?;
        check_alone(&decoder, &mesh, f, &alone);
    }
    Ok(())
}

/// Frame `f` decoded alone against the same frame decoded in sequence.
fn check_alone(
    decoder: &Decoder<std::io::Cursor<&[u8]>>,
    mesh: &AnimatedMesh,
    f: usize,
    alone: &[[f32; 3]],
) {
    if decoder.codec().has_bands() {
        // The frame alone sums the bands' basis functions directly, the whole sequence goes
        // through the fast inverse DCT: equal up to rounding, of the order of the coordinates'.
        let scale = mesh
            .frames()
            .iter()
            .flatten()
            .chain(decoder.reference())
            .flatten()
            .filter(|x| x.is_finite())
            .fold(1.0f32, |m, x| m.max(x.abs()));
        assert!(
            close(alone, mesh.frame(f), 1e-6 * scale),
            "frame {f} decodes differently alone and in sequence"
        );
    } else {
        // Image codecs decode the same pictures either way: the frame read alone is the one read
        // in sequence, bit for bit.
        assert!(
            same_bits(alone, mesh.frame(f)),
            "frame {f} decodes differently alone and in sequence"
        );
    }
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
    let info = Summary::of(mesh);
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

/// Equal within `tol`; non-finite coordinates must be the same non-finite value in both.
fn close(a: &[[f32; 3]], b: &[[f32; 3]], tol: f32) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).all(|(p, q)| {
            (0..3).all(|k| {
                let (x, y) = (p[k], q[k]);
                x == y || (x.is_nan() && y.is_nan()) || (x - y).abs() <= tol
            })
        })
}

fn same_bits(a: &[[f32; 3]], b: &[[f32; 3]]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(p, q)| (0..3).all(|k| p[k].to_bits() == q[k].to_bits()))
}

/// Rewrites the checksums of a `.mcgv` file's parts and the first frame's own (the frame chunks'
/// are [`fix_frame_index`]'s, the bands' [`fix_band_index`]'s) to match the bytes, so that mutated files get past the
/// CRC checks, which would otherwise reject nearly every mutation before any decoder runs. Stops
/// quietly where the layout stops making sense: the decoder reports that itself.
pub fn fix_checksums(bytes: &mut [u8]) {
    let Some(count) = word(bytes, 12) else {
        return;
    };
    let mut pos = FILE_HEADER_LEN;
    for _ in 0..count.min(1024) {
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
        if whole {
            let crc = crc32fast::hash(&bytes[start..end]).to_le_bytes();
            bytes[pos + CRC_AT..pos + CRC_AT + 4].copy_from_slice(&crc);
        }
        pos = end;
    }
}

/// Where a part header holds its payload length (`u32`) and its CRC-32.
const LEN_AT: usize = 5;
const CRC_AT: usize = 9;

/// The little-endian `u32` at `at`, if `b` holds it.
fn word(b: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_le_bytes(b.get(at..at + 4)?.try_into().ok()?))
}

/// The payload length a part header at `head` declares.
fn declared_len(head: &[u8]) -> Option<u64> {
    word(head, LEN_AT).map(u64::from)
}

/// Repairs the frame chunks' CRCs in every frame index (one per segment) that still parses, so
/// that mutated pictures reach the picture decoders; the index is coded again and spliced in.
pub fn fix_frame_index(bytes: &mut Vec<u8>) {
    recode_indexes(bytes, (b"INDX", b"FRMS"), |bytes, (start, end), chunks| {
        // The index states its own frame count; the decoder checks it against the header's.
        let count = word(bytes, start)? as usize;
        let mut index = FrameIndex::from_bytes(&bytes[start..end], count, chunks.1).ok()?;
        for e in index.entries_mut() {
            if let Some(crc) = chunk_crc(bytes, (chunks.0, chunks.2), e.offset, e.len) {
                e.crc = crc;
            }
        }
        index.to_bytes().ok()
    });
}

/// For the `n`-th part tagged `index` and the `n`-th tagged `chunks` (one pair per segment, up to
/// 64): `recode` gets the file, the index's payload span and the chunked part's (start, declared
/// length, end), and returns the index coded again, which is spliced in; `None` leaves it as it
/// is (an index that no longer parses: refusing it is the decoder's job).
fn recode_indexes(
    bytes: &mut Vec<u8>,
    (index, chunks): (&[u8; 4], &[u8; 4]),
    recode: impl Fn(&[u8], (usize, usize), (usize, u64, usize)) -> Option<Vec<u8>>,
) {
    // Each splice keeps the later parts' order.
    for n in 0..64 {
        let Some((_, c_start, c_declared, c_end)) = part_layout_nth(bytes, chunks, n) else {
            return;
        };
        let Some((i_pos, i_start, _, i_end)) = part_layout_nth(bytes, index, n) else {
            return;
        };
        if let Some(coded) = recode(bytes, (i_start, i_end), (c_start, c_declared, c_end)) {
            splice_part(bytes, (i_pos, i_start, i_end), &coded);
        }
    }
}

/// The CRC-32 of the non-empty chunk at `offset`, `len` bytes into the part payload
/// `start..end`; `None` for an empty chunk or one past the payload (a cut file keeps its CRC: the
/// decoder stops before it).
fn chunk_crc(bytes: &[u8], (start, end): (usize, usize), offset: u64, len: u64) -> Option<u32> {
    let from = start.checked_add(usize::try_from(offset).ok()?)?;
    let to = from.checked_add(usize::try_from(len).ok()?)?;
    (len > 0 && to <= end).then(|| crc32fast::hash(&bytes[from..to]))
}

/// Puts `coded` in place of the payload `start..end` of the part whose header is at `pos`, and
/// fixes its declared length: re-coding may change an index's length (a mutated index that still
/// parses need not be the encoder's own coding of it).
fn splice_part(bytes: &mut Vec<u8>, (pos, start, end): (usize, usize, usize), coded: &[u8]) {
    bytes.splice(start..end, coded.iter().copied());
    let len = u32::try_from(coded.len()).unwrap_or(u32::MAX);
    bytes[pos + LEN_AT..pos + LEN_AT + 4].copy_from_slice(&len.to_le_bytes());
}

/// Where the payload of the part whose header starts at `pos` lies, if it lies inside `bytes`.
fn payload_span(bytes: &[u8], pos: usize) -> Option<(usize, usize)> {
    let head = bytes.get(pos..pos + PART_HEADER_LEN)?;
    let len = declared_len(head)?;
    let start = pos + PART_HEADER_LEN;
    let end = usize::try_from(len).ok()?.checked_add(start)?;
    (end <= bytes.len()).then_some((start, end))
}

/// Payload span of the (first) part tagged `tag`. The last part may be cut short by the end of the
/// file (a progressive part does that legitimately): its span then ends with the file.
fn part_span(bytes: &[u8], tag: &[u8; 4]) -> Option<(usize, usize)> {
    part_layout(bytes, tag).map(|(_, start, _, end)| (start, end))
}

/// Header offset, payload start, declared payload length and payload end (clipped to the file) of
/// the first part tagged `tag`, walking the part table as far as it makes sense.
fn part_layout(bytes: &[u8], tag: &[u8; 4]) -> Option<(usize, usize, u64, usize)> {
    part_layout_nth(bytes, tag, 0)
}

/// [`part_layout`] of the `n`-th part tagged `tag` (a segmented stream repeats a segment's tags).
fn part_layout_nth(
    bytes: &[u8],
    tag: &[u8; 4],
    mut n: usize,
) -> Option<(usize, usize, u64, usize)> {
    let mut pos = FILE_HEADER_LEN;
    loop {
        let head = bytes.get(pos..pos + PART_HEADER_LEN)?;
        let len = declared_len(head)?;
        let start = pos + PART_HEADER_LEN;
        let end = usize::try_from(len)
            .ok()
            .and_then(|l| l.checked_add(start))
            .map_or(bytes.len(), |e| e.min(bytes.len()));
        if &head[..4] == tag {
            if n == 0 {
                return Some((pos, start, len, end));
            }
            n -= 1;
        }
        if end == bytes.len() {
            return None;
        }
        pos = end;
    }
}

/// Rewrites the per-band CRCs of a temporal-DCT index (TDIX) to match the bands in the
/// coefficients part (TDCT), re-coding the index; its part CRC is left to [`fix_checksums`]. An
/// index that no longer parses is left as it is: refusing it is the decoder's job.
pub fn fix_band_index(bytes: &mut Vec<u8>) {
    recode_indexes(bytes, (b"TDIX", b"TDCT"), |bytes, (start, end), chunks| {
        // The index states its own band count; the decoder checks it against the header's frames.
        let count = word(bytes, start + 4)? as usize;
        let mut index = BandIndex::from_bytes(&bytes[start..end], count, chunks.1).ok()?;
        for band in &mut index.bands {
            if let Some(crc) = chunk_crc(bytes, (chunks.0, chunks.2), band.offset, band.len) {
                band.crc = crc;
            }
        }
        index.to_bytes().ok()
    });
}
