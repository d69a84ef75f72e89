//! The residual ranges part (picture set-up version 2): the pixel step, every frame's step and
//! offset per axis, and the correction list, entropy-coded with what the decoder already has.
//!
//! Version 1 stored 8 raw bytes a frame and axis and LEB128 corrections. But a frame's range is
//! almost always the previous frame's (P-frame groups share one; intra frames drift by a few
//! steps) and almost always at the pixel step, so a range costs one adaptive bit when it repeats,
//! else a bit for a widened step and the offset's change. A correction is a residual beyond its
//! frame's range: it is coded as the side of the range it left and its distance past that
//! bound, in pixel steps, instead of its whole value.

use super::corrections::{Correction, Corrections};
use super::quantise::{AxisRange, FrameRanges};
use crate::error::{Error, Result};
use crate::stream::bytes::{ByteReader, ByteWriter};
use crate::stream::entropy::{
    self, BitModel, Decoder, Encoder, IntModel, SymbolCoder, SymbolModel, UIntModel,
};

/// Coded after the last correction, checked by the decoder: the range decoder reads a cut-off
/// stream as if zeros followed, which would otherwise decode to plausible ranges.
const RANGES_END: u32 = 0x4A4E_6E5D;

/// The adaptive models of the traversal.
#[derive(Default)]
struct Models {
    /// Per axis: the range is the previous frame's.
    same: [BitModel; 3],
    /// Per axis: the step is wider than the pixel step.
    wide: [BitModel; 3],
    /// Per axis: the offset's change from the previous frame's.
    offset: [IntModel; 3],
    /// Corrections in a frame.
    count: UIntModel,
    /// Vertex gap since the previous correction of the frame.
    gap: UIntModel,
    /// Per axis: above (true) or below the range.
    above: [BitModel; 3],
    /// Per axis: distance past the bound, in pixel steps.
    excess: [IntModel; 3],
}

/// The bound a correction of `range` crossed, in pixel steps: its largest value when `above`,
/// else its smallest (computed alike on both sides, so only the distance past it is coded).
fn bound(range: AxisRange, pixel_step: f32, above: bool) -> i64 {
    let edge = if above { range.max() } else { range.min() };
    let steps = (f64::from(edge) / f64::from(pixel_step)).round();
    let limit = (1u64 << 62) as f64;
    if steps.is_nan() {
        0
    } else {
        steps.clamp(-limit, limit) as i64
    }
}

/// Codes (or, decoding, fills) every frame's ranges, `prev` starting at the pixel step and
/// offset 0.
fn code_ranges<C: SymbolCoder>(
    c: &mut C,
    m: &mut Models,
    pixel_step: f32,
    ranges: &mut [FrameRanges],
    depth: u8,
) -> Result<()> {
    let mut prev = [AxisRange::at_depth(pixel_step, 0, depth); 3];
    for frame in ranges.iter_mut() {
        for a in 0..3 {
            let r = frame[a];
            if c.bit(r == prev[a], &mut m.same[a])? {
                frame[a] = prev[a];
                continue;
            }
            let step = if c.bit(r.step != pixel_step, &mut m.wide[a])? {
                let step = f32::from_bits(c.raw_bits(u64::from(r.step.to_bits()), 32)? as u32);
                if !(step.is_finite() && step > pixel_step) {
                    return Err(Error::Stream(format!(
                        "a residual range has step {step}, not above the pixel step {pixel_step}"
                    )));
                }
                step
            } else {
                pixel_step
            };
            let change = i64::from(r.offset) - i64::from(prev[a].offset);
            let offset = i64::from(prev[a].offset) + c.signed(change, &mut m.offset[a])?;
            let offset = i32::try_from(offset)
                .map_err(|_| Error::Stream("a residual range's offset is beyond ±2^31".into()))?;
            frame[a] = AxisRange::at_depth(step, offset, depth);
            prev[a] = frame[a];
        }
    }
    Ok(())
}

/// Codes one frame's corrections (`list`, sorted by vertex then axis; filled when decoding).
fn code_corrections<C: SymbolCoder>(
    c: &mut C,
    m: &mut Models,
    (pixel_step, range): (f32, &FrameRanges),
    list: &mut Vec<Correction>,
    vertices: usize,
) -> Result<()> {
    let count = c.unsigned(list.len() as u64, &mut m.count)?;
    if count > 3 * vertices as u64 {
        return Err(Error::Stream(format!(
            "{count} corrections in a frame of {vertices} vertices"
        )));
    }
    let mut axes = SymbolModel::new(3);
    let mut last = 0u64;
    for i in 0..count as usize {
        let given = list.get(i).copied();
        let gap = given.map_or(0, |g| u64::from(g.vertex) - last);
        let vertex = last.saturating_add(c.unsigned(gap, &mut m.gap)?);
        let axis = c.symbol(given.map_or(0, |g| usize::from(g.axis)), &mut axes)?;
        if vertex >= vertices as u64 {
            return Err(Error::Stream(format!(
                "a correction of vertex {vertex} ({vertices} vertices)"
            )));
        }
        let value = given.map_or(0, |g| g.value);
        let (high, low) = (
            bound(range[axis], pixel_step, true),
            bound(range[axis], pixel_step, false),
        );
        let above = c.bit(value > low / 2 + high / 2, &mut m.above[axis])?;
        let edge = bound(range[axis], pixel_step, above);
        let value = c
            .signed(value.wrapping_sub(edge), &mut m.excess[axis])?
            .checked_add(edge)
            .ok_or_else(|| Error::Stream("a correction is beyond ±2^63 steps".into()))?;
        let correction = Correction {
            vertex: vertex as u32,
            axis: axis as u8,
            value,
        };
        match list.get_mut(i) {
            Some(slot) => *slot = correction,
            None => list.push(correction),
        }
        last = vertex;
    }
    Ok(())
}

