//! Round trips through the residual-image codecs: error bounds, rate control, random access, and
//! robustness against damaged input.

use mcgv_video::codec::pictures::mpeg4::mpeg4_law;
use mcgv_video::codec::pictures::mpeg4::{self, Mpeg4Options, Packet};
use mcgv_video::codec::pictures::{abbreviated, jpeg, Plane};
use mcgv_video::Result;
use std::f64::consts::TAU;
use std::process::Command;
use std::time::Instant;

/// A smooth pattern drifting a few pixels per frame, like a residual image of a moving surface:
/// two travelling waves of 30–100 pixel wavelength around mid-grey. `phase` decorrelates planes.
fn smooth_frame(width: u32, height: u32, t: u32, phase: f64) -> Plane {
    let t = f64::from(t);
    let mut data = Vec::with_capacity((width * height) as usize);
    for y in 0..height {
        for x in 0..width {
            let (x, y) = (f64::from(x), f64::from(y));
            let v = 128.0
                + 60.0
                    * (TAU * (x + 3.0 * t) / 64.0 + phase).sin()
                    * (TAU * (y - 2.0 * t) / 48.0).cos()
                + 30.0 * (TAU * (x + y + 5.0 * t) / 97.0 + 2.0 * phase).sin();
            data.push(v.round().clamp(0.0, 255.0) as u8);
        }
    }
    Plane {
        width,
        height,
        data,
    }
}

fn sequence(width: u32, height: u32, frames: u32) -> Vec<Plane> {
    (0..frames)
        .map(|t| smooth_frame(width, height, t, 0.0))
        .collect()
}

fn encode_all(planes: &[Plane], options: &Mpeg4Options) -> Result<Vec<Packet>> {
    let first = planes.first().expect("test sequences are not empty");
    let mut encoder = mpeg4::Encoder::new(first.width, first.height, options)?;
    let mut packets = Vec::new();
    for plane in planes {
        packets.extend(encoder.encode(plane)?);
    }
    packets.extend(encoder.finish()?);
    Ok(packets)
}

fn decode_all(packets: &[Packet], width: u32, height: u32) -> Result<Vec<Plane>> {
    let mut decoder = mpeg4::Decoder::new(width, height)?;
    let mut planes = Vec::new();
    for packet in packets {
        planes.extend(decoder.decode(&packet.data)?);
    }
    planes.extend(decoder.flush()?);
    Ok(planes)
}

fn mean_psnr(a: &[Plane], b: &[Plane]) -> Result<f64> {
    assert_eq!(a.len(), b.len());
    let mut sum = 0.0;
    for (x, y) in a.iter().zip(b) {
        sum += x.psnr(y)?;
    }
    Ok(sum / a.len() as f64)
}

#[test]
fn jpeg_round_trip_error_is_bounded_and_falls_with_quality() -> Result<()> {
    let plane = smooth_frame(256, 256, 0, 0.0);
    let mut last_psnr = 0.0;
    let mut last_size = 0;
    for quality in [50, 75, 90] {
        let bytes = jpeg::encode(&plane, quality)?;
        let decoded = jpeg::decode(&bytes, 256, 256)?;
        let psnr = plane.psnr(&decoded)?;
        assert!(
            psnr > last_psnr,
            "quality {quality}: {psnr} dB not above {last_psnr}"
        );
        assert!(
            bytes.len() > last_size,
            "quality {quality}: size did not grow"
        );
        // IJG quality 50 quantises the lowest frequencies with step 16: on a smooth image the error
        // stays a few grey levels (measured ≈ 40 dB); 35 dB leaves room for encoder changes.
        assert!(psnr > 35.0, "quality {quality}: {psnr} dB");
        last_psnr = psnr;
        last_size = bytes.len();
    }
    assert!(last_psnr > 45.0, "quality 90: {last_psnr} dB");
    Ok(())
}

#[test]
fn jpeg_residual_pictures_quantise_every_frequency_alike() -> Result<()> {
    // A residual picture is not a photograph: its high frequencies move vertices as far as its low
    // ones, so the quantisation table is flat (16 scaled by the quality), not Annex K's.
    let bytes = jpeg::encode(&smooth_frame(64, 64, 0, 0.0), 50)?;
    let dqt = bytes
        .windows(2)
        .position(|w| w == [0xFF, 0xDB])
        .expect("a quantisation table segment");
    // Marker, 2-byte length, precision/table id, then 64 8-bit entries.
    let table = &bytes[dqt + 5..dqt + 5 + 64];
    assert!(table.iter().all(|&q| q == 16), "{table:?}");
    Ok(())
}

