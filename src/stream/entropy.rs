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
use constriction::stream::queue::{DefaultRangeDecoder, DefaultRangeEncoder};
use constriction::stream::{Decode, Encode};

use crate::error::{Error, Result};

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
    #[cfg(any(test, feature = "internals"))]
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

/// Writes adaptive-coded symbols into a byte buffer.
pub struct Encoder {
    inner: DefaultRangeEncoder,
    /// The first coding error; reported by [`Encoder::finish`] so that coding calls stay infallible.
    failed: Option<String>,
}

impl Default for Encoder {
    fn default() -> Self {
        Self::new()
    }
}

impl Encoder {
    /// An empty encoder.
    pub fn new() -> Self {
        Self {
            inner: DefaultRangeEncoder::new(),
            failed: None,
        }
    }

    fn code<M>(&mut self, symbol: M::Symbol, model: M)
    where
        M: EncoderModel<PRECISION, Probability = u32>,
    {
        if let Err(e) = self.inner.encode_symbol(symbol, model) {
            self.failed
                .get_or_insert_with(|| format!("range coder: {e:?}"));
        }
    }

    /// Codes one bit with an adaptive model.
    pub fn bit(&mut self, bit: bool, model: &mut BitModel) {
        self.code(bit, model.frozen());
        model.update(bit);
    }

    /// Codes the low `n` bits of `value` (n ≤ 64) without modelling.
    pub fn raw_bits(&mut self, value: u64, n: u32) {
        let mut left = n.min(64);
        while left > 0 {
            let bits = left.min(16);
            left -= bits;
            let chunk = ((value >> left) & ((1u64 << bits) - 1)) as u32;
            self.code(chunk, RawChunk { bits });
        }
    }

    /// Codes a symbol of a small alphabet; a symbol outside it is an encoding error.
    pub fn symbol(&mut self, symbol: usize, model: &mut SymbolModel) {
        if symbol >= model.size {
            self.failed.get_or_insert_with(|| {
                format!("symbol {symbol} outside alphabet of {}", model.size)
            });
            return;
        }
        let mut node = 1usize;
        for level in (0..model.depth).rev() {
            let bit = (symbol >> level) & 1 == 1;
            if let Some(m) = model.nodes.get_mut(node) {
                self.code(bit, m.frozen());
                m.update(bit);
            }
            node = node * 2 + usize::from(bit);
        }
    }

    /// Codes an unsigned integer.
    pub fn unsigned(&mut self, value: u64, model: &mut UIntModel) {
        let shifted = u128::from(value) + 1;
        let length = 127 - shifted.leading_zeros(); // bits below the leading one
        for (i, m) in model.unary.iter_mut().enumerate().take(length as usize + 1) {
            let more = (i as u32) < length;
            self.code(more, m.frozen());
            m.update(more);
        }
        if length == 0 {
            return;
        }
        let low = (shifted - (1u128 << length)) as u64;
        let top = (low >> (length - 1)) & 1 == 1;
        if let Some(m) = model.top_bit.get_mut(length as usize) {
            self.code(top, m.frozen());
            m.update(top);
        }
        self.raw_bits(low, length - 1);
    }

    #[cfg(any(test, feature = "internals"))]
    /// Codes a signed integer.
    pub fn signed(&mut self, value: i64, model: &mut IntModel) {
        self.signed_with(value, model.parts());
    }

    /// Codes a signed integer with lent models.
    pub fn signed_with(&mut self, value: i64, models: SignedModels) {
        self.unsigned(value.unsigned_abs(), models.magnitude);
        if value != 0 {
            self.bit(value < 0, models.sign);
        }
    }

    /// The coded bytes (a multiple of four long).
    pub fn finish(self) -> Result<Vec<u8>> {
        if let Some(e) = self.failed {
            return Err(Error::Stream(format!("encoding failed: {e}")));
        }
        let words = self
            .inner
            .into_compressed()
            .map_err(|e| Error::Stream(format!("range coder: {e:?}")))?;
        Ok(words.iter().flat_map(|w| w.to_le_bytes()).collect())
    }
}

/// Reads adaptive-coded symbols from a byte buffer; never reads more than [`max_symbols`].
pub struct Decoder {
    inner: DefaultRangeDecoder,
    budget: u64,
}

fn corrupt(what: &str) -> Error {
    Error::Stream(format!("entropy-coded data: {what}"))
}

impl Decoder {
    /// A decoder over `bytes`, which must come from [`Encoder::finish`].
    pub fn new(bytes: &[u8]) -> Result<Self> {
        if bytes.len() % 4 != 0 {
            return Err(corrupt("length is not a multiple of 4"));
        }
        let words: Vec<u32> = bytes
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        let inner =
            DefaultRangeDecoder::from_compressed(words).map_err(|e| corrupt(&format!("{e:?}")))?;
        Ok(Self {
            inner,
            budget: max_symbols(bytes.len()),
        })
    }

