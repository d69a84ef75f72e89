#!/usr/bin/env python3
"""Lattice-density tables from scripts/sweep.sh rows made with LATTICES (codec column CODEC@WxH,
plain CODEC for the automatic lattice, either with an optional +VARIANT).

Usage: lattice_table.py CSV... > tables.md

Per sequence and image codec (jpeg, mpeg4, hevc): for each lattice, the RMSE (x 1e-4 of the bbox
diagonal) at the papers' 2.2 / 4 / 8 bpvf on that lattice's frontier (log-log, as rd_table.py; "—"
outside the measured range) and as a ratio to tdct's RMSE at the same rate; then the same on the
lower convex hull (in log bpvf, log RMSE) of every lattice's points together, naming the lattices
whose points make the hull. Last column: the bits a lattice spends at the reference lattice's
errors, as a ratio to the reference's bits (geometric mean over the reference's points that the
lattice's frontier reaches, log-log interpolated), so < 1 means cheaper at equal error. The
reference is the automatic lattice's rows (plain CODEC) when there are any, else the fixed lattice
the automatic rule before issue 15's measurement picked (28 pixels per vertex, at most 256x256 unless
that leaves fewer than 7.5, in multiples of 16; marked "ref").
Only standard-library Python.
"""
import math
import os
import sys
from collections import defaultdict

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from rd_table import PAPER_RATES, at_rate, bits_at_error, e4, frontier, read  # noqa: E402

IMAGE_CODECS = ("jpeg", "mpeg4", "hevc")


def series(codec):
    """(image codec, lattice) of a row's codec label; lattice "auto" when none is named."""
    base = codec.partition("+")[0]
    # hevc@12@128x128: the depth stays with the codec, the last WxH part is the lattice
    parts = base.split("@")
    if len(parts) > 1 and "x" in parts[-1]:
        return "@".join(parts[:-1]), parts[-1]
    return base, "auto"


def reference_lattice(vertices):
    """The lattice `--lattice auto` started from before issue 15's measurement (see the docstring)."""
    side = max(min(math.sqrt(vertices * 28.0), 256.0), math.sqrt(vertices * 7.5))
    side = max(int(math.ceil(side / 16.0) * 16), 32)
    return f"{side}x{side}"


def lower_hull(points):
    """Lower convex hull of (bpvf, rmse) points in log-log space, left to right (Andrew's chain),
    keeping only its falling part (a point past the minimum error adds rate for no gain)."""
    pts = sorted({(math.log(b), math.log(e), b, e) for b, e in points if b > 0 and e > 0})
    hull = []
    for p in pts:
        while len(hull) >= 2:
            (x0, y0, *_), (x1, y1, *_) = hull[-2], hull[-1]
            if (x1 - x0) * (p[1] - y0) - (y1 - y0) * (p[0] - x0) <= 0:
                hull.pop()
            else:
                break
        hull.append(p)
    out, best = [], math.inf
    for _, _, b, e in hull:
        if e < best:
            out.append((b, e))
            best = e
    return out


def ratio(value, reference):
    return "—" if value is None or reference is None else f"{value / reference:.2f}×"


def bits_ratio(front, auto_front):
    """Geometric mean of this frontier's rate / the automatic lattice's rate at the automatic
    lattice's points' errors."""
    logs = []
    for b, e in auto_front:
        mine = bits_at_error(front, e)
        if mine is not None:
            logs.append(math.log(mine / b))
    if not logs:
        return "—"
    return f"{math.exp(sum(logs) / len(logs)):.2f} ({len(logs)})"


def section(name, rows):
    tdct = frontier([(r["bpvf"], r["rmse"]) for r in rows if r["codec"].partition("+")[0] == "tdct"])
    tdct_at = [at_rate(tdct, rate) for rate in PAPER_RATES]
    by_series = defaultdict(list)
    for r in rows:
        codec, lattice = series(r["codec"])
        if codec.split("@")[0] in IMAGE_CODECS:
            by_series[(codec, lattice)].append((r["bpvf"], r["rmse"]))
    out = [f"### {name}", ""]
    if any(tdct_at):
        out.append("tdct RMSE ×1e-4 at 2.2 / 4 / 8 bpvf: " + " / ".join(e4(v) for v in tdct_at))
        out.append("")
    out.append("| codec | lattice | RMSE ×1e-4 at 2.2 / 4 / 8 | / tdct at 2.2 / 4 / 8 "
               "| bits at ref's error / ref's (points) |")
    out.append("|---|---|---|---|---|")
    for codec in sorted({c for c, _ in by_series}):
        lattices = sorted((lat for c, lat in by_series if c == codec),
                          key=lambda lat: (lat == "auto", int(lat.split("x")[0]) if "x" in lat else 0))
        ref = "auto" if (codec, "auto") in by_series else reference_lattice(int(rows[0]["vertices"]))
        auto = frontier(by_series.get((codec, ref), []))
        for lattice in lattices:
            front = frontier(by_series[(codec, lattice)])
            at = [at_rate(front, rate) for rate in PAPER_RATES]
            name = lattice + (" (ref)" if lattice == ref != "auto" else "")
            out.append(f"| {codec} | {name} | {' / '.join(e4(v) for v in at)} | "
                       f"{' / '.join(ratio(v, t) for v, t in zip(at, tdct_at))} | "
                       f"{bits_ratio(front, auto) if auto and lattice != ref else '—'} |")
        everything = [p for (c, _), pts in by_series.items() if c == codec for p in pts]
        hull = lower_hull(everything)
        at = [at_rate(hull, rate) for rate in PAPER_RATES]
        makers = sorted({lat for (c, lat), pts in by_series.items() if c == codec
                         for p in pts if p in hull})
        out.append(f"| {codec} | hull ({', '.join(makers)}) | {' / '.join(e4(v) for v in at)} | "
                   f"{' / '.join(ratio(v, t) for v, t in zip(at, tdct_at))} | — |")
    out.append("")
    return "\n".join(out)


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    rows = read(sys.argv[1:])
    by_seq = defaultdict(list)
    for r in rows:
        by_seq[r["sequence"]].append(r)
    print("\n".join(section(name, by_seq[name]) for name in sorted(by_seq)))


if __name__ == "__main__":
    main()
