//! The encoder: mesh → motion → atlas → geometry images → codec → stream.

use crate::codec::{self, abbreviated, mpeg4, Plane};
use crate::error::{Error, Result};
use crate::geometry_image::{quantise, tile, FrameRanges, RangeMode};
use crate::mesh::{AnimatedMesh, Point};
use crate::motion::{
    self, AffineTrack, DecimateOptions, Partition, PredictorKind, SegmentOptions, SkinningWeights,
};
use crate::stream::container::{Checksum, ContainerWriter, Tag};
use crate::stream::frame_index::{FrameChunk, FrameIndex};
use crate::stream::header::{CodecKind, Header};
use crate::stream::{first_frame, side_info, tdct};
use indicatif::ProgressBar;
use std::time::Instant;

/// Everything the user can choose about an encoding.
#[derive(Debug, Clone)]
pub struct EncodeOptions {
    /// The residual image codec.
    pub codec: CodecKind,
    /// Rate knob 1..100 (higher = better).
    pub quality: u8,
    /// MPEG-4 quantiser; `None` derives it from `quality`.
    pub qscale: Option<u8>,
    /// Motion clusters K (k-means only; decimation finds its own).
    pub clusters: usize,
    /// How the vertices are split into motion clusters.
    pub segmentation: Segmentation,
    /// Bits per affine coefficient.
    pub affine_bits: u8,
    /// Bits per coordinate of the first frame.
    pub first_frame_bits: u8,
    /// Lattice width and height, or chosen from the mesh.
    pub lattice: Lattice,
    /// Padding of the free pixels; `None` picks the codec's measured best (see [`padding_method`]).
    pub padding: Option<padding::Method>,
    /// MPEG-4 group of pictures.
    pub gop: usize,
    /// Let the first-frame coder permute vertices.
    pub reorder: bool,
    /// The motion predictor (piecewise affine by default).
    pub predictor: PredictorKind,
    /// Bits per skinning weight, sign included (the paper's 16 by default).
    pub weight_bits: u8,
    /// Residual ranges narrower than this fraction of the sequence's widest are widened to it, so
    /// frames with small residuals get coarser levels instead of the full 0..255 (0 = off).
    pub range_floor: f32,
    /// Temporal-DCT quantiser step as a fraction of the first frame's bounding-box diagonal;
    /// `None` derives it from `quality` (tdct only).
    pub step: Option<f64>,
}

impl Default for EncodeOptions {
    fn default() -> Self {
        Self {
            codec: CodecKind::Jpeg,
            quality: DEFAULT_QUALITY,
            qscale: None,
            clusters: 20,
            segmentation: Segmentation::KMeans,
            affine_bits: 17,
            first_frame_bits: 12,
            lattice: Lattice::Auto,
            padding: None,
            gop: 50,
            reorder: false,
            predictor: PredictorKind::Affine,
            weight_bits: motion::WEIGHT_BITS,
            range_floor: 0.0,
            step: None,
        }
    }
}

/// The size of the geometry-image lattice.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Lattice {
    /// Sized from the vertex count (see [`auto_side`]), grown until the charts fit.
    Auto,
    /// Exactly this width and height.
    Fixed(u16, u16),
}

/// Lattice pixels per vertex for `Lattice::Auto`. The papers' sequences (2900–8400 vertices) use
/// 256×256; a small mesh in that lattice pays for pixels it does not need: RiggedFigure (370
/// vertices) costs 96 bpvf at 256×256 and 37 bpvf at 96×96 at about the same RMSE, Fox (1728) is
/// best near 224×224 (encode --lattice WxH, eval; JPEG q30/q75).
const AUTO_PIXELS_PER_VERTEX: f64 = 28.0;

/// Lattice pixels per vertex below which `Lattice::Auto` grows past 256×256: BrainStem (34 159
/// vertices) at 336×336 had 70 % of its vertices moved off colliding pixels, at 512×512 28 %. At
/// 7.5 the papers' largest meshes (8431-vertex horses) stay at 256×256 and BrainStem gets 512×512.
const MIN_PIXELS_PER_VERTEX: f64 = 7.5;