#[test]
fn jpeg_decode_is_deterministic_and_size_checked() -> Result<()> {
    let plane = smooth_frame(64, 48, 1, 0.5);
    let bytes = jpeg::encode(&plane, 75)?;
    assert_eq!(jpeg::decode(&bytes, 64, 48)?, jpeg::decode(&bytes, 64, 48)?);
    assert!(jpeg::decode(&bytes, 48, 64).is_err());
    assert!(jpeg::encode(&plane, 0).is_err());
    assert!(jpeg::encode(&plane, 101).is_err());
    let bad = Plane {
        width: 64,
        height: 48,
        data: vec![0; 10],
    };
    assert!(jpeg::encode(&bad, 75).is_err());
    Ok(())
}

#[test]
fn jpeg_garbage_and_truncation_are_errors() -> Result<()> {
    assert!(jpeg::decode(&[], 16, 16).is_err());
    assert!(jpeg::decode(b"definitely not a jpeg", 16, 16).is_err());
    let bytes = jpeg::encode(&smooth_frame(64, 64, 0, 0.0), 75)?;
    for cut in [2, 20, bytes.len() / 2, bytes.len() - 2] {
        let truncated = bytes.get(..cut).unwrap_or_default();
        assert!(
            jpeg::decode(truncated, 64, 64).is_err(),
            "cut at {cut} decoded"
        );
    }
    // Pseudo-random bytes behind a valid SOI marker.
    let mut state = 0x1234_5678_u32;
    let mut noise = vec![0xFF, 0xD8];
    noise.extend((0..500).map(|_| {
        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (state >> 24) as u8
    }));
    assert!(jpeg::decode(&noise, 64, 64).is_err());
    Ok(())
}

/// Our decoder against OpenImageIO's (libjpeg-turbo): JPEG decoders may differ by one grey level.
#[test]
fn jpeg_agrees_with_openimageio_within_one() -> Result<()> {
    // A missing tool fails the test: a reference check that silently skips checks nothing.
    assert!(
        Command::new("oiiotool").arg("--help").output().is_ok(),
        "oiiotool not on PATH: run `make test` (it installs openimageio-tools)"
    );
    let dir = tempfile::tempdir().map_err(|e| mcgv_video::Error::io("tempdir", e))?;
    let plane = smooth_frame(256, 256, 3, 1.0);
    for quality in [30, 75, 95] {
        let bytes = jpeg::encode(&plane, quality)?;
        let ours = jpeg::decode(&bytes, 256, 256)?;
        let jpg = dir.path().join(format!("q{quality}.jpg"));
        let png = dir.path().join(format!("q{quality}.png"));
        std::fs::write(&jpg, &bytes).map_err(|e| mcgv_video::Error::io(&jpg, e))?;
        let status = Command::new("oiiotool")
            .arg(&jpg)
            .arg("-o")
            .arg(&png)
            .status()
            .map_err(|e| mcgv_video::Error::io("oiiotool", e))?;
        assert!(status.success(), "oiiotool failed on {}", jpg.display());
        let theirs = image::open(&png)
            .map_err(|e| mcgv_video::Error::Codec(format!("{}: {e}", png.display())))?
            .to_luma8();
        assert_eq!(theirs.dimensions(), (256, 256));
        let theirs = Plane::new(256, 256, theirs.into_raw())?;
        let max = ours.max_abs_diff(&theirs)?;
        let differing = ours
            .data
            .iter()
            .zip(&theirs.data)
            .filter(|(a, b)| a != b)
            .count();
        println!(
            "quality {quality}: max |ours − oiio| = {max}, {differing} of 65536 samples differ"
        );
        assert!(max <= 1, "quality {quality}: decoders differ by {max}");
    }
    Ok(())
}

