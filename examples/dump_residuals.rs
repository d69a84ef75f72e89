//! Writes the encoder's real residual images, before padding, for the padding bench:
//! `NNNN_C.png` (16-bit grey, the 8-bit levels × 257; free pixels 0) and `NNNN_C_mask.png`
//! (255 where a pixel carries data), C = x, y, z.
//!
//! `cargo run --release --example dump_residuals -- INPUT OUT_DIR [FRAMES]` (default 24 frames, evenly
//! spread), then `cargo run --release -p padding --example jpeg_bench -- folder --per-frame 3 OUT_DIR`.
//!
//! The images are a JPEG encoding's (affine predictor on k-means clusters, one segment), as
//! `mcgv-video inspect --png DIR --original INPUT` redoes them, unannotated.

use mcgv_video::codec::Codec;
use mcgv_video::encoder::{EncodeOptions, Segmentation};
use mcgv_video::mesh::read_animation;
use mcgv_video::{encode, Decoder, PredictorKind};
use std::path::PathBuf;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (input, out) = match (args.first(), args.get(1)) {
        (Some(i), Some(o)) => (i.clone(), PathBuf::from(o)),
        _ => return Err("usage: dump_residuals INPUT OUT_DIR [FRAMES]".into()),
    };
    let wanted: usize = args.get(2).map(|s| s.parse()).transpose()?.unwrap_or(24);
    let mesh = read_animation(&input, &Default::default())?;
    let opts = EncodeOptions {
        codec: Codec::Jpeg.into(),
        predictor: PredictorKind::Affine.into(),
        segmentation: Segmentation::KMeans.into(),
        segment_frames: None,
        ..EncodeOptions::default()
    };
    let bytes = encode(&mesh, &opts)?.to_bytes();
    let decoder = Decoder::new(&bytes)?;
    let pictures = decoder.describe().and_then(|d| d.pictures);
    let (w, h) = pictures.ok_or("a JPEG stream has pictures")?.lattice;
    let (w, h) = (u32::from(w), u32::from(h));
    let frames = mesh.frame_count();
    let count = wanted.clamp(1, frames);
    let chosen: Vec<usize> = (0..count).map(|i| i * frames / count).collect();
    std::fs::create_dir_all(&out)?;
    for images in mcgv_video::inspect::encoder_images(&decoder, &mesh, &chosen)? {
        let mask: Vec<u8> = images
            .fixed
            .iter()
            .map(|&f| if f { 255 } else { 0 })
            .collect();
        let raw = &images.raw;
        for (axis, c) in ["x", "y", "z"].into_iter().enumerate() {
            // One coordinate's columns of the x | y | z picture, 8-bit levels spread to 16 bits.
            let grey: Vec<u16> = raw
                .data
                .chunks_exact(raw.width as usize)
                .flat_map(|row| &row[axis * w as usize..(axis + 1) * w as usize])
                .map(|&v| v.min(255) * 257)
                .collect();
            let stem = format!("{:04}_{c}", images.frame);
            image::ImageBuffer::<image::Luma<u16>, _>::from_raw(w, h, grey)
                .ok_or("image size")?
                .save(out.join(format!("{stem}.png")))?;
            image::GrayImage::from_raw(w, h, mask.clone())
                .ok_or("mask size")?
                .save(out.join(format!("{stem}_mask.png")))?;
        }
    }
    eprintln!("{count} frames of {input} written to {}", out.display());
    Ok(())
}