/// Codes the pixel step, every frame's ranges and the corrections.
pub fn encode_ranges(
    pixel_step: f32,
    ranges: &[FrameRanges],
    corrections: &Corrections,
    vertices: usize,
) -> Result<Vec<u8>> {
    let mut w = ByteWriter::new();
    w.f32(pixel_step).u32(ranges.len() as u32);
    let depth = ranges.first().map_or(8, |r| r[0].depth);
    let mut enc = Encoder::new();
    let mut m = Models::default();
    code_ranges(&mut enc, &mut m, pixel_step, &mut ranges.to_vec(), depth)?;
    for (f, range) in ranges.iter().enumerate() {
        let mut list = corrections.frame(f).to_vec();
        code_corrections(&mut enc, &mut m, (pixel_step, range), &mut list, vertices)?;
    }
    enc.raw_bits(u64::from(RANGES_END), 32);
    w.raw(&enc.finish()?);
    Ok(w.into_bytes())
}

/// Reads what [`encode_ranges`] wrote for `frames` frames (the header's count) of `vertices`
/// vertices in `depth`-bit pictures.
pub fn decode_ranges(
    bytes: &[u8],
    frames: usize,
    vertices: usize,
    depth: u8,
) -> Result<(f32, Vec<FrameRanges>, Corrections)> {
    let mut r = ByteReader::new(bytes, "residual ranges");
    let pixel_step = r.f32()?;
    if !(pixel_step.is_normal() && pixel_step > 0.0) {
        return Err(Error::Stream(format!(
            "residual pixel step {pixel_step} is not a positive number"
        )));
    }
    let n = r.u32()? as usize;
    if n != frames {
        return Err(Error::Stream(format!(
            "{n} residual ranges for {frames} frames"
        )));
    }
    let coded = r.take(r.remaining())?;
    // Every frame codes at least four symbols (three ranges, a correction count).
    let symbols = (frames as u64).saturating_mul(4);
    entropy::check_capacity(symbols, coded.len(), "residual ranges")?;
    let mut dec = Decoder::new(coded)?;
    let mut m = Models::default();
    let mut ranges = vec![[AxisRange::at_depth(pixel_step, 0, depth); 3]; frames];
    code_ranges(&mut dec, &mut m, pixel_step, &mut ranges, depth)?;
    let mut lists = Vec::with_capacity(frames);
    for range in &ranges {
        let mut list = Vec::new();
        code_corrections(&mut dec, &mut m, (pixel_step, range), &mut list, vertices)?;
        lists.push(list);
    }
    if dec.raw_bits(32)? != u64::from(RANGES_END) {
        return Err(Error::Stream(
            "residual ranges: the coded data end early (truncated or damaged)".into(),
        ));
    }
    Ok((pixel_step, ranges, Corrections::from_frames(lists)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry_image::quantise::{choose, RangeMode};

    fn sample() -> (Vec<Vec<[f32; 3]>>, f32) {
        let frames = (0..40)
            .map(|f| {
                (0..300)
                    .map(|v| {
                        let x = (v as f32 * 0.37 + f as f32 * 0.1).sin() * 0.3;
                        // A few outliers far past any range: corrections.
                        let y = if v == f % 5 { 40.0 + f as f32 } else { 0.01 * f as f32 };
                        [x, y, -0.2 * x + (f as f32) * 0.02]
                    })
                    .collect()
            })
            .collect();
        (frames, 0.004)
    }

    #[test]
    fn ranges_and_corrections_round_trip_smaller_than_raw() {
        let (residuals, step) = sample();
        for (mode, depth) in [(RangeMode::PerFrame, 8), (RangeMode::PerGroup(8), 10)] {
            let chosen = choose(&residuals, mode, step, depth);
            let (ranges, corrections) = (chosen.ranges, chosen.corrections);
            assert!(!corrections.is_empty());
            let bytes = encode_ranges(step, &ranges, &corrections, 300).unwrap();
            let (back_step, back, back_corr) = decode_ranges(&bytes, 40, 300, depth).unwrap();
            assert_eq!((back_step, &back, &back_corr), (step, &ranges, &corrections));
            // The raw layout: 8 bytes a frame and axis, about 4 a correction.
            let raw = 40 * 24 + 4 * corrections.len();
            assert!(bytes.len() * 2 < raw, "{} vs {raw}", bytes.len());
        }
    }

    #[test]
    fn damaged_ranges_are_errors() {
        let (residuals, step) = sample();
        let chosen = choose(&residuals, RangeMode::PerFrame, step, 8);
        let (ranges, corrections) = (chosen.ranges, chosen.corrections);
        let bytes = encode_ranges(step, &ranges, &corrections, 300).unwrap();
        assert!(decode_ranges(&bytes, 41, 300, 8).is_err());
        assert!(decode_ranges(&bytes, 40, 3, 8).is_err());
        for cut in [0, 4, 8, 12, bytes.len() - 4] {
            assert!(decode_ranges(&bytes[..cut], 40, 300, 8).is_err(), "cut {cut}");
        }
        for i in 8..bytes.len() {
            let mut bad = bytes.clone();
            bad[i] ^= 0x5a;
            // Never a panic; most damage is caught by the end word.
            let _ = decode_ranges(&bad, 40, 300, 8);
        }
    }
}