#[test]
fn mpeg4_fixed_quantiser_controls_the_rate() -> Result<()> {
    let planes = sequence(128, 128, 4);
    let size = |qscale| -> Result<usize> {
        let packets = encode_all(&planes, &Mpeg4Options { qscale, gop: 10 })?;
        Ok(packets.iter().map(|p| p.data.len()).sum())
    };
    let (fine, coarse) = (size(2)?, size(20)?);
    // Were the per-frame quality ignored, both would run at qmin and come out alike.
    assert!(
        fine > 3 * coarse,
        "qscale 2: {fine} bytes, qscale 20: {coarse} bytes"
    );
    Ok(())
}

#[test]
fn mpeg4_round_trip_quality_and_gop_structure() -> Result<()> {
    let planes = sequence(256, 256, 10);
    let mut psnr_by_q = Vec::new();
    for qscale in [2, 31] {
        let packets = encode_all(&planes, &Mpeg4Options { qscale, gop: 5 })?;
        assert_eq!(packets.len(), planes.len(), "one packet per frame");
        for (i, packet) in packets.iter().enumerate() {
            assert_eq!(packet.pts, i as i64, "packets in order");
            assert_eq!(
                packet.key,
                i % 5 == 0,
                "I-frame exactly at GOP starts ({i})"
            );
        }
        let decoded = decode_all(&packets, 256, 256)?;
        assert_eq!(decoded.len(), planes.len());
        psnr_by_q.push(mean_psnr(&planes, &decoded)?);
    }
    let (fine, coarse) = (psnr_by_q[0], psnr_by_q[1]);
    // qscale 2 is an H.263 step of 4: uniform quantisation noise ≤ 4²/12 ≈ 1.3 per coefficient,
    // ≈ 47 dB; the dead zone and P-frame drift cost a few dB, so 40 dB is a safe floor.
    assert!(fine > 40.0, "qscale 2: {fine} dB");
    // qscale 31 (step 62) must be clearly worse.
    assert!(coarse < fine - 6.0, "qscale 31: {coarse} dB vs {fine} dB");
    assert!(coarse > 20.0, "qscale 31: {coarse} dB");
    Ok(())
}

#[test]
fn mpeg4_decodes_from_any_i_frame() -> Result<()> {
    let planes = sequence(128, 96, 10);
    let packets = encode_all(&planes, &Mpeg4Options { qscale: 4, gop: 4 })?;
    let all = decode_all(&packets, 128, 96)?;
    // Second GOP's I-frame alone, on a fresh decoder.
    let second_gop = packets.get(4..).unwrap_or_default();
    assert!(second_gop.first().is_some_and(|p| p.key));
    let tail = decode_all(second_gop, 128, 96)?;
    assert_eq!(tail.as_slice(), all.get(4..).unwrap_or_default());
    // Same after a reset on a decoder that has seen other frames.
    let mut decoder = mpeg4::Decoder::new(128, 96)?;
    for packet in packets.get(..3).unwrap_or_default() {
        decoder.decode(&packet.data)?;
    }
    decoder.reset();
    let i_frame = packets
        .get(8)
        .map(|p| p.data.as_slice())
        .unwrap_or_default();
    assert_eq!(decoder.decode(i_frame)?.first(), all.get(8));
    // After a reset the references are gone: a P-frame must be refused, not guessed.
    decoder.reset();
    let p_frame = packets
        .get(9)
        .map(|p| p.data.as_slice())
        .unwrap_or_default();
    assert!(decoder.decode(p_frame).is_err());
    Ok(())
}

/// The encoder codes groups of pictures on separate threads, each with its own FFmpeg encoder that
/// starts at the group's first frame: its packets must be the bytes one encoder makes of the whole
/// sequence (time codes included), so threading changes no stream.
#[test]
fn mpeg4_groups_coded_alone_match_one_encoder() -> Result<()> {
    let planes = sequence(64, 48, 60);
    let options = Mpeg4Options { qscale: 3, gop: 7 };
    let whole = encode_all(&planes, &options)?;
    let mut alone = Vec::new();
    for (g, group) in planes.chunks(options.gop).enumerate() {
        let mut encoder = mpeg4::Encoder::starting_at(64, 48, &options, g * options.gop)?;
        for plane in group {
            alone.extend(encoder.encode(plane)?);
        }
        alone.extend(encoder.finish()?);
    }
    assert_eq!(alone.len(), whole.len());
    for (f, (a, w)) in alone.iter().zip(&whole).enumerate() {
        assert_eq!((a.key, &a.data), (w.key, &w.data), "frame {f}");
    }
    Ok(())
}

