#!/usr/bin/env python3
"""Reads rows of examples/error_law_sweep.rs and prints, per sequence and image codec, the lower
convex hull of (bpvf, vertex RMSE) with the setting of each hull point (pixel step as a fraction of
the diagonal, picture quantiser), then the hull's rate at the error tdct reaches at each quality
(log-log interpolation, "-" outside the hull), so that the law in src/codec/quality.rs can be read
off it. Only standard-library Python.

Usage: error_law_fit.py SWEEP.csv
"""
import csv
import math
import sys
from collections import defaultdict


def lower_hull(points):
    """Lower convex hull of (bpvf, rmse) in log-log, cheapest first (Andrew's monotone chain)."""
    pts = sorted(set(points), key=lambda p: (p[0], p[1]))
    hull = []
    for p in pts:
        while len(hull) >= 2:
            (x1, y1, _), (x2, y2, _) = hull[-2], hull[-1]
            cross = (math.log(x2) - math.log(x1)) * (math.log(p[1]) - math.log(y1)) - \
                (math.log(y2) - math.log(y1)) * (math.log(p[0]) - math.log(x1))
            if cross <= 0:
                hull.pop()
            else:
                break
        hull.append(p)
    # Keep the decreasing part: a point costing more for no less error is not on the frontier.
    out, best = [], math.inf
    for p in hull:
        if p[1] < best:
            out.append(p)
            best = p[1]
    return out


def rate_at(hull, error):
    for (b0, e0, _), (b1, e1, _) in zip(hull, hull[1:]):
        if e1 <= error <= e0:
            t = (math.log(error) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(b0) + t * (math.log(b1) - math.log(b0)))
    return None


def main():
    rows = list(csv.DictReader(open(sys.argv[1])))
    seqs = defaultdict(lambda: defaultdict(list))
    for r in rows:
        setting = r["quality"] if r["codec"] == "tdct" else f"step {r['step']} q {r['quantiser']}"
        seqs[r["sequence"]][r["codec"]].append((float(r["bpvf"]), float(r["vertex_rmse"]), setting))
    for seq, codecs in seqs.items():
        print(f"## {seq}")
        hulls = {c: lower_hull(p) for c, p in codecs.items() if c != "tdct"}
        for c, hull in hulls.items():
            print(f"{c} hull: " + "; ".join(f"{s} {b:.2f}/{e:.2e}" for b, e, s in hull))
        for b, e, q in sorted(codecs.get("tdct", []), key=lambda p: -p[1]):
            cells = []
            for c, hull in hulls.items():
                r = rate_at(hull, e)
                cells.append(f"{c} {r:.2f}" if r else f"{c} -")
            print(f"tdct q{q}: {b:.2f} bpvf / {e:.2e}; at that error " + ", ".join(cells))


if __name__ == "__main__":
    main()
