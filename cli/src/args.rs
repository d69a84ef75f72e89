//! The command line: argument definitions (clap). `main.rs` dispatches them to [`crate::commands`].

use clap::builder::{PossibleValue, TypedValueParser};
use clap::{Args, Parser, Subcommand};
use mcgv_video::Codec;
use std::path::PathBuf;

/// mcgv-video: compress animated triangle meshes into one `.mcgv` file (Multi-Chart Geometry Video).
#[derive(Debug, Parser)]
// No `help` subcommand (every command takes --help): each subcommand has a man page, and a
// `help` page would only repeat this one.
#[command(name = "mcgv-video", version, about, long_about = None, after_help = MAIN_EXAMPLES)]
#[command(disable_help_subcommand = true)]
pub struct Cli {
    /// The command to run.
    #[command(subcommand)]
    pub command: Command,
    /// No progress bars or chatter; errors still go to stderr.
    #[arg(long, short, global = true)]
    pub quiet: bool,
    /// Also show the codec libraries' warnings and errors (FFmpeg's), which are dropped
    /// otherwise: the error the tool reports already says what failed.
    #[arg(long, short, global = true)]
    pub verbose: bool,
    /// Threads for the work done in parallel (groups of pictures, frames measured by eval)
    /// [default: one per core]; `encode` also codes N temporal segments at once (memory: N
    /// segments' working data; default one).
    #[arg(long, global = true, value_name = "N", value_parser = clap::value_parser!(u64).range(1..=1024))]
    pub threads: Option<u64>,
}

const MAIN_EXAMPLES: &str = "Examples:
  mcgv-video encode media/CesiumMan.glb -o cesium.mcgv
  mcgv-video decode cesium.mcgv -o cesium.pc2
  mcgv-video eval media/CesiumMan.glb cesium.mcgv";

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Compress an animation (OBJ sequence, PC2 + OBJ, glTF) into a .mcgv file.
    #[command(after_help = "Examples:
  mcgv-video encode media/CesiumMan.glb -o cesium.mcgv
  mcgv-video encode 'frames/*.obj' -o walk.mcgv --quality 70
  mcgv-video encode media/CesiumMan.glb -o cesium.mcgv --target-size 30000
  mcgv-video encode media/CesiumMan.glb -o cesium.mcgv --codec av1 --target-error 2e-4
  mcgv-video encode media/Fox.glb --clip all -o fox.mcgv   # fox-Survey.mcgv, fox-Walk.mcgv, ...")]
    Encode(EncodeArgs),
    /// Decode a .mcgv file to an OBJ sequence (a folder), one OBJ or a PC2 point cache.
    #[command(after_help = "Examples:
  mcgv-video decode cesium.mcgv -o frames/
  mcgv-video decode cesium.mcgv -o cesium.pc2        # also writes cesium.obj, its base mesh
  mcgv-video decode cesium.mcgv --frame 10 -o frame10.obj")]
    Decode(DecodeArgs),
    /// Show a .mcgv file's bit budget per part; optionally write its images as PNG.
    #[command(after_help = "Examples:
  mcgv-video inspect cesium.mcgv
  mcgv-video inspect cesium.mcgv --json
  mcgv-video inspect cesium-jpeg.mcgv --png pictures/ --frames 0,10   # see docs/reading-inspect-pictures.md")]
    Inspect(InspectArgs),
    /// Compare two animations (any input form, or a .mcgv) and print the error measures.
    #[command(after_help = "Examples:
  mcgv-video eval media/CesiumMan.glb cesium.mcgv
  mcgv-video eval media/CesiumMan.glb frames/ --json
  mcgv-video eval media/CesiumMan.glb cesium.mcgv --bands 4")]
    Eval(EvalArgs),
    /// Print vertices, frames, faces, components, manifoldness, bounding box and glTF clips.
    #[command(after_help = "Examples:
  mcgv-video info media/Fox.glb
  mcgv-video info 'frames/*.obj' --json
  mcgv-video info cache.pc2 --base cache.obj")]
    Info(InfoArgs),
    /// Rewrite an animation (any input form) losslessly as a PC2 + base OBJ or an OBJ folder.
    #[command(after_help = "Examples:
  mcgv-video convert media/CesiumMan.glb -o cesium.pc2   # also writes cesium.obj
  mcgv-video convert media/Fox.glb --clip Walk -o walk/")]
    Convert(ConvertArgs),
    /// Print a shell completion script (bash, zsh, fish, elvish or powershell) to stdout.
    #[command(after_help = "Examples:
  mcgv-video completions bash > /usr/local/share/bash-completion/completions/mcgv-video
  mcgv-video completions zsh > ~/.zfunc/_mcgv-video
  mcgv-video completions fish > ~/.config/fish/completions/mcgv-video.fish")]
    Completions {
        /// The shell.
        shell: clap_complete::Shell,
    },
    /// Print a man page (roff) to stdout: the command's, or a subcommand's (mcgv-video-encode(1)).
    #[command(after_help = "Examples:
  mcgv-video man > /usr/local/share/man/man1/mcgv-video.1
  mcgv-video man encode > /usr/local/share/man/man1/mcgv-video-encode.1
  mcgv-video man decode | man -l -")]
    Man {
        /// The subcommand whose page to print (default: the command's own page).
        #[arg(value_parser = subcommand_names())]
        command: Option<String>,
    },
}