    fn code<M>(&mut self, model: M) -> Result<M::Symbol>
    where
        M: DecoderModel<PRECISION, Probability = u32>,
    {
        self.budget = self
            .budget
            .checked_sub(1)
            .ok_or_else(|| corrupt("more symbols than the data can hold"))?;
        self.inner
            .decode_symbol(model)
            .map_err(|e| corrupt(&format!("{e:?}")))
    }

    /// Decodes one bit with an adaptive model.
    pub fn bit(&mut self, model: &mut BitModel) -> Result<bool> {
        let bit = self.code(model.frozen())?;
        model.update(bit);
        Ok(bit)
    }

    /// Decodes `n` raw bits (n ≤ 64).
    pub fn raw_bits(&mut self, n: u32) -> Result<u64> {
        let mut value = 0u64;
        let mut left = n.min(64);
        while left > 0 {
            let bits = left.min(16);
            left -= bits;
            let chunk = self.code(RawChunk { bits })?;
            value = (value << bits) | u64::from(chunk);
        }
        Ok(value)
    }

    /// Decodes a symbol of a small alphabet.
    pub fn symbol(&mut self, model: &mut SymbolModel) -> Result<usize> {
        let mut node = 1usize;
        for _ in 0..model.depth {
            let m = model
                .nodes
                .get_mut(node)
                .ok_or_else(|| corrupt("symbol tree"))?;
            let bit = self.code(m.frozen())?;
            m.update(bit);
            node = node * 2 + usize::from(bit);
        }
        let symbol = node - (1 << model.depth);
        if symbol >= model.size {
            return Err(corrupt("symbol outside its alphabet"));
        }
        Ok(symbol)
    }

    /// Decodes an unsigned integer.
    pub fn unsigned(&mut self, model: &mut UIntModel) -> Result<u64> {
        let mut length = 0u32;
        loop {
            let m = model
                .unary
                .get_mut(length as usize)
                .ok_or_else(|| corrupt("integer longer than 64 bits"))?;
            let more = self.code(m.frozen())?;
            m.update(more);
            if !more {
                break;
            }
            length += 1;
        }
        if length == 0 {
            return Ok(0);
        }
        let m = model
            .top_bit
            .get_mut(length as usize)
            .ok_or_else(|| corrupt("integer longer than 64 bits"))?;
        let top = self.code(m.frozen())?;
        m.update(top);
        let rest = self.raw_bits(length - 1)?;
        let low = (u128::from(top) << (length - 1)) | u128::from(rest);
        let value = (1u128 << length) + low - 1;
        u64::try_from(value).map_err(|_| corrupt("integer overflows 64 bits"))
    }

    #[cfg(any(test, feature = "internals"))]
    /// Decodes a signed integer.
    pub fn signed(&mut self, model: &mut IntModel) -> Result<i64> {
        self.signed_with(model.parts())
    }

    /// Decodes a signed integer with lent models.
    pub fn signed_with(&mut self, models: SignedModels) -> Result<i64> {
        let magnitude = self.unsigned(models.magnitude)?;
        if magnitude == 0 {
            return Ok(0);
        }
        // The sign is read before the range check: i64::MIN has magnitude 2^63, which the encoder
        // writes and only a negative sign makes representable.
        let value = if self.bit(models.sign)? {
            0i64.checked_sub_unsigned(magnitude)
        } else {
            i64::try_from(magnitude).ok()
        };
        value.ok_or_else(|| corrupt("signed integer overflows"))
    }
}

/// One coding routine for both directions: an [`Encoder`] codes the value it is given and
/// returns it, a [`Decoder`] ignores it and returns what it read.
pub trait SymbolCoder {
    /// Codes a bit.
    fn bit(&mut self, value: bool, model: &mut BitModel) -> Result<bool>;
    /// Codes a small-alphabet symbol.
    fn symbol(&mut self, value: usize, model: &mut SymbolModel) -> Result<usize>;
    /// Codes an unsigned integer.
    fn unsigned(&mut self, value: u64, model: &mut UIntModel) -> Result<u64>;
    /// Codes a signed integer with lent models.
    fn signed_with(&mut self, value: i64, models: SignedModels) -> Result<i64>;
    /// Codes a signed integer.
    fn signed(&mut self, value: i64, model: &mut IntModel) -> Result<i64> {
        self.signed_with(value, model.parts())
    }
    /// Codes `n` raw bits.
    fn raw_bits(&mut self, value: u64, n: u32) -> Result<u64>;
}

impl SymbolCoder for Encoder {
    fn bit(&mut self, value: bool, model: &mut BitModel) -> Result<bool> {
        Encoder::bit(self, value, model);
        Ok(value)
    }
    fn symbol(&mut self, value: usize, model: &mut SymbolModel) -> Result<usize> {
        Encoder::symbol(self, value, model);
        Ok(value)
    }
    fn unsigned(&mut self, value: u64, model: &mut UIntModel) -> Result<u64> {
        Encoder::unsigned(self, value, model);
        Ok(value)
    }
    fn signed_with(&mut self, value: i64, models: SignedModels) -> Result<i64> {
        Encoder::signed_with(self, value, models);
        Ok(value)
    }
    fn raw_bits(&mut self, value: u64, n: u32) -> Result<u64> {
        Encoder::raw_bits(self, value, n);
        Ok(if n >= 64 {
            value
        } else {
            value & ((1u64 << n) - 1)
        })
    }
}

