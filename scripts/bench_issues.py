#!/usr/bin/env python3
"""The derived tables of the rate-control and new-codec issues (15, 16) from bench CSVs.

Usage: bench_issues.py CSV... [--speed SEQUENCE] > issues.md

On the six OBJ sequences of ../shared/media (those present in the CSVs), default encoder rows only:
  1. bpvf / RMSE per --quality of jpeg, mpeg4 and tdct (issue 15's closing table);
  2. MPEG-4's and JPEG's RMSE over tdct's at 2.2 / 4 / 8 bpvf (issue 15: within 2x and 4x);
  3. RMSE of mpeg4, hevc, av1 at 2.2 / 4 / 8 bpvf and how much lower the better of hevc/av1 is than
     mpeg4 (issue 16: at least 35 %);
  4. all-intra bits (hevc-intra, av1-intra) against jpeg at equal RMSE (issue 16: 30 % fewer);
  5. whether hevc's and av1's RMSE keeps falling with quality up to 16 bpvf, and its slope (a uniform
     quantiser halves the error per 3 bpvf);
  6. encode frames per CPU-second of every codec on SEQUENCE (default pdance).
Rates and errors are read off each codec's frontier by log-log interpolation as scripts/rd_table.py
does (its functions), never extrapolated ("—").
"""
import sys
from collections import defaultdict

from rd_table import PAPER_RATES, at_rate, bits_at_error, e4, frontier, lower, read, take_option

OBJ = ("chickenCrossing", "horse-collapse", "horse-gallop", "pcow", "pdance", "walking_cat")
INTRA_TARGETS = (4e-4, 2e-4)


def better(*values):
    """The lowest of the measured `values` (None where none was)."""
    return min((v for v in values if v is not None), default=None)


def ratio(a, b):
    return "—" if a is None or b is None else f"{a / b:.2f}"


def quality(r):
    words = r["setting"].split()
    return int(float(words[1])) if len(words) == 2 and words[0] == "quality" else None


def tables(seqs, speed_rows):
    fr = {s: {c: frontier([(r["bpvf"], r["rmse"]) for r in rows if r["rmse"] > 0])
              for c, rows in codecs.items()} for s, codecs in seqs.items()}
    out = ["#### bpvf / RMSE ×1e-4 per `--quality`", "",
           "| sequence | quality | jpeg | mpeg4 | tdct |", "|---|---|---|---|---|"]
    for s, codecs in seqs.items():
        cells = defaultdict(dict)
        for c in ("jpeg", "mpeg4", "tdct"):
            for r in codecs.get(c, []):
                cells[quality(r)][c] = f"{r['bpvf']:.3g} / {e4(r['rmse'])}"
        for q in sorted(k for k in cells if k is not None):
            out.append(f"| {s} | {q} | " + " | ".join(cells[q].get(c, "—") for c in ("jpeg", "mpeg4", "tdct")) + " |")
    out += ["", "#### RMSE over tdct's at equal rate (mpeg4 / tdct, jpeg / tdct)", "",
            "The last column is at tdct's highest measured rate, where its points stop short of 8 bpvf.", "",
            "| sequence | " + " | ".join(f"at {b:g} bpvf" for b in PAPER_RATES) + " | at tdct's top rate |",
            "|---|---|---|---|---|"]
    for s, f in fr.items():
        def at(c, b):
            return at_rate(f.get(c, []), b)
        rates = PAPER_RATES + ((f["tdct"][-1][0],) if f.get("tdct") else ())
        out.append(f"| {s} | " + " | ".join(
            f"{ratio(at('mpeg4', b), at('tdct', b))}, {ratio(at('jpeg', b), at('tdct', b))}" for b in rates)
            + (f" ({rates[-1]:.3g} bpvf)" if len(rates) > 3 else " | —") + " |")
    out += ["", "#### mpeg4, hevc and av1 at equal rate: RMSE ×1e-4, and the better of hevc/av1 against mpeg4", "",
            "| sequence | " + " | ".join(f"{b:g} bpvf: mpeg4 / hevc / av1 | lower" for b in PAPER_RATES) + " |",
            "|---|" + "---|---|" * len(PAPER_RATES)]
    for s, f in fr.items():
        cells = []
        for b in PAPER_RATES:
            m, h, a = (at_rate(f.get(c, []), b) for c in ("mpeg4", "hevc", "av1"))
            cells.append(f"{e4(m)} / {e4(h)} / {e4(a)} | {lower(better(h, a), m)}")
        out.append(f"| {s} | " + " | ".join(cells) + " |")
    out += ["", "#### All-intra bits at equal RMSE: bpvf of jpeg / hevc-intra / av1-intra, and the better's saving", "",
            "| sequence | " + " | ".join(f"RMSE {t:.0e}: jpeg / hevc-intra / av1-intra | fewer bits" for t in INTRA_TARGETS)
            + " |", "|---|" + "---|---|" * len(INTRA_TARGETS)]
    for s, f in fr.items():
        cells = []
        for t in INTRA_TARGETS:
            j, h, a = (bits_at_error(f.get(c, []), t) for c in ("jpeg", "hevc-intra", "av1-intra"))
            cells.append(" / ".join("—" if v is None else f"{v:.3g}" for v in (j, h, a))
                         + f" | {lower(better(h, a), j)}")
        out.append(f"| {s} | " + " | ".join(cells) + " |")
    out += ["", "#### hevc and av1 up to 16 bpvf: points by quality, and the error's fall per 3 bpvf", "",
            "Falls: RMSE lower at every higher quality. Per 3 bpvf: the RMSE's factor of decrease per 3 bpvf "
            "from one quality to the next, for the steps that start at 4–16 bpvf (a uniform quantiser: "
            "about 2).", "",
            "| sequence | codec | quality: bpvf / RMSE ×1e-4 | falls | per 3 bpvf, quality → quality |",
            "|---|---|---|---|---|"]
    for s, codecs in seqs.items():
        for c in ("hevc", "av1"):
            pts = sorted((quality(r), r["bpvf"], r["rmse"]) for r in codecs.get(c, []) if quality(r) is not None)
            if not pts:
                continue
            falls = all(e1 < e0 for (_, _, e0), (_, _, e1) in zip(pts, pts[1:]))
            out.append(f"| {s} | {c} | " + ", ".join(f"{q}: {b:.3g} / {e4(e)}" for q, b, e in pts)
                       + f" | {'yes' if falls else 'no'} | {slope(pts)} |")
    return out + [""] + speed(speed_rows)


