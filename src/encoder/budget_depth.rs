//! An error budget search's sample depth for HEVC and AV1: 12 bits from the quality where
//! 10-bit pictures would widen a group's step, 10 below it (docs/design.md, "Budgets"). Size
//! budgets keep the depth their first encode's residuals turned to, else the automatic one: where
//! the depth turns the bytes jump (HEVC chickenCrossing: 229 733 bytes at quality 50 with 10
//! bits, 253 240 at 51.02 with 12), so no size there would land.

use super::budget::at_quality;
use super::EncodeOptions;
use crate::codec::pictures::deep::deeper_from_quality;
use crate::geometry_image::quantise::unwidened_step;
use crate::mesh::AnimatedMesh;

/// HEVC and AV1 at the automatic depth and the law's quantiser: the quality (in hundredths, below
/// the codec's threshold for 12 bits, [`deeper_from_quality`]) from which a search codes 12-bit
/// pictures and below which 10-bit ones — the lowest whose 10-bit pixel step is finer than
/// residuals of `spread` fit in 10-bit samples ([`EncodeReport::residual_spread`]). Where the
/// search's first encode, at quality `start`, was coded at 10 bits (`first_depth`), never at or
/// below `start` (a switch there would contradict it); where its residuals turned it to 12, that
/// lowest quality, below `start` too. There groups' steps widen, the error stops following the
/// quality (pcow's AV1 vertex RMSE stayed at 1.22e-4 from quality 88.67 to 89.42, then fell to
/// 4.4e-5 at 12 bits from 90) and no quality near the aim lands; where no group widens, 10 and 12
/// bits give about the same error and bytes (docs/design.md, "Budgets"). One quality for the whole
/// search, not each encode's own test: the pixel step is not monotone in the quality (it takes
/// the rest of the codec's integer quantiser), and a depth that flipped back would make the error
/// jump back. `None` for other codecs, a depth or quantiser the caller gave, a search starting at
/// the threshold or above, or residuals 10 bits hold below it.
///
/// [`EncodeReport::residual_spread`]: super::EncodeReport::residual_spread
pub(super) fn deeper_from(
    mesh: &AnimatedMesh,
    opts: &EncodeOptions,
    spread: f64,
    (start, first_depth): (f64, Option<u8>),
) -> Option<f64> {
    let mut ten = opts.clone();
    match ten.codec.bit_depth_mut() {
        Some(depth @ None) => *depth = Some(10),
        _ => return None,
    }
    if ten.codec.quantiser_mut().is_some_and(|(_, q)| q.is_some()) {
        return None;
    }
    let unwidened = unwidened_step(spread, 10);
    let diagonal = mesh.bbox_diagonal();
    let start = (start * 100.0).floor() as u32;
    let deepest = 100 * u32::from(deeper_from_quality(opts.codec.codec()));
    let widens = |hundredths: u32| {
        let quality = f64::from(hundredths) / 100.0;
        // A quality without a plan (a step too fine for the diagonal) is left to its encode.
        let plan = at_quality(&ten, quality).plan(diagonal).ok();
        plan.is_some_and(|p| f64::from(p.step) < unwidened)
    };
    let from = (100..deepest).find(|&h| widens(h))?;
    let from = match first_depth {
        Some(12) => from.min(start),
        _ => from.max(start + 1),
    };
    Some(f64::from(from) / 100.0).filter(|_| start < deepest && from < deepest)
}

/// A size budget's `pinned` options after its first encode (`first_opts` at quality `start`,
/// coded at `first_depth` bits a sample): where that encode's residuals turned its automatic
/// depth, the search keeps the depth they turned to — where the depth turns, the bytes jump
/// (12-bit pictures hold errors a widened 10-bit step let through), and no size there lands.
pub(super) fn keep_turned_depth(
    pinned: &mut EncodeOptions,
    (first_opts, start): (&EncodeOptions, f64),
    first_depth: Option<u8>,
) {
    if first_depth != first_opts.codec.picture_depth(start) {
        if let Some(depth @ None) = pinned.codec.bit_depth_mut() {
            *depth = first_depth;
        }
    }
}

