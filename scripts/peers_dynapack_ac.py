"""Dynapack with an adaptive arithmetic coder (issue 19), for scripts/peers.py: codec dynapack-ac.

Ibarria & Rossignac 2003 code the extended-Lorenzo residuals with an adaptive arithmetic coder; the
`dynapack` peer of peers.py uses zstd instead. This one keeps the same quantisation, traversal and
predictor (peers.dynapack_residuals, the same residuals bit for bit) and codes the residuals with
constriction's range coder (the coder mcgv-video itself uses) under an adaptive context model:

- symbol: a residual r with |r| <= SMALL is its own symbol; a larger one is an escape symbol naming
  its sign and bit length c, followed by its c-1 bits below the leading one, stored raw.
- context: the coordinate (x, y, z) and the magnitude class (bit length, capped) of the same vertex's
  residual of the same coordinate in the previous frame; frame 0 (spatial residuals only) has
  contexts of its own.
- adaptation: one symbol-count table per context, starting flat; symbols are coded in blocks of
  BLOCK, each block with the counts of everything coded before it (the decoder knows those counts
  and, from the previous frame, every symbol's context, so it decodes a block at once); counts are
  halved when a table passes LIMIT so that it follows the animation.
"""
import struct

import numpy as np

SMALL = 15
MAX_BITS = 26
ESCAPES = 2 * (MAX_BITS - SMALL.bit_length())
ALPHABET = 2 * SMALL + 1 + ESCAPES
CLASSES = 7          # previous-frame magnitude classes: bit length 0..5, then 6 and above
FIRST = CLASSES      # the class of frame 0's symbols
BLOCK = 4096
LIMIT = 1 << 16


def bit_length(values):
    v = np.abs(values).astype(np.int64)
    return np.where(v == 0, 0, np.floor(np.log2(np.maximum(v, 1))).astype(np.int64) + 1)


def to_symbols(residual):
    """(symbols, escape bit lengths c of the escaped values, their c-1 low bits)."""
    r = residual.astype(np.int64)
    c = bit_length(r)
    if c.max(initial=0) > MAX_BITS:
        raise ValueError("residual too large for the escape alphabet")
    small = np.abs(r) <= SMALL
    esc = 2 * SMALL + 1 + 2 * (c - SMALL.bit_length() - 1) + (r < 0)
    symbols = np.where(small, r + SMALL, esc)
    big = ~small
    return symbols, c[big], np.abs(r[big]) - (1 << (c[big] - 1))


def from_symbols(symbols, mantissas):
    s = symbols.astype(np.int64)
    out = s - SMALL
    big = s > 2 * SMALL
    e = s[big] - (2 * SMALL + 1)
    c = e // 2 + SMALL.bit_length() + 1
    magnitude = (1 << (c - 1)) + mantissas
    out[big] = np.where(e % 2 == 1, -magnitude, magnitude)
    return out


