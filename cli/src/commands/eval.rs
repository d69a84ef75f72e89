//! `mcgv-video eval`: the error measures of one animation against another.

use crate::args::EvalArgs;
use crate::progress;
use indicatif::ProgressBar;
use mcgv_video::mesh::Point;
use mcgv_video::mesh::{AnimatedMesh, FrameSource, ReadOptions};
use mcgv_video::metrics::{
    bpvf, same_frame_count, Comparison, FrameSampling, Measures, Surface, VertexSums,
    DEFAULT_RELATIVE_ERROR,
};
use mcgv_video::Decoder;
use mcgv_video::{Error, Result};
use serde::Serialize;
use std::fs::File;
use std::io::BufReader;
use std::path::Path;

/// Runs `eval`.
pub fn run(args: &EvalArgs, quiet: bool) -> Result<()> {
    let opts: ReadOptions = (&args.input_args).into();
    let sampling = if args.every_frame {
        FrameSampling::Every
    } else {
        FrameSampling::Converged {
            relative_error: DEFAULT_RELATIVE_ERROR,
        }
    };
    let tally = Tally::new(args.fast, sampling);
    let result = if is_mcgv(&args.decoded) {
        let mut original = super::open_source(&args.original, &opts, quiet)?;
        let options = super::decode::decode_options(args.bands, args.input_args.max_positions);
        let path = Path::new(&args.decoded);
        let mut decoder =
            Decoder::open_with(path, &options).map_err(|e| super::in_file(path, e))?;
        super::decode::warn_if_truncated(&decoder, args.bands);
        let bits = bits_read(&decoder, args.bands.is_some());
        compare_stream(&mut original, &mut decoder, tally, quiet)
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
        compare_sources(&mut original, &mut decoded, tally, quiet)?
    };
    if args.json {
        let json = match &result {
            Outcome::Full(m) => serde_json::to_string(m),
            Outcome::Fast(m) => serde_json::to_string(m),
        }
        .map_err(|e| Error::Usage(format!("cannot write the measures as JSON: {e}")))?;
        outln!("{json}")
    } else {
        match &result {
            Outcome::Full(m) => out!("{}", report(m)),
            Outcome::Fast(m) => out!("{}", fast_report(m)),
        }
    }
}

/// The measures `eval --fast` gives: the vertex ones, which need no surface distances.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FastMeasures {
    /// RMS vertex displacement over the original's first-frame bbox diagonal.
    pub vertex_rmse: f64,
    /// Karni–Gotsman error, percent (`None` when the original never leaves its centroids).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub kg_error: Option<f64>,
    /// Bits per vertex per frame of the stream, when there is one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bpvf: Option<f64>,
    /// Frames compared.
    pub frames: usize,
    /// Vertices of the original.
    pub vertices: usize,
}

/// What `eval` accumulates, a run of frames at a time: every measure, or the vertex ones.
enum Tally {
    /// Which frames to measure in full, and the comparison once started.
    Full(FrameSampling, Option<Box<Comparison>>),
    /// Running sums, the original's first-frame diagonal, vertices, frames so far.
    Fast(Option<(VertexSums, f64, usize, usize)>),
}

/// What `eval` found.
enum Outcome {
    Full(Measures),
    Fast(FastMeasures),
}

impl Outcome {
    fn with_bits(self, bits: u64) -> Self {
        match self {
            Self::Full(m) => Self::Full(m.with_bits(bits)),
            Self::Fast(mut m) => {
                m.bpvf = Some(bpvf(bits, m.vertices, m.frames));
                Self::Fast(m)
            }
        }
    }
}

impl Tally {
    fn new(fast: bool, sampling: FrameSampling) -> Self {
        if fast {
            Self::Fast(None)
        } else {
            Self::Full(sampling, None)
        }
    }

    /// Sets the comparison up from the two first frames, unless done already.
    fn start(&mut self, original: Surface<'_>, decoded: Surface<'_>) -> Result<()> {
        match self {
            Self::Full(sampling, c @ None) => {
                let comparison = Comparison::new(original, decoded)?.with_frame_sampling(*sampling);
                *c = Some(Box::new(comparison))
            }
            Self::Fast(f @ None) => {
                let (v, w) = (original.positions.len(), decoded.positions.len());
                if v != w {
                    return Err(Error::Usage(format!(
                        "--fast compares corresponding vertices, but the original has {v} and \
                         the decoded animation {w}; leave --fast out for the surface measures"
                    )));
                }
                let diagonal = mcgv_video::metrics::measure_unit(original.positions)?;
                *f = Some((VertexSums::default(), diagonal, v, 0));
            }
            _ => {}
        }
        Ok(())
    }

