"""The meshoptimizer peers of scripts/peers.py (issue 19): what the glTF ecosystem ships.

- gltfpack: the animation as a glTF binary with one morph target per frame (frame 0 the base mesh,
  target f = frame f - frame 0, target 0 all zero) and a STEP weights track with one key per frame at
  FPS frames per second, packed by `gltfpack -cc -af 0 -ac -vp BITS` (EXT_meshopt_compression and
  KHR_mesh_quantization; -af 0 keeps the keys as they are, -ac keeps constant tracks). The stream is
  gltfpack's output; gltfpack-br is the same output after Brotli (quality 11), what a web server sends.
  Decoding reads the file with @gltf-transform/core and meshoptimizer's decoder (node/gltf_frames.mjs):
  positions = world matrix x (base + sum of weight x delta) at every key. gltfpack renumbers and welds
  vertices, so the driver matches each original vertex to the decoded one nearest over all frames
  (match()), outside the timed decoding, and checks that no frame or target was dropped or resampled.
- meshopt-fm / meshopt-vm: meshoptimizer's vertex codec (format 1, level 3) on positions quantised to
  BITS over the animation's bounding cube (uint16 x 3 + 2 padding bytes, glTF's layout), laid out
  frame-major (every frame one after the other, as glTF's accessors) or vertex-major (each vertex's
  trajectory, so the codec's deltas are temporal), faces by its index codec, all zstd-coded (level 19).
"""
import json
import struct
import subprocess
import tempfile
from pathlib import Path

import numpy as np
import zstandard

NODE_DIR = Path(__file__).resolve().parent / "node"
GLTFPACK = NODE_DIR / "node_modules" / ".bin" / "gltfpack"
FPS = 30.0
BROTLI_QUALITY = 11


class PeerError(Exception):
    pass


def node_run(args):
    """Runs a Node tool of scripts/node, raising PeerError with its stderr when it fails."""
    result = subprocess.run([str(a) for a in args], capture_output=True, text=True, cwd=NODE_DIR)
    if result.returncode != 0:
        raise PeerError(f"{' '.join(map(str, args))} failed:\n{result.stderr}{result.stdout}")
    return result.stdout


# ---------------------------------------------------------------- glTF with morph targets

def glb_bytes(doc, blob):
    """A GLB container: JSON chunk (space padded) then BIN chunk (zero padded)."""
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    blob += b"\0" * (-len(blob) % 4)
    total = 12 + 8 + len(text) + 8 + len(blob)
    return (struct.pack("<III", 0x46546C67, 2, total) + struct.pack("<II", len(text), 0x4E4F534A) + text
            + struct.pack("<II", len(blob), 0x004E4942) + blob)


class Blob:
    """The binary chunk and the bufferViews/accessors pointing into it."""

    def __init__(self):
        self.parts, self.size, self.views, self.accessors = [], 0, [], []

    def add(self, array, component, kind, target=None, bounds=False):
        data = np.ascontiguousarray(array).tobytes()
        view = {"buffer": 0, "byteOffset": self.size, "byteLength": len(data)}
        if target:
            view["target"] = target
        self.views.append(view)
        self.parts.append(data + b"\0" * (-len(data) % 4))
        self.size += len(self.parts[-1])
        acc = {"bufferView": len(self.views) - 1, "componentType": component,
               "count": int(array.shape[0]), "type": kind}
        if bounds:
            flat = np.asarray(array, np.float64).reshape(array.shape[0], -1)
            acc["min"], acc["max"] = flat.min(axis=0).tolist(), flat.max(axis=0).tolist()
        self.accessors.append(acc)
        return len(self.accessors) - 1


