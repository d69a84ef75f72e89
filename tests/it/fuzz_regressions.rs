//! Hostile streams and meshes: every input the fuzzers once crashed on (tests/data/fuzz/TARGET/),
//! replayed through the fuzz targets' own code, and forged headers that claim absurd sizes.

use crate::common::{harness, parts, rebuild, tiny_stream};

use mcgv_video::codec::Codec;
use mcgv_video::stream::container::{ContainerReader, Tag, FILE_HEADER_LEN, PART_HEADER_LEN};
use mcgv_video::Decoder;
use mcgv_video::Error;
use std::io::Cursor;
use std::path::PathBuf;

fn crashers(target: &str) -> Vec<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/fuzz")
        .join(target);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    files.sort();
    files
}

/// A panic fails the test; an error is the right answer to these inputs.
#[test]
fn stream_crashers_are_errors_now() {
    for path in crashers("decode_stream") {
        let bytes = std::fs::read(&path).unwrap();
        if let Err(e) = harness::decode_stream(&bytes) {
            assert!(!e.to_string().is_empty(), "{}", path.display());
        }
    }
}

#[test]
fn mesh_crashers_are_errors_now() {
    for path in crashers("read_mesh") {
        let bytes = std::fs::read(&path).unwrap();
        // Each of these is malformed: it must be refused with a message, not read.
        match harness::read_mesh(&bytes) {
            Err(e) => assert!(!e.to_string().is_empty(), "{}", path.display()),
            Ok(()) => panic!("{} was accepted", path.display()),
        }
    }
}

#[test]
fn mesh_crashers_that_are_valid_meshes_now_read() {
    let found = crashers("read_mesh_valid");
    assert!(!found.is_empty());
    for path in found {
        let bytes = std::fs::read(&path).unwrap();
        // Well-formed but extreme (e.g. one edge shared by 256+ triangles, which overflowed a use
        // count in the first-frame coder): read, coded, and the connectivity comes back.
        if let Err(e) = harness::read_mesh(&bytes) {
            panic!("{}: {e}", path.display());
        }
    }
}

/// Offset of the header part's payload: the header is the first part.
const HEAD: usize = FILE_HEADER_LEN + PART_HEADER_LEN;

/// The stream with one header field (`u32` at `offset` in the header payload) replaced, every
/// checksum made right again so that only the size checks can refuse it.
fn forged(codec: Codec, offset: usize, value: u32) -> Vec<u8> {
    let mut bytes = tiny_stream(codec);
    assert_eq!(&bytes[FILE_HEADER_LEN..FILE_HEADER_LEN + 4], b"HEAD");
    bytes[HEAD + offset..HEAD + offset + 4].copy_from_slice(&value.to_le_bytes());
    harness::fix_checksums(&mut bytes);
    bytes
}

fn open(bytes: Vec<u8>) -> mcgv_video::Result<Decoder<Cursor<Vec<u8>>>> {
    crate::common::decoder(bytes)
}

fn stream_error(bytes: Vec<u8>) -> String {
    match open(bytes) {
        Err(Error::Stream(m)) => m,
        Err(other) => panic!("not a stream error: {other}"),
        Ok(_) => panic!("a forged header was accepted"),
    }
}

#[test]
fn the_forgery_helper_keeps_an_honest_stream_valid() {
    for codec in [Codec::Jpeg, Codec::Mpeg4, Codec::Hevc, Codec::Av1] {
        let mut bytes = tiny_stream(codec);
        harness::fix_checksums(&mut bytes);
        assert_eq!(
            bytes,
            tiny_stream(codec),
            "fixing right checksums changes nothing"
        );
        assert!(harness::decode_stream(&bytes).is_ok());
    }
}

#[test]
fn band_checksums_are_repaired_so_damage_reaches_the_band_decoder() {
    // The tiny square's bands are all empty (the affine predictor is exact): a real animation.
    let opts = mcgv_video::encoder::EncodeOptions {
        codec: Codec::Tdct.into(),
        quality: 10,
        ..Default::default()
    };
    let honest = crate::common::encode_bytes(&crate::common::read_media("RiggedSimple.glb"), &opts);
    let mut bytes = honest.clone();
    harness::fix_band_index(&mut bytes);
    harness::fix_checksums(&mut bytes);
    assert_eq!(bytes, honest, "fixing right checksums changes nothing");
    assert!(harness::decode_stream(&bytes).is_ok());
    // Damage the first band: unrepaired, its CRC ends decoding before it; repaired, the band
    // decoder gets it.
    let reader = ContainerReader::new(Cursor::new(honest.clone())).unwrap();
    let tdct = reader.entry(Tag::TDCT).unwrap();
    assert!(tdct.len > 0);
    let mut damaged = honest;
    damaged[tdct.offset as usize] ^= 0x5a;
    let stopped = open(damaged.clone()).expect("a damaged band ends decoding");
    let decoded = stopped.describe().and_then(|d| d.bands).map(|b| b.decoded);
    assert_eq!(decoded, Some(0));
    harness::fix_band_index(&mut damaged);
    harness::fix_checksums(&mut damaged);
    if let Err(e) = open(damaged) {
        assert!(!e.to_string().contains("checksum"), "{e}");
    }
}