    /// Measures the next frames (after [`Self::start`]), moving the bar `pb` frame by frame.
    fn add(
        &mut self,
        original: &[Vec<Point>],
        decoded: &[Vec<Point>],
        pb: &ProgressBar,
    ) -> Result<()> {
        match self {
            Self::Full(_, Some(c)) => {
                c.add_with_progress(original, decoded, &progress::Reporter(pb))
            }
            Self::Fast(Some((sums, _, _, frames))) => {
                for (a, b) in original.iter().zip(decoded) {
                    sums.add_frame(a, b);
                }
                *frames += original.len().min(decoded.len());
                pb.inc(original.len() as u64);
                Ok(())
            }
            _ => Err(Error::Stream("the stream has no frames".into())),
        }
    }

    fn finish(self) -> Result<Outcome> {
        match self {
            Self::Full(_, Some(c)) => Ok(Outcome::Full((*c).finish())),
            Self::Fast(Some((sums, diagonal, vertices, frames))) => {
                let e = sums.errors(vertices as f64 * frames.max(1) as f64);
                Ok(Outcome::Fast(FastMeasures {
                    vertex_rmse: e.rmse / diagonal,
                    kg_error: e.kg,
                    bpvf: None,
                    frames,
                    vertices,
                }))
            }
            _ => Err(Error::Stream("the stream has no frames".into())),
        }
    }
}

/// The measures of a stream against its original, a segment of each at a time: memory holds one
/// segment of both, whatever the clip's length.
fn compare_stream(
    original: &mut FrameSource,
    decoder: &mut Decoder<BufReader<File>>,
    mut tally: Tally,
    quiet: bool,
) -> Result<Outcome> {
    let frames = original.frame_count();
    same_frame_count(frames, decoder.header().frames as usize)?;
    let order = decoder.input_order(original.first())?;
    // Decoding is a small part of the time (pdance: 0.2 of 3 CPU s): the bar counts frames measured.
    let pb = progress::bar(frames as u64, "measure", quiet);
    for (s, range) in decoder.segments().to_vec().into_iter().enumerate() {
        let positions = decoder.decode_segment(s, &mcgv_video::Silent)?;
        let mut decoded = AnimatedMesh::new(decoder.triangles().to_vec(), positions)?;
        if let Some(inverse) = &order {
            decoded = decoded.permuted(inverse)?;
        }
        let originals = original.read(range)?;
        let first = originals.first().map_or(&[][..], |f| f.as_slice());
        tally.start(
            Surface {
                triangles: original.first().triangles(),
                positions: first,
            },
            Surface {
                triangles: decoded.triangles(),
                positions: decoded.frame(0),
            },
        )?;
        tally.add(&originals, decoded.frames(), &pb)?;
    }
    pb.finish_and_clear();
    tally.finish()
}

/// The measures of two animations read a run of frames at a time (OBJ and PC2 inputs are never
/// held whole).
fn compare_sources(
    original: &mut FrameSource,
    decoded: &mut FrameSource,
    mut tally: Tally,
    quiet: bool,
) -> Result<Outcome> {
    let frames = original.frame_count();
    same_frame_count(frames, decoded.frame_count())?;
    tally.start(first_surface(original), first_surface(decoded))?;
    let pb = progress::bar(frames as u64, "measure", quiet);
    let run = mcgv_video::encoder::DEFAULT_SEGMENT_FRAMES;
    for start in (0..frames).step_by(run) {
        let range = start..(start + run).min(frames);
        let (a, b) = (original.read(range.clone())?, decoded.read(range)?);
        tally.add(&a, &b, &pb)?;
    }
    pb.finish_and_clear();
    tally.finish()
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
        "RMSE         {:.6e} of the bbox diagonal = {:.4} ×10⁻⁴{}\n",
        m.rmse,
        m.rmse * 1e4,
        if m.surface_frames < m.frames {
            format!(
                " (from {} of the {} frames measured in full; --every-frame for all)",
                m.surface_frames, m.frames
            )
        } else {
            String::new()
        }
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

/// The lines `eval --fast` prints.
fn fast_report(m: &FastMeasures) -> String {
    let mut s = format!("vertices     {}\nframes       {}\n", m.vertices, m.frames);
    s.push_str("RMSE         not measured (--fast)\nHausdorff    not measured (--fast)\n");
    s.push_str(&format!(
        "vertex RMSE  {:.6e} of the bbox diagonal = {:.4} ×10⁻⁴\n",
        m.vertex_rmse,
        m.vertex_rmse * 1e4
    ));
    match m.kg_error {
        Some(kg) => s.push_str(&format!("KG error     {kg:.6} %\n")),
        None => s.push_str("KG error     n/a (the original never leaves its centroid)\n"),
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
            surface_frames: 10,
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