impl SymbolCoder for Decoder {
    fn bit(&mut self, _: bool, model: &mut BitModel) -> Result<bool> {
        Decoder::bit(self, model)
    }
    fn symbol(&mut self, _: usize, model: &mut SymbolModel) -> Result<usize> {
        Decoder::symbol(self, model)
    }
    fn unsigned(&mut self, _: u64, model: &mut UIntModel) -> Result<u64> {
        Decoder::unsigned(self, model)
    }
    fn signed_with(&mut self, _: i64, models: SignedModels) -> Result<i64> {
        Decoder::signed_with(self, models)
    }
    fn raw_bits(&mut self, _: u64, n: u32) -> Result<u64> {
        Decoder::raw_bits(self, n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cost estimate adds up to what the coder spends (within the range coder's overhead).
    #[test]
    fn integer_costs_add_up_to_the_coded_size() {
        let values: Vec<i64> = (0..4000i64).map(|k| (k * 7919 % 23) - 11 + k % 3).collect();
        let (mut enc, mut model) = (Encoder::new(), IntModel::default());
        let mut bits = 0.0;
        for &v in &values {
            bits += model.cost(v);
            enc.signed(v, &mut model);
        }
        let coded = 8.0 * enc.finish().unwrap().len() as f64;
        assert!(
            (coded - bits).abs() < 64.0 + 0.01 * bits,
            "{coded} vs {bits}"
        );
    }

    #[test]
    fn mixed_symbols_round_trip() {
        let values: Vec<i64> = vec![0, 1, -1, 5, -300, i64::MAX, i64::MIN + 1, 42, 0, 0, 7];
        let mut enc = Encoder::new();
        let (mut b, mut s, mut u, mut i) = (
            BitModel::default(),
            SymbolModel::new(5),
            UIntModel::default(),
            IntModel::default(),
        );
        for (k, &v) in values.iter().enumerate() {
            enc.bit(k % 3 == 0, &mut b);
            enc.symbol(k % 5, &mut s);
            enc.unsigned(v.unsigned_abs(), &mut u);
            enc.signed(v, &mut i);
            enc.raw_bits(v as u64, 37);
        }
        enc.unsigned(u64::MAX, &mut u);
        let bytes = enc.finish().unwrap();
        let mut dec = Decoder::new(&bytes).unwrap();
        let (mut b, mut s, mut u, mut i) = (
            BitModel::default(),
            SymbolModel::new(5),
            UIntModel::default(),
            IntModel::default(),
        );
        for (k, &v) in values.iter().enumerate() {
            assert_eq!(dec.bit(&mut b).unwrap(), k % 3 == 0);
            assert_eq!(dec.symbol(&mut s).unwrap(), k % 5);
            assert_eq!(dec.unsigned(&mut u).unwrap(), v.unsigned_abs());
            assert_eq!(dec.signed(&mut i).unwrap(), v);
            assert_eq!(dec.raw_bits(37).unwrap(), (v as u64) & ((1 << 37) - 1));
        }
        assert_eq!(dec.unsigned(&mut u).unwrap(), u64::MAX);
    }

    #[test]
    fn skewed_bits_compress() {
        let mut enc = Encoder::new();
        let mut m = BitModel::default();
        for k in 0..10_000 {
            enc.bit(k % 100 == 0, &mut m);
        }
        let bytes = enc.finish().unwrap();
        // entropy of p = 0.01 is 0.08 bit: 10 000 symbols fit well under 200 bytes
        assert!(bytes.len() < 200, "{} bytes", bytes.len());
    }

    /// The densest data the coder writes: one decision after another at the probability floor.
    /// `max_symbols` must let all of them decode back.
    #[test]
    fn decisions_at_the_floor_fit_the_symbol_bound() {
        const N: u64 = 10_000_000;
        let mut enc = Encoder::new();
        let mut m = BitModel::default();
        for _ in 0..N {
            enc.bit(false, &mut m);
        }
        let bytes = enc.finish().unwrap();
        // Within 1 % of the floor's 709.4 decisions a bit: the bound is as tight as it can be.
        let per_byte = N as f64 / bytes.len() as f64;
        assert!((5_620.0..=5_676.0).contains(&per_byte), "{per_byte}");
        let mut dec = Decoder::new(&bytes).unwrap();
        let mut m = BitModel::default();
        for k in 0..N {
            assert!(!dec.bit(&mut m).unwrap(), "decision {k}");
        }
    }

    #[test]
    fn garbage_never_loops_forever() {
        let bytes = vec![0xA5u8; 16];
        let mut dec = Decoder::new(&bytes).unwrap();
        let mut m = UIntModel::default();
        let mut reads = 0u64;
        while dec.unsigned(&mut m).is_ok() {
            reads += 1;
        }
        assert!(reads <= max_symbols(bytes.len()));
        assert!(Decoder::new(&[1, 2, 3]).is_err());
    }
}
