"""Shared pieces of the Python package's tests: generated animations, the command-line binary,
and PC2 files the command line reads."""

from __future__ import annotations

import os
import shutil
import struct
import subprocess
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]


def cloth(n: int = 12, frames: int = 20, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """A waving n×n cloth: positions float32 (frames, n², 3) and faces int64 (2(n-1)², 3)."""
    u, v = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n))
    u, v = u.ravel(), v.ravel()
    t = np.arange(frames)[:, None] / 30.0
    rng = np.random.default_rng(seed)
    phase = rng.uniform(0, 1)
    wave = 0.08 * np.sin(6 * u - 2 * t + phase) * v + 0.03 * np.sin(9 * v + 3.1 * t) * u
    sway = 0.2 * np.sin(0.5 * t + phase) * v * v
    positions = np.stack([u + sway + 0 * t, -v + 0 * t, wave + 0.5 * sway], axis=-1).astype(np.float32)
    faces = []
    for j in range(n - 1):
        for i in range(n - 1):
            a = j * n + i
            faces += [[a, a + 1, a + n + 1], [a, a + n + 1, a + n]]
    return positions, np.array(faces, dtype=np.int64)


def write_pc2(folder: Path, positions: np.ndarray, faces: np.ndarray, name: str = "clip") -> Path:
    """The animation as NAME.pc2 with its base NAME.obj (faces only matter: the PC2 holds every
    frame's positions, frame 0 included), as the command line reads it."""
    frames, vertices, _ = positions.shape
    base = folder / f"{name}.obj"
    with open(base, "w") as f:
        for x, y, z in positions[0]:
            f.write(f"v {np.format_float_positional(x, unique=True)} "
                    f"{np.format_float_positional(y, unique=True)} "
                    f"{np.format_float_positional(z, unique=True)}\n")
        for a, b, c in faces + 1:
            f.write(f"f {a} {b} {c}\n")
    cache = folder / f"{name}.pc2"
    with open(cache, "wb") as f:
        f.write(b"POINTCACHE2\0")
        f.write(struct.pack("<iiffi", 1, vertices, 0.0, 1.0, frames))
        f.write(np.ascontiguousarray(positions, dtype="<f4").tobytes())
    return cache


@pytest.fixture(scope="session")
def cli() -> str:
    """The mcgv-video binary: $MCGV_CLI, else the workspace's release or debug build (the
    Makefile builds it before the tests)."""
    candidates = [os.environ.get("MCGV_CLI")] + [
        str(REPO / "target" / profile / "mcgv-video") for profile in ("debug", "release")
    ]
    found = [c for c in candidates if c and os.access(c, os.X_OK)]
    if not found:
        pytest.fail("no mcgv-video binary: set MCGV_CLI or run cargo build -p mcgv-video-cli")
    # The most recently built one: it matches the library the package was built from.
    return max(found, key=lambda c: os.stat(c).st_mtime) if not os.environ.get("MCGV_CLI") else found[0]


def cli_encode(cli: str, input: Path | str, out: Path, *flags: str) -> bytes:
    subprocess.run([cli, "encode", str(input), "-o", str(out), "--quiet", *flags], check=True)
    return out.read_bytes()


def media(name: str) -> str:
    return str(REPO / "media" / name)


__all__ = ["cloth", "write_pc2", "cli_encode", "media", "shutil"]