/// The subcommands, each with a man page of its own (`mcgv-video-encode(1)` …).
pub const SUBCOMMANDS: [&str; 8] = [
    "encode",
    "decode",
    "inspect",
    "eval",
    "info",
    "convert",
    "completions",
    "man",
];

fn subcommand_names() -> clap::builder::PossibleValuesParser {
    clap::builder::PossibleValuesParser::new(SUBCOMMANDS)
}

/// How to read an animation: options that apply to every input form.
#[derive(Debug, Clone, Default, Args)]
pub struct InputArgs {
    /// Rate at which glTF animations are baked to frames (default: the animation's keyframe rate, or 30).
    #[arg(long)]
    pub fps: Option<f64>,
    /// glTF animation (clip) to bake, by name or index (default: the first; `info` lists them);
    /// `encode --clip all` writes one stream per clip.
    #[arg(long)]
    pub clip: Option<String>,
    /// Base OBJ giving the connectivity of a PC2 point cache (default: the .obj beside the .pc2).
    #[arg(long)]
    pub base: Option<PathBuf>,
    /// Refuse to bake a glTF clip or decode a .mcgv of more positions (frames × vertices) than N,
    /// before allocating them (default 10^9, 12 GB as f32 points).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    pub max_positions: Option<u64>,
}