/// `opts` (at `quality`) with 12-bit pictures from quality `deeper_from` on and 10-bit ones below,
/// where its depth is the automatic one: what a search codes ([`deeper_from`]).
pub(super) fn deeper_at(
    mut opts: EncodeOptions,
    quality: f64,
    deeper_from: Option<f64>,
) -> EncodeOptions {
    if let (Some(from), Some(depth @ None)) = (deeper_from, opts.codec.bit_depth_mut()) {
        *depth = Some(if quality >= from { 12 } else { 10 });
    }
    opts
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::codec::Codec;

    #[test]
    fn pictures_are_12_bits_deep_where_10_bit_ones_would_widen_a_group() {
        let mesh = AnimatedMesh::new(
            vec![[0, 1, 2]],
            vec![vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]; 2],
        );
        let mesh = mesh.expect("a triangle");
        let av1 = EncodeOptions {
            codec: Codec::Av1.into(),
            ..EncodeOptions::default()
        };
        let pixel_step = |quality: f64| {
            let mut opts = at_quality(&av1, quality);
            *opts.codec.bit_depth_mut().expect("AV1 has a depth") = Some(10);
            f64::from(opts.plan(mesh.bbox_diagonal()).expect("a plan").step)
        };
        // Residuals that 10-bit samples hold at quality 75's pixel step, not beyond.
        let spread = pixel_step(75.0) / unwidened_step(1.0, 10);
        let ten_at = |start: f64| (start, Some(10));
        let from = deeper_from(&mesh, &av1, spread, ten_at(50.0)).expect("a quality that widens");
        assert!((50.0..=75.01).contains(&from), "{from}");
        assert!(pixel_step(from) < pixel_step(75.0));
        let depth = |from: Option<f64>, opts: &EncodeOptions, quality| {
            let opts = deeper_at(at_quality(opts, quality), quality, from);
            opts.codec.picture_depth(quality)
        };
        // From there on, 12 bits, though the pixel step climbs back at a few qualities above;
        // below it 10 bits, whatever each encode's own residuals would say.
        assert_eq!(depth(Some(from), &av1, from - 0.01), Some(10));
        let mut below = deeper_at(at_quality(&av1, 30.0), 30.0, Some(from));
        assert_eq!(below.codec.bit_depth_mut().map(|d| *d), Some(Some(10)));
        for quality in [from, from + 0.5, 89.99, 95.0] {
            assert_eq!(depth(Some(from), &av1, quality), Some(12), "{quality}");
        }
        // A depth or a quantiser the caller gave stays, and has no quality to switch at.
        let mut ten = av1.clone();
        *ten.codec.bit_depth_mut().expect("AV1 has a depth") = Some(10);
        assert_eq!(depth(Some(from), &ten, 95.0), Some(10));
        assert_eq!(deeper_from(&mesh, &ten, spread, ten_at(50.0)), None);
        let mut crf = av1.clone();
        *crf.codec.quantiser_mut().expect("AV1 has a crf").1 = Some(20);
        assert_eq!(deeper_from(&mesh, &crf, spread, ten_at(50.0)), None);
        // Residuals 10 bits hold at every quality below 90, and tdct, which has no pictures.
        assert_eq!(deeper_from(&mesh, &av1, 1e-9, ten_at(50.0)), None);
        let tdct = EncodeOptions::default();
        assert_eq!(deeper_from(&mesh, &tdct, spread, ten_at(50.0)), None);
        assert_eq!(depth(Some(from), &tdct, 80.0), None);
        // A search whose first encode, above the quality where 10 bits widen, stayed at 10 bits
        // turns just above it, never below (it would contradict that encode); one whose first
        // encode turned to 12 bits, and one that started below, keep the lowest such quality;
        // one that started at 90 or more, at 12 bits, has nothing to turn.
        assert_eq!(deeper_from(&mesh, &av1, spread, ten_at(80.0)), Some(80.01));
        assert_eq!(
            deeper_from(&mesh, &av1, spread, ten_at(62.5)),
            Some(from.max(62.51))
        );
        assert_eq!(
            deeper_from(&mesh, &av1, spread, (80.0, Some(12))),
            Some(from)
        );
        assert_eq!(deeper_from(&mesh, &av1, spread, ten_at(30.0)), Some(from));
        assert_eq!(deeper_from(&mesh, &av1, spread, (90.0, Some(12))), None);
        assert_eq!(deeper_from(&mesh, &av1, spread, ten_at(89.995)), None);
    }
}