def slope(pts):
    """The RMSE's factor of decrease per 3 bpvf between successive qualities, for each step that
    starts at 4-16 bpvf (a uniform quantiser halves the error per bit a coordinate, 3 bpvf)."""
    steps = [f"{q0}→{q1} {(e0 / e1) ** (3 / (b1 - b0)):.2f}×" for (q0, b0, e0), (q1, b1, e1) in zip(pts, pts[1:])
             if 4 <= b0 < 16 and b1 > b0 and e1 > 0]
    return ", ".join(steps) or "—"


def speed(rows):
    if not rows:
        return []
    name, frames = rows[0]["sequence"], float(rows[0]["frames"])
    out = [f"#### Encode frames per CPU-second on {name} (V = {rows[0]['vertices']}, F = {rows[0]['frames']})", "",
           "Whole process (GNU time, user + system) per encoding, from the CSV's encode_cpu_s.", "",
           "| codec | at quality 50 | lowest – highest over its qualities |", "|---|---|---|"]
    by = defaultdict(list)
    for r in rows:
        if r.get("encode_cpu_s") and float(r["encode_cpu_s"]) > 0:
            by[r["codec"]].append((quality(r), frames / float(r["encode_cpu_s"])))
    for c, v in by.items():
        q50 = next((f"{s:.1f}" for q, s in v if q == 50), "—")
        out.append(f"| {c} | {q50} | {min(s for _, s in v):.1f} – {max(s for _, s in v):.1f} |")
    return out + [""]


def main():
    args = sys.argv[1:]
    name = take_option(args, "--speed", "pdance")
    if not args:
        sys.exit(__doc__)
    rows = [r for r in read(args) if "+" not in r["codec"]]
    seqs = {s: defaultdict(list) for s in OBJ if any(r["sequence"] == s for r in rows)}
    for r in rows:
        if r["sequence"] in seqs:
            seqs[r["sequence"]][r["codec"]].append(r)
    print("\n".join(tables(seqs, [r for r in rows if r["sequence"] == name])))


if __name__ == "__main__":
    main()