def symbol_class(symbols):
    """Bit length of the residual each symbol stands for, capped to CLASSES - 1."""
    s = symbols.astype(np.int64)
    small = s <= 2 * SMALL
    c = np.where(small, bit_length(s - SMALL), (s - 2 * SMALL - 1) // 2 + SMALL.bit_length() + 1)
    return np.minimum(c, CLASSES - 1)


def contexts(prev_symbols, nsym):
    """Context of each symbol of a frame (flattened vertex x coordinate) from the previous frame."""
    coord = np.arange(nsym) % 3
    cls = np.full(nsym, FIRST) if prev_symbols is None else symbol_class(prev_symbols)
    return coord * (CLASSES + 1) + cls


def pack_bits(lengths, values):
    """Values of the given bit lengths (MSB first), concatenated and packed into bytes."""
    if values.size == 0:
        return b""
    j = np.arange(MAX_BITS)
    bits = (values[:, None] >> np.maximum(lengths[:, None] - 1 - j, 0)) & 1
    return np.packbits(bits[j < lengths[:, None]].astype(np.uint8)).tobytes()


def unpack_bits(buf, lengths):
    if lengths.size == 0:
        return np.zeros(0, np.int64)
    bits = np.unpackbits(np.frombuffer(buf, np.uint8)).astype(np.int64)
    starts = np.concatenate([[0], np.cumsum(lengths)[:-1]])
    j = np.arange(MAX_BITS)
    pos = np.minimum(starts[:, None] + j, bits.size - 1)
    weights = np.where(j < lengths[:, None], 1 << np.maximum(lengths[:, None] - 1 - j, 0), 0)
    return (bits[pos] * weights).sum(axis=1)


class Model:
    """Adaptive symbol counts per context, shared by encoder and decoder."""

    def __init__(self):
        self.counts = np.ones(((CLASSES + 1) * 3, ALPHABET))

    def categorical(self, ctx):
        import constriction
        return constriction.stream.model.Categorical(self.counts[ctx], perfect=False)

    def update(self, ctx, symbols):
        self.counts[ctx] += np.bincount(symbols, minlength=ALPHABET)
        if self.counts[ctx].sum() > LIMIT:
            self.counts[ctx] = np.ceil(self.counts[ctx] / 2)


def blocks(ctx):
    """(start, stop, [(context, positions in the block)]) per block of a frame's symbols."""
    for lo in range(0, ctx.size, BLOCK):
        part = ctx[lo:lo + BLOCK]
        yield lo, [(int(k), lo + np.flatnonzero(part == k)) for k in np.unique(part)]


def encode_residuals(residual):
    """Range-coded symbols and packed escape bits of F x N x 3 residuals."""
    import constriction
    nf = residual.shape[0]
    symbols, lengths, mantissas = to_symbols(residual.reshape(nf, -1))
    coder, model, prev = constriction.stream.queue.RangeEncoder(), Model(), None
    for f in range(nf):
        for _lo, groups in blocks(contexts(prev, symbols.shape[1])):
            for k, at in groups:
                coder.encode(symbols[f, at].astype(np.int32), model.categorical(k))
            for k, at in groups:
                model.update(k, symbols[f, at])
        prev = symbols[f]
    words = coder.get_compressed().astype("<u4").tobytes()
    extra = pack_bits(lengths - 1, mantissas)
    return struct.pack("<II", len(words), len(extra)) + words + extra


def decode_residuals(buf, at, nf, nsym):
    import constriction
    nwords, nextra = struct.unpack_from("<II", buf, at)
    at += 8
    words = np.frombuffer(buf, "<u4", count=nwords // 4, offset=at)
    coder, model, prev = constriction.stream.queue.RangeDecoder(words.copy()), Model(), None
    symbols = np.zeros((nf, nsym), np.int64)
    for f in range(nf):
        for _lo, groups in blocks(contexts(prev, nsym)):
            for k, where in groups:
                symbols[f, where] = coder.decode(model.categorical(k), where.size)
            for k, where in groups:
                model.update(k, symbols[f, where])
        prev = symbols[f]
    flat = symbols.ravel()
    big = flat > 2 * SMALL
    c = (flat[big] - 2 * SMALL - 1) // 2 + SMALL.bit_length() + 1
    mantissas = unpack_bits(buf[at + nwords:at + nwords + nextra], c - 1)
    return from_symbols(flat, mantissas).reshape(nf, nsym), at + nwords + nextra


def encode(frames, faces, bits):
    import peers
    nf, nv, _ = frames.shape
    residual, low, step = peers.dynapack_residuals(frames, faces, bits)
    head = struct.pack("<IIId", nf, nv, faces.shape[0], step) + low.astype("<f8").tobytes()
    return head + peers.pack_faces(faces) + encode_residuals(residual)


def decode(buf):
    import peers
    nf, nv, _t, step = struct.unpack_from("<IIId", buf, 0)
    at = struct.calcsize("<IIId")
    low = np.frombuffer(buf, "<f8", count=3, offset=at)
    faces, at = peers.unpack_faces(buf, at + 24)
    residual, _ = decode_residuals(buf, at, nf, 3 * nv)
    return peers.dynapack_rebuild(residual.reshape(nf, nv, 3), faces, low, step), faces
