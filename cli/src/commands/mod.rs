//! One module per subcommand: each turns parsed arguments into work and prints the result.

pub mod achieved;
pub mod convert;
pub mod decode;
pub mod encode;
pub mod eval;
pub mod info;
pub mod inspect;

use mcgv_video::mesh::{clips, read_animation, AnimatedMesh, Clip, FrameSource, ReadOptions};
use mcgv_video::{Error, Result};
use std::path::Path;

/// An animation's frames as `encode` and `eval` read them: OBJ sequences and PC2 caches a run of
/// frames at a time (a long clip is never held whole), a glTF clip baked whole by [`read_input`].
pub fn open_source(input: &str, opts: &ReadOptions, quiet: bool) -> Result<FrameSource> {
    not_a_stream(input)?;
    let gltf = [".gltf", ".glb"]
        .iter()
        .any(|e| input.to_ascii_lowercase().ends_with(e));
    if gltf {
        return FrameSource::from_mesh(read_input(input, opts, quiet)?);
    }
    FrameSource::open(input, opts).map_err(|e| in_file(input, e))
}

/// Reads an animation as every command does; a glTF with several clips read without `--clip` says
/// on stderr which clip it took and how to pick another (unless `quiet`).
pub fn read_input(input: &str, opts: &ReadOptions, quiet: bool) -> Result<AnimatedMesh> {
    not_a_stream(input)?;
    if opts.clip.as_deref() == Some("all") {
        return Err(Error::option(
            "clip",
            "all: only `encode` takes every clip (one stream each); name one clip here",
        ));
    }
    let mesh = read_animation(input, opts).map_err(|e| in_file(input, e))?;
    if opts.clip.is_none() && !quiet {
        let clips = clips(input, opts.fps).unwrap_or_default();
        if clips.len() > 1 {
            eprintln!(
                "mcgv-video: {input} has {} clips ({}); took clip 0 `{}`. Pick one with --clip \
                 NAME|INDEX, or encode --clip all for one stream each",
                clips.len(),
                clip_list(&clips),
                clips[0].name,
            );
        }
    }
    Ok(mesh)
}

/// Where an animation is expected, a `.mcgv` stream is a usage error that names the commands
/// that read streams (rather than listing the mesh forms it is not).
fn not_a_stream(input: &str) -> Result<()> {
    if Path::new(input)
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mcgv"))
    {
        return Err(Error::Usage(format!(
            "{input} is a .mcgv stream, not an animation: `mcgv-video inspect {input}` describes \
             it, `mcgv-video decode {input} -o DIR/` writes its frames"
        )));
    }
    Ok(())
}

/// `0 Survey (84 frames at 24 fps), 1 Walk (…)`.
pub fn clip_list(clips: &[Clip]) -> String {
    clips
        .iter()
        .map(|c| {
            format!(
                "{} `{}` ({} frames at {} fps)",
                c.index, c.name, c.frames, c.fps
            )
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// A stream error named after its file: `corrupt stream` alone does not say which input it was.
pub fn in_file(path: impl AsRef<Path>, e: Error) -> Error {
    match e {
        Error::Stream(message) => Error::Stream(format!("{}: {message}", path.as_ref().display())),
        e => e,
    }
}