/// `encode` arguments.
#[derive(Debug, Args)]
pub struct EncodeArgs {
    /// Input animation: a folder or glob of .obj files, a .pc2 (with --base), or a .gltf/.glb.
    pub input: String,
    /// Output .mcgv file, or `-` for stdout. Missing parent folders are created. A folder or a
    /// mesh's name (.glb, .gltf, .obj, .pc2) is refused: those are what `decode` writes.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Replace the output file if it exists.
    #[arg(long, short = 'y')]
    pub force: bool,
    /// Residual coder: tdct is the smallest at equal error; jpeg decodes any frame on its own;
    /// mpeg4, hevc and av1 (10/12-bit pictures) suit hardware video decoders.
    #[arg(long, default_value_t = Codec::default(), value_parser = codec_names())]
    pub codec: Codec,
    /// Rate knob for every codec, 1..100 (higher = better quality, more bits; default 50);
    /// between the integers too (e.g. 47.31, as a --target-* search reports it). With a --target-*
    /// flag: where the search starts.
    #[arg(long, value_parser = parse_quality)]
    pub quality: Option<f64>,
    /// Budget: the stream's bytes at most; the encoder searches the quality whose stream lands
    /// within 3 % under it, within 2 % when its first two encodes can (at most 10 encodes,
    /// usually 2 or 3; docs/design.md, "Budgets").
    #[arg(long, value_name = "BYTES", group = "target", conflicts_with = "step",
          value_parser = clap::value_parser!(u64).range(1..))]
    pub target_size: Option<u64>,
    /// Budget: bits per vertex and frame at most (as --target-size).
    #[arg(long, value_name = "X", group = "target", conflicts_with = "step")]
    pub target_bpvf: Option<f64>,
    /// Budget: vertex RMSE (as a fraction of the first frame's bounding-box diagonal, eval's
    /// vertex_rmse) at most; the search lands within 3 % under it.
    #[arg(long, value_name = "E", group = "target", conflicts_with = "step")]
    pub target_error: Option<f64>,
    /// Budget: the largest displacement of any vertex in any frame (a fraction of the diagonal)
    /// at most; the search lands within 3 % under it.
    #[arg(long, value_name = "E", group = "target", conflicts_with = "step")]
    pub target_max_error: Option<f64>,
    /// MPEG-4 quantiser 1..31 (lower = better); overrides the one --quality sets for mpeg4.
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=31))]
    pub qscale: Option<u8>,
    /// hevc, av1: the codec's own quantiser (lower = better), overriding the one --quality sets:
    /// HEVC's QP 0..51, or libaom's constant-quality level (crf) 0..63 for av1.
    #[arg(long, value_parser = clap::value_parser!(u8).range(0..=63))]
    pub qp: Option<u8>,
    /// hevc, av1: bits a sample of the residual pictures, 10, 12 or auto: 12 from --quality 65
    /// (hevc) or 90 (av1), and below wherever the residuals would widen a group's step in
    /// 10-bit samples; else 10 (at equal error 12 bits cost less there, and reach errors 10 bits
    /// cannot; docs/design.md, "Sample depth"). --json's picture_depth says which was coded.
    /// With --target-error or --target-max-error, auto is 12 bits also from the quality where
    /// 10-bit pictures would widen a group's step, 10 below it; size budgets keep the depth the
    /// first encode's residuals turned to (the report names each encode's depth; docs/design.md,
    /// "Budgets").
    #[arg(long, default_value = "auto", value_parser = parse_bit_depth)]
    pub bit_depth: BitDepth,
    /// JPEG's own quality 1..100 for the residual pictures; overrides the one --quality sets.
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=100))]
    pub jpeg_quality: Option<u8>,
    /// Quantiser step (tdct) or pixel step (one grey level of the residual images, image codecs)
    /// as a fraction of the first frame's bounding-box diagonal (e.g. 0.001); overrides the one
    /// --quality sets.
    #[arg(long)]
    pub step: Option<f64>,
    /// Number of motion clusters K asked of k-means: alone, k-means into K; with --segmentation
    /// auto, the first of its k-means candidates (auto also tries 1.5 K, and 2 K when 1.5 K paid)
    /// [default: 20]. At most K are kept, often fewer: clusters of fewer than 4 vertices (too few
    /// to fit an affine map) merge into the nearest, clusters that border refinement empties
    /// vanish, K is at most the vertex count, and a mesh moving as one takes one; the report
    /// says how many.
    #[arg(long)]
    pub clusters: Option<usize>,
    /// Motion segmentation: k-means with K = --clusters, decimation, which finds K itself, or
    /// auto: both are tried at the quality's step and the smaller stream is kept (picture codecs:
    /// the fewer bits at equal error; see --json) [default: auto; kmeans when --clusters is
    /// given without --e0: a user who names K expects K].
    #[arg(long, value_enum)]
    pub segmentation: Option<SegmentationChoice>,
    /// Decimation's error threshold E0: RMS affine-fit error per vertex and frame, as a fraction of
    /// the bounding-box diagonal (default 0.003, the paper's; decimation and auto).
    #[arg(long)]
    pub e0: Option<f64>,
    /// The affine coefficients' quantiser step as a multiple of the residual step (whose size
    /// --quality or --step sets): smaller = finer maps, more side information (1/16..15.9;
    /// default 3/16 for tdct, jpeg and hevc, 0.25 for all-intra av1; for mpeg4 and av1 with
    /// --gop above 1, whose P-frames suffer from coarser maps, 1/8 below quality 85 and 1/16 from
    /// there; 1/16 for all-intra mpeg4).
    #[arg(long)]
    pub affine_precision: Option<f64>,
    /// Geometry-image lattice: WIDTHxHEIGHT (multiples of 16), or `auto` for the smallest square
    /// the charts fit, tried from about 2 pixels per vertex upwards (the fewest bits at equal
    /// error on the media sequences).
    #[arg(long, default_value = "auto")]
    pub lattice: String,
    /// jpeg, mpeg4, hevc, av1: how free pixels of the geometry images are filled [default: snap
    /// for jpeg, pushpull for all-intra hevc and av1 (--gop 1), biharmonic for the other video
    /// codecs].
    #[arg(long, value_parser = padding_methods())]
    pub padding: Option<String>,
    /// mpeg4, hevc, av1: group of pictures, an I-frame every N frames [default: 50]; 1 makes hevc
    /// and av1 all-intra (every frame decodes alone).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    pub gop: Option<u64>,
    /// Let the first-frame coder reorder vertices for fewer bits (default keeps the input order).
    #[arg(long)]
    pub reorder: bool,
    /// Bits per coordinate of the first frame, 1..=24 [default: 12; tdct tries 12, 10 and 8 and
    /// keeps the smallest stream, see --json's first_frame_trials].
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=24))]
    pub first_frame_bits: Option<u8>,
    /// Motion predictor: one affine map per cluster, per-vertex skinning weights over
    /// neighbouring clusters' maps (coded in the stream; the decoder follows the stream's choice),
    /// or auto: both are tried at the quality's step and the smaller stream is kept (picture
    /// codecs: the fewer bits at equal error).
    #[arg(long, value_enum, default_value_t = PredictorChoice::Auto)]
    pub predictor: PredictorChoice,
    /// Most bits per quantised skinning weight, sign included (the paper's 16); the encoder uses
    /// fewer where a coarser weight moves the vertices no more than the affine maps' step does
    /// (docs/design.md, "Skinning weights: quantised by their effect").
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u8).range(2..=31))]
    pub weight_bits: u8,
    /// Bits per texture coordinate over each UV set's bounding box (inputs with UVs only).
    #[arg(long, default_value_t = 12, value_parser = clap::value_parser!(u8).range(1..=24))]
    pub uv_bits: u8,
    /// Frames per temporal segment: a longer clip is coded as segments of N frames, each with its
    /// own temporal DCT or groups of pictures, sharing the first frame, clusters and atlas (the
    /// automatic choices are made on one segment's length of frames spread over the whole clip);
    /// 0 codes any clip as one segment [default: 128].
    #[arg(long, value_name = "N")]
    pub segment_frames: Option<u64>,
    /// Print the result as one JSON object.
    #[arg(long)]
    pub json: bool,
    /// How to read the input.
    #[command(flatten)]
    pub input_args: InputArgs,
}

