//! The encoder: mesh → motion → atlas → geometry images → codec → stream.

use crate::codec::{self, abbreviated, mpeg4, Plane};
use crate::error::{Error, Result};
use crate::geometry_image::{quantise, tile, FrameRanges, RangeMode};
use crate::mesh::{AnimatedMesh, Point};
use crate::motion::{self, AffineTrack, Partition, SegmentOptions};
use crate::stream::container::{Checksum, ContainerWriter, Tag};
use crate::stream::frame_index::{FrameChunk, FrameIndex};
use crate::stream::header::{CodecKind, Header};
use crate::stream::{first_frame, side_info};
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
    /// Motion clusters K.
    pub clusters: usize,
    /// Bits per affine coefficient.
    pub affine_bits: u8,
    /// Bits per coordinate of the first frame.
    pub first_frame_bits: u8,
    /// Lattice width and height.
    pub lattice: (u16, u16),
    /// Padding of the free pixels; `None` picks the codec's measured best (see [`padding_method`]).
    pub padding: Option<padding::Method>,
    /// MPEG-4 group of pictures.
    pub gop: usize,
    /// Let the first-frame coder permute vertices.
    pub reorder: bool,
}

impl Default for EncodeOptions {
    fn default() -> Self {
        Self {
            codec: CodecKind::Jpeg,
            quality: DEFAULT_QUALITY,
            qscale: None,
            clusters: 20,
            affine_bits: 17,
            first_frame_bits: 12,
            lattice: (256, 256),
            padding: None,
            gop: 50,
            reorder: false,
        }
    }
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
    /// Charts in the atlas.
    pub charts: usize,
    /// Chart pixels / lattice pixels.
    pub packing_efficiency: f64,
    /// Vertices moved to resolve lattice collisions.
    pub moved_vertices: usize,
    /// Area-weighted L2 stretch of the charts (1 = none).
    pub l2_stretch: f64,
    /// Seconds per stage.
    pub stage_seconds: Vec<(String, f64)>,
    /// If the first-frame coder reordered vertices: new index → input index.
    #[serde(skip)]
    pub permutation: Option<Vec<u32>>,
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

    progress.set_message("motion");
    let analysis = analyse(mesh, ff.decoded_positions, opts)?;
    lap("motion + atlas", &mut seconds);

    progress.set_message("images");
    let (setup, chunks) = code_images(&analysis, opts, progress)?;
    lap("images", &mut seconds);

    let header = Header {
        vertices: mesh.vertex_count() as u32,
        frames: mesh.frame_count() as u32,
        triangles: mesh.triangles().len() as u32,
        clusters: analysis.partition.clusters() as u32,
        lattice_width: opts.lattice.0,
        lattice_height: opts.lattice.1,
        codec: opts.codec,
        quality: opts.quality,
        qscale: qscale(opts),
        gop: match opts.codec {
            CodecKind::Jpeg => 1,
            CodecKind::Mpeg4 => opts.gop as u32,
        },
        affine_bits: opts.affine_bits,
        first_frame_bits: opts.first_frame_bits,
        padding: padding_method(opts).to_string(),
        requested_clusters: opts.clusters as u32,
        reorder: opts.reorder,
        charts: analysis.atlas.stats().charts as u32,
        chart_pixels: analysis.atlas.stats().chart_pixels as u32,
    };
    let mut container = ContainerWriter::new();
    container.add(Tag::HEADER, header.to_bytes(), Checksum::Whole);
    container.add(Tag::FIRST_FRAME, ff.bytes, Checksum::Whole);
    container.add(
        Tag::PARTITION,
        side_info::encode_partition(
            analysis.partition.labels(),
            analysis.partition.clusters(),
            mesh.triangles(),
        )?,
        Checksum::Whole,
    );
    container.add(
        Tag::LATTICE,
        side_info::encode_lattice(
            analysis.atlas.vertex_pixels(),
            opts.lattice,
            mesh.triangles(),
        )?,
        Checksum::Whole,
    );
    container.add(
        Tag::AFFINE,
        side_info::encode_affine(&analysis.track)?,
        Checksum::Whole,
    );
    let mut w = crate::stream::bytes::ByteWriter::new();
    quantise::write_ranges(&analysis.ranges, &mut w);
    container.add(Tag::RANGES, w.into_bytes(), Checksum::Whole);
    container.add(Tag::CODEC_SETUP, setup, Checksum::Whole);
    let (index, payload) = FrameIndex::build(chunks);
    container.add(Tag::FRAME_INDEX, index.to_bytes(), Checksum::Whole);
    container.add(Tag::FRAMES, payload, Checksum::Chunked);
    lap("side information", &mut seconds);

