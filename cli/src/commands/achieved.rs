//! What `encode` achieved: the error of the stream it wrote, measured by decoding that file and
//! comparing it with the input, so that the report states what the user got rather than what the
//! encoder aimed at (the quality's step bounds the residuals, not the error after every stage).

use mcgv_video::mesh::{AnimatedMesh, ReadOptions};
use mcgv_video::metrics::same_frame_count;
use mcgv_video::{Decoder, Result};
use serde::Serialize;
use std::path::Path;

/// The error of a written stream against its input, as fractions of the diagonal of the input's
/// first-frame bounding box (the unit `eval` measures in).
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Achieved {
    /// RMS per-vertex displacement over all vertices and frames (`eval`'s vertex RMSE).
    pub vertex_rmse: f64,
    /// The largest displacement of any vertex in any frame.
    pub max_error: f64,
}

impl Achieved {
    /// The report's line: both figures in units of 10⁻⁴ of the diagonal, as `eval` gives them.
    pub fn line(&self) -> String {
        format!(
            "error: vertex RMSE {:.4} ×10⁻⁴, max {:.4} ×10⁻⁴ of the bbox diagonal (the file decoded)",
            self.vertex_rmse * 1e4,
            self.max_error * 1e4
        )
    }
}

/// Decodes `stream` a segment at a time and compares it with `input` read with `read`: memory
/// holds one segment of each, as in `eval`.
pub fn measure(
    input: &str,
    read: &ReadOptions,
    stream: &Path,
    max_positions: Option<u64>,
) -> Result<Achieved> {
    let mut original = super::open_source(input, read, true)?;
    let options = super::decode::decode_options(None, max_positions);
    let mut decoder = Decoder::open_with(stream, &options)?;
    same_frame_count(original.frame_count(), decoder.header().frames as usize)?;
    // A stream coded with --reorder decodes in its own vertex order.
    let order = decoder.input_order(original.first())?;
    let diagonal = original.first().bbox_diagonal().max(f64::MIN_POSITIVE);
    let (mut squares, mut largest, mut count) = (0.0_f64, 0.0_f64, 0_u64);
    for (s, range) in decoder.segments().to_vec().into_iter().enumerate() {
        let positions = decoder.decode_segment(s, &mcgv_video::Silent)?;
        let mut decoded = AnimatedMesh::new(decoder.triangles().to_vec(), positions)?;
        if let Some(inverse) = &order {
            decoded = decoded.permuted(inverse)?;
        }
        for (a, b) in original.read(range)?.iter().zip(decoded.frames()) {
            for (p, q) in a.iter().zip(b) {
                let d2: f64 = (0..3)
                    .map(|k| (f64::from(p[k]) - f64::from(q[k])).powi(2))
                    .sum();
                squares += d2;
                largest = largest.max(d2);
                count += 1;
            }
        }
    }
    Ok(Achieved {
        vertex_rmse: (squares / count.max(1) as f64).sqrt() / diagonal,
        max_error: largest.sqrt() / diagonal,
    })
}
