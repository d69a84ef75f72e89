//! The range coder's two directions over the adaptive models of [`super`]: [`Encoder`] writes
//! symbols into a byte buffer, [`Decoder`] reads them back, and [`SymbolCoder`] lets a codec write
//! its traversal once for both.

use super::{
    max_symbols, BitModel, IntModel, RawChunk, SignedModels, SymbolModel, UIntModel, PRECISION,
};
use crate::error::{Error, Result};
use constriction::stream::model::{DecoderModel, EncoderModel};
use constriction::stream::queue::{DefaultRangeDecoder, DefaultRangeEncoder};
use constriction::stream::{Decode, Encode};

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
        // Each side starts from the same fresh models.
        let models = || {
            (
                BitModel::default(),
                SymbolModel::new(5),
                UIntModel::default(),
                IntModel::default(),
            )
        };
        let mut enc = Encoder::new();
        let (mut b, mut s, mut u, mut i) = models();
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
        let (mut b, mut s, mut u, mut i) = models();
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
