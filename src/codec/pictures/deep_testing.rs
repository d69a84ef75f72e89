//! What hevc's and av1's unit tests share: a smooth moving test pattern, a coder of planes and
//! the checks both codecs pass.

use super::coder::*;
use crate::codec::pictures::{PictureCodec, PictureSetup};
use crate::geometry_image::{quantise, Plane};

/// A smooth pattern moving with `t`, spanning most of the `depth`-bit range.
pub fn ramp(width: u32, height: u32, t: u32, depth: u8) -> Plane<u16> {
    let top = f64::from(quantise::max_level(depth));
    let data = (0..width * height)
        .map(|i| {
            let (x, y) = (f64::from(i % width), f64::from(i / width));
            let v = 0.5 + 0.3 * ((x + 2.0 * f64::from(t)) / 9.0).sin() * (y / 7.0).cos();
            (v * top).round() as u16
        })
        .collect();
    Plane::new(width, height, data).unwrap()
}

/// The packets of `planes` coded by `flavour` with `options`.
pub fn code(flavour: &dyn Flavour, planes: &[Plane<u16>], options: &Options) -> Vec<Packet> {
    let (w, h) = (planes[0].width, planes[0].height);
    let mut encoder = Encoder::new(flavour, w, h, options, 0).unwrap();
    let mut packets = Vec::new();
    for p in planes {
        packets.extend(encoder.encode(p).unwrap());
    }
    packets.extend(encoder.finish().unwrap());
    packets
}

/// Codes five frames of each depth and layout with key frames every 2, checks the key flags,
/// that a second coding gives the same bytes, that every decoded sample is within `tolerance`
/// levels of an 8-bit picture (scaled to the depth) and that a P-frame without its key frame
/// gives no picture.
pub fn round_trip(flavour: &dyn Flavour, qp: u8, tolerance: u16) {
    for (depth, layout) in [(10, Planes::Mono), (12, Planes::Mono), (10, Planes::Yuv444)] {
        let (w, h) = (96, 48);
        let planes: Vec<_> = (0..5).map(|t| ramp(w, h, t, depth)).collect();
        let options = Options {
            qp,
            gop: 2,
            depth,
            planes: layout,
        };
        let packets = code(flavour, &planes, &options);
        let keys: Vec<bool> = packets.iter().map(|p| p.key).collect();
        assert_eq!(keys, [true, false, true, false, true], "{depth} bits");
        assert_eq!(
            packets,
            code(flavour, &planes, &options),
            "not deterministic"
        );
        let mut decoder = Decoder::new(flavour, w, h, depth, layout).unwrap();
        for (plane, packet) in planes.iter().zip(&packets) {
            let back = decoder.decode(&packet.data).unwrap();
            let worst = back[0]
                .data
                .iter()
                .zip(&plane.data)
                .map(|(a, b)| a.abs_diff(*b))
                .max()
                .unwrap();
            let limit = tolerance << (depth - 8);
            assert!(worst <= limit, "{depth} bits {layout:?}: {worst}");
        }
        let mut cold = Decoder::new(flavour, w, h, depth, layout).unwrap();
        let first = cold.decode(&packets[1].data);
        assert!(first.map_or(true, |p| p.is_empty()));
    }
}

