//! `mcgv-video decode`.

use crate::args::DecodeArgs;
use crate::output::{
    animation_output, create_parent, prepare_frame_folder, write_pc2_with_base, OutputKind,
};
use crate::progress;
use mcgv_video::mesh::MANY_MORPH_TARGETS;
use mcgv_video::mesh::{write_gltf, AnimatedMesh, GltfOptions, DEFAULT_FPS};
use mcgv_video::mesh::{write_obj_mesh_frame, write_obj_sequence_from, ObjFrameWriter, Pc2Writer};
use mcgv_video::{DecodeOptions, Decoder};
use mcgv_video::{Error, Result};
use std::fs::File;
use std::io::BufReader;
use std::time::Instant;

/// The decoding options of `--bands` and `--max-positions`.
pub fn decode_options(bands: Option<u64>, max_positions: Option<u64>) -> DecodeOptions {
    DecodeOptions {
        max_bands: bands.map(|n| usize::try_from(n).unwrap_or(usize::MAX)),
        max_positions: max_positions.unwrap_or(mcgv_video::DEFAULT_MAX_POSITIONS),
        ..DecodeOptions::default()
    }
}

/// Tells on stderr when a temporal-DCT stream was cut short: it decodes, but coarser.
pub fn warn_if_truncated<R>(decoder: &Decoder<R>)
where
    R: std::io::Read + std::io::Seek,
{
    if decoder.truncated() && decoder.segments().len() > 1 {
        eprintln!(
            "mcgv-video: warning: stream truncated inside its last segment's temporal-DCT bands: \
             that segment decodes coarser"
        );
    } else if let Some(bands) = decoder.describe().and_then(|d| d.bands) {
        if decoder.truncated() {
            eprintln!(
                "mcgv-video: warning: stream truncated: decoded {} of {} temporal-DCT bands, a coarser animation",
                bands.decoded,
                bands.lengths.len()
            );
        }
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
    // The output's kind is checked before any work: a wrong name costs nothing.
    let kind = animation_output(&args.output, args.frame.is_some())?;
    if args.like.is_some() && kind != OutputKind::Gltf {
        return Err(Error::option(
            "like",
            "applies to a glTF output (.glb, .gltf)",
        ));
    }
    let mut decoder =
        Decoder::open_with(&args.input, &decode_options(args.bands, args.max_positions))
            .map_err(|e| super::in_file(&args.input, e))?;
    warn_if_truncated(&decoder);
    if decoder.header().reorder && !quiet {
        eprintln!(
            "mcgv-video: note: {} was encoded with --reorder: the vertices are written in the \
             stream's order (faces renumbered to match); `eval` against the original restores \
             the input order itself",
            args.input.display()
        );
    }
    let every_frame = args.frame.is_none() && args.frames.is_none();
    if every_frame && matches!(kind, OutputKind::ObjFolder | OutputKind::Pc2) {
        let frames = match kind {
            OutputKind::Pc2 => stream_pc2(&mut decoder, &args.output, quiet),
            _ => {
                prepare_frame_folder(&args.output, args.force)?;
                stream_obj_frames(&mut decoder, &args.output, quiet)
            }
        }
        .map_err(|e| super::in_file(&args.input, e))?;
        let vertices = decoder.header().vertices as usize;
        return report(args, quiet, start, frames, vertices);
    }
    let mesh =
        decode_mesh(&mut decoder, args, quiet).map_err(|e| super::in_file(&args.input, e))?;
    match kind {
        OutputKind::Pc2 => {
            write_pc2_with_base(&mesh, &args.output, None)?;
        }
        OutputKind::ObjFile => {
            create_parent(&args.output)?;
            write_obj_mesh_frame(&mesh, 0, &args.output)?;
        }
        OutputKind::ObjFolder => {
            prepare_frame_folder(&args.output, args.force)?;
            let first = args.frame.or(args.frames.as_ref().map(|r| r.start));
            write_obj_sequence_from(&mesh, &args.output, first.unwrap_or(0))?;
        }
        OutputKind::Gltf => {
            create_parent(&args.output)?;
            warn_if_many_targets(mesh.frame_count());
            let options = GltfOptions {
                fps: args.fps.or(mesh.frame_rate()).unwrap_or(DEFAULT_FPS),
                like: args.like.clone(),
                ..GltfOptions::default()
            };
            write_gltf(&mesh, Some(mesh.attributes()), &args.output, &options)?;
        }
    }
    report(args, quiet, start, mesh.frame_count(), mesh.vertex_count())
}

/// Says what was written, unless `quiet`.
fn report(
    args: &DecodeArgs,
    quiet: bool,
    start: Instant,
    frames: usize,
    vertices: usize,
) -> Result<()> {
    if !quiet {
        let seconds = start.elapsed().as_secs_f64();
        outln!(
            "{}: {frames} frame(s) of {vertices} vertices written in {seconds:.2} s ({:.1} frames/s)",
            args.output.display(),
            frames as f64 / seconds.max(1e-9)
        )?;
    }
    Ok(())
}

/// Decodes every frame into a PC2 cache (and its base OBJ, frame 0, beside it), each frame written
/// as soon as its segment is decoded. Returns the frames written.
fn stream_pc2(
    decoder: &mut Decoder<BufReader<File>>,
    path: &std::path::Path,
    quiet: bool,
) -> Result<usize> {
    let (frames, vertices) = (
        decoder.header().frames as usize,
        decoder.header().vertices as usize,
    );
    let (triangles, attributes) = (decoder.triangles().to_vec(), decoder.attributes().clone());
    create_parent(path)?;
    let base = path.with_extension("obj");
    let mut cache = Pc2Writer::create(path, vertices, frames)?;
    let pb = progress::bar(frames as u64, "decode", quiet);
    let mut first = None;
    decoder.for_each_frame(&crate::progress::Reporter(&pb), |f, positions| {
        cache.write(&positions)?;
        if f == 0 {
            first = Some(positions);
        }
        Ok(())
    })?;
    pb.finish_and_clear();
    // Both files are written only once every frame decoded: a damaged stream leaves neither.
    let first = first.ok_or_else(|| Error::Stream("the stream has no frames".into()))?;
    let first = AnimatedMesh::new(triangles, vec![first])?.with_attributes(attributes)?;
    write_obj_mesh_frame(&first, 0, &base)?;
    cache.finish()?;
    Ok(frames)
}

/// Decodes every frame into an OBJ folder, each file written as soon as its segment is decoded:
/// memory holds one segment, whatever the clip's length. Returns the frames written.
fn stream_obj_frames(
    decoder: &mut Decoder<BufReader<File>>,
    dir: &std::path::Path,
    quiet: bool,
) -> Result<usize> {
    let frames = decoder.header().frames as usize;
    let (triangles, attributes) = (decoder.triangles().to_vec(), decoder.attributes().clone());
    let writer = ObjFrameWriter::new(dir, frames.saturating_sub(1), &triangles, &attributes)?;
    let pb = progress::bar(frames as u64, "decode", quiet);
    decoder.for_each_frame(&crate::progress::Reporter(&pb), |f, positions| {
        writer.write(f, &positions)
    })?;
    pb.finish_and_clear();
    Ok(frames)
}

/// The frames `--frame` asks for (all by default), decoded.
fn decode_mesh(
    decoder: &mut Decoder<BufReader<File>>,
    args: &DecodeArgs,
    quiet: bool,
) -> Result<AnimatedMesh> {
    let frames = decoder.header().frames as usize;
    let rate = Some(f64::from(decoder.header().frame_rate));
    match args.frame {
        Some(f) => {
            if f >= frames {
                return Err(Error::option(
                    "frame",
                    format!("{f}: the stream has frames 0 to {}", frames - 1),
                ));
            }
            let positions = decoder.decode_frame(f)?;
            Ok(
                AnimatedMesh::new(decoder.triangles().to_vec(), vec![positions])?
                    .with_attributes(decoder.attributes().clone())?
                    .with_frame_rate(rate),
            )
        }
        None if args.frames.is_some() => {
            let range = args.frames.clone().unwrap_or(0..frames);
            if range.end > frames {
                return Err(Error::option(
                    "frames",
                    format!("{range:?}: the stream has frames 0 to {}", frames - 1),
                ));
            }
            let positions = range
                .map(|f| decoder.decode_frame(f))
                .collect::<Result<Vec<_>>>()?;
            Ok(AnimatedMesh::new(decoder.triangles().to_vec(), positions)?
                .with_attributes(decoder.attributes().clone())?
                .with_frame_rate(rate))
        }
        None => {
            let pb = progress::bar(frames as u64, "decode", quiet);
            let mesh = decoder.decode_all_with_progress(&crate::progress::Reporter(&pb))?;
            pb.finish_and_clear();
            Ok(mesh)
        }
    }
}
