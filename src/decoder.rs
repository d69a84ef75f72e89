//! The decoder: stream → first frame, partition, lattice coordinates, affine track, ranges → images → frames.

use crate::codec::{abbreviated, jpeg, mpeg4, Plane};
use crate::error::{Error, Result};
use crate::geometry_image::{quantise, tile, FrameRanges};
use crate::mesh::{AnimatedMesh, Point, Triangle};
use crate::motion::{predict_frame, AffineTrack, Partition, PredictorKind, SkinningWeights};
use crate::stream::bytes::ByteReader;
use crate::stream::container::{ContainerReader, Tag};
use crate::stream::frame_index::{ChunkEntry, FrameIndex};
use crate::stream::header::{CodecKind, Header};
use crate::stream::tdct::{self, BandCoder, BandIndex};
use crate::stream::{first_frame, side_info};
use indicatif::ProgressBar;
use std::fs::File;
use std::io::{BufReader, Read, Seek};
use std::path::Path;

/// Choices a reader can make about decoding.
#[derive(Debug, Clone, Copy, Default)]
pub struct DecodeOptions {
    /// Temporal DCT only: decode no more than this many frequency bands (a progressive preview).
    pub max_bands: Option<usize>,
}

/// An opened stream: everything but the images is read and checked at open; images on demand.
pub struct Decoder<R> {
    reader: ContainerReader<R>,
    header: Header,
    triangles: Vec<Triangle>,
    reference: Vec<Point>,
    partition: Partition,
    track: AffineTrack,
    weights: Option<SkinningWeights>,
    residuals: Residuals,
}

/// How the residuals are carried: geometry images, or temporal-DCT bands.
enum Residuals {
    Images {
        pixels: Vec<[u16; 2]>,
        ranges: Vec<FrameRanges>,
        index: FrameIndex,
        codec_setup: Vec<u8>,
    },
    Tdct(TdctBands),
}

/// The decoded temporal-DCT coefficients, read once at open.
struct TdctBands {
    /// Byte length of every band in the stream, decoded or not.
    band_lengths: Vec<u64>,
    /// Dequantised coefficients of the decoded bands (`[3v + a]`); `None` for an all-zero band.
    /// Bands past `decoded` are missing (truncated stream, or a preview) and count as zero.
    bands: Vec<Option<Vec<f32>>>,
    /// Whether the stream was cut inside the coefficients part.
    truncated: bool,
    /// The quantiser step.
    step: f32,
}

impl Decoder<BufReader<File>> {
    /// Opens a `.mcgv` file.
    pub fn open(path: &Path) -> Result<Self> {
        Self::new(ContainerReader::open(path)?)
    }

    /// Opens a `.mcgv` file with decoding options.
    pub fn open_with(path: &Path, options: &DecodeOptions) -> Result<Self> {
        Self::with_options(ContainerReader::open(path)?, options)
    }
}

impl<R: Read + Seek> Decoder<R> {
    /// Reads and checks every part but the images.
    pub fn new(reader: ContainerReader<R>) -> Result<Self> {
        Self::with_options(reader, &DecodeOptions::default())
    }

    /// Reads and checks every part but the images (temporal-DCT coefficients are decoded here).
    pub fn with_options(mut reader: ContainerReader<R>, options: &DecodeOptions) -> Result<Self> {
        let header = Header::from_bytes(&reader.part(Tag::HEADER)?)?;
        let (v, f) = (header.vertices as usize, header.frames as usize);
        let (triangles, reference) = first_frame::decode(&reader.part(Tag::FIRST_FRAME)?)?;
        if reference.len() != v || triangles.len() != header.triangles as usize {
            return Err(Error::Stream(format!(
                "first frame has {} vertices and {} triangles, header says {v} and {}",
                reference.len(),
                triangles.len(),
                header.triangles
            )));
        }
        let labels = side_info::decode_partition(
            &reader.part(Tag::PARTITION)?,
            v,
            header.clusters as usize,
            &triangles,
        )?;
        let partition = Partition::from_labels(labels, header.clusters as usize)?;
        if options.max_bands.is_some() && header.codec != CodecKind::Tdct {
            return Err(Error::Usage(format!(
                "--bands applies to tdct streams; this one is {}",
                header.codec.name()
            )));
        }
        let pixels = if header.codec.has_images() {
            let lattice = (header.lattice_width, header.lattice_height);
            side_info::decode_lattice(&reader.part(Tag::LATTICE)?, v, lattice, &triangles)?
        } else {
            Vec::new()
        };
        // The ranges take 24 bytes a frame (and the band index a few bits a band), so reading them
        // first proves the header's frame count before the affine track allocates 12 coefficients
        // per frame and cluster.
        let residuals = if header.codec.has_images() {
            let ranges_bytes = reader.part(Tag::RANGES)?;
            let mut r = ByteReader::new(&ranges_bytes, "residual ranges");
            let ranges = quantise::read_ranges(&mut r, f)?;
            r.finish()?;
            let codec_setup = reader.part(Tag::CODEC_SETUP)?;
            let images_len = reader.entry(Tag::FRAMES)?.len;
            let index = FrameIndex::from_bytes(&reader.part(Tag::FRAME_INDEX)?, f, images_len)?;
            Residuals::Images {
                pixels,
                ranges,
                index,
                codec_setup,
            }
        } else {
            Residuals::Tdct(read_bands(&mut reader, v, f, options.max_bands)?)
        };
        let track = side_info::decode_affine(
            &reader.part(Tag::AFFINE)?,
            f,
            partition.clusters(),
            header.affine_bits,
        )?;
        let weights = match header.predictor {
            PredictorKind::Affine if reader.has(Tag::WEIGHTS) => {
                return Err(Error::Stream(
                    "the header says affine predictor but the stream has skinning weights".into(),
                ))
            }
            PredictorKind::Affine => None,
            PredictorKind::Skinning => Some(side_info::decode_weights(
                &reader.part(Tag::WEIGHTS)?,
                &partition,
                &triangles,
            )?),
        };
        Ok(Self {
            reader,
            header,
            triangles,
            reference,
            partition,
            track,
            weights,
            residuals,
        })
    }