#[test]
fn mpeg4_sizes_not_multiple_of_16() -> Result<()> {
    // Macroblocks are 16×16, but FFmpeg pads internally: any even size works.
    for (w, h) in [(72, 40), (70, 38)] {
        let planes = sequence(w, h, 3);
        let packets = encode_all(&planes, &Mpeg4Options { qscale: 2, gop: 2 })?;
        let decoded = decode_all(&packets, w, h)?;
        assert_eq!(decoded.len(), 3);
        assert!(mean_psnr(&planes, &decoded)? > 40.0, "{w}×{h}");
    }
    assert!(mpeg4::Encoder::new(71, 40, &Mpeg4Options::default()).is_err());
    assert!(mpeg4::Encoder::new(72, 0, &Mpeg4Options::default()).is_err());
    assert!(mpeg4::Encoder::new(72, 40, &Mpeg4Options { qscale: 0, gop: 5 }).is_err());
    assert!(mpeg4::Encoder::new(72, 40, &Mpeg4Options { qscale: 32, gop: 5 }).is_err());
    assert!(mpeg4::Encoder::new(72, 40, &Mpeg4Options { qscale: 5, gop: 0 }).is_err());
    let mut encoder = mpeg4::Encoder::new(72, 40, &Mpeg4Options::default())?;
    assert!(encoder.encode(&smooth_frame(40, 72, 0, 0.0)).is_err());
    Ok(())
}

#[test]
fn mpeg4_garbage_is_an_error() -> Result<()> {
    let mut decoder = mpeg4::Decoder::new(64, 64)?;
    assert!(decoder.decode(&[]).is_err());
    let mut state = 0x9E37_79B9_u32;
    let noise: Vec<u8> = (0..400)
        .map(|_| {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (state >> 24) as u8
        })
        .collect();
    let out = decoder.decode(&noise);
    assert!(out.is_err(), "noise gave {out:?}");
    // A P-frame cannot start a stream: it has nothing to predict from.
    let packets = encode_all(&sequence(64, 64, 3), &Mpeg4Options::default())?;
    let p_frame = packets
        .get(1)
        .map(|p| p.data.as_slice())
        .unwrap_or_default();
    let out = mpeg4::Decoder::new(64, 64)?.decode(p_frame);
    assert!(out.is_err(), "a leading P-frame gave {out:?}");
    // Truncated I-frame.
    let i_frame = packets
        .first()
        .map(|p| p.data.as_slice())
        .unwrap_or_default();
    let out =
        mpeg4::Decoder::new(64, 64)?.decode(i_frame.get(..i_frame.len() / 2).unwrap_or_default());
    assert!(out.is_err(), "half an I-frame gave {out:?}");
    // A stream for a different size is refused rather than returned at the wrong size.
    let packets = encode_all(&sequence(64, 64, 1), &Mpeg4Options::default())?;
    let mut other = mpeg4::Decoder::new(32, 32)?;
    let first = packets
        .first()
        .map(|p| p.data.as_slice())
        .unwrap_or_default();
    assert!(other.decode(first).is_err());
    Ok(())
}