/// The first lattice side `Lattice::Auto` tries for `vertices`: about
/// [`AUTO_PIXELS_PER_VERTEX`] pixels per vertex, at least 32, at most the papers' 256 unless that
/// leaves fewer than [`MIN_PIXELS_PER_VERTEX`] (meshes over 8738 vertices).
pub fn auto_side(vertices: usize) -> u16 {
    let v = vertices as f64;
    let side = (v * AUTO_PIXELS_PER_VERTEX)
        .sqrt()
        .min(256.0)
        .max((v * MIN_PIXELS_PER_VERTEX).sqrt());
    round_up_16(side).max(32)
}

fn round_up_16(x: f64) -> u16 {
    ((x / 16.0).ceil() * 16.0).min(4096.0) as u16
}

/// The motion segmentation of an encoding.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Segmentation {
    /// k-means on per-vertex affine motion with border refinement, K = `EncodeOptions::clusters` (MCGV §3.1).
    KMeans,
    /// Half-edge collapses by affine-motion cost until the RMS fit error reaches `e0` of the
    /// bounding-box diagonal (skinning paper §3.1); K falls out of it.
    Decimation {
        /// The error threshold E0 (the paper's 0.003).
        e0: f64,
    },
}

impl Segmentation {
    /// The name used on the command line and in reports.
    pub fn name(&self) -> &'static str {
        match self {
            Segmentation::KMeans => "kmeans",
            Segmentation::Decimation { .. } => "decimation",
        }
    }
}

/// What the segmentation stage did, for reports.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SegmentationReport {
    /// `kmeans` or `decimation`.
    pub method: &'static str,
    /// Clusters found (K).
    pub clusters: usize,
    /// Seconds the segmentation took.
    pub seconds: f64,
    /// Decimation only: the threshold E0 asked for.
    pub e0: Option<f64>,
    /// Decimation only: the RMS affine-fit error per vertex and frame reached, over the bbox diagonal (E_l).
    pub error: Option<f64>,
    /// Decimation only: connected components (seams welded), a lower bound on K.
    pub components: Option<usize>,
}

/// Default `--quality`: the middle of the useful range. On CesiumMan it gives RMSE 2.6e-4 of the
/// diagonal (under half a millimetre on a 1.8 m figure) at 6.5 bpvf with MPEG-4 (qscale 4); 75
/// (qscale 2) costs 1.6× the bits for 0.6× the error (scripts/sweep.sh on media/CesiumMan.glb).
pub const DEFAULT_QUALITY: u8 = 50;

/// What an encoding produced, for reports.
#[derive(Debug, Clone, serde::Serialize)]
pub struct EncodeReport {
    /// The stream header.
    pub header: Header,
    /// Bytes per part, in file order.
    pub parts: Vec<(String, u64)>,
    /// Total file bytes.
    pub bytes: u64,
    /// Bits per vertex per frame.
    pub bpvf: f64,
    /// Charts in the atlas (0 for tdct, which has no atlas).
    pub charts: usize,
    /// Chart pixels / lattice pixels (0 without an atlas).
    pub packing_efficiency: f64,
    /// Vertices moved to resolve lattice collisions (0 without an atlas).
    pub moved_vertices: usize,
    /// Area-weighted L2 stretch of the charts (1 = none; 0 without an atlas).
    pub l2_stretch: f64,
    /// Seconds per stage.
    pub stage_seconds: Vec<(String, f64)>,
    /// The segmentation: method, K found, its time (and for decimation, the error reached).
    pub segmentation: SegmentationReport,
    /// If the first-frame coder reordered vertices: new index → input index.
    #[serde(skip)]
    pub permutation: Option<Vec<u32>>,
}