    /// Temporal-DCT bands decoded (all of them for a complete stream, fewer for a truncated one
    /// or a preview); 0 for image codecs.
    pub fn bands_decoded(&self) -> usize {
        match &self.residuals {
            Residuals::Tdct(t) => t.bands.len(),
            Residuals::Images { .. } => 0,
        }
    }

    /// Temporal-DCT bands in the stream (one per frame); 0 for image codecs.
    pub fn bands_total(&self) -> usize {
        match &self.residuals {
            Residuals::Tdct(t) => t.band_lengths.len(),
            Residuals::Images { .. } => 0,
        }
    }

    /// Byte length of every temporal-DCT band, low to high frequency (empty for image codecs).
    pub fn band_lengths(&self) -> &[u64] {
        match &self.residuals {
            Residuals::Tdct(t) => &t.band_lengths,
            Residuals::Images { .. } => &[],
        }
    }

    /// The temporal-DCT quantiser step in the mesh's units (`None` for image codecs).
    pub fn band_step(&self) -> Option<f32> {
        match &self.residuals {
            Residuals::Tdct(t) => Some(t.step),
            Residuals::Images { .. } => None,
        }
    }

    /// Whether the file ends inside the temporal-DCT coefficients (the bands after the cut are
    /// decoded as zero: a coarser animation).
    pub fn truncated(&self) -> bool {
        matches!(&self.residuals, Residuals::Tdct(t) if t.truncated)
    }

    /// The stream header.
    pub fn header(&self) -> &Header {
        &self.header
    }

    /// The shared connectivity.
    pub fn triangles(&self) -> &[Triangle] {
        &self.triangles
    }

    /// The decoded first frame (12-bit geometry), which every prediction starts from.
    pub fn reference(&self) -> &[Point] {
        &self.reference
    }

    /// The motion partition.
    pub fn partition(&self) -> &Partition {
        &self.partition
    }

    /// The skinning weights, when the stream uses the skinning predictor.
    pub fn weights(&self) -> Option<&SkinningWeights> {
        self.weights.as_ref()
    }

    /// Lattice pixel of every vertex (empty for tdct streams, which have no lattice).
    pub fn vertex_pixels(&self) -> &[[u16; 2]] {
        match &self.residuals {
            Residuals::Images { pixels, .. } => pixels,
            Residuals::Tdct(_) => &[],
        }
    }

    /// The residual range of every frame and coordinate (empty for tdct streams).
    pub fn ranges(&self) -> &[FrameRanges] {
        match &self.residuals {
            Residuals::Images { ranges, .. } => ranges,
            Residuals::Tdct(_) => &[],
        }
    }

    /// The part table, for bit budgets.
    pub fn container(&self) -> &ContainerReader<R> {
        &self.reader
    }

    /// Where frame `f`'s coded picture lies in the images part.
    pub fn frame_entry(&self, f: usize) -> Result<ChunkEntry> {
        self.index()?.entry(f)
    }

    fn index(&self) -> Result<&FrameIndex> {
        match &self.residuals {
            Residuals::Images { index, .. } => Ok(index),
            Residuals::Tdct(_) => Err(Error::Usage(
                "a tdct stream has no images: its residuals are temporal-DCT bands".into(),
            )),
        }
    }

