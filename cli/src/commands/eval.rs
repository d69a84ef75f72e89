//! `mcgv-video eval`: the error measures of one animation against another.

use crate::args::EvalArgs;
use crate::progress;
use mcgv_video::mesh::{AnimatedMesh, FrameSource, ReadOptions};
use mcgv_video::metrics::{same_frame_count, Comparison, Measures, Surface};
use mcgv_video::Decoder;
use mcgv_video::{Error, Result};
use std::fs::File;
use std::io::BufReader;
use std::path::Path;

/// Runs `eval`.
pub fn run(args: &EvalArgs, quiet: bool) -> Result<()> {
    let opts: ReadOptions = (&args.input_args).into();
    let measures = if is_mcgv(&args.decoded) {
        let mut original = super::open_source(&args.original, &opts, quiet)?;
        let options = super::decode::decode_options(args.bands, args.input_args.max_positions);
        let path = Path::new(&args.decoded);
        let mut decoder =
            Decoder::open_with(path, &options).map_err(|e| super::in_file(path, e))?;
        super::decode::warn_if_truncated(&decoder, args.bands);
        let bits = bits_read(&decoder, args.bands.is_some());
        compare_stream(&mut original, &mut decoder, quiet)
            .map_err(|e| super::in_file(path, e))?
            .with_bits(bits)
    } else {
        if args.bands.is_some() {
            return Err(Error::option(
                "max_bands",
                "applies to a .mcgv stream of codec tdct",
            ));
        }
        let mut original = super::open_source(&args.original, &opts, quiet)?;
        // --clip names the original's clip: a decoded glTF holds one clip (`frames`), whatever
        // the original's was called.
        let decoded_opts = ReadOptions {
            clip: None,
            ..opts.clone()
        };
        let mut decoded = super::open_source(&args.decoded, &decoded_opts, true)?;
        compare_sources(&mut original, &mut decoded)?
    };
    if args.json {
        let json = serde_json::to_string(&measures)
            .map_err(|e| Error::Usage(format!("cannot write the measures as JSON: {e}")))?;
        outln!("{json}")
    } else {
        out!("{}", report(&measures))
    }
}

/// The measures of a stream against its original, a segment of each at a time: memory holds one
/// segment of both, whatever the clip's length.
fn compare_stream(
    original: &mut FrameSource,
    decoder: &mut Decoder<BufReader<File>>,
    quiet: bool,
) -> Result<Measures> {
    let frames = original.frame_count();
    same_frame_count(frames, decoder.header().frames as usize)?;
    let order = decoder.input_order(original.first())?;
    let pb = progress::bar(frames as u64, "decode", quiet);
    let mut comparison: Option<Comparison> = None;
    for (s, range) in decoder.segments().to_vec().into_iter().enumerate() {
        let positions = decoder.decode_segment(s, &crate::progress::Reporter(&pb))?;
        let mut decoded = AnimatedMesh::new(decoder.triangles().to_vec(), positions)?;
        if let Some(inverse) = &order {
            decoded = decoded.permuted(inverse)?;
        }
        let originals = original.read(range)?;
        let comparison = match &mut comparison {
            Some(c) => c,
            None => comparison.insert(Comparison::new(
                Surface {
                    triangles: original.first().triangles(),
                    positions: &originals[0],
                },
                Surface {
                    triangles: decoded.triangles(),
                    positions: decoded.frame(0),
                },
            )?),
        };
        comparison.add(&originals, decoded.frames())?;
    }
    pb.finish_and_clear();
    comparison
        .map(Comparison::finish)
        .ok_or_else(|| Error::Stream("the stream has no frames".into()))
}

/// The measures of two animations read a run of frames at a time (OBJ and PC2 inputs are never
/// held whole).
fn compare_sources(original: &mut FrameSource, decoded: &mut FrameSource) -> Result<Measures> {
    let frames = original.frame_count();
    same_frame_count(frames, decoded.frame_count())?;
    let mut comparison = Comparison::new(first_surface(original), first_surface(decoded))?;
    let run = mcgv_video::encoder::DEFAULT_SEGMENT_FRAMES;
    for start in (0..frames).step_by(run) {
        let range = start..(start + run).min(frames);
        comparison.add(&original.read(range.clone())?, &decoded.read(range)?)?;
    }
    Ok(comparison.finish())
}

/// The bits the comparison stands on: the file's, less with `--bands` (`preview`) the bands it
/// left unread, so that a preview's bpvf is the preview's (of a one-segment stream; a segmented
/// one is charged whole, its other segments' bands being unknown until opened).
fn bits_read(decoder: &Decoder<BufReader<File>>, preview: bool) -> u64 {
    let unread = match decoder.describe().and_then(|d| d.bands) {
        Some(b) if preview && !decoder.truncated() && decoder.segments().len() == 1 => b.lengths
            [b.decoded.min(b.lengths.len())..]
            .iter()
            .sum::<u64>(),
        _ => 0,
    };
    decoder.file_len().saturating_sub(unread) * 8
}

/// The first frame of an animation as a surface.
fn first_surface(source: &FrameSource) -> Surface<'_> {
    Surface {
        triangles: source.first().triangles(),
        positions: source.first().frame(0),
    }
}

/// Whether a path names a `.mcgv` stream (compared after decoding, with its bpvf).
fn is_mcgv(input: &str) -> bool {
    Path::new(input)
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mcgv"))
}

/// The human-readable lines `eval` prints.
pub fn report(m: &Measures) -> String {
    let mut s = String::new();
    s.push_str(&format!("vertices     {}\n", m.vertices));
    s.push_str(&format!("frames       {}\n", m.frames));
    s.push_str(&format!(
        "RMSE         {:.6e} of the bbox diagonal = {:.4} ×10⁻⁴\n",
        m.rmse,
        m.rmse * 1e4
    ));
    s.push_str(&format!(
        "Hausdorff    {:.6e} of the bbox diagonal = {:.4} ×10⁻⁴\n",
        m.hausdorff,
        m.hausdorff * 1e4
    ));
    match m.vertex_rmse {
        Some(v) => s.push_str(&format!(
            "vertex RMSE  {v:.6e} of the bbox diagonal = {:.4} ×10⁻⁴\n",
            v * 1e4
        )),
        None => s.push_str("vertex RMSE  n/a (the vertex counts differ)\n"),
    }
    match (m.kg_error, m.vertex_rmse) {
        (Some(kg), _) => s.push_str(&format!("KG error     {kg:.6} %\n")),
        (None, Some(_)) => {
            s.push_str("KG error     n/a (the original never leaves its centroid)\n")
        }
        (None, None) => s.push_str("KG error     n/a (the vertex counts differ)\n"),
    }
    if let Some(b) = m.bpvf {
        s.push_str(&format!("bpvf         {b:.4}\n"));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn report_gives_rmse_as_fraction_and_per_ten_thousand() {
        let m = Measures {
            rmse: 1.5e-4,
            vertex_rmse: None,
            kg_error: None,
            hausdorff: 2e-3,
            bpvf: Some(3.25),
            frames: 10,
            vertices: 100,
            frame_rmse: vec![],
        };
        let r = report(&m);
        assert!(
            r.contains("1.500000e-4") && r.contains("1.5000 ×10⁻⁴"),
            "{r}"
        );
        assert!(r.contains("vertex counts differ") && r.contains("bpvf         3.2500"));
    }

    #[test]
    fn mcgv_streams_are_recognised_by_extension() {
        assert!(!is_mcgv("frames/"));
        assert!(is_mcgv("out.MCGV"));
        assert!(!is_mcgv("walk.glb"));
    }
}