/// What the residual coder of an encoding produced, before the container is assembled.
struct Coded {
    partition: Partition,
    track: AffineTrack,
    weights: Option<SkinningWeights>,
    /// Lattice size, (0, 0) without images.
    lattice: (u16, u16),
    /// The atlas's figures, when there is an atlas.
    stats: Option<atlas::AtlasStats>,
    /// Parts between the partition and the affine coefficients.
    before_affine: Vec<(Tag, Vec<u8>, Checksum)>,
    /// Parts after the predictor's.
    after_affine: Vec<(Tag, Vec<u8>, Checksum)>,
}

/// The encoded stream in memory, and what it took.
pub struct Encoded {
    /// The container, ready to be written.
    pub container: ContainerWriter,
    /// The figures of the encoding.
    pub report: EncodeReport,
}

/// The intermediate results of the analysis half of the encoder, kept for `inspect`.
pub struct Analysis {
    /// The decoded first frame the decoder will have.
    pub reference: Vec<Point>,
    /// Motion clusters.
    pub partition: Partition,
    /// The quantised affine predictor.
    pub track: AffineTrack,
    /// The quantised skinning weights, for the skinning predictor.
    pub weights: Option<SkinningWeights>,
    /// The lattice the atlas was built on.
    pub lattice: (u16, u16),
    /// The atlas.
    pub atlas: atlas::Atlas,
    /// Residuals per frame and vertex.
    pub residuals: Vec<Vec<[f32; 3]>>,
    /// Residual ranges per frame.
    pub ranges: Vec<FrameRanges>,
}

