//! Adaptive binary arithmetic coding on top of `constriction`'s range coder.
//!
//! Everything is binarised: [`BitModel`] is the only adaptive primitive, and small alphabets
//! ([`SymbolModel`]), unsigned ([`UIntModel`]) and signed ([`IntModel`]) integers are trees or
//! Exp-Golomb-like strings of adaptive bits. `constriction` ships only static models, so the
//! adaptive bit model implements its model traits here.
//!
//! Writing the traversal of a codec once for both directions is easiest through
//! [`SymbolCoder`]: the encoder codes the value it is given, the decoder ignores it and returns
//! what it read, so both sides update their state identically.

use std::borrow::Borrow;
use std::num::NonZeroU32;

use constriction::stream::model::{DecoderModel, EncoderModel, EntropyModel};

use crate::error::{Error, Result};

mod coder;

pub use coder::{Decoder, Encoder, SymbolCoder};

/// Fixed-point precision of every model handed to the range coder.
const PRECISION: usize = 16;
const ONE: u32 = 1 << PRECISION;
/// Probability floor of an adaptive bit (of `ONE`): bounds how many symbols a byte can hold.
const MIN_PROBABILITY: u32 = 64;
/// A symbol costs at least -log2(1 - MIN_PROBABILITY/ONE) = 1/709.4 bit (the range coder's
/// rounding only adds to that), so a bit holds at most 709.4 symbols: rounded up, since the bound
/// must never refuse what the encoder writes (10⁷ decisions at the floor take 1 764 bytes, 5 669
/// a byte, which 700 a bit refused).
const MAX_SYMBOLS_PER_BIT: u64 = 710;

/// Upper bound on the number of symbols a decoder over `byte_len` bytes may read.
///
/// Decoders refuse to read more, so a count in a header can be checked against it before
/// allocating anything.
pub fn max_symbols(byte_len: usize) -> u64 {
    (byte_len as u64 + 8) * 8 * MAX_SYMBOLS_PER_BIT
}

/// Refuses, before anything is allocated, a count of `symbols` that a decoder over `bytes` bytes
/// could never read ([`max_symbols`]): a forged or corrupted count in a header.
pub fn check_capacity(symbols: u64, bytes: usize, what: &str) -> Result<()> {
    if symbols > max_symbols(bytes) {
        return Err(Error::Stream(format!(
            "{what}: {symbols} values cannot fit in {bytes} bytes"
        )));
    }
    Ok(())
}

/// An adaptive probability for one binary decision.
#[derive(Clone, Debug)]
pub struct BitModel {
    /// Probability of `true`, in units of 2^-16.
    p_true: u32,
    /// Number of updates seen so far, saturating: adaptation is fast at first, slower later.
    seen: u8,
}

impl Default for BitModel {
    fn default() -> Self {
        Self {
            p_true: ONE / 2,
            seen: 0,
        }
    }
}

impl BitModel {
    fn update(&mut self, bit: bool) {
        // shift 1, 2, 2, 3, 3, 3, 3, 4 … 6: roughly a running average over the first 32 symbols.
        let shift = (u32::from(self.seen) + 1).ilog2() + 1;
        let shift = shift.min(6);
        if bit {
            self.p_true += (ONE - self.p_true) >> shift;
        } else {
            self.p_true -= self.p_true >> shift;
        }
        self.p_true = self.p_true.clamp(MIN_PROBABILITY, ONE - MIN_PROBABILITY);
        self.seen = self.seen.saturating_add(1).min(63);
    }

    /// Bits that coding `bit` would cost now (an estimate for rate–distortion choices).
    pub fn cost(&self, bit: bool) -> f64 {
        let p = if bit { self.p_true } else { ONE - self.p_true };
        bit_cost(p)
    }

    fn frozen(&self) -> FrozenBit {
        FrozenBit {
            p_true: self.p_true,
        }
    }
}

/// −log2(p / ONE) of every probability p the models hold, made once: the rate–distortion choices
/// of the coders ask for millions of bit costs, and a table gives the same values as the
/// logarithm (so the same choices) for a small part of its time.
static BIT_COSTS: std::sync::LazyLock<Vec<f64>> =
    std::sync::LazyLock::new(|| (0..=ONE).map(exact_bit_cost).collect());

fn exact_bit_cost(p: u32) -> f64 {
    -(f64::from(p) / f64::from(ONE)).log2()
}

/// The cost in bits of an outcome of probability `p` (in units of 2^-16).
fn bit_cost(p: u32) -> f64 {
    match BIT_COSTS.get(p as usize) {
        Some(&c) => c,
        None => exact_bit_cost(p),
    }
}

/// A snapshot of a [`BitModel`] that the range coder can use: `false` is the left interval.
#[derive(Clone, Copy)]
struct FrozenBit {
    p_true: u32,
}

fn nonzero(p: u32) -> NonZeroU32 {
    // Every probability handed out below is at least MIN_PROBABILITY or a power of two.
    NonZeroU32::new(p).unwrap_or(NonZeroU32::MIN)
}

impl EntropyModel<PRECISION> for FrozenBit {
    type Symbol = bool;
    type Probability = u32;
}

impl EncoderModel<PRECISION> for FrozenBit {
    fn left_cumulative_and_probability(
        &self,
        symbol: impl Borrow<bool>,
    ) -> Option<(u32, NonZeroU32)> {
        let p_false = ONE - self.p_true;
        Some(if *symbol.borrow() {
            (p_false, nonzero(self.p_true))
        } else {
            (0, nonzero(p_false))
        })
    }
}