/// `--bit-depth`: a number of bits, or chosen from the quality.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BitDepth {
    /// The measured rule: 12 bits from quality 65 (HEVC) or 90 (AV1), and where 10-bit
    /// samples would widen a group's step; else 10.
    Auto,
    /// 10 or 12 bits.
    Bits(u8),
}

/// `--quality`: 1..=100, between the integers too.
fn parse_quality(value: &str) -> Result<f64, String> {
    match value.trim().parse::<f64>() {
        Ok(q) if (1.0..=100.0).contains(&q) => Ok(q),
        _ => Err(format!("{value}: expected a quality between 1 and 100")),
    }
}

fn parse_bit_depth(value: &str) -> Result<BitDepth, String> {
    match value {
        "auto" => Ok(BitDepth::Auto),
        "10" => Ok(BitDepth::Bits(10)),
        "12" => Ok(BitDepth::Bits(12)),
        _ => Err("expected 10, 12 or auto".into()),
    }
}

/// The padding methods `--padding` takes, the codecs' defaults first (each the name of a
/// [`mcgv_video::PaddingMethod`]).
const PADDING_METHODS: [&str; 8] = [
    "snap",
    "biharmonic",
    "pushpull",
    "cg",
    "midgrey",
    "mean",
    "laplace",
    "dct",
];