/// Encodes an animation; `progress` is advanced once per frame coded.
pub fn encode(
    mesh: &AnimatedMesh,
    opts: &EncodeOptions,
    progress: &ProgressBar,
) -> Result<Encoded> {
    check_options(mesh, opts)?;
    let mut seconds = Vec::new();
    let mut clock = Instant::now();
    let mut lap = |name: &str, seconds: &mut Vec<(String, f64)>| {
        seconds.push((name.to_string(), clock.elapsed().as_secs_f64()));
        clock = Instant::now();
    };

    progress.set_message("first frame");
    let ff = first_frame::encode(
        mesh.frame(0),
        mesh.triangles(),
        &first_frame::FirstFrameOptions {
            bits: opts.first_frame_bits,
            reorder: opts.reorder,
        },
    )?;
    let permuted;
    let mesh = match &ff.permutation {
        Some(perm) => {
            permuted = mesh.permuted(perm)?;
            &permuted
        }
        None => mesh,
    };
    lap("first frame", &mut seconds);

    progress.set_message("segmentation");
    let (partition, segmentation) = segment(mesh, opts)?;
    lap("segmentation", &mut seconds);

    progress.set_message("motion");
    let coded = if opts.codec.has_images() {
        let analysis = analyse_partition(mesh, ff.decoded_positions, partition, opts)?;
        lap("motion + atlas", &mut seconds);
        progress.set_message("images");
        let (setup, chunks) = code_images(&analysis, opts, progress)?;
        lap("images", &mut seconds);
        let mut w = crate::stream::bytes::ByteWriter::new();
        quantise::write_ranges(&analysis.ranges, &mut w);
        let (index, payload) = FrameIndex::build(chunks);
        let lattice = side_info::encode_lattice(
            analysis.atlas.vertex_pixels(),
            analysis.lattice,
            mesh.triangles(),
        )?;
        let stats = analysis.atlas.stats().clone();
        Coded {
            lattice: analysis.lattice,
            stats: Some(stats),
            // The lattice coordinates come before the predictor, the rest after it (file order).
            before_affine: vec![(Tag::LATTICE, lattice, Checksum::Whole)],
            after_affine: vec![
                (Tag::RANGES, w.into_bytes(), Checksum::Whole),
                (Tag::CODEC_SETUP, setup, Checksum::Whole),
                (Tag::FRAME_INDEX, index.to_bytes(), Checksum::Whole),
                (Tag::FRAMES, payload, Checksum::Chunked),
            ],
            partition: analysis.partition,
            track: analysis.track,
            weights: analysis.weights,
        }
    } else {
        // No atlas, no images: the temporal DCT needs the residuals only (and skips xatlas).
        let (track, weights, residuals) =
            predict_residuals(mesh, &ff.decoded_positions, &partition, opts)?;
        lap("motion", &mut seconds);
        progress.set_message("temporal DCT");
        let (index, payload) = code_tdct(mesh, &residuals, opts)?;
        progress.inc(mesh.frame_count() as u64);
        lap("temporal DCT", &mut seconds);
        Coded {
            lattice: (0, 0),
            stats: None,
            before_affine: Vec::new(),
            after_affine: vec![
                (Tag::TDCT_INDEX, index, Checksum::Whole),
                // Last, so that a stream cut inside it still decodes the bands before the cut.
                (Tag::TDCT, payload, Checksum::Progressive),
            ],
            partition,
            track,
            weights,
        }
    };

    let header = Header {
        vertices: mesh.vertex_count() as u32,
        frames: mesh.frame_count() as u32,
        triangles: mesh.triangles().len() as u32,
        clusters: coded.partition.clusters() as u32,
        lattice_width: coded.lattice.0,
        lattice_height: coded.lattice.1,
        codec: opts.codec,
        quality: opts.quality,
        qscale: qscale(opts),
        gop: match opts.codec {
            CodecKind::Jpeg | CodecKind::Tdct => 1,
            CodecKind::Mpeg4 => opts.gop as u32,
        },
        affine_bits: opts.affine_bits,
        first_frame_bits: opts.first_frame_bits,
        padding: match opts.codec {
            CodecKind::Tdct => "none".to_string(),
            _ => padding_method(opts).to_string(),
        },
        // Decimation asks for no K: the header then records the K it found.
        requested_clusters: match opts.segmentation {
            Segmentation::KMeans => opts.clusters as u32,
            Segmentation::Decimation { .. } => coded.partition.clusters() as u32,
        },
        reorder: opts.reorder,
        charts: coded.stats.as_ref().map_or(0, |s| s.charts as u32),
        chart_pixels: coded.stats.as_ref().map_or(0, |s| s.chart_pixels as u32),
        predictor: opts.predictor,
    };
    let mut container = ContainerWriter::new();
    container.add(Tag::HEADER, header.to_bytes(), Checksum::Whole);
    container.add(Tag::FIRST_FRAME, ff.bytes, Checksum::Whole);
    container.add(
        Tag::PARTITION,
        side_info::encode_partition(
            coded.partition.labels(),
            coded.partition.clusters(),
            mesh.triangles(),
        )?,
        Checksum::Whole,
    );
    for (tag, bytes, checksum) in coded.before_affine {
        container.add(tag, bytes, checksum);
    }
    container.add(
        Tag::AFFINE,
        side_info::encode_affine(&coded.track)?,
        Checksum::Whole,
    );
    if let Some(weights) = &coded.weights {
        container.add(
            Tag::WEIGHTS,
            side_info::encode_weights(weights, &coded.partition, mesh.triangles())?,
            Checksum::Whole,
        );
    }
    for (tag, bytes, checksum) in coded.after_affine {
        container.add(tag, bytes, checksum);
    }
    lap("side information", &mut seconds);

    let bytes = container.to_bytes().len() as u64;
    let stats = coded.stats.as_ref();
    let report = EncodeReport {
        parts: container.part_sizes(),
        bpvf: bytes as f64 * 8.0 / (header.vertices as f64 * header.frames as f64),
        header,
        bytes,
        charts: stats.map_or(0, |s| s.charts),
        packing_efficiency: stats.map_or(0.0, |s| s.packing_efficiency),
        moved_vertices: stats.map_or(0, |s| s.moved_vertices),
        l2_stretch: stats.map_or(0.0, |s| s.l2_stretch),
        stage_seconds: seconds,
        segmentation,
        permutation: ff.permutation,
    };
    Ok(Encoded { container, report })
}

