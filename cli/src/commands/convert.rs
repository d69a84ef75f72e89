//! `mcgv-video convert`: an animation in any input form rewritten, unchanged, as a PC2 point cache
//! with its base OBJ, or as an OBJ folder.
//!
//! Outside tools (the peer codecs of `scripts/peers.py`) read PC2 and OBJ easily but cannot bake a
//! skinned or morph-target glTF the way this tool does; converting through the same reader that
//! `encode` and `eval` use makes every codec start from exactly the frames mcgv-video sees.
//! Positions are `f32` in both forms, so nothing is lost.

use crate::args::ConvertArgs;
use mcgv_video::error::{Error, Result};
use mcgv_video::mesh::gltf_write::is_gltf_path;
use mcgv_video::mesh::{
    read_animation, write_gltf, write_obj_frame, write_obj_sequence, write_pc2, GltfOptions,
    ReadOptions,
};
use std::path::Path;

/// Whether the output path names a PC2 point cache rather than an OBJ folder.
fn is_pc2(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("pc2"))
}

/// Runs `convert`.
pub fn run(args: &ConvertArgs, quiet: bool) -> Result<()> {
    let mesh = read_animation(&args.input, &ReadOptions::from(&args.input_args))?;
    if is_gltf_path(&args.output) {
        super::decode::warn_if_many_targets(mesh.frame_count());
        let options = GltfOptions {
            fps: args.input_args.fps.unwrap_or(30.0),
            ..GltfOptions::default()
        };
        write_gltf(&mesh, Some(mesh.attributes()), &args.output, &options)?;
    } else if is_pc2(&args.output) {
        // A PC2 holds no faces: the base OBJ beside it (same stem) is what `--base` defaults to.
        let base = args.output.with_extension("obj");
        if Path::new(&args.input) == base {
            return Err(Error::Usage(format!(
                "{}: writing the base OBJ would overwrite the input",
                base.display()
            )));
        }
        write_obj_frame(mesh.triangles(), mesh.frame(0), &base)?;
        write_pc2(&mesh, &args.output)?;
    } else {
        write_obj_sequence(&mesh, &args.output)?;
    }
    if !quiet {
        println!(
            "{}: {} frame(s) of {} vertices",
            args.output.display(),
            mesh.frame_count(),
            mesh.vertex_count()
        );
    }
    Ok(())
}