def morph_glb(frames, faces):
    """The animation as glTF morph targets: one target per frame and a STEP weights track."""
    nf = frames.shape[0]
    base = frames[0].astype("<f4")
    blob = Blob()
    idx = blob.add(faces.astype("<u4").ravel(), 5125, "SCALAR", 34963)
    pos = blob.add(base, 5126, "VEC3", 34962, bounds=True)
    targets = [{"POSITION": blob.add((frames[f] - frames[0]).astype("<f4"), 5126, "VEC3", 34962, True)}
               for f in range(nf)]
    times = blob.add((np.arange(nf) / FPS).astype("<f4"), 5126, "SCALAR", bounds=True)
    weights = blob.add(np.eye(nf, dtype="<f4").ravel(), 5126, "SCALAR")
    doc = {
        "asset": {"version": "2.0", "generator": "mcgv-video scripts/peers_meshopt.py"},
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0, "name": "animation"}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}, "indices": idx, "mode": 4,
                                    "targets": targets}], "weights": [0.0] * nf}],
        "animations": [{"channels": [{"sampler": 0, "target": {"node": 0, "path": "weights"}}],
                        "samplers": [{"input": times, "output": weights, "interpolation": "STEP"}]}],
        "buffers": [{"byteLength": blob.size}], "bufferViews": blob.views, "accessors": blob.accessors,
    }
    return glb_bytes(doc, b"".join(blob.parts))


def gltfpack_encode(frames, faces, bits, brotli_on):
    with tempfile.TemporaryDirectory() as tmp:
        src, dst = Path(tmp) / "in.glb", Path(tmp) / "out.glb"
        src.write_bytes(morph_glb(frames, faces))
        node_run([GLTFPACK, "-i", src, "-o", dst, "-cc", "-af", "0", "-ac", "-vp", bits])
        data = dst.read_bytes()
    if brotli_on:
        import brotli
        data = brotli.compress(data, quality=BROTLI_QUALITY)
    return data