/// Figures for the report: `cargo test --release --test codec -- --ignored --nocapture`.
#[test]
#[ignore]
fn measure_rate_distortion_and_speed() -> Result<()> {
    const FRAMES: u32 = 60;
    let planes = sequence(256, 256, FRAMES);
    println!("256×256 smooth moving pattern, {FRAMES} frames");
    for quality in [50, 75, 90] {
        let start = Instant::now();
        let coded: Vec<Vec<u8>> = planes
            .iter()
            .map(|p| jpeg::encode(p, quality))
            .collect::<Result<_>>()?;
        let enc = start.elapsed().as_secs_f64();
        let start = Instant::now();
        let decoded: Vec<Plane> = coded
            .iter()
            .map(|b| jpeg::decode(b, 256, 256))
            .collect::<Result<_>>()?;
        let dec = start.elapsed().as_secs_f64();
        let bytes: usize = coded.iter().map(Vec::len).sum();
        let compact: usize = planes
            .iter()
            .map(|p| stored_len(&jpeg::encode(p, quality)?))
            .sum::<Result<_>>()?;
        println!(
            "jpeg  q{quality:<3}  abbreviated {:7.0} B/frame",
            compact as f64 / f64::from(FRAMES)
        );
        println!(
            "jpeg  q{quality:<3}  {:7.0} B/frame  PSNR {:5.2} dB  encode {:6.0} f/s  decode {:6.0} f/s",
            bytes as f64 / f64::from(FRAMES),
            mean_psnr(&planes, &decoded)?,
            f64::from(FRAMES) / enc,
            f64::from(FRAMES) / dec
        );
    }
    for qscale in [2, 8, 20] {
        let options = Mpeg4Options { qscale, gop: 30 };
        let start = Instant::now();
        let packets = encode_all(&planes, &options)?;
        let enc = start.elapsed().as_secs_f64();
        let start = Instant::now();
        let decoded = decode_all(&packets, 256, 256)?;
        let dec = start.elapsed().as_secs_f64();
        let bytes: usize = packets.iter().map(|p| p.data.len()).sum();
        let i_bytes: usize = packets.iter().filter(|p| p.key).map(|p| p.data.len()).sum();
        println!(
            "mpeg4 qs{qscale:<2}  {:7.0} B/frame  PSNR {:5.2} dB  encode {:6.0} f/s  decode {:6.0} f/s  (I-frames {} B avg)",
            bytes as f64 / f64::from(FRAMES),
            mean_psnr(&planes, &decoded)?,
            f64::from(FRAMES) / enc,
            f64::from(FRAMES) / dec,
            i_bytes / packets.iter().filter(|p| p.key).count().max(1)
        );
    }
    println!(
        "quality → qscale: 50→{} 75→{} 90→{}",
        mpeg4_law(50).quantiser,
        mpeg4_law(75).quantiser,
        mpeg4_law(90).quantiser
    );
    let sample = jpeg::encode(&planes[0], 75)?;
    println!(
        "jpeg header (SOI … end of SOS header) {} of {} bytes",
        jpeg_header_len(&sample),
        sample.len()
    );
    // The same picture with the standard (Annex K) Huffman tables, identical in every file.
    let mut standard = Vec::new();
    jpeg_encoder::Encoder::new(&mut standard, 75)
        .encode(&planes[0].data, 256, 256, jpeg_encoder::ColorType::Luma)
        .map_err(|e| mcgv_video::Error::Codec(e.to_string()))?;
    println!(
        "jpeg q75 standard Huffman tables: header {} of {} bytes",
        jpeg_header_len(&standard),
        standard.len()
    );
    let still = vec![planes[0].clone(); 4];
    let still_packets = encode_all(&still, &Mpeg4Options { qscale: 8, gop: 30 })?;
    println!(
        "mpeg4 packet sizes for an unchanging picture (I then P): {:?}",
        still_packets
            .iter()
            .map(|p| p.data.len())
            .collect::<Vec<_>>()
    );
    let short = sequence(256, 256, 10);
    for quality in (10..=100).step_by(10) {
        let mut psnr = 0.0;
        let mut bytes = 0;
        for p in &short {
            let coded = jpeg::encode(p, quality)?;
            bytes += coded.len();
            psnr += p.psnr(&jpeg::decode(&coded, 256, 256)?)?;
        }
        println!(
            "sweep jpeg  q{quality:<3}  {:6} B/frame  PSNR {:5.2}",
            bytes / short.len(),
            psnr / short.len() as f64
        );
    }
    for qscale in [1, 2, 3, 4, 5, 6, 8, 10, 12, 16, 20, 25, 31] {
        let packets = encode_all(&short, &Mpeg4Options { qscale, gop: 30 })?;
        let decoded = decode_all(&packets, 256, 256)?;
        println!(
            "sweep mpeg4 qs{qscale:<2}  {:6} B/frame  PSNR {:5.2}  (I-frame {} B, {:5.2} dB)",
            packets.iter().map(|p| p.data.len()).sum::<usize>() / short.len(),
            mean_psnr(&short, &decoded)?,
            packets[0].data.len(),
            short[0].psnr(&decoded[0])?
        );
    }

    // Three coordinate images: three streams vs one 768×256 picture tiled side by side.
    let coords: Vec<[Plane; 3]> = (0..FRAMES)
        .map(|t| [0.0, 2.1, 4.2].map(|phase| smooth_frame(256, 256, t, phase)))
        .collect();
    let tiled: Vec<Plane> = coords.iter().map(tile).collect();
    for quality in [50, 75, 90] {
        // [full, abbreviated] bytes for three planes and for the tiled picture.
        let (mut separate, mut together) = ([0; 2], [0; 2]);
        for (c, t) in coords.iter().zip(&tiled) {
            for p in c {
                separate[0] += jpeg::encode(p, quality)?.len();
                separate[1] += stored_len(&jpeg::encode(p, quality)?)?;
            }
            together[0] += jpeg::encode(t, quality)?.len();
            together[1] += stored_len(&jpeg::encode(t, quality)?)?;
        }
        let per_frame = |b: usize| b as f64 / f64::from(FRAMES);
        println!(
            "jpeg  q{quality:<3} three planes {:7.0} B/frame (abbreviated {:7.0}), tiled 768×256 {:7.0} (abbreviated {:7.0})",
            per_frame(separate[0]),
            per_frame(separate[1]),
            per_frame(together[0]),
            per_frame(together[1])
        );
    }
    for qscale in [2, 8, 20] {
        let options = Mpeg4Options { qscale, gop: 30 };
        let mut separate = 0;
        for k in 0..3 {
            let stream: Vec<Plane> = coords.iter().filter_map(|c| c.get(k).cloned()).collect();
            separate += encode_all(&stream, &options)?
                .iter()
                .map(|p| p.data.len())
                .sum::<usize>();
        }
        let together: usize = encode_all(&tiled, &options)?
            .iter()
            .map(|p| p.data.len())
            .sum();
        println!(
            "mpeg4 qs{qscale:<2} three streams {:7.0} B/frame, tiled 768×256 {:7.0} B/frame",
            separate as f64 / f64::from(FRAMES),
            together as f64 / f64::from(FRAMES)
        );
    }
    Ok(())
}

