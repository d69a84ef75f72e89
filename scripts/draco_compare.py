#!/usr/bin/env python3
"""Compare the first-frame coder with Draco at the same quantisation.

Usage:
  cargo run --release --example first_frame_bench -- --dump DIR MESH... > ours.jsonl
  python scripts/draco_compare.py ours.jsonl DIR [--bits 12]

Draco (DracoPy, compression_level 10) is run on the very meshes the bench coded (DIR/NAME.mesh),
once letting it reorder vertices and faces and once with preserve_order=True. Prints a Markdown
table of bits per vertex. Draco quantises over the bounding cube (one step for all axes), the
first-frame coder over the per-axis box: at the same bits it is slightly finer on short axes.
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


def main():
    args = sys.argv[1:]
    bits = 12
    if "--bits" in args:
        k = args.index("--bits")
        bits = int(args[k + 1])
        del args[k:k + 2]
    if len(args) != 2:
        sys.exit(__doc__)
    ours_path, dump_dir = args
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
