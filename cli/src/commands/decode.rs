//! `mcgv-video decode`.

use crate::args::DecodeArgs;
use crate::progress;
use mcgv_video::decoder::{DecodeOptions, Decoder};
use mcgv_video::error::{Error, Result};
use mcgv_video::mesh::gltf_write::{is_gltf_path, MANY_MORPH_TARGETS};
use mcgv_video::mesh::io::write_obj_sequence_from;
use mcgv_video::mesh::{write_gltf, write_pc2, AnimatedMesh, GltfOptions};
use std::path::Path;
use std::time::Instant;

/// Whether the output path names a PC2 point cache rather than an OBJ folder.
fn is_pc2(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("pc2"))
}

/// The decoding options of `--bands`.
pub fn decode_options(bands: Option<u64>) -> DecodeOptions {
    DecodeOptions {
        max_bands: bands.map(|n| usize::try_from(n).unwrap_or(usize::MAX)),
    }
}

/// Tells on stderr when a temporal-DCT stream was cut short: it decodes, but coarser.
pub fn warn_if_truncated<R>(decoder: &Decoder<R>)
where
    R: std::io::Read + std::io::Seek,
{
    if decoder.truncated() {
        eprintln!(
            "mcgv-video: warning: stream truncated: decoded {} of {} temporal-DCT bands, a coarser animation",
            decoder.bands_decoded(),
            decoder.bands_total()
        );
    }
}

/// Tells on stderr when a glTF output gets more morph targets than viewers load comfortably.
pub fn warn_if_many_targets(frames: usize) {
    if frames > MANY_MORPH_TARGETS + 1 {
        eprintln!(
            "mcgv-video: warning: {} morph targets (one per frame after the first); viewers load more than {MANY_MORPH_TARGETS} slowly",
            frames - 1
        );
    }
}

/// Runs `decode`.
pub fn run(args: &DecodeArgs, quiet: bool) -> Result<()> {
    let start = Instant::now();
    let mut decoder = Decoder::open_with(&args.input, &decode_options(args.bands))?;
    warn_if_truncated(&decoder);
    let frames = decoder.header().frames as usize;
    let mesh = match args.frame {
        Some(f) => {
            if f >= frames {
                return Err(Error::Usage(format!(
                    "--frame {f}: the stream has frames 0 to {}",
                    frames - 1
                )));
            }
            let positions = decoder.decode_frame(f)?;
            AnimatedMesh::new(decoder.triangles().to_vec(), vec![positions])?
                .with_attributes(decoder.attributes().clone())?
        }
        None => {
            let pb = progress::bar(frames as u64, "decode", quiet);
            let mesh = decoder.decode_all_with_progress(&crate::progress::Reporter(&pb))?;
            pb.finish_and_clear();
            mesh
        }
    };
    if is_gltf_path(&args.output) {
        warn_if_many_targets(mesh.frame_count());
        let options = GltfOptions {
            fps: args.fps,
            ..GltfOptions::default()
        };
        write_gltf(&mesh, Some(mesh.attributes()), &args.output, &options)?;
    } else if is_pc2(&args.output) {
        write_pc2(&mesh, &args.output)?;
    } else {
        let first = args.frame.unwrap_or(0);
        write_obj_sequence_from(&mesh, &args.output, first)?;
    }
    if !quiet {
        let seconds = start.elapsed().as_secs_f64();
        println!(
            "{}: {} frame(s) of {} vertices written in {:.2} s ({:.1} frames/s)",
            args.output.display(),
            mesh.frame_count(),
            mesh.vertex_count(),
            seconds,
            mesh.frame_count() as f64 / seconds.max(1e-9)
        );
    }
    Ok(())
}