    /// Decodes frame `f` alone: reads only its own chunk for intra streams, the chunks from the
    /// last key frame for P-frame streams, and sums the decoded bands' basis functions at `f` for
    /// temporal-DCT streams.
    pub fn decode_frame(&mut self, f: usize) -> Result<Vec<Point>> {
        if let Residuals::Tdct(t) = &self.residuals {
            let frames = self.header.frames as usize;
            if f >= frames {
                return Err(Error::Usage(format!(
                    "frame {f}: the stream has frames 0 to {}",
                    frames - 1
                )));
            }
            let mut out = self.predict(f)?;
            let mut sum = vec![0.0f64; 3 * out.len()];
            for (k, band) in t.bands.iter().enumerate() {
                if let Some(c) = band {
                    let b = tdct::basis(k, f, frames);
                    for (s, &c) in sum.iter_mut().zip(c) {
                        *s += f64::from(c) * b;
                    }
                }
            }
            for (v, (p, s)) in out.iter_mut().zip(sum.chunks_exact(3)).enumerate() {
                for a in 0..3 {
                    p[a] += s[a] as f32;
                }
                // decode_all refuses such a frame (a mesh holds finite coordinates only): a frame
                // read alone must not come back as infinities instead.
                if p.iter().any(|x| !x.is_finite()) {
                    return Err(Error::Stream(format!(
                        "frame {f}, vertex {v}: coordinate is not a finite number"
                    )));
                }
            }
            return Ok(out);
        }
        let plane = self.decoded_plane(f)?;
        self.reconstruct(f, &plane)
    }

    /// The decoded picture (x | y | z residual images side by side) of frame `f`.
    pub fn decoded_plane(&mut self, f: usize) -> Result<Plane> {
        let key = {
            let index = self.index()?;
            index.entry(f)?;
            index.key_before(f)
        };
        match self.header.codec {
            CodecKind::Jpeg => self.jpeg_plane(f),
            CodecKind::Mpeg4 => {
                let mut dec = self.mpeg4_decoder()?;
                let mut last = None;
                for g in key..=f {
                    last = Some(self.mpeg4_next(&mut dec, g)?);
                }
                last.ok_or_else(|| Error::Stream("no frame decoded".into()))
            }
            CodecKind::Tdct => Err(Error::Usage(
                "a tdct stream has no images: its residuals are temporal-DCT bands".into(),
            )),
        }
    }

    /// Decodes every frame in order.
    pub fn decode_all(&mut self, progress: &ProgressBar) -> Result<AnimatedMesh> {
        if let Residuals::Tdct(t) = &self.residuals {
            let out = self.tdct_all(t)?;
            progress.inc(out.len() as u64);
            return AnimatedMesh::new(self.triangles.clone(), out);
        }
        let frames = self.header.frames as usize;
        let mut out = Vec::with_capacity(frames);
        let mut dec = match self.header.codec {
            CodecKind::Mpeg4 => Some(self.mpeg4_decoder()?),
            CodecKind::Jpeg | CodecKind::Tdct => None,
        };
        for f in 0..frames {
            let plane = match dec.as_mut() {
                Some(d) => self.mpeg4_next(d, f)?,
                None => self.jpeg_plane(f)?,
            };
            out.push(self.reconstruct(f, &plane)?);
            progress.inc(1);
        }
        AnimatedMesh::new(self.triangles.clone(), out)
    }

    /// Every frame of a temporal-DCT stream: the prediction plus the inverse DCT of each
    /// vertex/axis sequence (rustdct's DCT-III over all frames).
    fn tdct_all(&self, t: &TdctBands) -> Result<Vec<Vec<Point>>> {
        let frames = self.header.frames as usize;
        let mut out = (0..frames)
            .map(|f| self.predict(f))
            .collect::<Result<Vec<_>>>()?;
        let mut inverse = tdct::Inverse::new(frames);
        for v in 0..self.reference.len() {
            for a in 0..3 {
                let x = inverse.run(|k| match t.bands.get(k) {
                    Some(Some(c)) => f64::from(c[3 * v + a]),
                    _ => 0.0,
                });
                for (frame, &x) in out.iter_mut().zip(x) {
                    frame[v][a] += x as f32;
                }
            }
        }
        Ok(out)
    }

    fn predict(&self, f: usize) -> Result<Vec<Point>> {
        predict_frame(
            &self.track,
            self.weights.as_ref(),
            f,
            &self.reference,
            &self.partition,
        )
    }

    fn frame_bytes(&mut self, f: usize) -> Result<Vec<u8>> {
        let e = self.index()?.entry(f)?;
        self.reader
            .chunk(Tag::FRAMES, e.offset, e.len, e.crc, &format!("frame {f}"))
    }

