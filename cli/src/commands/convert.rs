//! `mcgv-video convert`: an animation in any input form rewritten, unchanged, as a PC2 point cache
//! with its base OBJ, or as an OBJ folder.
//!
//! Outside tools (the peer codecs of `scripts/peers.py`) read PC2 and OBJ easily but cannot bake a
//! skinned or morph-target glTF the way this tool does; converting through the same reader that
//! `encode` and `eval` use makes every codec start from exactly the frames mcgv-video sees.
//! Positions are `f32` in both forms, so nothing is lost.

use crate::args::ConvertArgs;
use crate::output::animation_output;
use crate::staging::{in_new_parent, Inputs};
use crate::target::{finish_pc2_pair, Target};
use mcgv_video::mesh::is_gltf_path;
use mcgv_video::mesh::{write_gltf, write_pc2, GltfOptions, ObjFrameWriter, ReadOptions};
use mcgv_video::Result;

/// Runs `convert`.
pub fn run(args: &ConvertArgs, quiet: bool) -> Result<()> {
    let kind = animation_output(&args.output, false)?;
    let read = ReadOptions::from(&args.input_args);
    let inputs = Inputs::of(&[&args.input], &read);
    // The outputs are checked before the input is read (a folder's frame names once it is).
    drop(Target::prepare(
        &args.output,
        kind,
        (Vec::new(), 0),
        args.force,
        &inputs,
    )?);
    let mesh = super::read_input(&args.input, &read, quiet)?;
    let count = mesh.frame_count();
    let span = ((0..count).collect(), count.saturating_sub(1));
    match Target::prepare(&args.output, kind, span, args.force, &inputs)? {
        Target::Pc2 { cache, base } => in_new_parent(&cache, || {
            finish_pc2_pair(&mesh, &base, || write_pc2(&mesh, &cache))
        })?,
        Target::Gltf(path) => {
            super::decode::warn_if_many_targets(count);
            // A glTF source lends its materials and textures to the rewritten asset.
            let source = std::path::Path::new(&args.input);
            let options = GltfOptions {
                fps: args
                    .input_args
                    .fps
                    .or(mesh.frame_rate())
                    .unwrap_or(mcgv_video::mesh::DEFAULT_FPS),
                like: (is_gltf_path(source) && source.is_file()).then(|| source.to_path_buf()),
                ..GltfOptions::default()
            };
            in_new_parent(&path, || {
                write_gltf(&mesh, Some(mesh.attributes()), &path, &options)
            })?;
        }
        Target::Folder { staged, last } => {
            let writer =
                ObjFrameWriter::new(staged.path(), last, mesh.triangles(), mesh.attributes())?;
            for (f, positions) in mesh.frames().iter().enumerate() {
                writer.write(f, positions)?;
            }
            staged.commit_and_tell(quiet)?;
        }
        Target::ObjFile(path) => {
            return Err(mcgv_video::Error::option(
                "output",
                format!("{}: convert writes a whole animation", path.display()),
            ))
        }
    }
    if !quiet {
        outln!(
            "{}: {} frame{} of {} vertices",
            args.output.display(),
            count,
            if count == 1 { "" } else { "s" },
            mesh.vertex_count()
        )?;
    }
    Ok(())
}
