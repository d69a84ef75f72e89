#!/usr/bin/env python3
"""Peer codecs for the rate-distortion bench (issue 7): what a user would pick instead of mcgv-video.

Usage (with the virtualenv `make venv` makes):
  peers.py run OUT.csv INPUT...        every peer at every setting on every input, rows appended to OUT.csv
  peers.py encode CODEC SETTING IN.pc2 STREAM     one encoding (IN.obj beside IN.pc2 gives the faces)
  peers.py decode CODEC STREAM OUT.pc2            one decoding (writes OUT.obj, the faces, beside it)

Environment for `run`: MCGV_BIN (default target/release/mcgv-video), PEERS_WORK (scratch folder,
default bench-out/peers-work), PEERS_CODECS (default: ALL_CODECS below), PEERS_DRACO_QP (default "8 10 12 14 16": Draco
is the slowest peer to measure, see below), PEERS_SETTINGS (e.g. "dynapack=qp 6,qp 8;pca=basis 32":
other settings for the codecs named).

Each input is first rewritten losslessly by `mcgv-video convert` as a PC2 + base OBJ, so every codec
starts from exactly the frames mcgv-video reads (glTF baked by the same code). Each encoding and each
decoding is its own process under GNU time, so times and peak memory are whole-process figures like
those of scripts/sweep.sh (they include starting Python and importing numpy, about 0.1-0.2 s and
30-40 MB). Every byte of the stream file counts. The reconstruction is measured with `mcgv-video eval`,
the code that measures mcgv-video itself. Rows follow the schema of scripts/sweep.sh.

The peers:
- draco: every frame a Draco mesh (DracoPy, compression level 10, quantisation 8-16 bits). Draco
  renumbers vertices and merges those that coincide (seams, touching parts), which is what a user
  gets by default and is 5-8x smaller than preserve_order=True. Which vertices merge depends on each
  frame's positions, so the decoded frames need not share one connectivity (chickenCrossing's do
  not) and cannot form one animation: each run of frames sharing one connectivity is measured by
  `mcgv-video eval` as an animation of its own, its RMSE and Hausdorff rescaled from the run's
  first-frame bounding box diagonal to the sequence's (the unit of the measures), RMSE averaged and
  Hausdorff maximised over frames, as `eval` does for one animation. Surface samples are then placed
  on each run's first frame rather than the sequence's, a small difference (CesiumMan, one frame per
  run against one animation: RMSE within 0.04 %). Vertex RMSE and KG error need vertices
  that correspond and are left empty.
- zstd: the raw float32 positions and uint32 faces, zstd level 19: lossless, the floor to clear.
- pca: Alexa & Mueller 2000 without their rigid-motion alignment: the frames x 3V matrix minus the
  mean shape, truncated SVD with k basis shapes; basis shapes quantised to 12 bits (per shape's
  range), coefficients and mean to 16 bits, everything zstd-coded.
- dynapack: Ibarria & Rossignac 2003's extended Lorenzo predictor on a quantised grid (q bits over
  the animation's bounding cube): each vertex predicted from the same frame's parallelogram plus the
  previous frame's parallelogram error, traversal by face adjacency; residuals zstd-coded instead of
  Dynapack's arithmetic coder.
- dynapack-ac (peers_dynapack_ac.py): the same residuals, adaptive arithmetic coder, as the paper.
- gltfpack, gltfpack-br, meshopt-fm, meshopt-vm (peers_meshopt.py, Node tools in scripts/node): glTF
  morph targets packed by gltfpack (raw, Brotli'd), meshoptimizer's vertex codec; see that module.
"""
import hashlib
import json
import os
import shutil
import struct
import subprocess
import sys
from collections import deque
from pathlib import Path

import numpy as np
import zstandard

SCHEMA = ("sequence,codec,setting,bytes,bpvf,rmse,vertex_rmse,kg_error,hausdorff,encode_s,decode_s,"
          "encode_cpu_s,decode_cpu_s,encode_rss_kb,decode_rss_kb,frames,vertices")
