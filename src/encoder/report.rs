//! What an encoding gives back: the stream in memory ([`Encoded`]) and its figures
//! ([`EncodeReport`]).

use super::{ChoiceReport, FirstFrameTrial, MotionModel, SegmentationReport};
use crate::codec::Codec;
use crate::error::Result;
use crate::motion::Partition;
use crate::stream::container::ContainerWriter;
use crate::stream::header::Header;
use std::path::Path;

/// What an encoding produced, for reports.
#[derive(Debug, Clone, serde::Serialize)]
pub struct EncodeReport {
    /// The stream header.
    pub header: Header,
    /// The residual codec.
    pub codec: Codec,
    /// Bytes per part, in file order.
    pub parts: Vec<(String, u64)>,
    /// Total file bytes.
    pub bytes: u64,
    /// Bits per vertex per frame.
    pub bpvf: f64,
    /// Charts in the atlas (0 for codecs without an atlas).
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
    /// With an automatic predictor or segmentation: the candidates measured and the one kept.
    pub choice: Option<ChoiceReport>,
    /// tdct with the first frame's precision left open: each precision tried and its stream's
    /// bytes (empty otherwise); the header says which was kept.
    pub first_frame_trials: Vec<FirstFrameTrial>,
    /// Picture codecs: the widest window a group of pictures' residuals of one coordinate span
    /// (model units; all but the share sent as corrections), over every group and segment coded
    /// by this encoding; a pixel step finer than it over a sample's levels widens a group's step,
    /// and the error stops following the quality. `None` for tdct, and for a segmented encoding
    /// one of whose segments came in as bytes ([`super::CodedSegment::from_bytes`]).
    pub residual_spread: Option<f64>,
    /// Picture codecs: the bits a sample of the pictures coded (8 for JPEG and MPEG-4; HEVC and
    /// AV1 at the automatic depth: 12 from quality 65 for HEVC, 90 for AV1, and
    /// below where 10-bit samples would widen a group's step); `None` for tdct.
    pub picture_depth: Option<u8>,
    /// Temporal segments the stream is cut into (1: not cut). The choices above were made on the
    /// first segment.
    pub segments: usize,
    /// If the first-frame coder reordered vertices: new index → input index.
    #[serde(skip)]
    pub permutation: Option<Vec<u32>>,
}

/// An encoded stream in memory, and what it took.
pub struct Encoded {
    /// The container, ready to be written.
    pub container: ContainerWriter,
    /// The figures of the encoding.
    pub report: EncodeReport,
    /// The motion model and clusters it was coded with, for trials that keep them.
    pub(crate) model: MotionModel,
    pub(crate) partition: Partition,
    /// The atlas the pictures were laid on (picture codecs), which a segmented encoding's
    /// segments reuse instead of building it again.
    pub(crate) atlas: Option<((u16, u16), atlas::Atlas)>,
}

impl Encoded {
    /// The `.mcgv` file's bytes.
    pub fn to_bytes(&self) -> Vec<u8> {
        self.container.to_bytes()
    }

    /// Writes the `.mcgv` file so that a failure never leaves half of one; returns its size.
    pub fn write(&self, path: &Path) -> Result<u64> {
        self.container.write_atomic(path)
    }
}
