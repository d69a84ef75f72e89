//! `mcgv-video encode`.

use super::achieved::Achieved;
use crate::args::{BitDepth, EncodeArgs, PredictorChoice, SegmentationChoice};
use crate::output::count;
use crate::progress;
use mcgv_video::codec::{Codec, CodecConfig, PictureOptions};
use mcgv_video::encoder::EncodeReport;
use mcgv_video::encoder::DEFAULT_PARALLEL_SEGMENTS;
use mcgv_video::encoder::{self, Budget, BudgetReport, EncodeOptions, Encoded, Segmentation};
use mcgv_video::encoder::{PredictorChoice as Predictor, SegmentationChoice as Segmenting};
use mcgv_video::mesh::ReadOptions;
use mcgv_video::Lattice;
use mcgv_video::PredictorKind;
use mcgv_video::{Error, Result};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Parses the encode arguments into encoder options, rejecting nonsense with a clear message.
pub fn options(args: &EncodeArgs, threads: Option<u64>) -> Result<EncodeOptions> {
    let e0 = args.e0.unwrap_or(mcgv_video::encoder::DEFAULT_E0);
    // Only what the user left unsaid is chosen automatically: `--clusters K` alone is k-means
    // with K, not a candidate the automatic choice may drop for decimation's own K (both
    // --clusters and --e0 name both candidates: auto).
    let choice = args.segmentation.unwrap_or(match (args.clusters, args.e0) {
        (Some(_), None) => SegmentationChoice::Kmeans,
        _ => SegmentationChoice::Auto,
    });
    let segmentation = match choice {
        SegmentationChoice::Kmeans => {
            if args.e0.is_some() {
                return Err(Error::option(
                    "e0",
                    "applies to --segmentation decimation (or auto) only",
                ));
            }
            Segmenting::Fixed(Segmentation::KMeans)
        }
        SegmentationChoice::Decimation => {
            if args.clusters.is_some() {
                return Err(Error::option(
                    "clusters",
                    "applies to --segmentation kmeans (or auto) only: decimation finds K from --e0",
                ));
            }
            Segmenting::Fixed(Segmentation::Decimation { e0 })
        }
        SegmentationChoice::Auto => Segmenting::Auto { e0 },
    };
    let defaults = EncodeOptions::default();
    Ok(EncodeOptions {
        codec: codec_config(args)?,
        quality: args
            .quality
            .map_or(encoder::DEFAULT_QUALITY, |q| q.round() as u8),
        fine_quality: args.quality.filter(|q| q.fract() != 0.0),
        clusters: args.clusters.unwrap_or(defaults.clusters),
        segmentation,
        affine_precision: args.affine_precision,
        reorder: args.reorder,
        first_frame_bits: args.first_frame_bits,
        predictor: match args.predictor {
            PredictorChoice::Affine => Predictor::Fixed(PredictorKind::Affine),
            PredictorChoice::Skinning => Predictor::Fixed(PredictorKind::Skinning),
            PredictorChoice::Auto => Predictor::Auto,
        },
        weight_bits: args.weight_bits,
        step: args.step,
        uv_bits: args.uv_bits,
        segment_frames: match args.segment_frames {
            None => defaults.segment_frames,
            Some(0) => None,
            Some(n) => Some(usize::try_from(n).unwrap_or(usize::MAX)),
        },
        // `--threads N` also codes N segments at once (memory: N segments' working data).
        parallel_segments: threads.map_or(DEFAULT_PARALLEL_SEGMENTS, |n| {
            usize::try_from(n).unwrap_or(1)
        }),
    })
}