    fn jpeg_plane(&mut self, f: usize) -> Result<Plane> {
        let chunk = self.frame_bytes(f)?;
        let mut r = ByteReader::new(&chunk, "JPEG frame");
        let tables = r.blob()?;
        let scan = r.take(r.remaining())?;
        let setup = match &self.residuals {
            Residuals::Images { codec_setup, .. } => codec_setup.as_slice(),
            Residuals::Tdct(_) => &[],
        };
        let bytes = abbreviated::join(setup, tables, scan)
            .map_err(|e| Error::Stream(format!("frame {f}: {e}")))?;
        let (w, h) = self.picture_size();
        jpeg::decode(&bytes, w, h).map_err(|e| Error::Stream(format!("frame {f}: {e}")))
    }

    fn mpeg4_decoder(&self) -> Result<mpeg4::Decoder> {
        let (w, h) = self.picture_size();
        mpeg4::Decoder::new(w, h)
    }

    /// Feeds frame `f`'s packet and returns its picture (one packet per frame, no B-frames: no reordering).
    fn mpeg4_next(&mut self, dec: &mut mpeg4::Decoder, f: usize) -> Result<Plane> {
        let packet = self.frame_bytes(f)?;
        let mut planes = dec.decode(&packet)?;
        if planes.is_empty() {
            planes = dec.flush()?;
        }
        planes.pop().ok_or_else(|| {
            Error::Stream(format!(
                "frame {f}: the MPEG-4 packet decoded to no picture"
            ))
        })
    }

    fn picture_size(&self) -> (u32, u32) {
        (
            3 * self.header.lattice_width as u32,
            self.header.lattice_height as u32,
        )
    }

    fn reconstruct(&self, f: usize, plane: &Plane) -> Result<Vec<Point>> {
        let (w, h) = self.picture_size();
        if plane.width != w || plane.height != h {
            return Err(Error::Stream(format!(
                "frame {f}: picture is {}x{}, expected {w}x{h}",
                plane.width, plane.height
            )));
        }
        let Residuals::Images { pixels, ranges, .. } = &self.residuals else {
            return Err(Error::Usage("a tdct stream has no images".into()));
        };
        let lw = self.header.lattice_width as usize;
        let mut out = self.predict(f)?;
        for a in 0..3 {
            let levels = tile::sample(plane, a, lw, pixels);
            let range = ranges[f][a];
            for (p, l) in out.iter_mut().zip(levels) {
                p[a] += range.dequantise(l);
            }
        }
        Ok(out)
    }
}

/// Reads the temporal-DCT index and decodes the bands, low to high, up to `max_bands`, the end of
/// a truncated file, or the last band. A band cut by the end of the file ends decoding (it and the
/// rest count as zero); a band present in full that fails its CRC is damage, an error.
fn read_bands<R: Read + Seek>(
    reader: &mut ContainerReader<R>,
    vertices: usize,
    frames: usize,
    max_bands: Option<usize>,
) -> Result<TdctBands> {
    let entry = reader.entry(Tag::TDCT)?;
    let declared = reader.truncated(Tag::TDCT);
    let index = BandIndex::from_bytes(
        &reader.part(Tag::TDCT_INDEX)?,
        frames,
        declared.unwrap_or(entry.len),
    )?;
    let step = index.step;
    let limit = max_bands.unwrap_or(frames).min(frames);
    let mut coder = BandCoder::new(vertices);
    let mut bands = Vec::new();
    for (k, band) in index.bands.iter().enumerate().take(limit) {
        let present = band.offset + band.len <= entry.len;
        if !present {
            break;
        }
        let bytes = if band.len == 0 {
            Vec::new()
        } else {
            reader.chunk(
                Tag::TDCT,
                band.offset,
                band.len,
                band.crc,
                &format!("temporal-DCT band {k}"),
            )?
        };
        let levels = coder.decode(k, &bytes)?;
        let coefficients = levels.map(|l| -> Vec<f32> {
            l.iter()
                .map(|&q| (q as f64 * f64::from(step)) as f32)
                .collect()
        });
        // Levels are bounded but the step is any positive f32: their product can overflow, and an
        // infinite coefficient would turn every frame's coordinates into infinities or NaN.
        if coefficients
            .as_ref()
            .is_some_and(|c| c.iter().any(|x| !x.is_finite()))
        {
            return Err(Error::Stream(format!(
                "temporal-DCT band {k}: a level times the step {step:e} is not a finite number"
            )));
        }
        bands.push(coefficients);
    }
    Ok(TdctBands {
        band_lengths: index.bands.iter().map(|b| b.len).collect(),
        bands,
        truncated: declared.is_some(),
        step,
    })
}
