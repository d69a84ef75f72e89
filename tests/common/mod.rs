//! Helpers shared by the integration tests (the library's in `tests/it`, the command line's in
//! `cli/tests/cli`, which adds running the binary): the media samples, encoding and decoding in
//! memory, forging streams, and synthetic meshes.
//!
//! Each test binary uses only part of it, so unused items are not warnings here.
#![allow(dead_code)]

use mcgv_video::codec::{Codec, CodecConfig};
use mcgv_video::encoder::{encode, EncodeOptions};
use mcgv_video::mesh::{read_animation, AnimatedMesh, Point, ReadOptions, Triangle};
use mcgv_video::stream::container::{Checksum, ContainerReader, ContainerWriter, Tag};
use mcgv_video::{DecodeOptions, Decoder};
use mcgv_video::{Lattice, PaddingMethod};
use std::io::Cursor;
use std::path::{Path, PathBuf};

/// The fuzz targets' bodies, for replaying their inputs; they compare connectivity the way the
/// tests do, so `canonical` has one definition for both.
#[path = "../../fuzz/src/harness.rs"]
pub mod harness;
// Like the items above, unused in the test files that compare no connectivity.
#[allow(unused_imports)]
pub use harness::canonical;

/// The path of a sample in `media/`.
pub fn media_path(name: &str) -> String {
    repo_root().join("media").join(name).display().to_string()
}

/// The repository's top folder (this file is compiled into test binaries of the root crate and of
/// `cli/`).
pub fn repo_root() -> PathBuf {
    let here = Path::new(env!("CARGO_MANIFEST_DIR"));
    match here.join("media").is_dir() {
        true => here.to_path_buf(),
        false => here.parent().unwrap_or(here).to_path_buf(),
    }
}

/// A sample in `media/`, read with the default options.
pub fn read_media(name: &str) -> AnimatedMesh {
    read_animation(&media_path(name), &ReadOptions::default()).expect("media sample reads")
}

/// Encodes in memory to the bytes of a `.mcgv` file.
pub fn encode_bytes(mesh: &AnimatedMesh, opts: &EncodeOptions) -> Vec<u8> {
    encode(mesh, opts).expect("encodes").to_bytes()
}

/// A decoder over in-memory stream bytes; damaged bytes are its error, not a panic.
pub fn decoder(bytes: Vec<u8>) -> mcgv_video::Result<Decoder<Cursor<Vec<u8>>>> {
    Decoder::from_container(
        ContainerReader::new(Cursor::new(bytes))?,
        &DecodeOptions::default(),
    )
}

/// Decodes every frame of in-memory stream bytes.
pub fn decode_all(bytes: Vec<u8>) -> mcgv_video::Result<AnimatedMesh> {
    decoder(bytes)?.decode_all()
}

/// `codec`'s default options with, where the codec has them, this lattice, padding and GOP.
pub fn config(
    codec: Codec,
    lattice: Option<Lattice>,
    padding: Option<PaddingMethod>,
    gop: Option<usize>,
) -> CodecConfig {
    let mut config = CodecConfig::from(codec);
    if let Some(pictures) = config.pictures_mut() {
        pictures.lattice = lattice.unwrap_or(pictures.lattice);
        pictures.padding = padding.or(pictures.padding);
    }
    if let (Some(g), Some(gop)) = (config.gop_mut(), gop) {
        *g = gop;
    }
    config
}

/// A real two-frame stream of a square (two triangles, one cluster), small enough to forge quickly
/// (a 16 × 16 lattice for the image codecs).
pub fn tiny_stream(codec: Codec) -> Vec<u8> {
    let square = |t: f32| {
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, t],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, -t],
        ]
    };
    let mesh = AnimatedMesh::new(vec![[0, 1, 2], [0, 2, 3]], vec![square(0.0), square(0.1)])
        .expect("a valid animation");
    // Only the image codecs have a lattice to pad.
    let config = config(
        codec,
        Some(Lattice::Fixed(16, 16)),
        Some(PaddingMethod::Cg),
        None,
    );
    let opts = EncodeOptions {
        codec: config,
        clusters: 1,
        ..EncodeOptions::default()
    };
    encode(&mesh, &opts).expect("encodes").to_bytes()
}