fn check_options(mesh: &AnimatedMesh, opts: &EncodeOptions) -> Result<()> {
    if opts.clusters == 0 {
        return Err(Error::Usage("--clusters must be at least 1".into()));
    }
    if let Segmentation::Decimation { e0 } = opts.segmentation {
        if !(e0.is_finite() && e0 > 0.0) {
            return Err(Error::Usage(format!(
                "--e0 must be a positive fraction of the bounding-box diagonal, not {e0}"
            )));
        }
    }
    if !(8..=32).contains(&opts.affine_bits) {
        return Err(Error::Usage(
            "--affine-bits must be between 8 and 32".into(),
        ));
    }
    if let Lattice::Fixed(w, h) = opts.lattice {
        check_lattice(w, h)?;
    }
    if !(2..=31).contains(&opts.weight_bits) {
        return Err(Error::Usage(
            "--weight-bits must be between 2 and 31".into(),
        ));
    }
    if !(0.0..=1.0).contains(&opts.range_floor) {
        return Err(Error::Usage(format!(
            "--range-floor must be between 0 and 1, not {}",
            opts.range_floor
        )));
    }
    if opts.gop == 0 {
        return Err(Error::Usage("--gop must be at least 1".into()));
    }
    if let Some(step) = opts.step {
        if opts.codec != CodecKind::Tdct {
            return Err(Error::Usage("--step applies to --codec tdct only".into()));
        }
        if !(step.is_finite() && step > 0.0 && step <= 1.0) {
            return Err(Error::Usage(format!(
                "--step {step}: expected a fraction of the bounding-box diagonal in (0, 1]"
            )));
        }
    }
    if opts.codec == CodecKind::Tdct {
        if let Lattice::Fixed(..) = opts.lattice {
            return Err(Error::Usage(
                "--lattice applies to the image codecs: tdct has no geometry images".into(),
            ));
        }
        if opts.range_floor > 0.0 {
            return Err(Error::Usage(
                "--range-floor applies to the image codecs: tdct has no residual ranges".into(),
            ));
        }
        if opts.padding.is_some() {
            return Err(Error::Usage(
                "--padding applies to the image codecs: tdct has no geometry images".into(),
            ));
        }
    }
    if mesh.triangles().is_empty() {
        return Err(Error::Mesh(
            "the mesh has no triangles: nothing to parameterize".into(),
        ));
    }
    Ok(())
}

fn check_lattice(w: u16, h: u16) -> Result<()> {
    let max = crate::stream::header::MAX_LATTICE_SIDE;
    if w == 0 || h == 0 || w % 16 != 0 || h % 16 != 0 || w > max || h > max {
        return Err(Error::Usage(format!(
            "lattice {w}x{h}: width and height must be multiples of 16 between 16 and {max}"
        )));
    }
    Ok(())
}

/// The padding an encoding uses: the user's choice, else the measured winner for the codec —
/// `snap` (tuned to JPEG's quantiser at the stream's quality) for JPEG, and for MPEG-4, whose
/// quantiser differs, the quality-independent `biharmonic`.
pub fn padding_method(opts: &EncodeOptions) -> padding::Method {
    opts.padding.unwrap_or(match opts.codec {
        CodecKind::Jpeg => padding::Method::Snap,
        // tdct pads nothing; the image codecs' choice keeps `inspect`'s re-analysis total.
        CodecKind::Mpeg4 | CodecKind::Tdct => padding::Method::Biharmonic,
    })
}

/// The MPEG-4 quantiser an encoding uses (0 for JPEG and tdct).
pub fn qscale(opts: &EncodeOptions) -> u8 {
    match opts.codec {
        CodecKind::Jpeg | CodecKind::Tdct => 0,
        CodecKind::Mpeg4 => opts
            .qscale
            .unwrap_or_else(|| codec::quality_to_qscale(opts.quality)),
    }
}

