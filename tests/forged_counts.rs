//! Forged streams whose counts fit the header's limits but not the bytes that should carry them:
//! refused with a clear error before anything is allocated per claimed element; and the positions
//! limit, which bounds what a valid stream makes the decoder produce. A counting allocator measures
//! the peak memory of each refusal on its own thread.

mod common;

use common::{encode_bytes, parts, rebuild, tiny_stream};
use mcgv_video::first_frame::{self, FirstFrameOptions};
use mcgv_video::stream::container::ContainerReader;
use mcgv_video::stream::container::Tag;
use mcgv_video::stream::entropy::max_symbols;
use mcgv_video::{codec::Codec, stream::header::Header};
use mcgv_video::{
    AnimatedMesh, DecodeOptions, Decoder, EncodeOptions, Error, DEFAULT_MAX_POSITIONS,
};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::io::Cursor;

/// The system allocator, counting the bytes live on each thread and their peak.
struct Counting;

thread_local! {
    static LIVE: Cell<usize> = const { Cell::new(0) };
    static PEAK: Cell<usize> = const { Cell::new(0) };
}

fn grow(bytes: usize) {
    // `try_with`: the allocator also runs while thread-locals are torn down.
    let _ = LIVE.try_with(|live| {
        let now = live.get() + bytes;
        live.set(now);
        let _ = PEAK.try_with(|peak| peak.set(peak.get().max(now)));
    });
}