fn padding_methods() -> clap::builder::PossibleValuesParser {
    clap::builder::PossibleValuesParser::new(PADDING_METHODS)
}

/// The codecs `--codec` takes, by their names, each with its line of help.
fn codec_names() -> impl clap::builder::TypedValueParser<Value = Codec> {
    let names = Codec::ALL.map(|c| PossibleValue::new(c.name()).help(c.summary()));
    // Only the listed names get through, each the name of a codec.
    clap::builder::PossibleValuesParser::new(names)
        .map(|n| Codec::from_name(&n).unwrap_or_default())
}

/// The motion segmentations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SegmentationChoice {
    /// k-means on per-vertex affine motion, K = --clusters (MCGV).
    Kmeans,
    /// Half-edge collapses by affine-motion cost until the error reaches --e0 (skinning paper).
    Decimation,
    /// Both, at the quality's step; the smaller stream is kept.
    Auto,
}

/// The motion predictors.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum PredictorChoice {
    /// One affine map per cluster and frame.
    Affine,
    /// Per-vertex weights blending the own and neighbouring clusters' maps.
    Skinning,
    /// Both, at the quality's step; the smaller stream is kept.
    Auto,
}

/// `decode` arguments.
#[derive(Debug, Args)]
pub struct DecodeArgs {
    /// The .mcgv file.
    pub input: PathBuf,
    /// Output, by its name: `DIR/` (or an existing folder, or a name without extension) for OBJ
    /// frames frame_0000.obj …; `X.pc2` for a point cache with its base `X.obj` beside it;
    /// `X.obj` with --frame for that one frame; `X.glb` or `X.gltf` for a glTF asset (morph
    /// targets, one per frame). Missing parent folders are created.
    #[arg(short, long)]
    pub output: PathBuf,
    /// glTF output: frames per second of the animation (default: the source's, which the stream
    /// records for glTF inputs; else 30).
    #[arg(long)]
    pub fps: Option<f64>,
    /// glTF output: copy the materials, textures and node name of this glTF file (the encoded
    /// source), so the decoded asset renders as the source did.
    #[arg(long, value_name = "SOURCE.glb")]
    pub like: Option<PathBuf>,
    /// Decode only this frame (numbered from 0), e.g. into one X.obj.
    #[arg(long)]
    pub frame: Option<usize>,
    /// Decode only these frames (numbered from 0): `A..B` is A to B - 1 (`10..20` is ten
    /// frames), `A..` from A on, `..B` up to B - 1, `N` one frame, and `a,b,c` a list of any of
    /// these; e.g. a part of a long clip as glTF with fewer morph targets. OBJ frames keep their
    /// numbers.
    #[arg(long, value_name = "A..B|N|a,b,c", conflicts_with = "frame")]
    pub frames: Option<Frames>,
    /// Replace output files that exist; in a folder that holds files, write the frames among them
    /// (only files of the names this run writes are replaced; the others are left and counted).
    #[arg(long, short = 'y')]
    pub force: bool,
    /// tdct streams: decode only the first N temporal-DCT bands (a coarser, progressive preview).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    pub bands: Option<u64>,
    /// Refuse a stream whose header promises more positions (frames × vertices) than N, before
    /// allocating them (default 10^9, 12 GB as f32 points).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    pub max_positions: Option<u64>,
}