/// The motion segmentation `opts` ask for, and what it did.
pub fn segment(
    mesh: &AnimatedMesh,
    opts: &EncodeOptions,
) -> Result<(Partition, SegmentationReport)> {
    let start = Instant::now();
    let (partition, e0, error, components) = match opts.segmentation {
        Segmentation::KMeans => {
            let partition = motion::segment(
                mesh,
                &SegmentOptions {
                    clusters: opts.clusters,
                    ..SegmentOptions::default()
                },
            )?;
            (partition, None, None, None)
        }
        Segmentation::Decimation { e0 } => {
            let d = motion::decimate(
                mesh,
                &DecimateOptions {
                    e0,
                    ..DecimateOptions::default()
                },
            )?;
            (d.partition, Some(e0), Some(d.error), Some(d.components))
        }
    };
    let report = SegmentationReport {
        method: opts.segmentation.name(),
        clusters: partition.clusters(),
        seconds: start.elapsed().as_secs_f64(),
        e0,
        error,
        components,
    };
    Ok((partition, report))
}

/// Segmentation, prediction, atlas and residuals: everything before the images are coded.
pub fn analyse(
    mesh: &AnimatedMesh,
    reference: Vec<Point>,
    opts: &EncodeOptions,
) -> Result<Analysis> {
    let (partition, _) = segment(mesh, opts)?;
    analyse_partition(mesh, reference, partition, opts)
}

/// Prediction, atlas and residuals for a given partition (e.g. the one a stream carries).
pub fn analyse_partition(
    mesh: &AnimatedMesh,
    reference: Vec<Point>,
    partition: Partition,
    opts: &EncodeOptions,
) -> Result<Analysis> {
    let (track, weights, residuals) = predict_residuals(mesh, &reference, &partition, opts)?;
    let (lattice, atlas) = build_atlas(&reference, mesh.triangles(), &partition, opts.lattice)?;
    let mode = match opts.codec {
        CodecKind::Jpeg | CodecKind::Tdct => RangeMode::PerFrame,
        CodecKind::Mpeg4 => RangeMode::PerGroup(opts.gop),
    };
    let mut ranges = quantise::frame_ranges(&residuals, mode);
    quantise::widen(&mut ranges, opts.range_floor);
    Ok(Analysis {
        reference,
        partition,
        track,
        weights,
        lattice,
        atlas,
        residuals,
        ranges,
    })
}

/// The quantised affine track, the skinning weights (skinning predictor only) and every frame's
/// residuals against them (`[frame][vertex]`).
pub type Prediction = (AffineTrack, Option<SkinningWeights>, Vec<Vec<[f32; 3]>>);

/// The quantised predictor (affine track, skinning weights) and every frame's residuals against
/// it: the motion half of the analysis, all that the temporal DCT needs.
pub fn predict_residuals(
    mesh: &AnimatedMesh,
    reference: &[Point],
    partition: &Partition,
    opts: &EncodeOptions,
) -> Result<Prediction> {
    let track = AffineTrack::fit(mesh.frames(), reference, partition, opts.affine_bits)?;
    let weights = match opts.predictor {
        PredictorKind::Affine => None,
        PredictorKind::Skinning => Some(SkinningWeights::fit_with(
            mesh.frames(),
            reference,
            partition,
            mesh.triangles(),
            &track,
            motion::DEFAULT_RIDGE,
            opts.weight_bits,
        )?),
    };
    // Against the quantised predictor the decoder will rebuild: closed loop.
    let residuals: Vec<Vec<[f32; 3]>> = (0..mesh.frame_count())
        .map(|f| {
            Ok(motion::residuals(
                mesh.frame(f),
                &motion::predict_frame(&track, weights.as_ref(), f, reference, partition)?,
            ))
        })
        .collect::<Result<_>>()?;
    Ok((track, weights, residuals))
}

/// The absolute temporal-DCT quantiser step of an encoding: `--step` (a fraction of the first
/// frame's bounding-box diagonal) or the one `--quality` maps to, rounded to the `f32` the stream
/// stores, so that the encoder quantises with exactly the step the decoder reads.
pub fn tdct_step(mesh: &AnimatedMesh, opts: &EncodeOptions) -> Result<f32> {
    let diagonal = mesh.bbox_diagonal();
    let step = match opts.step {
        Some(fraction) => diagonal * fraction,
        None => tdct::step_for_quality(opts.quality, diagonal),
    };
    let stored = step as f32;
    if !(stored.is_normal() && stored > 0.0) {
        return Err(Error::Mesh(format!(
            "the temporal-DCT step is {step} (first frame's bounding-box diagonal {diagonal}): \
             a degenerate first frame gives no scale to quantise against"
        )));
    }
    Ok(stored)
}