impl DecoderModel<PRECISION> for FrozenBit {
    fn quantile_function(&self, quantile: u32) -> (bool, u32, NonZeroU32) {
        let p_false = ONE - self.p_true;
        if quantile < p_false {
            (false, 0, nonzero(p_false))
        } else {
            (true, p_false, nonzero(self.p_true))
        }
    }
}

/// Equiprobable `bits`-bit values (1 ≤ bits ≤ 16).
#[derive(Clone, Copy)]
struct RawChunk {
    bits: u32,
}

impl EntropyModel<PRECISION> for RawChunk {
    type Symbol = u32;
    type Probability = u32;
}

impl EncoderModel<PRECISION> for RawChunk {
    fn left_cumulative_and_probability(
        &self,
        symbol: impl Borrow<u32>,
    ) -> Option<(u32, NonZeroU32)> {
        let shift = PRECISION as u32 - self.bits;
        let value = *symbol.borrow();
        (value < (1 << self.bits)).then(|| (value << shift, nonzero(1 << shift)))
    }
}

impl DecoderModel<PRECISION> for RawChunk {
    fn quantile_function(&self, quantile: u32) -> (u32, u32, NonZeroU32) {
        let shift = PRECISION as u32 - self.bits;
        let value = quantile >> shift;
        (value, value << shift, nonzero(1 << shift))
    }
}

/// An adaptive model over the alphabet `0..n` (n ≤ 256), coded as a binary tree of [`BitModel`]s.
#[derive(Clone, Debug)]
pub struct SymbolModel {
    size: usize,
    depth: u32,
    nodes: Vec<BitModel>,
}

impl SymbolModel {
    /// A model for symbols `0..size`; `size` is clamped to `1..=256`.
    pub fn new(size: usize) -> Self {
        let size = size.clamp(1, 256);
        let depth = (size as u32).next_power_of_two().ilog2();
        Self {
            size,
            depth,
            nodes: vec![BitModel::default(); 1 << depth],
        }
    }

    #[cfg(any(test, feature = "internals"))]
    /// Number of symbols.
    pub fn size(&self) -> usize {
        self.size
    }
}

/// Adaptive contexts per integer model: bit lengths 0..=64 of value + 1.
const BUCKETS: usize = 65;

/// An adaptive model for unsigned integers: Exp-Golomb, i.e. the bit length in unary with one
/// adaptive context per position, the bit just below the leading one adaptive per length, and
/// the remaining low bits raw.
#[derive(Clone, Debug)]
pub struct UIntModel {
    // Arrays, not vectors: coders clone whole banks of these models per trial.
    unary: [BitModel; BUCKETS],
    top_bit: [BitModel; BUCKETS],
}

impl Default for UIntModel {
    fn default() -> Self {
        Self {
            unary: std::array::from_fn(|_| BitModel::default()),
            top_bit: std::array::from_fn(|_| BitModel::default()),
        }
    }
}

/// An adaptive model for signed integers: magnitude as a [`UIntModel`], then an adaptive sign.
#[derive(Clone, Debug, Default)]
pub struct IntModel {
    magnitude: UIntModel,
    sign: BitModel,
}

impl UIntModel {
    /// Bits that coding `value` would cost now, without coding it.
    pub fn cost(&self, value: u64) -> f64 {
        // value + 1 fits in 64 bits but for u64::MAX, whose length is 64 and top bit 0.
        let (length, top) = match value.checked_add(1) {
            Some(shifted) => {
                let length = 63 - shifted.leading_zeros();
                let top = length > 0 && (shifted >> (length - 1)) & 1 == 1;
                (length, top)
            }
            None => (64, false),
        };
        // The same sum, in the same order, as the iterator form: the same f64.
        let mut unary = 0.0;
        for (i, m) in self.unary.iter().enumerate().take(length as usize + 1) {
            unary += m.cost((i as u32) < length);
        }
        if length == 0 {
            return unary;
        }
        let top_cost = self
            .top_bit
            .get(length as usize)
            .map_or(1.0, |m| m.cost(top));
        unary + top_cost + f64::from(length - 1)
    }
}

impl IntModel {
    /// Bits that coding `value` would cost now, without coding it.
    pub fn cost(&self, value: i64) -> f64 {
        signed_cost(value, &self.magnitude, &self.sign)
    }

    /// Its two models, lent.
    pub fn parts(&mut self) -> SignedModels<'_> {
        SignedModels {
            magnitude: &mut self.magnitude,
            sign: &mut self.sign,
        }
    }
}

/// The two models a signed integer is coded with, borrowed: its magnitude's and, when non-zero,
/// its sign's. [`IntModel`] owns one such pair; a coder that picks the sign's model by a context
/// of its own lends a pair it assembles.
pub struct SignedModels<'a> {
    /// The magnitude's model.
    pub magnitude: &'a mut UIntModel,
    /// The sign's model (`true`: negative).
    pub sign: &'a mut BitModel,
}

impl SignedModels<'_> {
    /// Bits that coding `value` would cost now, without coding it.
    pub fn cost(&self, value: i64) -> f64 {
        signed_cost(value, self.magnitude, self.sign)
    }
}

fn signed_cost(value: i64, magnitude: &UIntModel, sign: &BitModel) -> f64 {
    let sign = match value {
        0 => 0.0,
        _ => sign.cost(value < 0),
    };
    magnitude.cost(value.unsigned_abs()) + sign
}
