#!/usr/bin/env python3
"""Issue 16's comparisons from scripts/sweep.sh rows (codec columns mpeg4, hevc, jpeg, hevc-intra):

- per sequence, the surface RMSE (x 1e-4 of the bbox diagonal) of mpeg4 and hevc at 2.2, 4 and 8
  bpvf and how much lower hevc's is;
- per sequence, the bpvf jpeg and hevc-intra (all-intra, `--gop 1`) need at RMSE 4e-4 and 2e-4 and
  how much less hevc-intra needs;
- encode speed in frames per CPU-second (user + system, whole process) of every codec at
  `--quality 50` on the sequence given by --speed (default pdance).

Both read each codec's frontier with rd_table.py's log-log interpolation ("—" outside the measured
range, never extrapolated). Only standard-library Python.

Usage: hevc_compare.py CSV... [--speed SEQUENCE]
"""
import os
import sys
from collections import defaultdict

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from rd_table import at_rate, bits_at_error, frontier, read  # noqa: E402

RATES = (2.2, 4.0, 8.0)
ERRORS = (4e-4, 2e-4)


def fmt(value, scale=1.0):
    return "—" if value is None else f"{value * scale:.3g}"


def lower(ours, theirs):
    """How much lower `ours` is than `theirs`, in per cent."""
    if ours is None or theirs is None:
        return "—"
    return f"{100.0 * (1.0 - ours / theirs):.0f} %"


def main():
    args = sys.argv[1:]
    speed = "pdance"
    if "--speed" in args:
        i = args.index("--speed")
        speed = args[i + 1]
        del args[i:i + 2]
    rows = read(args)
    fronts = defaultdict(dict)
    points = defaultdict(lambda: defaultdict(list))
    for r in rows:
        points[r["sequence"]][r["codec"]].append((r["bpvf"], r["rmse"]))
    for seq, codecs in points.items():
        for codec, pts in codecs.items():
            fronts[seq][codec] = frontier(pts)
    print("| sequence | bpvf | mpeg4 RMSE ×1e-4 | hevc | hevc lower by |")
    print("|---|---|---|---|---|")
    for seq in sorted(fronts):
        f = fronts[seq]
        for rate in RATES:
            m = at_rate(f.get("mpeg4", []), rate)
            h = at_rate(f.get("hevc", []), rate)
            print(f"| {seq} | {rate:g} | {fmt(m, 1e4)} | {fmt(h, 1e4)} | {lower(h, m)} |")
    print()
    print("| sequence | RMSE | jpeg bpvf | hevc-intra bpvf | hevc-intra lower by |")
    print("|---|---|---|---|---|")
    for seq in sorted(fronts):
        f = fronts[seq]
        for error in ERRORS:
            j = bits_at_error(f.get("jpeg", []), error)
            h = bits_at_error(f.get("hevc-intra", []), error)
            print(f"| {seq} | {error:g} | {fmt(j)} | {fmt(h)} | {lower(h, j)} |")
    print()
    print(f"Encode speed on {speed}, `--quality 50`:")
    print()
    print("| codec | frames | encode CPU s | frames per CPU-second |")
    print("|---|---|---|---|")
    for r in rows:
        if r["sequence"] == speed and r["setting"] == "quality 50" and r.get("encode_cpu_s"):
            cpu, frames = float(r["encode_cpu_s"]), int(r["frames"])
            print(f"| {r['codec']} | {frames} | {cpu:.1f} | {frames / cpu:.1f} |")


if __name__ == "__main__":
    main()