/// Sizes, quantisers, depths, samples and set-up parts out of range are errors.
pub fn bad_settings_are_errors<F: Flavour>(flavour: F, qp: u8) {
    let options = Options {
        qp,
        gop: 50,
        depth: 10,
        planes: Planes::Mono,
    };
    let too_fine = flavour.max_qp() + 1;
    assert!(Encoder::new(&flavour, 15, 32, &options, 0).is_err());
    let coarse = Options {
        qp: too_fine,
        ..options
    };
    assert!(Encoder::new(&flavour, 32, 32, &coarse, 0).is_err());
    let shallow = Options {
        depth: 8,
        ..options
    };
    assert!(Encoder::new(&flavour, 32, 32, &shallow, 0).is_err());
    let yuv = Options {
        planes: Planes::Yuv444,
        ..options
    };
    let error = Encoder::new(&flavour, 64, 32, &yuv, 0).err();
    assert!(error.is_some(), "not three images wide");
    let mut encoder = Encoder::new(&flavour, 96, 32, &options, 0).unwrap();
    assert!(encoder.encode(&Plane::filled(96, 32, 1024)).is_err());
    assert!(encoder.encode(&Plane::filled(48, 32, 0)).is_err());
    let name = flavour.name();
    assert!(read_planes(name, &[]).is_err());
    assert!(read_planes(name, &[2]).is_err());
    assert!(read_planes(name, &[1, 0]).is_err());
    assert_eq!(read_planes(name, &[1]).unwrap(), Planes::Yuv444);
    assert_eq!(read_planes(name, &[0]).unwrap(), Planes::Mono);
    let setup = |depth, codec_data| PictureSetup {
        lattice: (32, 32),
        quantiser: qp,
        gop: 50,
        depth,
        padding: padding::Method::Cg,
        charts: 1,
        chart_pixels: 0,
        codec_data,
    };
    let pictures = Pictures(flavour);
    assert!(pictures.decoder(96, 32, &setup(12, vec![1])).is_ok());
    assert!(pictures.decoder(96, 32, &setup(9, vec![1])).is_err());
    assert!(pictures.decoder(96, 32, &setup(10, vec![2])).is_err());
}

/// A moving pattern with noise on top (a pseudo-random sequence from `seed`), the kind of picture
/// on which x265's reference limits once gave different bytes from one encoder to the next.
pub fn noisy(width: u32, height: u32, t: u32, seed: u64) -> Plane<u16> {
    let mut state = seed.wrapping_add(u64::from(t)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    let data = (0..width * height)
        .map(|i| {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            let (x, y) = (f64::from(i % width), f64::from(i / width));
            let smooth = 0.5 + 0.2 * ((x + 3.0 * f64::from(t)) / 11.0).sin() * (y / 5.0).cos();
            let noise = ((state >> 33) % 41) as f64 - 20.0;
            (smooth * 1023.0 + noise).clamp(0.0, 1023.0) as u16
        })
        .collect();
    Plane::new(width, height, data).unwrap()
}

/// Codes the same `frames` noisy 4:4:4 pictures of one 64-pixel block (x265's largest coding
/// tree unit), key frames every `gop`, `runs` times in this process, each with a new encoder on a
/// heap the runs before have used, and (glibc) once more with every new allocation filled with a
/// fixed byte: every run must give the first one's bytes, so no byte the encoder leaves unwritten
/// can change its output.
pub fn same_bytes_every_run(flavour: &dyn Flavour, frames: u32, gop: usize, runs: usize) {
    let planes: Vec<_> = (0..frames).map(|t| noisy(3 * 64, 64, t, 64)).collect();
    let options = Options {
        qp: 22,
        gop,
        depth: 10,
        planes: Planes::Yuv444,
    };
    let first = code(flavour, &planes, &options);
    let same = |again: Vec<Packet>, run: &str| {
        let differs = again.iter().zip(&first).position(|(a, b)| a != b);
        assert_eq!(differs, None, "{run}: frame {differs:?} differs");
        assert_eq!(again.len(), first.len(), "{run}");
    };
    for run in 1..runs {
        same(code(flavour, &planes, &options), &format!("run {run}"));
    }
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        perturb_allocations(0x55);
        let perturbed = code(flavour, &planes, &options);
        perturb_allocations(0);
        same(perturbed, "filled allocations");
    }
}

/// glibc's `M_PERTURB`: new allocations are filled with `!byte` and freed ones with `byte` (0:
/// off), for the whole process while it lasts.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn perturb_allocations(byte: i32) {
    extern "C" {
        fn mallopt(param: i32, value: i32) -> i32;
    }
    const M_PERTURB: i32 = -6;
    // SAFETY: mallopt only sets an allocator parameter; M_PERTURB takes any byte value.
    let set = unsafe { mallopt(M_PERTURB, byte) };
    assert_eq!(set, 1, "mallopt(M_PERTURB) refused");
}
