//! Skinning weights chosen by their bits and the prediction error they add.
//!
//! The weights are fitted per vertex by least squares and quantised at the step their effect
//! allows (`motion/skinning.rs`). Rounding each on its own ignores two things the encoder knows:
//! how the weights of one vertex trade against each other (the fit's normal matrix,
//! [`WeightFits::growth`]), and what the coder will pay for each value (its guess from the
//! vertex's coded neighbours and the adaptive model, [`side_info::choose_weights`]). Going through
//! the weights in coding order, each takes, among its rounded value, the coder's guess and the
//! value one step from the rounded one toward the guess, the one with the least
//! `growth / Δ² + λ · bits`, `Δ` the quality's target step (the temporal DCT's quantiser step; a
//! picture codec's pixel step is a fraction of it) and `λ` the price of a bit in squared target
//! steps, at which the residual coder meets the error a weight adds: the temporal DCT's rounding
//! price ([`ROUNDING_LAMBDA`]), a quarter of it for the picture codecs ([`PICTURE_PRICE`], which
//! was measured, so it absorbs their pixel step too). The decoder reads the weights as always:
//! only the encoder's choice changed.

use crate::codec::tdct::ROUNDING_LAMBDA;
use crate::codec::Codec;
use crate::error::Result;
use crate::mesh::{AnimatedMesh, Point};
use crate::motion::{self, AffineTrack, Partition, SkinningWeights, WeightFits};
use crate::stream::side_info::{self, WeightSlot};

/// The price of a bit for the picture codecs, as a share of the temporal DCT's: they pay more
/// bits for the same error energy. At the temporal DCT's price AV1's streams of the glTF
/// characters grew at equal error (RiggedFigure's error +21 % for 2 % fewer bytes, BrainStem's
/// pictures twice as large); at a quarter every AV1 stream measured shrank, a tenth gained less
/// on the larger clips (docs/design.md, "Skinning weights").
pub const PICTURE_PRICE: f64 = 0.25;

/// How an encoding quantises its skinning weights.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WeightPlan {
    /// Bits per weight at most (`EncodeOptions::weight_bits`).
    pub bits: u8,
    /// The affine step over the residual step (the plan's affine precision): the track knows
    /// its own step, the price of an error is in residual steps.
    pub affine_precision: f64,
    /// The price of a bit in squared residual steps of prediction error (0: the weights are
    /// rounded).
    pub price: f64,
}

impl WeightPlan {
    /// `bits` at most, for maps at `affine_precision` sixteenths of the residual step (as the
    /// header stores it), for residuals coded by `codec`.
    pub fn new(bits: u8, affine_precision: u8, codec: Codec) -> Self {
        Self {
            bits,
            affine_precision: f64::from(affine_precision.max(1)) / 16.0,
            price: match codec {
                Codec::Tdct => ROUNDING_LAMBDA,
                Codec::Jpeg | Codec::Mpeg4 | Codec::Hevc | Codec::Av1 => {
                    ROUNDING_LAMBDA * PICTURE_PRICE
                }
                #[cfg(test)]
                Codec::Raw => 0.0,
            },
        }
    }
}

/// Fits `mesh`'s skinning weights on `track` and chooses each by its bits and the prediction
/// error it adds at `plan`'s price (rounds them at a price of 0; see the module notes).
pub fn fit(
    mesh: &AnimatedMesh,
    reference: &[Point],
    partition: &Partition,
    track: &AffineTrack,
    plan: WeightPlan,
) -> Result<SkinningWeights> {
    let triangles = mesh.triangles();
    let ridge = motion::DEFAULT_RIDGE;
    let input = (mesh.frames(), reference, partition, triangles, track);
    let (mut weights, fits) = SkinningWeights::fit_exact(input, ridge, plan.bits)?;
    if plan.price <= 0.0 || plan.price.is_nan() {
        return Ok(weights);
    }
    // Growth is in the unit frame, as the track's step: Δ = step / precision (the affine step is
    // clamped only at absurd qualities and diagonals, where the price matters least).
    let residual_step = f64::from(track.quantised().step) / plan.affine_precision;
    let per_growth = 1.0 / (residual_step * residual_step);
    let price = (per_growth, plan.price);
    let mut choose = |slot: WeightSlot| i64::from(cheapest(&fits, &slot, price));
    side_info::choose_weights(&mut weights, partition, (triangles, reference), &mut choose)?;
    Ok(weights)
}

/// The value of `slot` with the least `growth × per_growth + price × bits`: its value now (the
/// rounded fit), the coder's guess, or one step from the value now toward the guess.
fn cheapest(fits: &WeightFits, slot: &WeightSlot, (per_growth, price): (f64, f64)) -> i32 {
    let now = slot.values[slot.index];
    let Ok(guess) = i32::try_from(slot.guess) else {
        return now;
    };
    if guess == now {
        return now;
    }
    let price = |q: i32| {
        let growth = fits.growth(slot.vertex, slot.index, slot.values, q);
        growth * per_growth + price * slot.model.cost(i64::from(q) - slot.guess)
    };
    let toward = now + (guess - now).signum();
    [now, toward, guess]
        .into_iter()
        .map(|q| (q, price(q)))
        .fold((now, f64::INFINITY), |best, c| if c.1 < best.1 { c } else { best })
        .0
}