    let bytes = container.to_bytes().len() as u64;
    let stats = analysis.atlas.stats();
    let report = EncodeReport {
        parts: container.part_sizes(),
        bpvf: bytes as f64 * 8.0 / (header.vertices as f64 * header.frames as f64),
        header,
        bytes,
        charts: stats.charts,
        packing_efficiency: stats.packing_efficiency,
        moved_vertices: stats.moved_vertices,
        l2_stretch: stats.l2_stretch,
        stage_seconds: seconds,
        permutation: ff.permutation,
    };
    Ok(Encoded { container, report })
}

fn check_options(mesh: &AnimatedMesh, opts: &EncodeOptions) -> Result<()> {
    if opts.clusters == 0 {
        return Err(Error::Usage("--clusters must be at least 1".into()));
    }
    if !(8..=32).contains(&opts.affine_bits) {
        return Err(Error::Usage(
            "--affine-bits must be between 8 and 32".into(),
        ));
    }
    let (w, h) = opts.lattice;
    let max = crate::stream::header::MAX_LATTICE_SIDE;
    if w == 0 || h == 0 || w % 16 != 0 || h % 16 != 0 || w > max || h > max {
        return Err(Error::Usage(format!(
            "lattice {w}x{h}: width and height must be multiples of 16 between 16 and {max}"
        )));
    }
    if opts.gop == 0 {
        return Err(Error::Usage("--gop must be at least 1".into()));
    }
    if mesh.triangles().is_empty() {
        return Err(Error::Mesh(
            "the mesh has no triangles: nothing to parameterize".into(),
        ));
    }
    Ok(())
}

/// The padding an encoding uses: the user's choice, else the measured winner for the codec —
/// `snap` (tuned to JPEG's quantiser at the stream's quality) for JPEG, and for MPEG-4, whose
/// quantiser differs, the quality-independent `biharmonic`.
pub fn padding_method(opts: &EncodeOptions) -> padding::Method {
    opts.padding.unwrap_or(match opts.codec {
        CodecKind::Jpeg => padding::Method::Snap,
        CodecKind::Mpeg4 => padding::Method::Biharmonic,
    })
}

/// The MPEG-4 quantiser an encoding uses (0 for JPEG).
pub fn qscale(opts: &EncodeOptions) -> u8 {
    match opts.codec {
        CodecKind::Jpeg => 0,
        CodecKind::Mpeg4 => opts
            .qscale
            .unwrap_or_else(|| codec::quality_to_qscale(opts.quality)),
    }
}

/// Segmentation, prediction, atlas and residuals: everything before the images are coded.
pub fn analyse(
    mesh: &AnimatedMesh,
    reference: Vec<Point>,
    opts: &EncodeOptions,
) -> Result<Analysis> {
    let partition = motion::segment(
        mesh,
        &SegmentOptions {
            clusters: opts.clusters,
            ..SegmentOptions::default()
        },
    )?;
    let track = AffineTrack::fit(mesh.frames(), &reference, &partition, opts.affine_bits)?;
    let atlas = atlas::build(
        &reference,
        mesh.triangles(),
        partition.labels(),
        &atlas::AtlasOptions {
            width: opts.lattice.0 as u32,
            height: opts.lattice.1 as u32,
            ..atlas::AtlasOptions::default()
        },
    )
    .map_err(|e| Error::Usage(format!("atlas: {e}")))?;
    let residuals: Vec<Vec<[f32; 3]>> = (0..mesh.frame_count())
        .map(|f| {
            Ok(motion::residuals(
                mesh.frame(f),
                &track.try_predict(f, &reference, &partition)?,
            ))
        })
        .collect::<Result<_>>()?;
    let mode = match opts.codec {
        CodecKind::Jpeg => RangeMode::PerFrame,
        CodecKind::Mpeg4 => RangeMode::PerGroup(opts.gop),
    };
    let ranges = quantise::frame_ranges(&residuals, mode);
    Ok(Analysis {
        reference,
        partition,
        track,
        atlas,
        residuals,
        ranges,
    })
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
    let (w, h) = (opts.lattice.0 as usize, opts.lattice.1 as usize);
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
    let (w, h) = (opts.lattice.0 as usize, opts.lattice.1 as usize);
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
    }
}