/// A selection of frames, as `--frames` takes it: spans separated by commas, each `A..B` (A to
/// B - 1), `A..` (A to the last), `..B` (the first to B - 1) or `N` (frame N).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Frames(Vec<(Option<usize>, Option<usize>)>);

impl std::str::FromStr for Frames {
    type Err = String;

    fn from_str(text: &str) -> std::result::Result<Self, String> {
        let number = |t: &str| {
            t.trim().parse::<usize>().map_err(|_| {
                format!("{text}: `{t}` is not a frame number (A..B, A.., ..B, N or a,b,c)")
            })
        };
        let mut spans = Vec::new();
        for span in text.split(',') {
            let span = span.trim();
            let (from, to) = match span.split_once("..") {
                None => {
                    let n = number(span)?;
                    (Some(n), Some(n + 1))
                }
                Some((a, b)) => {
                    let end = |t: &str| (!t.trim().is_empty()).then(|| number(t)).transpose();
                    (end(a)?, end(b)?)
                }
            };
            // A missing start is frame 0, so `..0` is as empty as `5..5`.
            if let Some(b) = to {
                if from.unwrap_or(0) >= b {
                    return Err(format!("{text}: {span} is empty (A must be below B)"));
                }
            }
            spans.push((from, to));
        }
        Ok(Frames(spans))
    }
}

impl Frames {
    /// The frames selected of a clip of `count` frames, in order, each once; a frame past the
    /// end is a usage error of `option` (the flag's field name).
    pub fn resolve(&self, count: usize, option: &'static str) -> mcgv_video::Result<Vec<usize>> {
        let mut frames = Vec::new();
        for &(from, to) in &self.0 {
            let (a, b) = (from.unwrap_or(0), to.unwrap_or(count));
            if b > count || a >= count {
                return Err(mcgv_video::Error::option(
                    option,
                    format!(
                        "{}..{b}: the stream has frames 0 to {}",
                        a,
                        count.saturating_sub(1)
                    ),
                ));
            }
            frames.extend(a..b);
        }
        frames.sort_unstable();
        frames.dedup();
        Ok(frames)
    }
}

/// `inspect` arguments.
#[derive(Debug, Args)]
pub struct InspectArgs {
    /// The .mcgv file.
    pub input: PathBuf,
    /// Write residual images (raw, padded, decoded), the atlas and the segmentation as PNG here.
    #[arg(long)]
    pub png: Option<PathBuf>,
    /// Frames whose images --png writes (default: 0), as `decode --frames` takes them: `A..B`,
    /// `A..`, `..B`, `N` or a list `a,b,c`.
    #[arg(long, value_name = "A..B|N|a,b,c", requires = "png")]
    pub frames: Option<Frames>,
    /// The original animation: with --png, also write the raw and padded residual images the encoder
    /// made (the encoder's analysis is re-run; it is deterministic).
    #[arg(long, requires = "png")]
    pub original: Option<String>,
    /// With --png: replace the images of a folder that holds files (only files of the names this
    /// run writes are replaced; the others are left and counted).
    #[arg(long, short = 'y', requires = "png")]
    pub force: bool,
    /// How to read the original.
    #[command(flatten)]
    pub input_args: InputArgs,
    /// Print the result as one JSON object.
    #[arg(long)]
    pub json: bool,
}