fn shrink(bytes: usize) {
    let _ = LIVE.try_with(|live| live.set(live.get().saturating_sub(bytes)));
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        grow(layout.size());
        // SAFETY: the caller's contract is passed on unchanged.
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        grow(layout.size());
        // SAFETY: as above.
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        shrink(layout.size());
        // SAFETY: as above.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        shrink(layout.size());
        grow(new_size);
        // SAFETY: as above.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Runs `f`, returning what it returns and the most memory it had allocated at once (bytes).
fn peak_of<T>(f: impl FnOnce() -> T) -> (T, usize) {
    let base = LIVE.with(Cell::get);
    PEAK.with(|p| p.set(base));
    let out = f();
    (out, PEAK.with(Cell::get) - base)
}

/// What a refusal may allocate: the input's copies and small tables, never per claimed element.
const SMALL: usize = 1 << 20;

/// Byte offsets in the first frame's header: counts, then the three stream lengths, then the CRC.
const VERTEX_COUNT: usize = 4;
const TRAVERSED: usize = 8;
const WELDED: usize = 16;
const CONNECTIVITY_LEN: usize = 36;
const GEOMETRY_LEN: usize = 40;
const FIRST_FRAME_HEADER_LEN: usize = first_frame::HEADER_LEN;

fn word(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(bytes[at..at + 4].try_into().expect("four bytes"))
}

fn set_word(bytes: &mut [u8], at: usize, value: u32) {
    bytes[at..at + 4].copy_from_slice(&value.to_le_bytes());
}

/// A real first frame (a 3×3 grid of squares, two triangles each) with `extra` zero bytes added to
/// its connectivity or geometry stream, then `forge` applied to its header and the checksum made
/// right, so that only the count checks stand in the way. Zero bytes are what decode cheapest:
/// each symbol from them costs the coder's floor.
fn forged_first_frame(
    reorder: bool,
    pad_at: usize,
    extra: usize,
    forge: impl Fn(&mut [u8]),
) -> Vec<u8> {
    let mut positions = Vec::new();
    for y in 0..4 {
        for x in 0..4 {
            positions.push([x as f32, y as f32, (x * y) as f32 * 0.1]);
        }
    }
    let mut triangles = Vec::new();
    for y in 0..3u32 {
        for x in 0..3u32 {
            let v = 4 * y + x;
            triangles.push([v, v + 1, v + 5]);
            triangles.push([v, v + 5, v + 4]);
        }
    }
    let opts = FirstFrameOptions { bits: 12, reorder };
    let mut bytes = first_frame::encode(&positions, &triangles, &opts)
        .expect("encodes")
        .bytes;
    // Streams follow the header in the order connectivity, geometry, order.
    let lc = word(&bytes, CONNECTIVITY_LEN) as usize;
    let end = match pad_at {
        CONNECTIVITY_LEN => FIRST_FRAME_HEADER_LEN + lc,
        _ => FIRST_FRAME_HEADER_LEN + lc + word(&bytes, GEOMETRY_LEN) as usize,
    };
    bytes.splice(end..end, vec![0u8; extra]);
    let grown = word(&bytes, pad_at) + extra as u32;
    set_word(&mut bytes, pad_at, grown);
    forge(&mut bytes);
    let mut hasher = crc32fast::Hasher::new();
    hasher.update(&bytes[..FIRST_FRAME_HEADER_LEN - 4]);
    hasher.update(&bytes[FIRST_FRAME_HEADER_LEN..]);
    let crc = hasher.finalize();
    set_word(&mut bytes, FIRST_FRAME_HEADER_LEN - 4, crc);
    bytes
}

/// Pads a stream of a real first frame (as [`forged_first_frame`]), sets the header's u32 at
/// `field` to `claim(padded bytes)`, decodes, and returns the claim and the error, checking that the
/// refusal allocated little.
fn refused(
    reorder: bool,
    pad_at: usize,
    extra: usize,
    field: usize,
    claim: impl Fn(&[u8]) -> u32,
) -> (u32, String) {
    let claim = claim(&forged_first_frame(reorder, pad_at, extra, |_| {}));
    let bytes = forged_first_frame(reorder, pad_at, extra, |b| set_word(b, field, claim));
    let (result, peak) = peak_of(|| first_frame::decode(&bytes));
    let msg = match result {
        Ok(_) => panic!("a forged first frame was accepted"),
        Err(e) => e.to_string(),
    };
    assert!(peak < SMALL, "refusing took {peak} bytes: {msg}");
    (claim, msg)
}

#[test]
fn the_forgery_keeps_an_honest_first_frame_valid() {
    for reorder in [false, true] {
        let bytes = forged_first_frame(reorder, GEOMETRY_LEN, 4000, |_| {});
        let (triangles, positions) = first_frame::decode(&bytes).expect("padding decodes");
        assert_eq!((triangles.len(), positions.len()), (18, 16));
    }
}

#[test]
fn vertices_past_what_the_geometry_stream_holds_are_refused_before_allocating() {
    // 4 KB of geometry hold at most max_symbols / 3 welded vertices (three residuals each); the
    // vertex count is raised with them, as welded vertices are never more than the vertices.
    let pad = |b: &[u8]| (max_symbols(word(b, GEOMETRY_LEN) as usize) / 3 + 1) as u32;
    let claim = pad(&forged_first_frame(true, GEOMETRY_LEN, 4000, |_| {}));
    let bytes = forged_first_frame(true, GEOMETRY_LEN, 4000, |b| {
        set_word(b, VERTEX_COUNT, claim);
        set_word(b, WELDED, claim);
    });
    let (result, peak) = peak_of(|| first_frame::decode(&bytes));
    let msg = result
        .expect_err("a forged first frame was accepted")
        .to_string();
    assert!(peak < SMALL, "refusing took {peak} bytes: {msg}");
    assert!(claim > 7_000_000, "a claim worth refusing: {claim}");
    assert!(
        msg.contains(&format!("{claim} welded vertices")) && msg.contains("geometry stream"),
        "{msg}"
    );
}

#[test]
fn vertices_past_what_the_connectivity_stream_holds_are_refused_before_allocating() {
    // Each vertex is at least one "another copy?" decision in the connectivity stream.
    let (claim, msg) = refused(true, CONNECTIVITY_LEN, 4000, VERTEX_COUNT, |b| {
        max_symbols(word(b, CONNECTIVITY_LEN) as usize) as u32
    });
    assert!(
        msg.contains(&format!("{claim} vertices")) && msg.contains("connectivity stream"),
        "{msg}"
    );
}

#[test]
fn vertices_past_what_the_order_stream_holds_are_refused() {
    // Plenty of geometry, but the stored order takes at least four decisions a vertex.
    let (_, msg) = refused(false, GEOMETRY_LEN, 40_000, VERTEX_COUNT, |b| {
        let lo = b.len()
            - FIRST_FRAME_HEADER_LEN
            - word(b, CONNECTIVITY_LEN) as usize
            - word(b, GEOMETRY_LEN) as usize;
        (max_symbols(lo) / 4 + 1) as u32
    });
    assert!(msg.contains("order stream"), "{msg}");
}

#[test]
fn triangles_past_what_the_connectivity_stream_holds_are_refused() {
    let (claim, msg) = refused(true, CONNECTIVITY_LEN, 4000, TRAVERSED, |b| {
        (max_symbols(word(b, CONNECTIVITY_LEN) as usize) / 3 + 1) as u32
    });
    assert!(
        msg.contains(&format!("{claim} triangles")) && msg.contains("connectivity stream"),
        "{msg}"
    );
}

#[test]
fn frames_past_what_the_affine_part_holds_are_refused_before_the_affine_track() {
    // 4M frames of one cluster are 48M affine coefficients: 12 KB of zero bytes decode as that
    // many (each at the coder's floor), so the affine part's length alone cannot refuse the claim.
    // Its end word does, read in a dry run that keeps no level; the residual ranges (24 bytes a
    // frame: a step and an offset per axis) would refuse it next, still before the track's 384 MB.
    const FRAMES: u32 = 1 << 22;
    let mut forged = parts(&tiny_stream(Codec::Jpeg));
    for (tag, payload, _) in forged.iter_mut() {
        if *tag == Tag::HEADER {
            let mut header = Header::from_bytes(payload).expect("a valid header");
            header.frames = FRAMES;
            *payload = header.to_bytes();
        } else if *tag == Tag::AFFINE {
            // The step, then the coded levels.
            payload.truncate(4);
            payload.extend(vec![0u8; 12_000]);
            assert!(12 * u64::from(FRAMES) <= max_symbols(12_000));
        }
    }
    let bytes = rebuild(forged);
    let start = std::time::Instant::now();
    let (result, peak) = peak_of(|| Decoder::new(&bytes).map(|_| ()));
    let msg = match result {
        Ok(_) => panic!("a forged frame count was accepted"),
        Err(e) => e.to_string(),
    };
    assert!(msg.contains(&format!("{FRAMES} frames")), "{msg}");
    assert!(peak < SMALL, "refusing took {peak} bytes");
    assert!(start.elapsed().as_secs() < 5, "refusing did the work first");
}

/// A real tdct stream whose header claims `frames` frames: its band index lists that many empty
/// bands (zero bytes: each decodes as an empty band at the coder's floor, so the index is valid), and
/// its affine part is zero bytes too, as few as the affine count check lets pass. About 15 KB with
/// valid checksums; only the affine part's end word, after 12 levels a frame, is wrong.
fn forged_tdct_frames(frames: u32) -> Vec<u8> {
    let mut forged = parts(&tiny_stream(Codec::Tdct));
    // Bytes that hold `n` symbols by `max_symbols`, and a margin for the models to reach the floor.
    let holding = |n: u64| {
        let per_byte = max_symbols(1) - max_symbols(0);
        (n.div_ceil(per_byte) as usize + 64).next_multiple_of(4)
    };
    let (index_len, affine_len) = (holding(u64::from(frames)), holding(12 * u64::from(frames)));
    for (tag, payload, _) in forged.iter_mut() {
        if *tag == Tag::HEADER {
            let mut header = Header::from_bytes(payload).expect("a valid header");
            header.frames = frames;
            *payload = header.to_bytes();
        } else if *tag == Tag::TDCT_INDEX {
            // The step, the band count, then the coded lengths.
            payload.truncate(4);
            payload.extend(frames.to_le_bytes());
            payload.extend(vec![0u8; index_len]);
        } else if *tag == Tag::TDCT {
            payload.clear();
        } else if *tag == Tag::AFFINE {
            payload.truncate(4);
            payload.extend(vec![0u8; affine_len]);
        }
    }
    rebuild(forged)
}

#[test]
fn a_forged_15_kb_tdct_stream_claiming_millions_of_frames_is_refused_in_little_memory() {
    const FRAMES: u32 = 6_000_000;
    let bytes = forged_tdct_frames(FRAMES);
    assert!(
        (12_000..16_000).contains(&bytes.len()),
        "{} bytes",
        bytes.len()
    );
    let (result, peak) = peak_of(|| Decoder::new(&bytes).map(|_| ()));
    let msg = match result {
        Ok(_) => panic!("a forged frame count was accepted"),
        Err(e) => e.to_string(),
    };
    eprintln!(
        "forged tdct stream of {} bytes: peak {peak} bytes: {msg}",
        bytes.len()
    );
    assert!(msg.contains(&format!("{FRAMES} frames")), "{msg}");
    assert!(peak < 64 << 20, "refusing took {peak} bytes: {msg}");
}

#[test]
fn a_first_frame_claiming_the_vertices_its_padding_could_hold_is_refused_in_little_memory() {
    // 15 KB of zero bytes after the geometry pass the count check for 28M vertices: the decoder
    // used to make room for all of them (786 MB) before decoding the first padded one.
    let pad = 15_000;
    let claim = |b: &[u8]| (max_symbols(word(b, GEOMETRY_LEN) as usize) / 3) as u32;
    let c = claim(&forged_first_frame(true, GEOMETRY_LEN, pad, |_| {}));
    // The connectivity stream padded as well, for its one decision per vertex.
    let mut bytes = forged_first_frame(true, GEOMETRY_LEN, pad, |b| {
        set_word(b, VERTEX_COUNT, c);
        set_word(b, WELDED, c);
    });
    let end = FIRST_FRAME_HEADER_LEN + word(&bytes, CONNECTIVITY_LEN) as usize;
    bytes.splice(end..end, vec![0u8; 2 * pad]);
    let grown = word(&bytes, CONNECTIVITY_LEN) + 2 * pad as u32;
    set_word(&mut bytes, CONNECTIVITY_LEN, grown);
    let mut hasher = crc32fast::Hasher::new();
    hasher.update(&bytes[..FIRST_FRAME_HEADER_LEN - 4]);
    hasher.update(&bytes[FIRST_FRAME_HEADER_LEN..]);
    set_word(&mut bytes, FIRST_FRAME_HEADER_LEN - 4, hasher.finalize());
    let (result, peak) = peak_of(|| first_frame::decode(&bytes).map(|_| ()));
    let msg = result
        .expect_err("zero bytes are not 28M positions")
        .to_string();
    assert!(c > 25_000_000, "a claim worth refusing: {c}");
    assert!(msg.contains("first frame geometry"), "{msg}");
    assert!(peak < SMALL, "refusing took {peak} bytes: {msg}");
}

/// Opens `bytes` with a positions limit.
fn open_limited(bytes: &[u8], max_positions: u64) -> mcgv_video::Result<()> {
    let options = DecodeOptions {
        max_positions,
        ..DecodeOptions::default()
    };
    let reader = ContainerReader::new(Cursor::new(bytes))?;
    Decoder::from_container(reader, &options).map(|_| ())
}

#[test]
fn the_positions_limit_refuses_a_stream_past_it_and_opens_one_at_it() {
    let bytes = tiny_stream(Codec::Jpeg); // 4 vertices × 2 frames
    open_limited(&bytes, 8).expect("8 positions are within a limit of 8");
    let err = open_limited(&bytes, 7).expect_err("8 positions are past 7");
    let msg = err.to_string();
    assert!(
        matches!(
            err,
            Error::InvalidOption {
                option: "max_positions",
                ..
            }
        ),
        "{msg}"
    );
    assert!(
        msg.contains("is 7") && msg.contains("4 vertices × 2 frames = 8 positions"),
        "{msg}"
    );

    // The default limit, against a header that claims 2^28 frames: refused before any other part.
    let mut forged = parts(&bytes);
    for (tag, payload, _) in forged.iter_mut() {
        if *tag == Tag::HEADER {
            let mut header = Header::from_bytes(payload).expect("a valid header");
            header.frames = 1 << 28;
            *payload = header.to_bytes();
        }
    }
    let forged = rebuild(forged);
    let (result, peak) = peak_of(|| open_limited(&forged, DEFAULT_MAX_POSITIONS));
    let msg = result.expect_err("past the default").to_string();
    assert!(
        msg.contains(&format!("4 vertices × {} frames", 1 << 28)),
        "{msg}"
    );
    assert!(peak < SMALL, "refusing took {peak} bytes");
}

#[test]
fn a_valid_long_unsegmented_stream_opens_in_memory_of_what_it_produces() {
    // Four still vertices over 20 000 frames in one segment: a few hundred bytes of stream that
    // the decoder must open holding the affine levels of every frame. Its memory follows the
    // frames, at about the size of the positions it decodes (4 × 12 bytes a frame); the maps
    // were stored beside the levels until 2026-11-30: 239 bytes a frame then, 143 now.
    const FRAMES: usize = 20_000;
    let base = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let triangles = vec![[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]];
    let mesh = AnimatedMesh::new(triangles, vec![base.to_vec(); FRAMES]).expect("an animation");
    let opts = EncodeOptions {
        codec: Codec::Tdct.into(),
        segment_frames: None,
        ..EncodeOptions::default()
    };
    let bytes = encode_bytes(&mesh, &opts);
    let (result, peak) = peak_of(|| {
        let mut decoder = Decoder::new(&bytes)?;
        decoder.decode_frame(FRAMES / 2).map(|frame| frame.len())
    });
    eprintln!(
        "{FRAMES} frames in {} bytes: peak {peak} bytes, {} a frame",
        bytes.len(),
        peak / FRAMES
    );
    assert_eq!(result.expect("decodes"), 4);
    assert!(peak < 160 * FRAMES, "peak {peak} bytes");
}
