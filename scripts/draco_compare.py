#!/usr/bin/env python3
"""Compare the first-frame coder with Draco at the same quantisation.

Usage:
  cargo run --release --example first_frame_bench -- --dump DIR MESH... > ours.jsonl
  python scripts/draco_compare.py ours.jsonl DIR [--bits 12] [--bytes [--before OLD.jsonl]]

Draco (DracoPy, compression_level 10) is run on the very meshes the bench coded (DIR/NAME.mesh),
once letting it reorder vertices and faces and once with preserve_order=True. Prints a Markdown
table of bits per vertex. Draco quantises over the bounding cube (one step for all axes), the
first-frame coder over the per-axis box: at the same bits it is slightly finer on short axes.

--bytes prints bytes instead, with the ratios to Draco (ours keeping the order against Draco's
preserve_order, ours with reorder against Draco's free mode) and the vertices Draco's free mode
decodes: it merges vertices of equal position, which the first-frame coder keeps. --before adds
the bytes of an older bench run.
"""
import json
import sys
from pathlib import Path

import numpy as np
import DracoPy


def load_mesh(path):
    raw = Path(path).read_bytes()
    v, f = np.frombuffer(raw[:8], dtype="<u4")
    pos = np.frombuffer(raw[8:8 + 12 * v], dtype="<f4").reshape(-1, 3)
    tri = np.frombuffer(raw[8 + 12 * v:8 + 12 * v + 12 * f], dtype="<u4").reshape(-1, 3)
    return pos, tri


def draco_bits(pos, tri, bits, preserve_order):
    data = DracoPy.encode(pos, tri, quantization_bits=bits, compression_level=10,
                          preserve_order=preserve_order)
    return len(data) * 8


def draco_free(pos, tri, bits):
    data = DracoPy.encode(pos, tri, quantization_bits=bits, compression_level=10,
                          preserve_order=False)
    return len(data), len(DracoPy.decode(data).points)


def bytes_table(rows, dump_dir, bits, before):
    print("| mesh | V | Draco preserve_order | Draco free (V decoded) | ours keep order "
          "(before) | ours reorder (before) | keep / Draco preserve | reorder / Draco free |")
    print("|---|---|---|---|---|---|---|---|")
    for row in rows:
        pos, tri = load_mesh(Path(dump_dir) / f"{row['mesh']}.mesh")
        keep = len(DracoPy.encode(pos, tri, quantization_bits=bits, compression_level=10,
                                  preserve_order=True))
        free, decoded = draco_free(pos, tri, bits)
        k, r = row["keep_order"]["bytes"], row["reorder"]["bytes"]
        old = before.get(row["mesh"])
        was = (lambda key: f" ({old[key]['bytes']})") if old else (lambda key: "")
        print(f"| {row['mesh']} | {len(pos)} | {keep} | {free} ({decoded}) | {k}{was('keep_order')} "
              f"| {r}{was('reorder')} | {k / keep:.3f} | {r / free:.3f} |")


def main():
    args = sys.argv[1:]
    bits = 12
    as_bytes = "--bytes" in args
    if as_bytes:
        args.remove("--bytes")
    before = {}
    if "--before" in args:
        k = args.index("--before")
        for line in Path(args[k + 1]).read_text().splitlines():
            row = json.loads(line)
            before[row["mesh"]] = row
        del args[k:k + 2]
    if "--bits" in args:
        k = args.index("--bits")
        bits = int(args[k + 1])
        del args[k:k + 2]
    if len(args) != 2:
        sys.exit(__doc__)
    ours_path, dump_dir = args
    if as_bytes:
        rows = [json.loads(line) for line in Path(ours_path).read_text().splitlines()]
        bytes_table(rows, dump_dir, bits, before)
        return
    print("| mesh | V | F | ours keep order: conn / geom / order / total | ours reorder: total "
          "| Draco preserve_order | Draco |")
    print("|---|---|---|---|---|---|---|")
    for line in Path(ours_path).read_text().splitlines():
        row = json.loads(line)
        pos, tri = load_mesh(Path(dump_dir) / f"{row['mesh']}.mesh")
        v = len(pos)
        keep, reo = row["keep_order"], row["reorder"]
        d_keep = draco_bits(pos, tri, bits, True) / v
        d_free = draco_bits(pos, tri, bits, False) / v
        print(f"| {row['mesh']} | {v} | {len(tri)} | {keep['bpv_connectivity']:.2f} / "
              f"{keep['bpv_geometry']:.2f} / {keep['bpv_order']:.2f} / {keep['bpv_total']:.2f} | "
              f"{reo['bpv_total']:.2f} | {d_keep:.2f} | {d_free:.2f} |")


if __name__ == "__main__":
    main()
