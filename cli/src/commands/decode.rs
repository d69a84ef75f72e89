//! `mcgv-video decode`.

use crate::args::DecodeArgs;
use crate::output::{animation_output, OutputKind};
use crate::progress;
use crate::staging::{in_new_parent, Inputs};
use crate::target::{finish_pc2_pair, Target};
use mcgv_video::mesh::MANY_MORPH_TARGETS;
use mcgv_video::mesh::{write_gltf, AnimatedMesh, GltfOptions, DEFAULT_FPS};
use mcgv_video::mesh::{write_obj_mesh_frame, ObjFrameWriter, Pc2Writer};
use mcgv_video::{DecodeOptions, Decoder};
use mcgv_video::{Error, Result};
use std::fs::File;
use std::io::BufReader;
use std::path::Path;
use std::time::Instant;

/// The decoding options of `--bands` and `--max-positions`.
pub fn decode_options(bands: Option<u64>, max_positions: Option<u64>) -> DecodeOptions {
    DecodeOptions {
        max_bands: bands.map(|n| usize::try_from(n).unwrap_or(usize::MAX)),
        max_positions: max_positions.unwrap_or(mcgv_video::DEFAULT_MAX_POSITIONS),
        ..DecodeOptions::default()
    }
}

/// Tells on stderr when a temporal-DCT stream was cut short or has a damaged band: it decodes,
/// but coarser. `bands` is `--bands`: fewer bands asked for is no damage.
pub fn warn_if_truncated<R>(decoder: &Decoder<R>, bands: Option<u64>)
where
    R: std::io::Read + std::io::Seek,
{
    if decoder.truncated() && decoder.segments().len() > 1 {
        eprintln!(
            "mcgv-video: warning: stream truncated inside its last segment's temporal-DCT bands: \
             that segment decodes coarser"
        );
    } else if let Some(described) = decoder.describe().and_then(|d| d.bands) {
        let (bands, asked) = (described, bands);
        let total = bands.lengths.len();
        if decoder.truncated() {
            eprintln!(
                "mcgv-video: warning: stream truncated: decoded {} of {total} temporal-DCT bands, a coarser animation",
                bands.decoded,
            );
        } else if bands.decoded < total && asked.is_none_or(|n| n > bands.decoded as u64) {
            eprintln!(
                "mcgv-video: warning: temporal-DCT band {} of {total} is damaged: decoded the bands before it, a coarser animation",
                bands.decoded,
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
    // Options are checked before a frame is decoded or a folder made (glTF writing would find
    // a bad rate only at the end).
    if let Some(fps) = args.fps.filter(|r| !(r.is_finite() && *r > 0.0)) {
        return Err(Error::option(
            "fps",
            format!("{fps}: the frame rate must be a positive number"),
        ));
    }
    let mut decoder =
        Decoder::open_with(&args.input, &decode_options(args.bands, args.max_positions))
            .map_err(|e| super::in_file(&args.input, e))?;
    warn_if_truncated(&decoder, args.bands);
    if decoder.header().reorder && !quiet {
        eprintln!(
            "mcgv-video: note: {} was encoded with --reorder: the vertices are written in the \
             stream's order (faces renumbered to match); `eval` against the original restores \
             the input order itself",
            args.input.display()
        );
    }
    let count = decoder.header().frames as usize;
    let frames = selected(args, count)?;
    // Every file the run writes is checked before the frames are decoded.
    let span = (frames.clone(), count - 1);
    let mut read_from = vec![args.input.as_path()];
    read_from.extend(args.like.as_deref());
    let inputs = Inputs::of(&read_from, &mcgv_video::ReadOptions::default());
    let target = Target::prepare(&args.output, kind, span, args.force, &inputs)?;
    let every_frame = frames.len() == count;
    let in_file = |e| super::in_file(&args.input, e);
    match target {
        Target::Folder { staged, last } if every_frame => {
            stream_obj_frames(&mut decoder, staged.path(), last, quiet).map_err(in_file)?;
            staged.commit_and_tell(quiet)?;
        }
        Target::Pc2 { cache, base } if every_frame => {
            in_new_parent(&cache, || {
                stream_pc2(&mut decoder, (&cache, &base), quiet).map_err(in_file)
            })?;
        }
        target => {
            let mesh = decode_mesh(&mut decoder, &frames, quiet).map_err(in_file)?;
            write_mesh(target, &mesh, &frames, args, quiet)?;
        }
    }
    report(
        args,
        quiet,
        start,
        frames.len(),
        decoder.header().vertices as usize,
    )
}

/// The frames `--frame` or `--frames` selects (all by default); one past the stream's end is a
/// usage error.
fn selected(args: &DecodeArgs, count: usize) -> Result<Vec<usize>> {
    match (args.frame, &args.frames) {
        (Some(f), _) if f >= count => Err(Error::option(
            "frame",
            format!("{f}: the stream has frames 0 to {}", count - 1),
        )),
        (Some(f), _) => Ok(vec![f]),
        (None, Some(frames)) => frames.resolve(count, "frames"),
        (None, None) => Ok((0..count).collect()),
    }
}

/// Writes the decoded `mesh` (the stream's `frames`) to the checked `target`.
fn write_mesh(
    target: Target,
    mesh: &AnimatedMesh,
    frames: &[usize],
    args: &DecodeArgs,
    quiet: bool,
) -> Result<()> {
    match target {
        Target::Pc2 { cache, base } => in_new_parent(&cache, || {
            finish_pc2_pair(mesh, &base, || mcgv_video::mesh::write_pc2(mesh, &cache))
        }),
        Target::ObjFile(path) => in_new_parent(&path, || write_obj_mesh_frame(mesh, 0, &path)),
        Target::Folder { staged, last } => {
            let writer =
                ObjFrameWriter::new(staged.path(), last, mesh.triangles(), mesh.attributes())?;
            for (positions, &f) in mesh.frames().iter().zip(frames) {
                writer.write(f, positions)?;
            }
            staged.commit_and_tell(quiet)
        }
        Target::Gltf(path) => {
            warn_if_many_targets(mesh.frame_count());
            let options = GltfOptions {
                fps: args.fps.or(mesh.frame_rate()).unwrap_or(DEFAULT_FPS),
                like: args.like.clone(),
                ..GltfOptions::default()
            };
            in_new_parent(&path, || {
                write_gltf(mesh, Some(mesh.attributes()), &path, &options)
            })
        }
    }
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
            "{}: {frames} frame{} of {vertices} vertices written in {seconds:.2} s ({:.1} frames/s)",
            args.output.display(),
            if frames == 1 { "" } else { "s" },
            frames as f64 / seconds.max(1e-9)
        )?;
    }
    Ok(())
}

/// Decodes every frame into a PC2 cache (and its base OBJ, frame 0, beside it), each frame written
/// as soon as its segment is decoded; both files are put in place only once every frame decoded.
fn stream_pc2(
    decoder: &mut Decoder<BufReader<File>>,
    (cache, base): (&Path, &Path),
    quiet: bool,
) -> Result<()> {
    let (frames, vertices) = (
        decoder.header().frames as usize,
        decoder.header().vertices as usize,
    );
    let (triangles, attributes) = (decoder.triangles().to_vec(), decoder.attributes().clone());
    let mut writer = Pc2Writer::create(cache, vertices, frames)?;
    let pb = progress::bar(frames as u64, "decode", quiet);
    let mut first = None;
    decoder.for_each_frame(&crate::progress::Reporter(&pb), |f, positions| {
        writer.write(&positions)?;
        if f == 0 {
            first = Some(positions);
        }
        Ok(())
    })?;
    pb.finish_and_clear();
    let first = first.ok_or_else(|| Error::Stream("the stream has no frames".into()))?;
    let first = AnimatedMesh::new(triangles, vec![first])?.with_attributes(attributes)?;
    finish_pc2_pair(&first, base, || writer.finish())
}

/// Decodes every frame into the staging folder `dir` of an OBJ folder, each file written as soon
/// as its segment is decoded: memory holds one segment, whatever the clip's length.
fn stream_obj_frames(
    decoder: &mut Decoder<BufReader<File>>,
    dir: &Path,
    last: usize,
    quiet: bool,
) -> Result<()> {
    let frames = decoder.header().frames as usize;
    let (triangles, attributes) = (decoder.triangles().to_vec(), decoder.attributes().clone());
    let writer = ObjFrameWriter::new(dir, last, &triangles, &attributes)?;
    let pb = progress::bar(frames as u64, "decode", quiet);
    decoder.for_each_frame(&crate::progress::Reporter(&pb), |f, positions| {
        writer.write(f, &positions)
    })?;
    pb.finish_and_clear();
    Ok(())
}

/// The stream's `frames`, decoded (all of them with a progress bar).
fn decode_mesh(
    decoder: &mut Decoder<BufReader<File>>,
    frames: &[usize],
    quiet: bool,
) -> Result<AnimatedMesh> {
    let count = decoder.header().frames as usize;
    if frames.len() == count {
        let pb = progress::bar(count as u64, "decode", quiet);
        let mesh = decoder.decode_all_with_progress(&crate::progress::Reporter(&pb))?;
        pb.finish_and_clear();
        return Ok(mesh);
    }
    let rate = Some(f64::from(decoder.header().frame_rate));
    let positions = frames
        .iter()
        .map(|&f| decoder.decode_frame(f))
        .collect::<Result<Vec<_>>>()?;
    Ok(AnimatedMesh::new(decoder.triangles().to_vec(), positions)?
        .with_attributes(decoder.attributes().clone())?
        .with_frame_rate(rate))
}