SETTINGS = {
    "draco": [f"qp {q}" for q in os.environ.get("PEERS_DRACO_QP", "8 10 12 14 16").split()],
    "zstd": ["level 19"],
    "pca": ["basis 2", "basis 4", "basis 8", "basis 16", "basis 32", "basis 64"],
    "dynapack": ["qp 8", "qp 10", "qp 12", "qp 14", "qp 16"],
    "dynapack-ac": ["qp 8", "qp 10", "qp 12", "qp 14", "qp 16"],
    "gltfpack": ["vp 10", "vp 12", "vp 14", "vp 16"],
    "gltfpack-br": ["vp 10", "vp 12", "vp 14", "vp 16"],
    "meshopt-fm": ["qp 10", "qp 12", "qp 14", "qp 16"],
    "meshopt-vm": ["qp 10", "qp 12", "qp 14", "qp 16"],
}
ALL_CODECS = "draco zstd pca dynapack dynapack-ac gltfpack gltfpack-br meshopt-fm meshopt-vm"
# PEERS_SETTINGS="dynapack=qp 6,qp 8;pca=basis 32" replaces the settings of the codecs it names.
for _item in filter(None, os.environ.get("PEERS_SETTINGS", "").split(";")):
    _codec, _, _list = _item.partition("=")
    SETTINGS[_codec.strip()] = [x.strip() for x in _list.split(",") if x.strip()]
ZSTD_LEVEL = 19


def die(message):
    sys.exit(f"peers.py: error: {message}")


# ---------------------------------------------------------------- PC2 + OBJ

def read_pc2(path):
    """Frames x V x 3 float32 positions of a PC2 point cache."""
    raw = Path(path).read_bytes()
    if raw[:12] != b"POINTCACHE2\0":
        die(f"{path}: not a PC2 point cache")
    _version, points = struct.unpack_from("<ii", raw, 12)
    (samples,) = struct.unpack_from("<i", raw, 28)
    if len(raw) != 32 + 12 * points * samples:
        die(f"{path}: {len(raw)} bytes, expected {32 + 12 * points * samples}")
    return np.frombuffer(raw, dtype="<f4", offset=32).reshape(samples, points, 3)


def write_pc2(path, frames):
    frames = np.ascontiguousarray(frames, dtype="<f4")
    # Layout: magic, version, points, start frame (f32), sample rate (f32), samples.
    header = b"POINTCACHE2\0" + struct.pack("<iiffi", 1, frames.shape[1], 0.0, 1.0, frames.shape[0])
    Path(path).write_bytes(header + frames.tobytes())


def read_faces(obj_path):
    """Triangles of an OBJ written by `mcgv-video convert` (only `f a b c` lines, 1-based)."""
    rows = [line.split()[1:] for line in Path(obj_path).read_text().splitlines()
            if line.startswith("f ")]
    if any(len(r) != 3 for r in rows):
        die(f"{obj_path}: only triangles are expected")
    faces = np.array(rows, dtype=np.int64).reshape(-1, 3) - 1
    return faces.astype(np.uint32)


def write_recon(pc2_path, frames, faces):
    """PC2 plus the base OBJ of the same stem, which `mcgv-video eval` reads by default."""
    write_pc2(pc2_path, frames)
    lines = ["v %r %r %r" % tuple(float(c) for c in p) for p in frames[0]]
    lines += ["f %d %d %d" % (a + 1, b + 1, c + 1) for a, b, c in faces]
    Path(pc2_path).with_suffix(".obj").write_text("\n".join(lines) + "\n")


# ---------------------------------------------------------------- byte helpers

def pack_ints(values):
    """Signed integers zigzagged, stored in the narrowest of u8/u16/u32 with bytes split into planes
    (high bytes of all values, then the next...), then zstd: the planes make runs zstd can find."""
    v = np.asarray(values, dtype=np.int64).ravel()
    z = np.where(v >= 0, 2 * v, -2 * v - 1).astype(np.uint64)
    top = int(z.max()) if z.size else 0
    width = 1 if top < 1 << 8 else 2 if top < 1 << 16 else 4
    if top >= 1 << 32:
        die("integer out of range for pack_ints")
    planes = z.astype(f"<u{width}").view(np.uint8).reshape(-1, width).T.copy()
    body = zstandard.ZstdCompressor(level=ZSTD_LEVEL).compress(planes.tobytes())
    return struct.pack("<BQI", width, v.size, len(body)) + body


