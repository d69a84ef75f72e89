#!/usr/bin/env python3
"""Round trips of the peers of issue 19 (scripts/peers_meshopt.py, scripts/peers_dynapack_ac.py) on a
small generated animation, so that a broken peer fails here instead of passing as a weak one in the
bench. A missing tool (Node, the npm packages of scripts/node, brotli, constriction) is a failure, not
a skip: `make node-deps venv` installs them all. `make test` runs this with the virtualenv's python:
  .venv/bin/python scripts/test_peers.py
"""
import importlib
import shutil
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import peers  # noqa: E402
import peers_dynapack_ac  # noqa: E402
import peers_meshopt  # noqa: E402

FRAMES = 12


def animation():
    """A bent, waving 14 x 14 sheet that also walks along x, plus two vertices that start closer than
    any grid step and then part (what frame-0 matching gets wrong), and one vertex doubled exactly
    (what gltfpack welds)."""
    n = 14
    u, v = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n))
    base = np.stack([u.ravel(), v.ravel(), 0.1 * np.sin(3 * u.ravel())], axis=1)
    faces = [(i * n + j, i * n + j + 1, i * n + j + n) for i in range(n - 1) for j in range(n - 1)]
    faces += [(i * n + j + 1, i * n + j + n + 1, i * n + j + n) for i in range(n - 1) for j in range(n - 1)]
    t = np.arange(FRAMES)[:, None, None]
    frames = base[None] + 0.04 * t * np.array([1.0, 0, 0]) + 0.05 * np.sin(0.7 * t + 4 * base[None, :, :1])
    nv = len(base)
    pair = np.stack([frames[:, 0] + [0, 0, 0.3], frames[:, 0] + [0, 0, 0.3]], axis=1)
    pair[:, 1, 2] += 1e-7 + 0.02 * np.arange(FRAMES)    # same place in frame 0, apart after
    frames = np.concatenate([frames, pair, frames[:, 5:6]], axis=1)
    faces += [(0, nv, nv + 1), (nv + 1, nv, 1), (5, 6, nv + 2)]
    return frames.astype(np.float32), np.array(faces, np.uint32)


def cube_step(frames, bits):
    extent = (frames.reshape(-1, 3).max(axis=0) - frames.reshape(-1, 3).min(axis=0)).max()
    return float(extent) / ((1 << bits) - 1)


def rotated_first_lowest(faces):
    faces = np.asarray(faces)
    shift = faces.argmin(axis=1)
    return np.stack([faces[np.arange(len(faces)), (shift + k) % 3] for k in range(3)], axis=1)


class Tools(unittest.TestCase):
    """What the Makefile installs must be there: the peers are measured with them."""

    def test_node_tools(self):
        self.assertIsNotNone(shutil.which("node"), "node is missing: make node-deps")
        self.assertTrue(peers_meshopt.GLTFPACK.exists(), f"{peers_meshopt.GLTFPACK} missing: make node-deps")
        for pkg in ("meshoptimizer", "@gltf-transform/core", "@gltf-transform/extensions"):
            self.assertTrue((peers_meshopt.NODE_DIR / "node_modules" / pkg).is_dir(), f"{pkg}: make node-deps")

    def test_python_packages(self):
        for pkg in ("brotli", "constriction", "zstandard"):
            importlib.import_module(pkg)