/// The codec and its own options from the flags: each flag sets a field of the codec's
/// configuration; a flag of a field the codec has not is a usage error naming the codecs it
/// belongs to (the configurations say which, [`CodecConfig`]).
fn codec_config(args: &EncodeArgs) -> Result<CodecConfig> {
    let lattice = parse_lattice(&args.lattice)?;
    let padding = match &args.padding {
        Some(name) => Some(
            name.parse::<mcgv_video::PaddingMethod>()
                .map_err(|e| Error::option("padding", format!("{name}: {e}")))?,
        ),
        None => None,
    };
    let bit_depth = match args.bit_depth {
        BitDepth::Auto => None,
        BitDepth::Bits(bits) => Some(bits),
    };
    let gop = args.gop.map(|g| usize::try_from(g).unwrap_or(usize::MAX));
    let mut config = CodecConfig::from(args.codec);
    let quantiser = |name: &'static str, value: Option<u8>| {
        move |c: &mut CodecConfig| match c.quantiser_mut() {
            Some((n, q)) if n == name => {
                *q = value;
                true
            }
            _ => false,
        }
    };
    set(
        &mut config,
        "qscale",
        args.qscale.is_some(),
        quantiser("qscale", args.qscale),
    )?;
    set(
        &mut config,
        "qp",
        args.qp.is_some(),
        quantiser("qp", args.qp),
    )?;
    let jpeg = quantiser("jpeg_quality", args.jpeg_quality);
    set(
        &mut config,
        "jpeg_quality",
        args.jpeg_quality.is_some(),
        jpeg,
    )?;
    set(&mut config, "bit_depth", bit_depth.is_some(), |c| {
        c.bit_depth_mut().map(|d| *d = bit_depth).is_some()
    })?;
    set(&mut config, "gop", gop.is_some(), |c| {
        c.gop_mut().zip(gop).map(|(g, gop)| *g = gop).is_some()
    })?;
    let picture = |c: &mut CodecConfig| c.pictures_mut().is_some();
    set(&mut config, "padding", padding.is_some(), picture)?;
    set(&mut config, "lattice", lattice != Lattice::Auto, picture)?;
    if let Some(pictures) = config.pictures_mut() {
        *pictures = PictureOptions { lattice, padding };
    }
    Ok(config)
}

/// Sets `option` of `config` with `apply`, which tells whether the codec has it, when the user
/// gave it; an option the codec has not is a usage error naming the codecs that have it.
fn set(
    config: &mut CodecConfig,
    option: &'static str,
    given: bool,
    apply: impl Fn(&mut CodecConfig) -> bool,
) -> Result<()> {
    if !given || apply(config) {
        return Ok(());
    }
    let takers: Vec<&str> = Codec::ALL
        .into_iter()
        .filter(|c| apply(&mut c.default_config()))
        .map(Codec::name)
        .collect();
    let codec = config.codec();
    Err(Error::option(
        option,
        format!(
            "applies to the {} codec only, not {}{}; add --codec {} or leave it out",
            takers.join(" and "),
            codec.name(),
            if codec == Codec::default() {
                " (the default)"
            } else {
                ""
            },
            takers.first().copied().unwrap_or_default()
        ),
    ))
}

/// Parses `auto` or `WIDTHxHEIGHT`.
pub fn parse_lattice(s: &str) -> Result<Lattice> {
    if s.trim().eq_ignore_ascii_case("auto") {
        return Ok(Lattice::Auto);
    }
    let bad = || {
        Error::option(
            "lattice",
            format!("{s}: expected auto or WIDTHxHEIGHT, e.g. 256x256"),
        )
    };
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    Ok(Lattice::Fixed(
        w.trim().parse().map_err(|_| bad())?,
        h.trim().parse().map_err(|_| bad())?,
    ))
}

/// Runs `encode`: one stream, or with `--clip all` one stream per glTF clip. Every output is
/// checked before any work, and with several clips every stream is coded before any is written.
pub fn run(args: &EncodeArgs, quiet: bool, threads: Option<u64>) -> Result<()> {
    let opts = options(args, threads)?;
    opts.validate()?;
    let read_options: ReadOptions = (&args.input_args).into();
    let to_stdout = args.output.as_os_str() == "-";
    if to_stdout && args.json {
        return Err(Error::option(
            "json",
            "cannot share stdout with the stream of -o -; write the stream to a file",
        ));
    }
    if read_options.clip.as_deref() != Some("all") {
        check_output(args, &read_options, &args.output)?;
        let encoded = encode_one(args, &opts, &read_options, quiet)?;
        return write_and_report(args, &read_options, encoded, &args.output, quiet);
    }
    if !to_stdout {
        // The name given: each clip's name made of it drops a trailing `/` (`-o clips/` would
        // write `clips-NAME.mcgv` beside the folder).
        refuse_mesh_name(&args.output)?;
    }
    let clips = mcgv_video::mesh::clips(&args.input, read_options.fps)?;
    if clips.is_empty() || to_stdout {
        return Err(Error::option(
            "clip",
            "all: needs a glTF input with animations and a file -o (one stream per clip)",
        ));
    }
    let mut jobs = Vec::with_capacity(clips.len());
    for (clip, output) in clips.iter().zip(clip_outputs(&args.output, &clips)) {
        let read = ReadOptions {
            clip: Some(clip.index.to_string()),
            ..read_options.clone()
        };
        check_output(args, &read, &output)?;
        jobs.push((read, output));
    }
    let mut encoded = Vec::with_capacity(jobs.len());
    for (read, output) in jobs {
        encoded.push((encode_one(args, &opts, &read, quiet)?, read, output));
    }
    for (encoded, read, output) in encoded {
        write_and_report(args, &read, encoded, &output, quiet)?;
    }
    Ok(())
}