/// Transforms, quantises and codes the residuals band by band: the index part and the coefficients part.
fn code_tdct(
    mesh: &AnimatedMesh,
    residuals: &[Vec<[f32; 3]>],
    opts: &EncodeOptions,
) -> Result<(Vec<u8>, Vec<u8>)> {
    let step = tdct_step(mesh, opts)?;
    let coefficients = tdct::forward(residuals)?;
    let levels = tdct::quantise(&coefficients, f64::from(step), tdct::DEAD_ZONE)?;
    let mut coder = tdct::BandCoder::new(mesh.vertex_count());
    let chunks = levels
        .iter()
        .enumerate()
        .map(|(k, band)| coder.encode(k, band))
        .collect::<Result<Vec<_>>>()?;
    let (index, payload) = tdct::BandIndex::build(step, chunks);
    Ok((index.to_bytes()?, payload))
}

/// Builds the atlas on the requested lattice, or for `Lattice::Auto` on the smallest lattice from
/// [`auto_side`] upwards on which the charts fit.
fn build_atlas(
    reference: &[Point],
    triangles: &[[u32; 3]],
    partition: &Partition,
    lattice: Lattice,
) -> Result<((u16, u16), atlas::Atlas)> {
    let build = |w: u16, h: u16| {
        atlas::build(
            reference,
            triangles,
            partition.labels(),
            &atlas::AtlasOptions {
                width: u32::from(w),
                height: u32::from(h),
                ..atlas::AtlasOptions::default()
            },
        )
    };
    let fail = |e: atlas::AtlasError| Error::Usage(format!("atlas: {e}"));
    let mut side = match lattice {
        Lattice::Fixed(w, h) => return build(w, h).map(|a| ((w, h), a)).map_err(fail),
        Lattice::Auto => auto_side(reference.len()),
    };
    loop {
        let next = match build(side, side) {
            Ok(a) => return Ok(((side, side), a)),
            Err(atlas::AtlasError::ChartsDoNotFit { blocks, block, .. }) => {
                // Room for the blocks with some slack, and at least a quarter more each time.
                let needed = f64::from(block) * (blocks as f64 * 1.3).sqrt();
                round_up_16(needed.max(f64::from(side) * 1.25))
            }
            Err(atlas::AtlasError::TooManyVertices { vertices, .. }) => {
                round_up_16((vertices as f64 * 2.0).sqrt().max(f64::from(side) * 1.25))
            }
            Err(e) => return Err(fail(e)),
        };
        if side >= 4096 {
            return Err(Error::Usage(format!(
                "atlas: the charts do not fit even a {side}x{side} lattice"
            )));
        }
        side = next;
    }
}

/// Frame `f`'s residuals of coordinate `axis` as levels in `0..=255` on the lattice, before padding
/// (free pixels are 0).
pub fn level_image(analysis: &Analysis, f: usize, axis: usize) -> Result<Vec<f32>> {
    let range = analysis.ranges[f][axis];
    let levels: Vec<f32> = analysis.residuals[f]
        .iter()
        .map(|r| range.quantise(r[axis]))
        .collect();
    analysis
        .atlas
        .try_splat(&levels)
        .map_err(|e| Error::Codec(format!("atlas: {e}")))
}

