//! Pad, code with JPEG, decode, and measure bytes and the error on fixed pixels.

use std::time::Instant;

use padding::{pad, Method, PaddingOptions};

use crate::images::{Sample, Sequence};

/// Totals of one (sequence, method, quality).
#[derive(Debug, Clone, Copy, Default)]
pub struct Point {
    pub bytes_per_frame: f64,
    /// RMS error over all fixed pixels, in grey levels (0–255 scale).
    pub rmse: f64,
}

/// Everything measured for one method on one sequence.
pub struct MethodResult {
    pub label: String,
    /// One point per quality of the sweep, in sweep order.
    pub points: Vec<Point>,
    pub pad_ms_per_frame: f64,
    pub cg_iterations_per_system: f64,
    pub unconverged: usize,
}

/// Pads every sample with `options` and codes it at every quality in `qualities`.
pub fn run(
    sequence: &Sequence,
    label: &str,
    options: &PaddingOptions,
    qualities: &[u8],
) -> Result<MethodResult, String> {
    let mut bytes = vec![0usize; qualities.len()];
    let mut sse = vec![0.0f64; qualities.len()];
    let mut fixed_count = 0usize;
    let mut pad_seconds = 0.0;
    let mut iterations = 0usize;
    let mut systems = 0usize;
    let mut unconverged = 0usize;
    // Methods that read `jpeg_quality` are padded once per quality; the others once per image.
    let per_quality = options.method == Method::Snap;
    let mut pads = 0usize;
    for sample in &sequence.samples {
        fixed_count += sample.fixed.iter().filter(|&&f| f).count();
        let mut grey = Vec::new();
        for (q, &quality) in qualities.iter().enumerate() {
            if grey.is_empty() || per_quality {
                let options = PaddingOptions {
                    jpeg_quality: quality,
                    ..options.clone()
                };
                let mut image = sample.grey.clone();
                let start = Instant::now();
                let stats = pad(
                    &mut image,
                    sample.width,
                    sample.height,
                    &sample.fixed,
                    None,
                    &options,
                )
                .map_err(|e| e.to_string())?;
                pad_seconds += start.elapsed().as_secs_f64();
                pads += 1;
                iterations += stats.cg_iterations;
                systems += stats.systems;
                unconverged += stats.unconverged;
                grey = image
                    .iter()
                    .map(|&v| v.round().clamp(0.0, 255.0) as u8)
                    .collect();
            }
            let (coded, decoded) = jpeg_round_trip(&grey, sample, quality)?;
            bytes[q] += coded;
            sse[q] += fixed_sse(sample, &decoded);
        }
    }
    // Time of one padding of every image of a frame.
    pad_seconds *= sequence.samples.len() as f64 / pads.max(1) as f64;
    let frames = sequence.frames();
    Ok(MethodResult {
        label: label.to_string(),
        points: bytes
            .iter()
            .zip(&sse)
            .map(|(&b, &e)| Point {
                bytes_per_frame: b as f64 / frames,
                rmse: (e / fixed_count.max(1) as f64).sqrt(),
            })
            .collect(),
        pad_ms_per_frame: pad_seconds * 1000.0 / frames,
        cg_iterations_per_system: iterations as f64 / systems.max(1) as f64,
        unconverged,
    })
}

/// Baseline JPEG (Annex K tables scaled by quality, standard Huffman tables, one grey channel).
fn jpeg_round_trip(grey: &[u8], sample: &Sample, quality: u8) -> Result<(usize, Vec<u8>), String> {
    let mut coded = Vec::new();
    let encoder = jpeg_encoder::Encoder::new(&mut coded, quality);
    let (w, h) = (
        u16::try_from(sample.width).map_err(|_| "image too wide for JPEG")?,
        u16::try_from(sample.height).map_err(|_| "image too tall for JPEG")?,
    );
    encoder
        .encode(grey, w, h, jpeg_encoder::ColorType::Luma)
        .map_err(|e| e.to_string())?;
    let decoded = image::load_from_memory_with_format(&coded, image::ImageFormat::Jpeg)
        .map_err(|e| e.to_string())?
        .to_luma8()
        .into_raw();
    Ok((coded.len(), decoded))
}

fn fixed_sse(sample: &Sample, decoded: &[u8]) -> f64 {
    sample
        .grey
        .iter()
        .zip(decoded)
        .zip(&sample.fixed)
        .filter(|(_, &f)| f)
        .map(|((&r, &d), _)| (f64::from(r) - f64::from(d)).powi(2))
        .sum()
}

/// Bytes per frame `result` would need to reach `target` RMSE: linear interpolation of log(bytes)
/// against log(error) between the two sweep points that bracket `target`; None outside the sweep.
pub fn bytes_at_error(result: &MethodResult, target: f64) -> Option<f64> {
    let mut points = result.points.clone();
    points.sort_by(|a, b| a.rmse.total_cmp(&b.rmse));
    points.windows(2).find_map(|pair| {
        let (a, b) = (pair[0], pair[1]);
        if target < a.rmse || target > b.rmse {
            return None;
        }
        if (b.rmse - a.rmse).abs() < 1e-12 {
            return Some(a.bytes_per_frame.min(b.bytes_per_frame));
        }
        let t = (target.ln() - a.rmse.ln()) / (b.rmse.ln() - a.rmse.ln());
        Some((a.bytes_per_frame.ln() * (1.0 - t) + b.bytes_per_frame.ln() * t).exp())
    })
}
