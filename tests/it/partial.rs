//! Decoding a stream still arriving (`DecodeOptions::partial`) and pictures decoded outside the
//! library (`Decoder::coded_picture`, `Decoder::decode_frame_from_picture`): what the WebAssembly
//! decoder (web/) streams and hands to WebCodecs, checked here against the whole stream's decode.

use crate::common::{animate, config, encode_bytes, tube};
use mcgv_video::codec::{Codec, Plane};
use mcgv_video::encoder::EncodeOptions;
use mcgv_video::stream::container::{ContainerReader, Tag};
use mcgv_video::{DecodeOptions, Decoder, Lattice};
use std::io::Cursor;

/// A bending tube, 12 frames, coded by `codec` on a 32 × 32 lattice where it has one.
fn stream(codec: Codec) -> Vec<u8> {
    let (mut points, mut tris) = (Vec::new(), Vec::new());
    tube(&mut points, &mut tris, -2.0, 2.0, 12, 10);
    let mesh = animate(&points, tris, 12, |t, _, p| {
        let bend = 0.3 * t * p[0] * p[0];
        [p[0], p[1] + bend, p[2] + 0.1 * t * p[0]]
    });
    let opts = EncodeOptions {
        codec: config(codec, Some(Lattice::Fixed(32, 32)), None, None),
        clusters: 3,
        ..EncodeOptions::default()
    };
    encode_bytes(&mesh, &opts)
}

fn open(bytes: &[u8], partial: bool) -> mcgv_video::Result<Decoder<Cursor<&[u8]>>> {
    let options = DecodeOptions {
        partial,
        ..DecodeOptions::default()
    };
    Decoder::from_reader(Cursor::new(bytes), &options)
}

#[test]
fn a_jpeg_stream_still_arriving_decodes_the_frames_whose_chunks_have_arrived() {
    let bytes = stream(Codec::Jpeg);
    let mut whole = open(&bytes, false).unwrap();
    let frames: Vec<_> = (0..12).map(|f| whole.decode_frame(f).unwrap()).collect();
    let reader = ContainerReader::new(Cursor::new(&bytes[..])).unwrap();
    let images = reader.entry(Tag::FRAMES).unwrap();
    let index = (0..12)
        .map(|f| whole.frame_entry(f).unwrap())
        .collect::<Vec<_>>();
    // Every cut inside the images part: the frames whose chunk is whole decode as in the whole
    // stream, the others are errors; without `partial` the cut stream does not open.
    let mut decoded_some_not_all = false;
    for cut in (images.offset..=images.offset + images.len).step_by(97) {
        let prefix = &bytes[..cut as usize];
        if cut < images.offset + images.len {
            assert!(open(prefix, false).is_err(), "cut at {cut} opened whole");
        }
        let mut d = open(prefix, true).unwrap_or_else(|e| panic!("cut at {cut}: {e}"));
        let mut arrived = 0;
        for (f, e) in index.iter().enumerate() {
            let complete = images.offset + e.offset + e.len <= cut;
            match d.decode_frame(f) {
                Ok(frame) => {
                    assert!(complete, "frame {f} decoded from a cut chunk at {cut}");
                    assert_eq!(frame, frames[f], "frame {f}, cut at {cut}");
                    arrived += 1;
                }
                Err(e) => {
                    assert!(!complete, "frame {f} at {cut}: {e}");
                    assert!(e.to_string().contains("past the end"), "{e}");
                }
            }
        }
        decoded_some_not_all |= arrived > 0 && arrived < 12;
    }
    assert!(decoded_some_not_all);
}

#[test]
fn partial_streams_cut_before_their_last_part_are_errors() {
    let bytes = stream(Codec::Jpeg);
    let reader = ContainerReader::new(Cursor::new(&bytes[..])).unwrap();
    for tag in [Tag::FIRST_FRAME, Tag::AFFINE, Tag::FRAME_INDEX] {
        let e = reader.entry(tag).unwrap();
        let cut = (e.offset + e.len / 2) as usize;
        assert!(open(&bytes[..cut], true).is_err(), "cut inside {tag}");
    }
    // A temporal-DCT stream is progressive with or without `partial`: the same frames.
    let tdct = stream(Codec::Tdct);
    let cut = &tdct[..tdct.len() - 40];
    let a = open(cut, true).unwrap().decode_all().unwrap();
    let b = open(cut, false).unwrap().decode_all().unwrap();
    assert_eq!(a, b);
}

#[test]
fn a_picture_decoded_outside_gives_the_frame_the_decoder_gives() {
    let bytes = stream(Codec::Jpeg);
    let mut d = open(&bytes, false).unwrap();
    for f in [0, 5, 11] {
        let plane = d.decoded_plane(f).unwrap();
        let (chunk, key) = d.coded_picture(f).unwrap();
        assert!(key && !chunk.is_empty());
        let outside = d.decode_frame_from_picture(f, &plane).unwrap();
        assert_eq!(outside, d.decode_frame(f).unwrap(), "frame {f}");
        // Another picture gives another frame: the picture is used.
        let black = Plane::new(plane.width, plane.height, vec![0; plane.data.len()]).unwrap();
        let other = d.decode_frame_from_picture(f, &black).unwrap();
        assert!(
            other != outside,
            "frame {f}: a black picture changed nothing"
        );
    }
    let plane = d.decoded_plane(3).unwrap();
    let small = Plane::new(
        plane.width - 3,
        plane.height,
        vec![0; plane.data.len() - 3 * 32],
    );
    assert!(d.decode_frame_from_picture(3, &small.unwrap()).is_err());
    let deep = Plane::new(plane.width, plane.height, vec![300; plane.data.len()]).unwrap();
    assert!(
        d.decode_frame_from_picture(3, &deep).is_err(),
        "9-bit samples at 8 bits"
    );
    assert!(d.decode_frame_from_picture(12, &plane).is_err());
    let tdct = stream(Codec::Tdct);
    let mut t = open(&tdct, false).unwrap();
    assert!(t.coded_picture(0).is_err());
    assert!(t.decode_frame_from_picture(0, &plane).is_err());
}

#[test]
fn the_first_frame_draws_from_the_first_parts_alone() {
    let bytes = stream(Codec::Tdct);
    let whole = open(&bytes, false).unwrap();
    let reader = ContainerReader::new(Cursor::new(&bytes[..])).unwrap();
    let mesh = reader.entry(Tag::FIRST_FRAME).unwrap();
    let partition = reader.entry(Tag::PARTITION).unwrap();
    let first = |cut: u64| {
        let source = Cursor::new(&bytes[..cut as usize]);
        Decoder::first_frame(source, &DecodeOptions::default())
    };
    assert!(
        first(mesh.offset + mesh.len - 1).is_err(),
        "a cut first frame"
    );
    for cut in [mesh.offset + mesh.len, partition.offset - 5] {
        let f = first(cut).unwrap();
        assert_eq!(f.positions, whole.reference());
        assert_eq!(f.triangles, whole.triangles());
        assert_eq!(f.header, *whole.header());
        assert_eq!(
            f.attributes, None,
            "cut at {cut}: the attributes may still come"
        );
    }
    // Once a later part has arrived, a stream without attributes is known to have none.
    let f = first(partition.offset + partition.len).unwrap();
    assert_eq!(f.attributes, Some(Default::default()));
    assert_eq!(
        first(bytes.len() as u64).unwrap().positions,
        whole.reference()
    );
}
