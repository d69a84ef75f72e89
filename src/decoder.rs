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
use crate::stream::{first_frame, side_info};
use indicatif::ProgressBar;
use std::fs::File;
use std::io::{BufReader, Read, Seek};
use std::path::Path;

/// An opened stream: everything but the images is read and checked at open; images on demand.
pub struct Decoder<R> {
    reader: ContainerReader<R>,
    header: Header,
    triangles: Vec<Triangle>,
    reference: Vec<Point>,
    partition: Partition,
    track: AffineTrack,
    weights: Option<SkinningWeights>,
    pixels: Vec<[u16; 2]>,
    ranges: Vec<FrameRanges>,
    index: FrameIndex,
    codec_setup: Vec<u8>,
}

impl Decoder<BufReader<File>> {
    /// Opens a `.mcgv` file.
    pub fn open(path: &Path) -> Result<Self> {
        Self::new(ContainerReader::open(path)?)
    }
}

impl<R: Read + Seek> Decoder<R> {
    /// Reads and checks every part but the images.
    pub fn new(mut reader: ContainerReader<R>) -> Result<Self> {
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
        let lattice = (header.lattice_width, header.lattice_height);
        let pixels =
            side_info::decode_lattice(&reader.part(Tag::LATTICE)?, v, lattice, &triangles)?;
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
        let ranges_bytes = reader.part(Tag::RANGES)?;
        let mut r = ByteReader::new(&ranges_bytes, "residual ranges");
        let ranges = quantise::read_ranges(&mut r, f)?;
        r.finish()?;
        let codec_setup = reader.part(Tag::CODEC_SETUP)?;
        let images_len = reader.entry(Tag::FRAMES)?.len;
        let index = FrameIndex::from_bytes(&reader.part(Tag::FRAME_INDEX)?, f, images_len)?;
        Ok(Self {
            reader,
            header,
            triangles,
            reference,
            partition,
            track,
            weights,
            pixels,
            ranges,
            index,
            codec_setup,
        })
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

    /// Lattice pixel of every vertex.
    pub fn vertex_pixels(&self) -> &[[u16; 2]] {
        &self.pixels
    }

    /// The residual range of every frame and coordinate.
    pub fn ranges(&self) -> &[FrameRanges] {
        &self.ranges
    }

    /// The part table, for bit budgets.
    pub fn container(&self) -> &ContainerReader<R> {
        &self.reader
    }

    /// Where frame `f`'s coded picture lies in the images part.
    pub fn frame_entry(&self, f: usize) -> Result<ChunkEntry> {
        self.index.entry(f)
    }

    /// Decodes frame `f` alone: reads only its own chunk for intra streams, and the chunks from the
    /// last key frame for P-frame streams.
    pub fn decode_frame(&mut self, f: usize) -> Result<Vec<Point>> {
        let plane = self.decoded_plane(f)?;
        self.reconstruct(f, &plane)
    }

    /// The decoded picture (x | y | z residual images side by side) of frame `f`.
    pub fn decoded_plane(&mut self, f: usize) -> Result<Plane> {
        self.index.entry(f)?;
        match self.header.codec {
            CodecKind::Jpeg => self.jpeg_plane(f),
            CodecKind::Mpeg4 => {
                let mut dec = self.mpeg4_decoder()?;
                let mut last = None;
                for g in self.index.key_before(f)..=f {
                    last = Some(self.mpeg4_next(&mut dec, g)?);
                }
                last.ok_or_else(|| Error::Stream("no frame decoded".into()))
            }
        }
    }

    /// Decodes every frame in order.
    pub fn decode_all(&mut self, progress: &ProgressBar) -> Result<AnimatedMesh> {
        let frames = self.header.frames as usize;
        let mut out = Vec::with_capacity(frames);
        let mut dec = match self.header.codec {
            CodecKind::Mpeg4 => Some(self.mpeg4_decoder()?),
            CodecKind::Jpeg => None,
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

    fn frame_bytes(&mut self, f: usize) -> Result<Vec<u8>> {
        let e = self.index.entry(f)?;
        self.reader
            .chunk(Tag::FRAMES, e.offset, e.len, e.crc, &format!("frame {f}"))
    }

    fn jpeg_plane(&mut self, f: usize) -> Result<Plane> {
        let chunk = self.frame_bytes(f)?;
        let mut r = ByteReader::new(&chunk, "JPEG frame");
        let tables = r.blob()?;
        let scan = r.take(r.remaining())?;
        let bytes = abbreviated::join(&self.codec_setup, tables, scan)
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
        let lw = self.header.lattice_width as usize;
        let mut out = predict_frame(
            &self.track,
            self.weights.as_ref(),
            f,
            &self.reference,
            &self.partition,
        )?;
        for a in 0..3 {
            let levels = tile::sample(plane, a, lw, &self.pixels);
            let range = self.ranges[f][a];
            for (p, l) in out.iter_mut().zip(levels) {
                p[a] += range.dequantise(l);
            }
        }
        Ok(out)
    }
}