class Gltfpack(unittest.TestCase):
    def round_trip(self, codec, bits):
        frames, faces = animation()
        stream = peers_meshopt.encoders()[codec](frames, faces, bits)
        decoded, _faces, info = peers_meshopt.decoders()[codec](stream)
        peers_meshopt.check_keys(info, FRAMES)
        self.assertEqual(decoded.shape[0], FRAMES)
        self.assertLess(decoded.shape[1], frames.shape[1], "the doubled vertex should be welded")
        index = peers_meshopt.match(frames, decoded)
        error = np.abs(decoded[:, index] - frames).max()
        # One grid for positions and deltas: frame 0's box padded by the largest delta, `bits` bits;
        # base and delta each round by at most half a step.
        deltas = np.abs(frames - frames[0]).max()
        extent = float((frames[0].max(axis=0) - frames[0].min(axis=0)).max()) + 2 * deltas
        self.assertLess(error, 1.01 * extent / ((1 << bits) - 1), f"{codec}: error {error}")
        return stream

    def test_gltfpack(self):
        raw = self.round_trip("gltfpack", 12)
        self.assertEqual(raw[:4], b"glTF")
        self.assertIn(b"EXT_meshopt_compression", raw)
        self.assertIn(b"KHR_mesh_quantization", raw)

    def test_gltfpack_brotli(self):
        raw = peers_meshopt.encoders()["gltfpack"](*animation(), 14)
        self.assertLess(len(self.round_trip("gltfpack-br", 14)), len(raw))

    def test_driver_matches_gltfpack_through_files(self):
        frames, faces = animation()
        with tempfile.TemporaryDirectory() as tmp:
            src, stream, recon = Path(tmp) / "a.pc2", Path(tmp) / "s.glb", Path(tmp) / "r.pc2"
            peers.write_recon(src, frames, faces)
            me = [sys.executable, str(HERE / "peers.py")]
            subprocess.run(me + ["encode", "gltfpack", "vp 12", src, stream], check=True)
            subprocess.run(me + ["decode", "gltfpack", stream, recon], check=True)
            used = peers.match_gltfpack(src, recon)
            back = peers.read_pc2(recon)
            self.assertEqual(back.shape, frames.shape)
            self.assertEqual(used, frames.shape[1] - 1)
            np.testing.assert_array_equal(peers.read_faces(recon.with_suffix(".obj")), faces)
            self.assertLess(np.abs(back - frames).max(), 2 * cube_step(frames, 12) + 1e-3)


class Meshopt(unittest.TestCase):
    def test_both_layouts(self):
        frames, faces = animation()
        for codec in ("meshopt-fm", "meshopt-vm"):
            for bits in (10, 16):
                stream = peers_meshopt.encoders()[codec](frames, faces, bits)
                decoded, back, _ = peers_meshopt.decoders()[codec](stream)
                # The index codec may rotate a triangle's corners (same winding).
                np.testing.assert_array_equal(rotated_first_lowest(back), rotated_first_lowest(faces))
                self.assertEqual(decoded.shape, frames.shape)
                error = np.abs(decoded - frames).max()
                self.assertLessEqual(error, 0.5 * cube_step(frames, bits) * 1.001 + 1e-7, f"{codec} {bits}")


class DynapackAc(unittest.TestCase):
    def test_same_reconstruction_as_zstd_dynapack(self):
        frames, faces = animation()
        for bits in (8, 12, 16):
            stream = peers_dynapack_ac.encode(frames, faces, bits)
            decoded, back = peers_dynapack_ac.decode(stream)
            reference, _ = peers.dynapack_decode(peers.dynapack_encode(frames, faces, bits))
            np.testing.assert_array_equal(back, faces)
            np.testing.assert_array_equal(decoded, reference)
            self.assertLessEqual(np.abs(decoded - frames).max(), 0.5 * cube_step(frames, bits) * 1.001 + 1e-7)

    def test_escapes(self):
        values = np.array([0, 1, -1, 15, -15, 16, -16, 1000, -70000, 1 << 24], np.int64)
        symbols, lengths, mantissas = peers_dynapack_ac.to_symbols(values)
        packed = peers_dynapack_ac.pack_bits(lengths - 1, mantissas)
        back = peers_dynapack_ac.unpack_bits(packed, lengths - 1)
        np.testing.assert_array_equal(peers_dynapack_ac.from_symbols(symbols, back), values)


if __name__ == "__main__":
    unittest.main(verbosity=1)