/// The parts of a stream as (tag, payload, checksum kind), to rebuild it altered.
pub fn parts(bytes: &[u8]) -> Vec<(Tag, Vec<u8>, Checksum)> {
    let reader = ContainerReader::new(Cursor::new(bytes.to_vec())).expect("a valid container");
    reader
        .parts()
        .iter()
        .map(|p| {
            let (o, l) = (p.offset as usize, p.len as usize);
            (p.tag, bytes[o..o + l].to_vec(), p.checksum)
        })
        .collect()
}

/// A stream of `parts`, with checksums made for their payloads.
pub fn rebuild(parts: Vec<(Tag, Vec<u8>, Checksum)>) -> Vec<u8> {
    let mut w = ContainerWriter::new();
    for (tag, payload, checksum) in parts {
        w.add(tag, payload, checksum).expect("a part under 4 GiB");
    }
    w.to_bytes()
}

/// A closed-around tube along x from `x0` to `x1`, `rings` rings of `ring_size` vertices, appended
/// to `points` and `tris`.
pub fn tube(
    points: &mut Vec<Point>,
    tris: &mut Vec<Triangle>,
    x0: f32,
    x1: f32,
    rings: usize,
    ring_size: usize,
) {
    let base = points.len() as u32;
    for r in 0..rings {
        let x = x0 + (x1 - x0) * r as f32 / (rings - 1) as f32;
        for s in 0..ring_size {
            let a = std::f32::consts::TAU * s as f32 / ring_size as f32;
            // A slight bulge keeps the surface from being a ruled one.
            let radius = 1.0 + 0.2 * (x * 1.3).sin();
            points.push([x, radius * a.cos(), radius * a.sin()]);
        }
    }
    let n = ring_size as u32;
    for r in 0..rings as u32 - 1 {
        for s in 0..n {
            let (a, b) = (base + r * n + s, base + r * n + (s + 1) % n);
            let (c, d) = (a + n, b + n);
            tris.push([a, b, d]);
            tris.push([a, d, c]);
        }
    }
}

/// An animation of `frames` frames over `tris`: vertex `i` of a frame at time `t` ∈ [0, 1] (frame 0
/// at 0, the last at 1) is `motion(t, i, p)`, `p` being its place in `points`.
pub fn animate(
    points: &[Point],
    tris: Vec<Triangle>,
    frames: usize,
    motion: impl Fn(f32, usize, Point) -> Point,
) -> AnimatedMesh {
    let frames = (0..frames)
        .map(|f| {
            let t = f as f32 / (frames - 1) as f32;
            points
                .iter()
                .enumerate()
                .map(|(i, &p)| motion(t, i, p))
                .collect()
        })
        .collect();
    AnimatedMesh::new(tris, frames).expect("valid animation")
}

/// Fraction of vertex pairs on which two labelings agree (same/different): the Rand index.
pub fn rand_index(a: &[u32], b: &[usize]) -> f64 {
    let (mut agree, mut total) = (0u64, 0u64);
    for i in 0..a.len() {
        for j in i + 1..a.len() {
            agree += u64::from((a[i] == a[j]) == (b[i] == b[j]));
            total += 1;
        }
    }
    agree as f64 / total as f64
}

/// Standard base64 with padding, for `data:` URIs in hand-written glTF fixtures.
pub fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Counts the frames an encoding announces (its latest total) and reports done.
#[derive(Default)]
pub struct Counter {
    pub total: std::sync::atomic::AtomicU64,
    pub done: std::sync::atomic::AtomicU64,
}

impl mcgv_video::Progress for Counter {
    fn total(&self, frames: u64) {
        self.total
            .store(frames, std::sync::atomic::Ordering::Relaxed);
    }

    fn frames(&self, count: u64) {
        self.done
            .fetch_add(count, std::sync::atomic::Ordering::Relaxed);
    }
}

/// RMS vertex displacement over the first frame's bounding-box diagonal (cheap, and
/// independent of the library's metrics: tests compare many decodings with it).
pub fn vertex_rmse(a: &AnimatedMesh, b: &AnimatedMesh) -> f64 {
    let mut sum = 0.0f64;
    let mut n = 0usize;
    for f in 0..a.frame_count() {
        for (p, q) in a.frame(f).iter().zip(b.frame(f)) {
            sum += (0..3).map(|i| f64::from(p[i] - q[i]).powi(2)).sum::<f64>();
            n += 1;
        }
    }
    (sum / n as f64).sqrt() / a.bbox_diagonal()
}