/// `eval` arguments.
#[derive(Debug, Args)]
pub struct EvalArgs {
    /// The original animation.
    pub original: String,
    /// The animation to compare with it (any input form, or a .mcgv).
    pub decoded: String,
    /// tdct streams: decode only the first N temporal-DCT bands before comparing.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    pub bands: Option<u64>,
    /// Vertex RMSE and KG error only (and bpvf), skipping the surface measures (RMSE, Hausdorff)
    /// that take most of the time; needs the same vertex count on both sides.
    #[arg(long)]
    pub fast: bool,
    /// Measure the surface distances of every frame in full. By default only one frame in eight
    /// is (then one in four, in two, all, until the estimate converges) and the other frames' RMS
    /// is estimated from a cheap bound, to a standard error of at most 0.2 % of the RMSE (within
    /// 0.32 % of the full figure on 23 streams); runs under 32 frames and meshes of other
    /// connectivity are measured in full. The Hausdorff distance is exact either way
    #[arg(long, conflicts_with = "fast")]
    pub every_frame: bool,
    /// Print the result as one JSON object.
    #[arg(long)]
    pub json: bool,
    /// How to read the inputs.
    #[command(flatten)]
    pub input_args: InputArgs,
}

/// `info` arguments.
#[derive(Debug, Args)]
pub struct InfoArgs {
    /// The animation (any input form).
    pub input: String,
    /// Print the result as one JSON object.
    #[arg(long)]
    pub json: bool,
    /// How to read the input.
    #[command(flatten)]
    pub input_args: InputArgs,
}

/// `convert` arguments.
#[derive(Debug, Args)]
pub struct ConvertArgs {
    /// The animation (any input form).
    pub input: String,
    /// Output, by its name: `X.pc2` (the base OBJ with the faces is written beside it, same stem),
    /// `X.glb` or `X.gltf` (morph targets at --fps, default 30), or `DIR/` (an existing folder, or
    /// a name without extension) for OBJ frames frame_0000.obj ….
    #[arg(short, long)]
    pub output: PathBuf,
    /// Replace output files that exist; in a folder that holds files, write the frames among them
    /// (only files of the names this run writes are replaced; the others are left and counted).
    #[arg(long, short = 'y')]
    pub force: bool,
    /// How to read the input.
    #[command(flatten)]
    pub input_args: InputArgs,
}

impl From<&InputArgs> for mcgv_video::ReadOptions {
    fn from(args: &InputArgs) -> Self {
        Self {
            fps: args.fps,
            clip: args.clip.clone(),
            base: args.base.clone(),
            max_positions: args
                .max_positions
                .unwrap_or(mcgv_video::DEFAULT_MAX_POSITIONS),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{Cli, Frames, PADDING_METHODS, SUBCOMMANDS};

    #[test]
    fn every_subcommand_has_a_man_page() {
        use clap::CommandFactory;
        let names: Vec<String> = Cli::command()
            .get_subcommands()
            .map(|c| c.get_name().to_string())
            .collect();
        assert_eq!(names, SUBCOMMANDS);
    }

    #[test]
    fn one_frame_syntax_for_every_command() {
        let pick = |text: &str, count| text.parse::<Frames>().unwrap().resolve(count, "frames");
        assert_eq!(pick("2..5", 10).unwrap(), [2, 3, 4]);
        assert_eq!(pick("7..", 10).unwrap(), [7, 8, 9]);
        assert_eq!(pick("..2", 10).unwrap(), [0, 1]);
        assert_eq!(pick("3", 10).unwrap(), [3]);
        assert_eq!(pick("0,9, 4..6,5", 10).unwrap(), [0, 4, 5, 9]);
        assert_eq!(pick("..", 3).unwrap(), [0, 1, 2]);
        assert!(pick("8..12", 10).is_err());
        assert!(pick("10", 10).is_err());
        for bad in [
            "5..5", "6..2", "..0", "1,..0", "a", "1..x", "", "1,,2", "-1",
        ] {
            assert!(bad.parse::<Frames>().is_err(), "{bad}");
        }
    }

    #[test]
    fn every_padding_method_is_offered_once() {
        let mut offered = PADDING_METHODS.to_vec();
        let mut methods = mcgv_video::PaddingMethod::NAMES.to_vec();
        offered.sort_unstable();
        methods.sort_unstable();
        assert_eq!(offered, methods);
    }
}