/// Checks `output` before any work: not an input file, not a mesh's name or a folder
/// ([`refuse_mesh_name`]), not a file that exists unless `--force`,
/// in a folder that takes files (stdout needs no check).
fn check_output(args: &EncodeArgs, read: &ReadOptions, output: &Path) -> Result<()> {
    if output.as_os_str() == "-" {
        return Ok(());
    }
    // An input named as the output is the graver slip, so it is the one reported.
    crate::staging::Inputs::of(&[&args.input], read).refuse(output)?;
    refuse_mesh_name(output)?;
    crate::staging::check_file(output, args.force)
}

/// `encode` writes one stream file. An output named as a folder (`out/`) or as an animation
/// (`walk.glb`, `walk.obj`, `walk.pc2`) is a slip for `decode` or `convert`, or a missing file
/// name: refused before any work instead of an `.mcgv` stream under a mesh's name, or a failure
/// to write once the encode is done.
fn refuse_mesh_name(output: &Path) -> Result<()> {
    let text = output.to_string_lossy();
    if text.ends_with('/') || text.ends_with(std::path::MAIN_SEPARATOR) {
        return Err(Error::option(
            "output",
            format!(
                "{text} names a folder; encode writes one stream file: name it, e.g. \
                 {text}walk.mcgv"
            ),
        ));
    }
    let extension = output
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    match extension.as_deref() {
        Some(mesh @ ("glb" | "gltf" | "obj" | "pc2")) => Err(Error::option(
            "output",
            format!(
                "{}: encode writes an .mcgv stream, not a .{mesh}; name the output {}, and \
                 `mcgv-video decode` it to a .{mesh}",
                output.display(),
                output.with_extension("mcgv").display()
            ),
        )),
        _ => Ok(()),
    }
}

/// One distinct output per clip. Cleaned names can clash (two unnamed clips named by index beside
/// a clip named `1`, `a/b` beside `a_b`, names equal but for case on a case-blind file system),
/// and each stream would then silently replace the one before: a clip whose name is taken gets
/// its index appended (`fox-Walk-3.mcgv`), again until the name is free.
fn clip_outputs(output: &Path, clips: &[mcgv_video::mesh::Clip]) -> Vec<PathBuf> {
    let mut taken = std::collections::HashSet::new();
    clips
        .iter()
        .map(|clip| {
            let mut name = match clip.name.is_empty() {
                true => clip.index.to_string(),
                false => clip.name.clone(),
            };
            let mut path = clip_output(output, &name);
            while !taken.insert(path.to_string_lossy().to_lowercase()) {
                name = format!("{name}-{}", clip.index);
                path = clip_output(output, &name);
            }
            path
        })
        .collect()
}

