//! `mcgv-video encode`.

use crate::args::{CodecChoice, EncodeArgs, PredictorChoice, SegmentationChoice};
use crate::progress;
use mcgv_video::codec::Codec;
use mcgv_video::encoder::{self, EncodeOptions, Segmentation};
use mcgv_video::error::{Error, Result};
use mcgv_video::mesh::io::input_files;
use mcgv_video::mesh::{read_animation, ReadOptions};
use mcgv_video::motion::PredictorKind;
use mcgv_video::Lattice;
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
    let segmentation = match args.segmentation {
        SegmentationChoice::Kmeans => {
            if args.e0.is_some() {
                return Err(Error::Usage(
                    "--e0 applies to --segmentation decimation only".into(),
                ));
            }
            Segmentation::KMeans
        }
        SegmentationChoice::Decimation => {
            if args.clusters.is_some() {
                return Err(Error::Usage(
                    "--clusters applies to --segmentation kmeans only: decimation finds K from --e0"
                        .into(),
                ));
            }
            Segmentation::Decimation {
                e0: args.e0.unwrap_or(mcgv_video::motion::DEFAULT_E0),
            }
        }
    };
    let defaults = EncodeOptions::default();
    Ok(EncodeOptions {
        codec: match args.codec {
            CodecChoice::Jpeg => Codec::Jpeg,
            CodecChoice::Mpeg4 => Codec::Mpeg4,
            CodecChoice::Tdct => Codec::Tdct,
        },
        quality: args.quality.unwrap_or(encoder::DEFAULT_QUALITY),
        qscale: args.qscale,
        clusters: args.clusters.unwrap_or(defaults.clusters),
        segmentation,
        affine_bits: args.affine_bits,
        lattice,
        padding,
        gop: args.gop,
        reorder: args.reorder,
        predictor: match args.predictor {
            PredictorChoice::Affine => PredictorKind::Affine,
            PredictorChoice::Skinning => PredictorKind::Skinning,
        },
        weight_bits: args.weight_bits,
        range_floor: args.range_floor,
        step: args.step,
        uv_bits: args.uv_bits,
        ..defaults
    })
}

/// Parses `auto` or `WIDTHxHEIGHT`.
pub fn parse_lattice(s: &str) -> Result<Lattice> {
    if s.trim().eq_ignore_ascii_case("auto") {
        return Ok(Lattice::Auto);
    }
    let bad = || {
        Error::Usage(format!(
            "--lattice {s}: expected auto or WIDTHxHEIGHT, e.g. 256x256"
        ))
    };
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    Ok(Lattice::Fixed(
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
    let encoded = encoder::encode_with_progress(&mesh, &opts, &progress::Reporter(&pb))?;
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
            "{}: {} bytes, {:.3} bpvf ({} vertices x {} frames, {} clusters by {} in {:.2} s, {} predictor, {} charts), {:.1} s ({:.1} frames/s)",
            args.output.display(),
            r.bytes,
            r.bpvf,
            r.header.vertices,
            r.header.frames,
            r.header.clusters,
            r.segmentation.method,
            r.segmentation.seconds,
            r.header.predictor.name(),
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
        assert_eq!(parse_lattice("256x128").unwrap(), Lattice::Fixed(256, 128));
        assert_eq!(parse_lattice("auto").unwrap(), Lattice::Auto);
        assert!(parse_lattice("256").is_err());
        assert!(parse_lattice("ax2").is_err());
        assert!(parse_lattice("99999x2").is_err());
    }
}
