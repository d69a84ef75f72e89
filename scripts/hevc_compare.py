#!/usr/bin/env python3
"""Issue 16's comparisons from scripts/sweep.sh rows (codec columns mpeg4, hevc, av1, jpeg, hevc-intra,
av1-intra; the av1 columns only when the CSVs have av1 rows):

- per sequence, the surface RMSE (x 1e-4 of the bbox diagonal) of mpeg4, hevc (and av1) at 2.2, 4
  and 8 bpvf and how much lower hevc's (and av1's) is than mpeg4's;
- per sequence, the bpvf jpeg and hevc-intra (and av1-intra; all-intra, `--gop 1`) need at RMSE 4e-4
  and 2e-4 and how much less the all-intra modes need;
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
from rd_table import at_rate, bits_at_error, frontier, lower, read, take_option  # noqa: E402

RATES = (2.2, 4.0, 8.0)
ERRORS = (4e-4, 2e-4)


def fmt(value, scale=1.0):
    return "—" if value is None else f"{value * scale:.3g}"


def main():
    args = sys.argv[1:]
    speed = take_option(args, "--speed", "pdance")
    rows = read(args)
    fronts = defaultdict(dict)
    points = defaultdict(lambda: defaultdict(list))
    for r in rows:
        points[r["sequence"]][r["codec"]].append((r["bpvf"], r["rmse"]))
    for seq, codecs in points.items():
        for codec, pts in codecs.items():
            fronts[seq][codec] = frontier(pts)
    video = [c for c in ("hevc", "av1") if any(c in f for f in fronts.values())]
    header = " | ".join(video + [f"{c} lower by" for c in video])
    print(f"| sequence | bpvf | mpeg4 RMSE ×1e-4 | {header} |")
    print("|---|---|---|" + "---|" * (2 * len(video)))
    for seq in sorted(fronts):
        f = fronts[seq]
        for rate in RATES:
            m = at_rate(f.get("mpeg4", []), rate)
            ours = [at_rate(f.get(c, []), rate) for c in video]
            cells = [fmt(o, 1e4) for o in ours] + [lower(o, m) for o in ours]
            print(f"| {seq} | {rate:g} | {fmt(m, 1e4)} | {' | '.join(cells)} |")
    print()
    intra = [f"{c}-intra" for c in video]
    header = " bpvf | ".join(intra) + " bpvf | " + " | ".join(f"{c} lower by" for c in intra)
    print(f"| sequence | RMSE | jpeg bpvf | {header} |")
    print("|---|---|---|" + "---|" * (2 * len(intra)))
    for seq in sorted(fronts):
        f = fronts[seq]
        for error in ERRORS:
            j = bits_at_error(f.get("jpeg", []), error)
            ours = [bits_at_error(f.get(c, []), error) for c in intra]
            cells = [fmt(o) for o in ours] + [lower(o, j) for o in ours]
            print(f"| {seq} | {error:g} | {fmt(j)} | {' | '.join(cells)} |")
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