#[test]
fn a_step_that_overflows_the_coefficients_is_refused() {
    // The affine predictor leaves levels beyond ±1 (skinning predicts this figure so well that
    // its bands hold ±1 at most, which 3e38 keeps finite).
    let opts = mcgv_video::encoder::EncodeOptions {
        codec: Codec::Tdct.into(),
        quality: 10,
        predictor: mcgv_video::encoder::PredictorChoice::Fixed(
            mcgv_video::motion::PredictorKind::Affine,
        ),
        ..Default::default()
    };
    let honest = crate::common::encode_bytes(&crate::common::read_media("RiggedSimple.glb"), &opts);
    let index = ContainerReader::new(Cursor::new(honest.clone()))
        .unwrap()
        .entry(Tag::TDCT_INDEX)
        .unwrap()
        .offset as usize;
    // The step is the index's first field: 3e38 times any level beyond ±1 is beyond f32, which
    // the full decode refused only when building the mesh, while a frame read alone came back as
    // infinities. Now the bands are refused as they are read.
    let mut bytes = honest;
    bytes[index..index + 4].copy_from_slice(&3e38f32.to_le_bytes());
    harness::fix_checksums(&mut bytes);
    match open(bytes) {
        Err(e) => assert!(e.to_string().contains("not a finite number"), "{e}"),
        Ok(_) => panic!("a step of 3e38 was accepted"),
    }
}

#[test]
fn a_billion_vertices_or_frames_is_refused_before_allocating() {
    for codec in [Codec::Jpeg, Codec::Mpeg4, Codec::Hevc, Codec::Av1] {
        // Header layout: vertices, frames, triangles, clusters (u32 each), then the lattice.
        for (offset, what) in [
            (0, "vertices"),
            (4, "frames"),
            (8, "triangles"),
            (12, "clusters"),
        ] {
            let msg = stream_error(forged(codec, offset, 1_000_000_000));
            assert!(
                msg.contains("1000000000") && msg.contains(what),
                "{what}: {msg}"
            );
        }
    }
}

#[test]
fn counts_under_the_header_limit_are_checked_against_the_bytes() {
    // 2^27 passes the header's own limit; the parts' real sizes must refuse it, quickly.
    let start = std::time::Instant::now();
    for codec in [Codec::Jpeg, Codec::Mpeg4, Codec::Hevc, Codec::Av1] {
        for offset in [4, 8] {
            let msg = stream_error(forged(codec, offset, 1 << 27));
            assert!(!msg.is_empty());
        }
        // More vertices than the first frame holds (and than the 16x16 lattice has pixels: the
        // set-up's own check, `codec::pictures::setup`'s tests).
        let msg = stream_error(forged(codec, 0, 257));
        assert!(msg.contains("257"), "{msg}");
    }
    assert!(
        start.elapsed().as_secs() < 30,
        "refusals must not do the work first"
    );
}

#[test]
fn a_huge_lattice_is_refused() {
    let mut all = parts(&tiny_stream(Codec::Jpeg));
    // Lattice width and height are u16 after the version byte of the picture set-up.
    let setup = all.iter_mut().find(|p| p.0 == Tag::CODEC_SETUP).unwrap();
    setup.1[1..5].copy_from_slice(&[0xF0, 0xFF, 0xF0, 0xFF]);
    let msg = stream_error(rebuild(all));
    assert!(msg.contains("65520x65520"), "{msg}");
}

#[test]
fn a_glb_claiming_4_gb_is_refused_without_allocating_it() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/fuzz/glb-claims-4gb.glb");
    assert_eq!(std::fs::metadata(&path).unwrap().len(), 12);
    let err = mcgv_video::mesh::read_animation(path.to_str().unwrap(), &Default::default())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("GLB header gives a length of 4294967280 bytes"),
        "{err}"
    );
}
