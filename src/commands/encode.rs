//! `mcgv-video encode`.

use crate::cli::{CodecChoice, EncodeArgs};
use crate::encoder::{self, EncodeOptions};
use crate::error::{Error, Result};
use crate::mesh::io::input_files;
use crate::mesh::{read_animation, ReadOptions};
use crate::progress;
use crate::stream::header::CodecKind;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Parses the encode arguments into encoder options, rejecting nonsense with a clear message.
pub fn options(args: &EncodeArgs) -> Result<EncodeOptions> {
    let lattice = parse_lattice(&args.lattice)?;
    let padding = match &args.padding {
        Some(name) => Some(
            name.parse::<padding::Method>()
                .map_err(|e| Error::Usage(format!("--padding {name}: {e}")))?,
        ),
        None => None,
    };
    Ok(EncodeOptions {
        codec: match args.codec {
            CodecChoice::Jpeg => CodecKind::Jpeg,
            CodecChoice::Mpeg4 => CodecKind::Mpeg4,
        },
        quality: args.quality.unwrap_or(encoder::DEFAULT_QUALITY),
        qscale: args.qscale,
        clusters: args.clusters,
        affine_bits: args.affine_bits,
        lattice,
        padding,
        gop: args.gop,
        reorder: args.reorder,
        ..EncodeOptions::default()
    })
}

/// Parses `WIDTHxHEIGHT`.
pub fn parse_lattice(s: &str) -> Result<(u16, u16)> {
    let bad = || {
        Error::Usage(format!(
            "--lattice {s}: expected WIDTHxHEIGHT, e.g. 256x256"
        ))
    };
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    Ok((
        w.trim().parse().map_err(|_| bad())?,
        h.trim().parse().map_err(|_| bad())?,
    ))
}

/// Refuses to write the output over the input or any file it is read from (a frame of an OBJ folder
/// or glob, the base OBJ of a PC2 cache, a glTF's buffer), comparing canonical paths so that links
/// and `./` spellings cannot sneak past. An output that does not exist yet cannot be an input.
fn check_not_input(input: &str, opts: &ReadOptions, output: &Path) -> Result<()> {
    let Ok(target) = output.canonicalize() else {
        return Ok(());
    };
    let mut inputs = vec![PathBuf::from(input)];
    // Listing fails for inputs that do not exist or are not readable; reading reports that.
    inputs.extend(input_files(input, opts).unwrap_or_default());
    if inputs
        .iter()
        .any(|p| p.canonicalize().is_ok_and(|p| p == target))
    {
        return Err(Error::Usage(format!(
            "refusing to overwrite the input {}",
            output.display()
        )));
    }
    Ok(())
}

/// Runs `encode`.
pub fn run(args: &EncodeArgs, quiet: bool) -> Result<()> {
    let opts = options(args)?;
    let read_options: ReadOptions = (&args.input_args).into();
    check_not_input(&args.input, &read_options, &args.output)?;
    let start = Instant::now();
    let spin = progress::spinner("reading", quiet);
    let mesh = read_animation(&args.input, &read_options)?;
    spin.finish_and_clear();
    let pb = progress::bar(mesh.frame_count() as u64, "encode", quiet);
    let encoded = encoder::encode(&mesh, &opts, &pb)?;
    pb.finish_and_clear();
    encoded.container.write_atomic(&args.output)?;
    let seconds = start.elapsed().as_secs_f64();
    let r = &encoded.report;
    if args.json {
        let mut value = serde_json::to_value(r).map_err(|e| Error::Usage(e.to_string()))?;
        value["seconds"] = serde_json::json!(seconds);
        value["vertices"] = serde_json::json!(r.header.vertices);
        value["frames"] = serde_json::json!(r.header.frames);
        println!("{value}");
    } else if !quiet {
        println!(
            "{}: {} bytes, {:.3} bpvf ({} vertices x {} frames, {} clusters, {} charts), {:.1} s ({:.1} frames/s)",
            args.output.display(),
            r.bytes,
            r.bpvf,
            r.header.vertices,
            r.header.frames,
            r.header.clusters,
            r.charts,
            seconds,
            r.header.frames as f64 / seconds.max(1e-9)
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lattice_parsing() {
        assert_eq!(parse_lattice("256x128").unwrap(), (256, 128));
        assert!(parse_lattice("256").is_err());
        assert!(parse_lattice("ax2").is_err());
        assert!(parse_lattice("99999x2").is_err());
    }
}