/// The three padded residual images of frame `f` (levels in `0..=255`, before rounding).
/// `previous` holds the previous frame's padded images for P-frame coding.
pub fn residual_images(
    analysis: &Analysis,
    f: usize,
    opts: &EncodeOptions,
    previous: Option<&[Vec<f32>; 3]>,
) -> Result<[Vec<f32>; 3]> {
    let (w, h) = (analysis.lattice.0 as usize, analysis.lattice.1 as usize);
    let fixed = analysis.atlas.fixed_mask();
    let mut out: [Vec<f32>; 3] = Default::default();
    for (a, img) in out.iter_mut().enumerate() {
        let mut image = level_image(analysis, f, a)?;
        padding::pad(
            &mut image,
            w,
            h,
            &fixed,
            previous.map(|p| p[a].as_slice()),
            &padding::PaddingOptions {
                method: padding_method(opts),
                jpeg_quality: opts.quality,
                ..padding::PaddingOptions::default()
            },
        )
        .map_err(|e| Error::Codec(format!("padding: {e}")))?;
        *img = image;
    }
    Ok(out)
}

/// Codes every frame's images: returns the codec set-up part and one chunk per frame.
fn code_images(
    analysis: &Analysis,
    opts: &EncodeOptions,
    progress: &ProgressBar,
) -> Result<(Vec<u8>, Vec<FrameChunk>)> {
    let (w, h) = (analysis.lattice.0 as usize, analysis.lattice.1 as usize);
    let frames = analysis.residuals.len();
    let mut chunks = Vec::with_capacity(frames);
    match opts.codec {
        CodecKind::Jpeg => {
            let mut shared_header: Option<Vec<u8>> = None;
            for f in 0..frames {
                let imgs = residual_images(analysis, f, opts, None)?;
                let plane = tile::compose([&imgs[0], &imgs[1], &imgs[2]], w, h);
                let jpeg = codec::jpeg::encode(&plane, opts.quality)?;
                let parts = abbreviated::split(&jpeg)?;
                match &shared_header {
                    None => shared_header = Some(parts.shared.clone()),
                    Some(s) if *s != parts.shared => {
                        return Err(Error::Codec("JPEG headers differ between frames".into()))
                    }
                    Some(_) => {}
                }
                let mut data = crate::stream::bytes::ByteWriter::new();
                data.blob(&parts.tables).raw(parts.scan);
                chunks.push(FrameChunk {
                    data: data.into_bytes(),
                    key: true,
                });
                progress.inc(1);
            }
            Ok((shared_header.unwrap_or_default(), chunks))
        }
        CodecKind::Mpeg4 => {
            let mut enc = mpeg4::Encoder::new(
                (3 * w) as u32,
                h as u32,
                &mpeg4::Mpeg4Options {
                    qscale: qscale(opts),
                    gop: opts.gop,
                },
            )?;
            let mut previous: Option<[Vec<f32>; 3]> = None;
            let mut packets = Vec::with_capacity(frames);
            for f in 0..frames {
                // A new group starts from an I-frame: its blocks without data need no temporal continuity.
                let prev = if f % opts.gop == 0 {
                    None
                } else {
                    previous.as_ref()
                };
                let imgs = residual_images(analysis, f, opts, prev)?;
                let plane: Plane = tile::compose([&imgs[0], &imgs[1], &imgs[2]], w, h);
                packets.extend(enc.encode(&plane)?);
                previous = Some(imgs);
                progress.inc(1);
            }
            packets.extend(enc.finish()?);
            if packets.len() != frames {
                return Err(Error::Codec(format!(
                    "the MPEG-4 encoder gave {} packets for {frames} frames",
                    packets.len()
                )));
            }
            chunks.extend(packets.into_iter().map(|p| FrameChunk {
                data: p.data,
                key: p.key,
            }));
            Ok((Vec::new(), chunks))
        }
        CodecKind::Tdct => Err(Error::Codec(
            "the temporal-DCT codec codes no images".into(),
        )),
    }
}

#[cfg(test)]
mod lattice_tests {
    use super::auto_side;

    #[test]
    fn auto_lattice_scales_with_vertices_up_to_the_papers_size() {
        assert_eq!(auto_side(3), 32);
        assert_eq!(auto_side(160), 80);
        assert_eq!(auto_side(1728), 224);
        assert_eq!(auto_side(3030), 256);
        assert_eq!(auto_side(8431), 256);
        assert_eq!(auto_side(34_159), 512);
        assert_eq!(auto_side(160) % 16, 0);
    }
}