def gltf_frames(glb_path):
    """(frames F x V x 3, faces, info) of a morph-animated glTF binary, info from gltf_frames.mjs."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "frames.bin"
        info = json.loads(node_run(["node", NODE_DIR / "gltf_frames.mjs", Path(glb_path).resolve(), out]))
        raw = out.read_bytes()
    nf, nv, nt, _k = struct.unpack_from("<iiii", raw, 0)
    at = 16
    frames = np.frombuffer(raw, "<f4", count=3 * nf * nv, offset=at).reshape(nf, nv, 3)
    at += 12 * nf * nv
    faces = np.frombuffer(raw, "<u4", count=3 * nt, offset=at).reshape(nt, 3)
    info["times"] = np.frombuffer(raw, "<f4", count=nf, offset=at + 12 * nt).tolist()
    return frames, faces, info


def gltfpack_decode(buf, brotli_on):
    """(frames in gltfpack's vertex order, its faces, info)."""
    if brotli_on:
        import brotli
        buf = brotli.decompress(buf)
    with tempfile.TemporaryDirectory() as tmp:
        glb = Path(tmp) / "in.glb"
        glb.write_bytes(buf)
        return gltf_frames(glb)


def check_keys(info, nf):
    """gltfpack must keep one key per frame at the input's times and one target per frame."""
    if info["frames"] != nf or info["targets"] != nf:
        raise PeerError(f"decoded {info['frames']} keys and {info['targets']} targets for {nf} frames")
    if not np.allclose(info["times"], np.arange(nf) / FPS, rtol=0, atol=1e-4):
        raise PeerError("decoded key times differ from the input's: the animation was resampled")


def match(original, decoded):
    """For each original vertex, the decoded vertex whose trajectory is nearest over all frames
    (several originals may share one where gltfpack welded them). Returns the index array."""
    nf = original.shape[0]
    centre = original.reshape(-1, 3).mean(axis=0)
    a = (original - centre).transpose(1, 0, 2).reshape(original.shape[1], 3 * nf).astype(np.float64)
    b = (decoded - centre).transpose(1, 0, 2).reshape(decoded.shape[1], 3 * nf).astype(np.float64)
    bb = (b * b).sum(axis=1)
    out = np.empty(a.shape[0], np.int64)
    for lo in range(0, a.shape[0], 1024):
        chunk = a[lo:lo + 1024]
        d = bb[None, :] - 2.0 * chunk @ b.T
        out[lo:lo + 1024] = d.argmin(axis=1)
    return out


# ---------------------------------------------------------------- meshoptimizer's vertex codec

def cube_quantise(frames, bits):
    """Positions on a grid of 2^bits levels over the animation's bounding cube: (levels, low, step)."""
    flat = frames.reshape(-1, 3).astype(np.float64)
    low = flat.min(axis=0)
    step = max(float((flat.max(axis=0) - low).max()), 1e-30) / ((1 << bits) - 1)
    return np.rint((frames - low) / step).astype(np.uint16), low, step


def meshopt_encode(frames, faces, bits, layout):
    if not 1 <= bits <= 16:
        raise PeerError("meshopt: 1 to 16 bits")
    nf, nv, _ = frames.shape
    q, low, step = cube_quantise(frames, bits)
    padded = np.zeros((nf, nv, 4), "<u2")
    padded[..., :3] = q
    if layout == "vertex":
        padded = padded.transpose(1, 0, 2)
    with tempfile.TemporaryDirectory() as tmp:
        vert, idx, out = Path(tmp) / "v.raw", Path(tmp) / "i.raw", Path(tmp) / "out.bin"
        vert.write_bytes(np.ascontiguousarray(padded).tobytes())
        idx.write_bytes(faces.astype("<u4").tobytes())
        node_run(["node", NODE_DIR / "meshopt_codec.mjs", "encode", 8, vert, idx, out])
        body = out.read_bytes()
    head = struct.pack("<IIIBd", nf, nv, faces.shape[0], layout == "vertex", step) + low.astype("<f8").tobytes()
    return head + zstandard.ZstdCompressor(level=19).compress(body)


def meshopt_decode(buf):
    nf, nv, nt, vertex_major, step = struct.unpack_from("<IIIBd", buf, 0)
    at = struct.calcsize("<IIIBd")
    low = np.frombuffer(buf, "<f8", count=3, offset=at)
    body = zstandard.ZstdDecompressor().decompress(buf[at + 24:], max_output_size=64 * nf * nv + 64 * nt + 64)
    with tempfile.TemporaryDirectory() as tmp:
        src, vert, idx = Path(tmp) / "in.bin", Path(tmp) / "v.raw", Path(tmp) / "i.raw"
        src.write_bytes(body)
        node_run(["node", NODE_DIR / "meshopt_codec.mjs", "decode", 8, nf * nv, nt, src, vert, idx])
        q = np.frombuffer(vert.read_bytes(), "<u2")
        faces = np.frombuffer(idx.read_bytes(), "<u4").reshape(nt, 3)
    q = q.reshape((nv, nf, 4) if vertex_major else (nf, nv, 4))[..., :3]
    if vertex_major:
        q = q.transpose(1, 0, 2)
    return (low + q.astype(np.float64) * step).astype(np.float32), faces


# ---------------------------------------------------------------- the codecs, for peers.py

def encoders():
    """codec -> encode(frames, faces, setting value) -> stream bytes."""
    return {
        "gltfpack": lambda fr, fa, v: gltfpack_encode(fr, fa, v, False),
        "gltfpack-br": lambda fr, fa, v: gltfpack_encode(fr, fa, v, True),
        "meshopt-fm": lambda fr, fa, v: meshopt_encode(fr, fa, v, "frame"),
        "meshopt-vm": lambda fr, fa, v: meshopt_encode(fr, fa, v, "vertex"),
    }


def decoders():
    """codec -> decode(stream bytes) -> (frames, faces, info or None); info only for gltfpack,
    whose vertices must be matched (match()) and keys checked (check_keys()) by the caller."""
    return {
        "gltfpack": lambda b: gltfpack_decode(b, False),
        "gltfpack-br": lambda b: gltfpack_decode(b, True),
        "meshopt-fm": lambda b: meshopt_decode(b) + (None,),
        "meshopt-vm": lambda b: meshopt_decode(b) + (None,),
    }
