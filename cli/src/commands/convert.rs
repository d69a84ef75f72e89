//! `mcgv-video convert`: an animation in any input form rewritten, unchanged, as a PC2 point cache
//! with its base OBJ, or as an OBJ folder.
//!
//! Outside tools (the peer codecs of `scripts/peers.py`) read PC2 and OBJ easily but cannot bake a
//! skinned or morph-target glTF the way this tool does; converting through the same reader that
//! `encode` and `eval` use makes every codec start from exactly the frames mcgv-video sees.
//! Positions are `f32` in both forms, so nothing is lost.

use crate::args::ConvertArgs;
use crate::output::{
    animation_output, create_parent, prepare_frame_folder, write_pc2_with_base, OutputKind,
};
use mcgv_video::mesh::is_gltf_path;
use mcgv_video::mesh::{write_gltf, write_obj_sequence, GltfOptions, ReadOptions};
use mcgv_video::Result;

/// Runs `convert`.
pub fn run(args: &ConvertArgs, quiet: bool) -> Result<()> {
    let kind = animation_output(&args.output, false)?;
    let mesh = super::read_input(&args.input, &ReadOptions::from(&args.input_args), quiet)?;
    match kind {
        OutputKind::Pc2 => {
            write_pc2_with_base(&mesh, &args.output, Some(&args.input))?;
        }
        OutputKind::Gltf => {
            create_parent(&args.output)?;
            super::decode::warn_if_many_targets(mesh.frame_count());
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
            write_gltf(&mesh, Some(mesh.attributes()), &args.output, &options)?;
        }
        OutputKind::ObjFolder | OutputKind::ObjFile => {
            prepare_frame_folder(&args.output, args.force)?;
            write_obj_sequence(&mesh, &args.output)?;
        }
    }
    if !quiet {
        outln!(
            "{}: {} frame(s) of {} vertices",
            args.output.display(),
            mesh.frame_count(),
            mesh.vertex_count()
        )?;
    }
    Ok(())
}