/// `fox.mcgv` for clip `Walk` → `fox-Walk.mcgv` (characters a file name cannot hold become `_`).
fn clip_output(output: &Path, clip: &str) -> PathBuf {
    let clean: String = clip
        .chars()
        .map(|c| {
            if c.is_alphanumeric() || "-_.".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect();
    let stem = output.file_stem().unwrap_or_default().to_string_lossy();
    let extension = output
        .extension()
        .map_or("mcgv".into(), |e| e.to_string_lossy());
    output.with_file_name(format!("{stem}-{clean}.{extension}"))
}

/// Encodes one animation, timed.
fn encode_one(
    args: &EncodeArgs,
    opts: &EncodeOptions,
    read_options: &ReadOptions,
    quiet: bool,
) -> Result<Coded> {
    let start = Instant::now();
    let (encoded, search) = match budget(args) {
        None => (encode_streaming(args, opts, read_options, quiet)?, None),
        Some(budget) => {
            let mesh = super::read_input(&args.input, read_options, quiet)?;
            let spin = progress::spinner("budget search", quiet);
            let found = encoder::encode_to_budget(&mesh, opts, budget);
            spin.finish_and_clear();
            let found = found?;
            (found.encoded, Some(found.search))
        }
    };
    Ok(Coded {
        encoded,
        start,
        search,
    })
}

/// One encoding, when it started, and its budget search if it had one.
struct Coded {
    encoded: Encoded,
    start: Instant,
    search: Option<BudgetReport>,
}

/// Writes a stream to `output` (a file, or stdout for `-`) and reports it, with the error of
/// the file written (read from `input` with `read`) unless the stream went to stdout.
fn write_and_report(
    args: &EncodeArgs,
    read: &ReadOptions,
    coded: Coded,
    output: &Path,
    quiet: bool,
) -> Result<()> {
    let Coded {
        encoded,
        start,
        search,
    } = coded;
    let to_stdout = output.as_os_str() == "-";
    if to_stdout {
        write_stdout_bytes(&encoded.to_bytes())?;
    } else {
        crate::staging::in_new_parent(output, || encoded.container.write_atomic(output))?;
    }
    let seconds = start.elapsed().as_secs_f64();
    let achieved = match (to_stdout, quiet && !args.json) {
        (false, false) => {
            let spin = progress::spinner("measuring the error of the file written", quiet);
            let achieved =
                super::achieved::measure(&args.input, read, output, args.input_args.max_positions);
            spin.finish_and_clear();
            Some(achieved.map_err(|e| super::in_file(output, e))?)
        }
        _ => None,
    };
    let r = &encoded.report;
    if args.json {
        return outln!("{}", report_json(r, seconds, achieved, search.as_ref())?);
    }
    if quiet {
        return Ok(());
    }
    let place = match to_stdout {
        true => "stdout".to_string(),
        false => output.display().to_string(),
    };
    let line = report_text(r, (&place, seconds), search.as_ref(), achieved);
    // With `-o -` stdout carries the stream: the report goes to stderr.
    if to_stdout {
        eprintln!("{line}");
        Ok(())
    } else {
        outln!("{line}")
    }
}

/// `encode --json`'s object: the report, the seconds taken, the error of the file written and
/// the budget search.
fn report_json(
    r: &EncodeReport,
    seconds: f64,
    achieved: Option<Achieved>,
    search: Option<&BudgetReport>,
) -> Result<serde_json::Value> {
    let mut value = serde_json::to_value(r).map_err(|e| Error::Usage(e.to_string()))?;
    value["seconds"] = serde_json::json!(seconds);
    value["vertices"] = serde_json::json!(r.header.vertices);
    value["frames"] = serde_json::json!(r.header.frames);
    value["achieved"] = serde_json::json!(achieved);
    if let Some(search) = search {
        value["budget"] = serde_json::to_value(search).map_err(|e| Error::Usage(e.to_string()))?;
    }
    Ok(value)
}

/// `encode`'s plain report of the stream written to `place` in `seconds`.
fn report_text(
    r: &EncodeReport,
    (place, seconds): (&str, f64),
    search: Option<&BudgetReport>,
    achieved: Option<Achieved>,
) -> String {
    // HEVC's and AV1's depth: the automatic one turns with the residuals (JPEG's and MPEG-4's 8
    // bits go unsaid).
    let charts = match r.picture_depth {
        Some(depth) if depth > 8 => {
            format!("{}, {depth}-bit pictures", count(r.charts as u64, "chart"))
        }
        _ => count(r.charts as u64, "chart"),
    };
    let line = format!(
        "{}: {} bytes, {:.3} bpvf ({} vertices x {}, {} by {} in {:.2} s, {} predictor, {}), {:.1} s ({:.1} frames/s)",
        place,
        r.bytes,
        r.bpvf,
        r.header.vertices,
        count(r.header.frames, "frame"),
        count(r.header.clusters, "cluster"),
        r.segmentation.method,
        r.segmentation.seconds,
        r.header.predictor.name(),
        charts,
        seconds,
        r.header.frames as f64 / seconds.max(1e-9)
    );
    let line = match search {
        Some(search) => format!("{line}\n{}", budget_line(search)),
        None => line,
    };
    let line = match &r.choice {
        // No trial (the estimates left one candidate): no trial size to tell apart from the file's.
        Some(choice) if choice.trial_frames == 0 && choice.candidates.len() == 1 => {
            format!("{line}\nauto: kept {}, {}", choice.chosen, choice.reason)
        }
        Some(choice) => format!(
            "{line}\nauto: kept {} of {} candidates: {}{}",
            choice.chosen,
            choice.candidates.len(),
            choice.reason,
            trial_size_note(choice, r)
        ),
        None => line,
    };
    let line = match achieved {
        Some(a) => format!("{line}\n{}", a.line()),
        None => line,
    };
    let line = match r.segments {
        1 => line,
        n => format!("{line}\nsegments: {n}, coded with the first segment's choices"),
    };
    match r.first_frame_trials.as_slice() {
        [] => line,
        trials => {
            let tried: Vec<String> = trials
                .iter()
                .map(|t| format!("{} bits {} bytes", t.bits, t.bytes))
                .collect();
            format!(
                "{line}\nfirst frame: kept {} bits of {}",
                r.header.first_frame_bits,
                tried.join(", ")
            )
        }
    }
}

/// The budget of the `--target-*` flag given (clap lets at most one through).
fn budget(args: &EncodeArgs) -> Option<Budget> {
    let targets = (
        args.target_size,
        args.target_bpvf,
        args.target_error,
        args.target_max_error,
    );
    match targets {
        (Some(bytes), ..) => Some(Budget::Bytes(bytes)),
        (_, Some(x), ..) => Some(Budget::Bpvf(x)),
        (_, _, Some(e), _) => Some(Budget::VertexRmse(e)),
        (_, _, _, Some(e)) => Some(Budget::MaxVertexError(e)),
        _ => None,
    }
}

/// Encodes reading the input a run of frames at a time (a long clip is never held whole).
fn encode_streaming(
    args: &EncodeArgs,
    opts: &EncodeOptions,
    read_options: &ReadOptions,
    quiet: bool,
) -> Result<Encoded> {
    let spin = progress::spinner("reading", quiet);
    let source = super::open_source(&args.input, read_options, quiet);
    spin.finish_and_clear();
    let mut source = source?;
    let pb = progress::bar(source.frame_count() as u64, "encode", quiet);
    let encoded = encoder::encode_source(&mut source, opts, &progress::Reporter(&pb))?;
    pb.finish_and_clear();
    Ok(encoded)
}

/// `budget: vertex RMSE <= 2.0000e-4: quality 62.91 in 2 encodes (q50 31879 bytes, q62.91 35147
/// bytes); kept 35147 bytes at vertex RMSE 1.9907e-4, largest vertex error 8.4022e-4; model ...`.
fn budget_line(search: &BudgetReport) -> String {
    let kept = search.trials.iter().find(|t| t.quality == search.quality);
    let (bound, what) = match search.budget {
        Budget::Bytes(_) | Budget::Bpvf(_) => (format!("{}", search.limit), "bytes"),
        Budget::VertexRmse(_) => (format!("{:.4e}", search.limit), "vertex RMSE"),
        Budget::MaxVertexError(_) => (format!("{:.4e}", search.limit), "largest vertex error"),
    };
    let trials: Vec<String> = search
        .trials
        .iter()
        .map(
            |t| match t.vertex_rmse.filter(|_| !matches!(what, "bytes")) {
                Some(e) => format!(
                    "q{}{} {} bytes {e:.4e}",
                    t.quality,
                    depth(t.bit_depth),
                    t.bytes
                ),
                None => format!("q{}{} {} bytes", t.quality, depth(t.bit_depth), t.bytes),
            },
        )
        .collect();
    let kept = kept.map_or(String::new(), |t| {
        format!(
            "kept {} bytes at vertex RMSE {:.4e}, largest vertex error {:.4e}",
            t.bytes,
            t.vertex_rmse.unwrap_or(f64::NAN),
            t.max_vertex_error.unwrap_or(f64::NAN)
        )
    });
    format!(
        "budget: {what} <= {bound}: quality {}{} in {} encodes ({}); {kept}{}; model kept from the \
         first encode: {}",
        search.quality,
        depth(search.bit_depth),
        search.encodes,
        trials.join(", "),
        if search.within_tolerance {
            ""
        } else {
            " (not within the tolerance: the closest under the budget found)"
        },
        search.model
    )
}

/// HEVC's and AV1's bits a sample as a budget line names them (` 12-bit`), nothing for the others.
fn depth(bit_depth: Option<u8>) -> String {
    bit_depth.map_or_else(String::new, |d| format!(" {d}-bit"))
}

/// The candidates' sizes are their trials' (estimated from a sample of frames, or before the
/// first frame's precision was chosen): when the kept one's is not the file's, says so, so that
/// the report never leaves a size that is not the file's unexplained.
fn trial_size_note(choice: &encoder::ChoiceReport, r: &encoder::EncodeReport) -> String {
    let kept = choice.candidates.iter().find(|c| {
        format!("{}+{}", c.predictor.name(), c.segmentation) == choice.chosen
            && c.clusters == r.header.clusters as usize
    });
    match kept {
        Some(c) if c.bytes != r.bytes => format!(
            " (trial sizes; the file written is {} bytes{})",
            r.bytes,
            if r.first_frame_trials.is_empty() {
                ""
            } else {
                ", its first frame's precision chosen after"
            }
        ),
        _ => String::new(),
    }
}

/// The stream's bytes on stdout (a closed pipe is reported like any write to stdout).
fn write_stdout_bytes(bytes: &[u8]) -> Result<()> {
    use std::io::Write;
    let mut stdout = std::io::stdout().lock();
    stdout
        .write_all(bytes)
        .and_then(|()| stdout.flush())
        .map_err(|e| Error::io("stdout", e))
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