def unpack_ints(buf, at):
    width, count, length = struct.unpack_from("<BQI", buf, at)
    at += struct.calcsize("<BQI")
    planes = zstandard.ZstdDecompressor().decompress(buf[at:at + length], max_output_size=width * count)
    z = np.frombuffer(planes, dtype=np.uint8).reshape(width, count).T.copy().view(f"<u{width}")
    z = z.ravel().astype(np.int64)
    v = np.where(z % 2 == 0, z // 2, -(z + 1) // 2)
    return v, at + length


def pack_faces(faces):
    """Faces as index deltas along the flat list (neighbouring faces share vertices), zigzag + zstd."""
    flat = faces.astype(np.int64).ravel()
    return pack_ints(np.diff(flat, prepend=0))


def unpack_faces(buf, at):
    deltas, at = unpack_ints(buf, at)
    return np.cumsum(deltas).reshape(-1, 3).astype(np.uint32), at


# ---------------------------------------------------------------- codecs

def draco_encode(frames, faces, bits):
    import DracoPy
    out = [struct.pack("<II", frames.shape[0], frames.shape[1])]
    for f in range(frames.shape[0]):
        buf = DracoPy.encode(frames[f], faces, quantization_bits=bits, compression_level=10)
        out.append(struct.pack("<I", len(buf)) + buf)
    return b"".join(out)


def draco_decode(buf):
    """Every frame's own (positions, faces): Draco's connectivity may change from frame to frame."""
    import DracoPy
    count, _v = struct.unpack_from("<II", buf, 0)
    at, meshes = 8, []
    for _ in range(count):
        (length,) = struct.unpack_from("<I", buf, at)
        mesh = DracoPy.decode(buf[at + 4:at + 4 + length])
        at += 4 + length
        meshes.append((np.asarray(mesh.points, dtype=np.float32).reshape(-1, 3),
                       np.asarray(mesh.faces, dtype=np.uint32).reshape(-1, 3)))
    return meshes


def write_meshes(path, meshes):
    """Decoded Draco frames as one binary file (V, T, positions, faces per frame); turned into OBJ
    files for measuring by the driver, outside the timed decoding."""
    with open(path, "wb") as f:
        for pos, tri in meshes:
            f.write(struct.pack("<II", len(pos), len(tri)))
            f.write(np.ascontiguousarray(pos, "<f4").tobytes())
            f.write(np.ascontiguousarray(tri, "<u4").tobytes())


def read_meshes(path):
    raw, at, meshes = Path(path).read_bytes(), 0, []
    while at < len(raw):
        nv, nt = struct.unpack_from("<II", raw, at)
        at += 8
        pos = np.frombuffer(raw, "<f4", count=3 * nv, offset=at).reshape(nv, 3)
        at += 12 * nv
        tri = np.frombuffer(raw, "<u4", count=3 * nt, offset=at).reshape(nt, 3)
        at += 12 * nt
        meshes.append((pos, tri))
    return meshes


def write_obj(path, pos, tri):
    lines = ["v %r %r %r" % (float(x), float(y), float(z)) for x, y, z in pos]
    lines += ["f %d %d %d" % (a + 1, b + 1, c + 1) for a, b, c in tri]
    Path(path).write_text("\n".join(lines) + "\n")


def zstd_encode(frames, faces):
    body = np.ascontiguousarray(frames, "<f4").tobytes() + np.ascontiguousarray(faces, "<u4").tobytes()
    return struct.pack("<III", frames.shape[0], frames.shape[1], faces.shape[0]) + \
        zstandard.ZstdCompressor(level=ZSTD_LEVEL).compress(body)


def zstd_decode(buf):
    f, v, t = struct.unpack_from("<III", buf, 0)
    raw = zstandard.ZstdDecompressor().decompress(buf[12:], max_output_size=12 * f * v + 12 * t)
    frames = np.frombuffer(raw, "<f4", count=3 * f * v).reshape(f, v, 3)
    faces = np.frombuffer(raw, "<u4", offset=12 * f * v).reshape(t, 3)
    return frames, faces


def quantise(values, bits, axis):
    """Uniform quantisation over the range along `axis`; returns (levels, low, step)."""
    low = values.min(axis=axis, keepdims=True)
    high = values.max(axis=axis, keepdims=True)
    step = np.maximum(high - low, 1e-30) / ((1 << bits) - 1)
    return np.rint((values - low) / step).astype(np.int64), low, step


def pca_encode(frames, faces, k):
    nf, nv, _ = frames.shape
    k = min(k, nf - 1)
    a = frames.reshape(nf, 3 * nv).astype(np.float64)
    mean = a.mean(axis=0)
    u, s, vt = np.linalg.svd(a - mean, full_matrices=False)
    basis = vt[:k]                      # k x 3V, orthonormal shapes
    coeff = u[:, :k] * s[:k]            # F x k
    qm, mlo, mstep = quantise(mean[None, :], 16, axis=1)
    qb, blo, bstep = quantise(basis, 12, axis=1)
    qc, clo, cstep = quantise(coeff, 16, axis=0)
    head = struct.pack("<IIII", nf, nv, faces.shape[0], k)
    floats = np.concatenate([mlo.ravel(), mstep.ravel(), blo.ravel(), bstep.ravel(),
                             clo.ravel(), cstep.ravel()]).astype("<f8").tobytes()
    return head + floats + pack_ints(qm) + pack_ints(qb) + pack_ints(qc) + pack_faces(faces)


def pca_decode(buf):
    nf, nv, _t, k = struct.unpack_from("<IIII", buf, 0)
    at = 16
    n_floats = 2 + 2 * k + 2 * k
    fl = np.frombuffer(buf, "<f8", count=n_floats, offset=at)
    at += 8 * n_floats
    mlo, mstep = fl[0], fl[1]
    blo, bstep = fl[2:2 + k, None], fl[2 + k:2 + 2 * k, None]
    clo, cstep = fl[2 + 2 * k:2 + 3 * k][None, :], fl[2 + 3 * k:][None, :]
    qm, at = unpack_ints(buf, at)
    qb, at = unpack_ints(buf, at)
    qc, at = unpack_ints(buf, at)
    faces, at = unpack_faces(buf, at)
    mean = mlo + qm * mstep
    basis = blo + qb.reshape(k, 3 * nv) * bstep
    coeff = clo + qc.reshape(nf, k) * cstep
    frames = (mean[None, :] + coeff @ basis).reshape(nf, nv, 3).astype(np.float32)
    return frames, faces


def traversal(nv, faces):
    """Vertex order and predictor of each vertex, from a breadth-first walk over faces sharing edges.

    Returns (order, kind, a, b, c): vertex order[i] is predicted by nothing (kind 0), by vertex a
    (kind 1), or by the parallelogram a + b - c across an edge (kind 2), all earlier in the order.
    Decoder and encoder both compute it from the connectivity alone.
    """
    edge_faces = {}
    for fi, (x, y, z) in enumerate(faces.tolist()):
        for e in ((x, y), (y, z), (z, x)):
            edge_faces.setdefault((min(e), max(e)), []).append(fi)
    known = np.zeros(nv, bool)
    done = np.zeros(len(faces), bool)
    order, kind, pa, pb, pc = [], [], [], [], []

    def emit(v, k, a=0, b=0, c=0):
        known[v] = True
        order.append(v), kind.append(k), pa.append(a), pb.append(b), pc.append(c)

    tri = faces.tolist()
    for seed in range(len(faces)):
        if done[seed]:
            continue
        queue = deque([seed])
        done[seed] = True
        while queue:
            fi = queue.popleft()
            verts = tri[fi]
            for j, v in enumerate(verts):
                if known[v]:
                    continue
                a, b = verts[(j + 1) % 3], verts[(j + 2) % 3]
                if known[a] and known[b]:
                    # The third vertex of an already walked face across edge (a, b).
                    c = next((w for g in edge_faces[(min(a, b), max(a, b))] if g != fi and done[g]
                              for w in tri[g] if w != a and w != b and known[w]), None)
                    if c is not None:
                        emit(v, 2, a, b, c)
                        continue
                ref = a if known[a] else b if known[b] else None
                if ref is None:
                    emit(v, 0)
                else:
                    emit(v, 1, ref)
            for e in ((verts[0], verts[1]), (verts[1], verts[2]), (verts[2], verts[0])):
                for g in edge_faces[(min(e), max(e))]:
                    if not done[g]:
                        done[g] = True
                        queue.append(g)
    for v in np.flatnonzero(~known):      # vertices no face uses
        emit(int(v), 0)
    return tuple(np.array(x, dtype=np.int64) for x in (order, kind, pa, pb, pc))


def dynapack_residuals(frames, faces, bits):
    """Quantised positions' prediction residuals (F x V x 3, vertices in traversal order), the grid's
    low corner and step: the part of the encoder the zstd and the arithmetic-coded variants share."""
    nf, nv, _ = frames.shape
    flat = frames.reshape(-1, 3).astype(np.float64)
    low = flat.min(axis=0)
    step = max(float((flat.max(axis=0) - low).max()), 1e-30) / ((1 << bits) - 1)
    q = np.rint((frames - low) / step).astype(np.int64)          # F x V x 3
    d = np.diff(q, axis=0, prepend=0)                            # frame 0 raw, then temporal deltas
    order, kind, a, b, c = traversal(nv, faces)
    pred = np.zeros((nf, nv, 3), np.int64)
    one, par = kind == 1, kind == 2
    pred[:, order[one]] = d[:, a[one]]
    pred[:, order[par]] = d[:, a[par]] + d[:, b[par]] - d[:, c[par]]
    return (d - pred)[:, order], low, step


def dynapack_encode(frames, faces, bits):
    nf, nv, _ = frames.shape
    residual, low, step = dynapack_residuals(frames, faces, bits)
    head = struct.pack("<IIId", nf, nv, faces.shape[0], step) + low.astype("<f8").tobytes()
    return head + pack_faces(faces) + pack_ints(residual)


def dynapack_decode(buf):
    nf, nv, _t, step = struct.unpack_from("<IIId", buf, 0)
    at = struct.calcsize("<IIId")
    low = np.frombuffer(buf, "<f8", count=3, offset=at)
    at += 24
    faces, at = unpack_faces(buf, at)
    residual, at = unpack_ints(buf, at)
    return dynapack_rebuild(residual.reshape(nf, nv, 3), faces, low, step), faces


def dynapack_rebuild(residual, faces, low, step):
    """Positions from the residuals of dynapack_residuals()."""
    nf, nv, _ = residual.shape
    order, kind, a, b, c = traversal(nv, faces)
    d = np.zeros((nf, nv, 3), np.int64)
    # The recurrence is linear in the frames, so each vertex is decoded for all frames at once.
    for i in range(nv):
        v, k = order[i], kind[i]
        if k == 0:
            d[:, v] = residual[:, i]
        elif k == 1:
            d[:, v] = residual[:, i] + d[:, a[i]]
        else:
            d[:, v] = residual[:, i] + d[:, a[i]] + d[:, b[i]] - d[:, c[i]]
    q = np.cumsum(d, axis=0)
    return (low + q * step).astype(np.float32)


def extra_codecs():
    """The peers of issue 19, in modules of their own: codec -> (encode, decode), where
    encode(frames, faces, value) -> bytes and decode(bytes) -> (frames, faces, info or None)."""
    import peers_dynapack_ac
    import peers_meshopt
    table = {c: (e, peers_meshopt.decoders()[c]) for c, e in peers_meshopt.encoders().items()}
    table["dynapack-ac"] = (peers_dynapack_ac.encode, lambda b: peers_dynapack_ac.decode(b) + (None,))
    return table


def encode(codec, setting, src, stream):
    frames = read_pc2(src)
    faces = read_faces(Path(src).with_suffix(".obj"))
    value = int(setting.split()[-1])
    if codec == "draco":
        data = draco_encode(frames, faces, value)
    elif codec == "zstd":
        data = zstd_encode(frames, faces)
    elif codec == "pca":
        data = pca_encode(frames, faces, value)
    elif codec == "dynapack":
        data = dynapack_encode(frames, faces, value)
    elif codec in extra_codecs():
        data = extra_codecs()[codec][0](frames, faces, value)
    else:
        die(f"unknown codec {codec}")
    Path(stream).write_bytes(data)


def decode(codec, stream, out):
    """Writes OUT.pc2 + OUT.obj; for gltfpack, in the decoder's own vertex order, with OUT.json
    (keys, targets and key times) for the driver's checks and matching (match_gltfpack)."""
    buf = Path(stream).read_bytes()
    decoders = {"draco": draco_decode, "zstd": zstd_decode, "pca": pca_decode,
                "dynapack": dynapack_decode}
    if codec == "draco":
        write_meshes(out, draco_decode(buf))
        return
    if codec in decoders:
        frames, faces = decoders[codec](buf)
    elif codec in extra_codecs():
        frames, faces, info = extra_codecs()[codec][1](buf)
        if info is not None:
            Path(out).with_suffix(".json").write_text(json.dumps(info))
    else:
        die(f"unknown codec {codec}")
    write_recon(out, frames, faces)


def match_gltfpack(original, recon):
    """Checks gltfpack's keys and targets against the original's frames, then rewrites the decoded
    PC2 in the original's vertex order (each original vertex takes the decoded vertex nearest over all
    frames) with the original's faces, so that `mcgv-video eval` compares vertex with vertex.
    Returns how many distinct decoded vertices were used."""
    import peers_meshopt
    frames = read_pc2(original)
    decoded = read_pc2(recon)
    peers_meshopt.check_keys(json.loads(Path(recon).with_suffix(".json").read_text()), frames.shape[0])
    index = peers_meshopt.match(frames, decoded)
    write_recon(recon, decoded[:, index], read_faces(Path(original).with_suffix(".obj")))
    return len(np.unique(index))


# ---------------------------------------------------------------- the driver

class Failure(Exception):
    """A peer that cannot take an input: `run` notes why in OUT.skipped.csv and goes on."""


def timed(cmd, time_file):
    """Runs cmd under GNU time; returns (wall s, cpu s, peak RSS kB). Fails loudly."""
    full = ["/usr/bin/time", "-f", "%e %U %S %M", "-o", str(time_file)] + [str(c) for c in cmd]
    result = subprocess.run(full, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if result.returncode != 0:
        last = (result.stderr.strip().splitlines() or ["no message"])[-1]
        raise Failure(f"{' '.join(map(str, cmd[2:5]))}: {last}")
    wall, user, system, rss = Path(time_file).read_text().split()[-4:]
    return float(wall), float(user) + float(system), int(rss)


def evaluate(binary, original, other):
    # Every frame in full: the bench compares codecs at equal error, so no estimate.
    result = subprocess.run([binary, "eval", str(original), str(other), "--json", "--quiet", "--every-frame"],
                            capture_output=True, text=True)
    if result.returncode != 0:
        die(f"mcgv-video eval {original} {other} failed:\n{result.stderr}")
    return json.loads(result.stdout)


def evaluate_frames(binary, original_frames, original, meshes, folder):
    """The animation measures of per-frame meshes, as `eval` computes them for one animation.

    Runs of consecutive frames that share one connectivity are measured together, as one animation
    (`eval` on two OBJ folders); its RMSE and Hausdorff, relative to the run's first-frame bounding
    box, are rescaled to the sequence's first frame, RMSE averaged over all frames, Hausdorff maximised.
    """
    frames = read_pc2(original).astype(np.float64)
    diagonals = np.linalg.norm(frames.max(axis=1) - frames.min(axis=1), axis=1)
    originals = sorted(original_frames.glob("frame_*.obj"))
    if len(originals) != len(meshes):
        die(f"{len(meshes)} decoded frames for {len(originals)} original ones")
    runs, start = [], 0
    for f in range(1, len(meshes) + 1):
        if f == len(meshes) or not np.array_equal(meshes[f][1], meshes[start][1]) \
                or len(meshes[f][0]) != len(meshes[start][0]):
            runs.append((start, f))
            start = f
    rmse_sum, hausdorff = 0.0, 0.0
    for a, b in runs:
        orig_dir, recon_dir = folder / "original", folder / "decoded"
        for d in (orig_dir, recon_dir):
            shutil.rmtree(d, ignore_errors=True)
            d.mkdir(parents=True)
        for f in range(a, b):
            (orig_dir / f"frame_{f:05d}.obj").symlink_to(originals[f].resolve())
            write_obj(recon_dir / f"frame_{f:05d}.obj", *meshes[f])
        m = evaluate(binary, orig_dir, recon_dir)
        if m["frames"] != b - a:
            die(f"eval saw {m['frames']} frames in a run of {b - a}")
        scale = diagonals[a] / diagonals[0]
        rmse_sum += m["rmse"] * scale * (b - a)
        hausdorff = max(hausdorff, m["hausdorff"] * scale)
    print(f"{original.parent.name}: Draco frames measured in {len(runs)} run(s) of one connectivity",
          file=sys.stderr)
    return {"rmse": rmse_sum / len(meshes), "hausdorff": hausdorff}


def sequence_name(input_path):
    """The name scripts/sweep.sh gives the same input, so rows of both join."""
    name = os.path.basename(input_path.rstrip("/"))
    return name.rsplit(".", 1)[0] if "." in name else name


def fmt(value, spec):
    return "" if value is None else format(value, spec)


def run(out_csv, inputs):
    binary = os.environ.get("MCGV_BIN", "target/release/mcgv-video")
    work = Path(os.environ.get("PEERS_WORK", "bench-out/peers-work"))
    codecs = os.environ.get("PEERS_CODECS", ALL_CODECS).split()
    work.mkdir(parents=True, exist_ok=True)
    out = Path(out_csv)
    if not out.exists() or out.stat().st_size == 0:
        out.write_text(SCHEMA + "\n")
    # Rows already in OUT.csv are not measured again, so an interrupted run resumes where it stopped.
    done = {tuple(line.split(",")[:3]) for line in out.read_text().splitlines()[1:]}
    for input_path in inputs:
        name = sequence_name(input_path)
        seq = work / name
        seq.mkdir(exist_ok=True)
        original = seq / "original.pc2"
        subprocess.run([binary, "convert", input_path, "-o", str(original), "--force", "--quiet"],
                       check=True)
        # The conversion must be exact, or every peer would be measured against other frames.
        check = evaluate(binary, input_path, original)
        if check["vertex_rmse"] != 0.0 or check["rmse"] != 0.0:
            die(f"{input_path}: conversion to PC2 is not exact: {check}")
        nf, nv = check["frames"], check["vertices"]
        original_frames = seq / "original_frames"
        if "draco" in codecs and not original_frames.is_dir():
            subprocess.run([binary, "convert", str(original), "-o", str(original_frames), "--quiet"],
                           check=True)
        for codec in codecs:
            for setting in SETTINGS[codec]:
                if codec == "pca" and int(setting.split()[1]) >= nf or (name, codec, setting) in done:
                    continue    # as many shapes as frames is no compression; measured already
                try:
                    row = measure(binary, seq, codec, setting, original_frames)
                except Failure as e:
                    skipped = out.with_suffix(".skipped.csv")
                    with skipped.open("a") as f:
                        f.write(f"{name},{codec},{setting},\"{str(e).replace(chr(34), chr(39))}\"\n")
                    print(f"{name}: {codec} {setting} skipped: {e}", file=sys.stderr)
                    continue
                print(row, flush=True)
                with out.open("a") as f:
                    f.write(row + "\n")


EVALUATED = {}


def measure(binary, seq, codec, setting, original_frames):
    """One encoding and decoding of seq/original.pc2, measured: the CSV row."""
    me = [sys.executable, os.path.abspath(__file__)]
    original, name = seq / "original.pc2", seq.name
    nf, nv = read_pc2(original).shape[:2]
    stream, recon = seq / f"{codec}.bin", seq / f"{codec}_recon.pc2"
    ew, ec, em = timed(me + ["encode", codec, setting, original, stream], seq / "time")
    dw, dc, dm = timed(me + ["decode", codec, stream, recon], seq / "time")
    if codec.startswith("gltfpack"):
        import peers_meshopt
        try:
            used = match_gltfpack(original, recon)
        except peers_meshopt.PeerError as e:
            raise Failure(str(e)) from e
        print(f"{name}: {codec} {setting}: {used} of {nv} vertices after welding", file=sys.stderr)
    if codec == "draco":
        m = evaluate_frames(binary, original_frames, original, read_meshes(recon), seq / "draco_frames")
    else:
        # Codecs that decode to the same frames and triangles (gltfpack and gltfpack-br; dynapack,
        # dynapack-ac and meshopt on one grid) share one measurement.
        tri = read_faces(recon.with_suffix(".obj"))
        turn = (tri.argmin(axis=1)[:, None] + np.arange(3)) % 3     # lowest corner first
        tri = np.take_along_axis(tri, turn, axis=1)
        key = hashlib.sha1(recon.read_bytes() + tri.tobytes()).hexdigest()
        m = EVALUATED.get(key) or evaluate(binary, original, recon)
        EVALUATED[key] = m
    size = stream.stat().st_size
    return (f"{name},{codec},{setting},{size},{size * 8 / (nv * nf):.4f},"
            f"{fmt(m['rmse'], '.6e')},{fmt(m.get('vertex_rmse'), '.6e')},"
            f"{fmt(m.get('kg_error'), '.5f')},{fmt(m['hausdorff'], '.6e')},"
            f"{ew},{dw},{ec:.2f},{dc:.2f},{em},{dm},{nf},{nv}")


def main():
    args = sys.argv[1:]
    if len(args) >= 2 and args[0] == "run":
        run(args[1], args[2:])
    elif len(args) == 5 and args[0] == "encode":
        encode(args[1], args[2], args[3], args[4])
    elif len(args) == 4 and args[0] == "decode":
        decode(args[1], args[2], args[3])
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main()