/// Bytes a stream stores per picture in the abbreviated form (`codec::abbreviated`): its Huffman
/// tables and scan; the headers fixed by size and quality are stored once per stream.
fn stored_len(jpeg: &[u8]) -> Result<usize> {
    let parts = abbreviated::split(jpeg)?;
    Ok(parts.tables.len() + parts.scan.len())
}

/// Bytes before the entropy-coded data: markers, tables, frame and scan headers.
fn jpeg_header_len(jpeg: &[u8]) -> usize {
    jpeg.windows(2)
        .position(|w| w == [0xFF, 0xDA])
        .and_then(|sos| {
            let len = usize::from(*jpeg.get(sos + 2)?) << 8 | usize::from(*jpeg.get(sos + 3)?);
            Some(sos + 2 + len)
        })
        .unwrap_or(0)
}

fn tile(planes: &[Plane; 3]) -> Plane {
    let (w, h) = (planes[0].width, planes[0].height);
    let mut data = Vec::with_capacity((3 * w * h) as usize);
    for y in 0..h {
        for p in planes {
            data.extend_from_slice(p.row(y).unwrap_or_default());
        }
    }
    Plane {
        width: 3 * w,
        height: h,
        data,
    }
}

/// Our decoder forces zune-jpeg's scalar path so every platform decodes alike; where the machine has
/// a SIMD path, it must agree with it exactly, or the choice would matter.
#[test]
fn jpeg_scalar_decode_equals_simd_decode() -> Result<()> {
    use zune_core::{bytestream::ZCursor, colorspace::ColorSpace, options::DecoderOptions};
    for quality in [10, 75, 100] {
        let bytes = jpeg::encode(&smooth_frame(128, 64, 2, 0.7), quality)?;
        let ours = jpeg::decode(&bytes, 128, 64)?;
        let options = DecoderOptions::default()
            .set_use_unsafe(true)
            .jpeg_set_out_colorspace(ColorSpace::Luma);
        let simd = zune_jpeg::JpegDecoder::new_with_options(ZCursor::new(&bytes), options)
            .decode()
            .map_err(|e| mcgv_video::Error::Codec(format!("{e:?}")))?;
        assert_eq!(ours.data, simd, "quality {quality}");
    }
    Ok(())
}
