//! Writes the encoder's real residual images, before padding, for the padding bench:
//! `NNNN_C.png` (16-bit grey, the 8-bit levels × 257; free pixels 0) and `NNNN_C_mask.png`
//! (255 where a pixel carries data), C = x, y, z.
//!
//! `cargo run --release --example dump_residuals -- INPUT OUT_DIR [FRAMES]` (default 24 frames, evenly
//! spread), then `cargo run --release -p padding --example jpeg_bench -- folder --per-frame 3 OUT_DIR`.

use mcgv_video::codec::{geometry_video, Codec};
use mcgv_video::encoder::{analysis, EncodeOptions, Segmentation};
use mcgv_video::first_frame;
use mcgv_video::mesh::read_animation;
use mcgv_video::motion::PredictorKind;
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
        codec: Codec::Jpeg,
        ..EncodeOptions::default()
    };
    let ff = first_frame::encode(
        mesh.frame(0),
        mesh.triangles(),
        &first_frame::FirstFrameOptions {
            bits: opts.first_frame_bits_or_default(),
            reorder: false,
        },
    )?;
    let (partition, _) = analysis::segment(&mesh, Segmentation::KMeans, opts.clusters)?;
    let reference = &ff.decoded_positions;
    let prediction = analysis::predict(&mesh, reference, &partition, &opts, PredictorKind::Affine)?;
    let pictures = opts.codec.pictures()?.ok_or("the codec makes no images")?;
    let step = geometry_video::pixel_step(pictures.as_ref(), mesh.bbox_diagonal(), &opts)?;
    let images = geometry_video::images_of(
        pictures.as_ref(),
        &ff.decoded_positions,
        mesh.triangles(),
        &partition,
        &prediction.residuals,
        &opts,
        step,
    )?;
    let (w, h) = (images.lattice.0 as u32, images.lattice.1 as u32);
    let mask: Vec<u8> = images
        .atlas
        .fixed_mask()
        .iter()
        .map(|&f| if f { 255 } else { 0 })
        .collect();
    std::fs::create_dir_all(&out)?;
    let frames = mesh.frame_count();
    for i in 0..wanted.min(frames) {
        let f = i * frames / wanted.min(frames);
        for (a, c) in ["x", "y", "z"].iter().enumerate() {
            let levels = images.level_image(&prediction.residuals[f], f, a)?;
            let grey: Vec<u16> = levels
                .iter()
                .map(|&v| (v.clamp(0.0, 255.0) * 257.0).round() as u16)
                .collect();
            let stem = format!("{f:04}_{c}");
            image::ImageBuffer::<image::Luma<u16>, _>::from_raw(w, h, grey)
                .ok_or("image size")?
                .save(out.join(format!("{stem}.png")))?;
            image::GrayImage::from_raw(w, h, mask.clone())
                .ok_or("mask size")?
                .save(out.join(format!("{stem}_mask.png")))?;
        }
    }
    eprintln!(
        "{} frames of {input} written to {}",
        wanted.min(frames),
        out.display()
    );
    Ok(())
}
