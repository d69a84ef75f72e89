#!/usr/bin/env python3
"""Markdown tables for the README from bench CSVs (scripts/sweep.sh and scripts/peers.py rows).

Usage: rd_table.py CSV... [--speed SEQUENCE] > table.md

Per sequence: for each codec, the RMSE (x 1e-4 of the bbox diagonal) at the MCGV paper's rates 2.2,
4 and 8 bpvf, read off the codec's rate-distortion frontier (its points no other of its points beats
at a lower or equal rate) by linear interpolation in log(bpvf)-log(RMSE); "—" outside the measured
range, never extrapolated. Then one line naming the rates at which mcgv-video (the better of its JPEG
and MPEG-4 frontiers) has the lowest RMSE of all codecs measured there, and the peers that beat it
elsewhere with the largest factor (rates where no peer was measured are left out).
mcgv-video's encoder variants (scripts/sweep.sh VARIANTS: codec column CODEC+VARIANT, e.g.
mpeg4+skinning) are series of their own, all counted as mcgv-video. When a sequence has any, two more
things follow: which mcgv-video series has the lowest RMSE at equal rate, over which rates (on the
same log grid), and a table of bpvf / RMSE per image-codec setting with one column per variant
(default = affine predictor, k-means segmentation), so that variants are compared at the same settings.
Also per sequence, the default encoder's bpvf / RMSE at each `--quality`, one column per codec.
Last, speed and peak memory for the largest sequence (V x F),
or for --speed SEQUENCE: whole-process figures as the CSV records them.
Only standard-library Python, so it also runs outside the virtualenv.
"""
import csv
import math
import sys
from collections import defaultdict

PAPER_RATES = (2.2, 4.0, 8.0)
# mcgv-video's codecs (hevc-intra, av1-intra: `--gop 1`; @12: `--bit-depth 12`); a variant is
# CODEC+VARIANT
OURS = ("jpeg", "mpeg4", "tdct", "hevc", "hevc-intra", "hevc@12", "hevc-intra@12",
        "av1", "av1-intra", "av1@12", "av1-intra@12")
VARIANTS = ("", "skinning", "decimation", "skinning+decimation")   # column order of the variant table
TARGETS = (2e-4, 5e-5)   # RMSE targets of the equal-error table
GRID = 200  # rates per sequence at which codecs are compared for the closing line


def die(message):
    sys.exit(f"rd_table.py: error: {message}")


def read(paths):
    rows = []
    for path in paths:
        with open(path, newline="") as f:
            reader = csv.DictReader(f)
            for need in ("sequence", "codec", "setting", "bpvf", "rmse"):
                if need not in (reader.fieldnames or []):
                    die(f"{path}: no column {need}")
            for r in reader:
                r["bpvf"], r["rmse"] = float(r["bpvf"]), float(r["rmse"])
                r["kg"] = float(r["kg_error"]) if r.get("kg_error") else None
                rows.append(r)
    if not rows:
        die("no rows")
    return rows


def frontier(points):
    """Points (bpvf, rmse) sorted by rate, keeping only those with a lower RMSE than every cheaper one."""
    best, out = math.inf, []
    for b, e in sorted(points):
        if e < best:
            out.append((b, e))
            best = e
    return out


def at_rate(front, rate):
    """RMSE at `rate` by log-log interpolation on the frontier; None outside its range."""
    if not front or rate < front[0][0] or rate > front[-1][0]:
        return None
    for (b0, e0), (b1, e1) in zip(front, front[1:]):
        if b0 <= rate <= b1:
            if e0 <= 0 or e1 <= 0:
                return None
            t = (math.log(rate) - math.log(b0)) / (math.log(b1) - math.log(b0))
            return math.exp(math.log(e0) + t * (math.log(e1) - math.log(e0)))
    return front[0][1] if rate == front[0][0] else None


def kg_at_rate(points, rate):
    """KG error at `rate`, interpolated like at_rate on the RMSE frontier's points that carry one;
    None where the codec's vertices do not correspond (no KG) or outside the measured range."""
    front = frontier([(b, e) for b, e, k in points if e > 0])
    kg = {(b, e): k for b, e, k in points}
    for (b0, e0), (b1, e1) in zip(front, front[1:]):
        if b0 <= rate <= b1:
            k0, k1 = kg[(b0, e0)], kg[(b1, e1)]
            if not k0 or not k1:
                return None
            t = (math.log(rate) - math.log(b0)) / (math.log(b1) - math.log(b0))
            return math.exp(math.log(k0) + t * (math.log(k1) - math.log(k0)))
    return kg.get(front[0]) if front and rate == front[0][0] else None


def bits_at_error(front, target):
    """The rate at which a frontier reaches RMSE `target`, log-log interpolated; None outside."""
    for (b0, e0), (b1, e1) in zip(front, front[1:]):
        if e1 <= target <= e0:
            t = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(b0) + t * (math.log(b1) - math.log(b0)))
    return None


def e4(value):
    return "—" if value is None else f"{value * 1e4:.3g}"


def lower(ours, theirs):
    """How much lower `ours` is than `theirs`, in per cent ("—" without both)."""
    if ours is None or theirs is None:
        return "—"
    return f"{100.0 * (1.0 - ours / theirs):.0f} %"


def take_option(args, name, default):
    """Removes `name VALUE` from the argument list `args` and returns VALUE (`default` without)."""
    if name not in args:
        return default
    k = args.index(name)
    value = args[k + 1]
    del args[k:k + 2]
    return value


def split(codec):
    """(image codec, variant) of an mcgv-video series, variant "" for the default encoder."""
    base, _, variant = codec.partition("+")
    return base, variant


def ours(codec):
    return split(codec)[0] in OURS


def order(codec):
    """Sort key: mcgv-video's series first, by image codec then variant, then the peers."""
    if not ours(codec):
        return (1, 0, 0, codec)
    base, variant = split(codec)
    v = VARIANTS.index(variant) if variant in VARIANTS else len(VARIANTS)
    return (0, OURS.index(base), v, variant)


def label(codec):
    return f"mcgv-video {codec}" if ours(codec) else codec


def cell(points, front, rate):
    """RMSE x 1e-4 (KG error) at `rate`; the KG part left out where the codec has none."""
    e = at_rate(front, rate)
    if e is None:
        return "—"
    kg = kg_at_rate(points, rate)
    return e4(e) + ("" if kg is None else f" ({kg:.3g})")


def sequence_section(name, rows):
    by_codec = defaultdict(list)
    for r in rows:
        by_codec[r["codec"]].append((r["bpvf"], r["rmse"], r["kg"]))
    frames, vertices = rows[0].get("frames", "?"), rows[0].get("vertices", "?")
    out = [f"#### {name} (V = {vertices}, F = {frames})", "",
           "RMSE ×1e-4 of the bbox diagonal (KG error in parentheses where vertices correspond):", "",
           "| codec | points | bpvf measured | at 2.2 bpvf | at 4 | at 8 | lowest RMSE ×1e-4 (KG) at bpvf |",
           "|---|---|---|---|---|---|---|"]
    fronts = {}
    for codec in sorted(by_codec, key=order):
        pts = by_codec[codec]
        lo, hi = min(p[0] for p in pts), max(p[0] for p in pts)
        if all(p[1] == 0 for p in pts):
            out.append(f"| {label(codec)} | {len(pts)} | {lo:.3g} | lossless | lossless | lossless | "
                       f"0 (0) at {lo:.3g} |")
            continue
        front = frontier([p[:2] for p in pts if p[1] > 0])
        fronts[codec] = front
        cells = " | ".join(cell(pts, front, r) for r in PAPER_RATES)
        best_b, best_e, best_k = min(pts, key=lambda p: (p[1], p[0]))
        kg = "" if best_k is None else f" ({best_k:.3g})"
        out.append(f"| {label(codec)} | {len(pts)} | {lo:.3g}–{hi:.3g} | {cells} | "
                   f"{e4(best_e)}{kg} at {best_b:.3g} |")
    lossless = min((b for c, pts in by_codec.items() for b, e, _k in pts if e == 0), default=None)
    out += ["", closing_line(fronts, lossless), ""] + quality_table(rows)
    if any(ours(c) and split(c)[1] for c in by_codec):
        out += [best_series_line(fronts), ""] + variant_table(rows) + [""]
    return out


def log_grid(lo, hi):
    return [math.exp(math.log(lo) + (math.log(hi) - math.log(lo)) * i / GRID) for i in range(GRID + 1)]


def spans_of(rates, lo, hi):
    """Contiguous runs of grid rates, as (first, last) pairs."""
    step = math.exp((math.log(hi) - math.log(lo)) / GRID) * 1.0001
    spans, start, prev = [], rates[0], rates[0]
    for r in rates[1:]:
        if r > prev * step:
            spans.append((start, prev))
            start = r
        prev = r
    spans.append((start, prev))
    return spans


def best_series_line(fronts):
    """Which mcgv-video series (image codec and variant) has the lowest RMSE at each rate where at
    least two of them are measured, as spans of rates."""
    mine = {c: f for c, f in fronts.items() if ours(c)}
    lo = min(f[0][0] for f in mine.values())
    hi = max(f[-1][0] for f in mine.values())
    winners = defaultdict(list)
    for rate in log_grid(lo, hi):
        there = {c: at_rate(f, rate) for c, f in mine.items()}
        there = {c: v for c, v in there.items() if v is not None}
        if len(there) >= 2:
            winners[min(there, key=lambda c: (there[c], order(c)))].append(rate)
    if not winners:
        return "Best mcgv-video series: no rate where two of them were measured."
    parts = []
    for codec in sorted(winners, key=lambda c: winners[c][0]):
        spans = spans_of(winners[codec], lo, hi)
        parts.append(f"{codec} at " + ", ".join(f"{a:.3g}–{b:.3g}" for a, b in spans))
    return ("Best mcgv-video series (lowest RMSE at equal rate, where two or more are measured): "
            + "; ".join(parts) + " bpvf.")


def quality_table(rows):
    """bpvf / RMSE x 1e-4 of the default encoder per `--quality`, one column per codec: one quality
    should mean about the same error whichever codec (the one error law)."""
    cells = defaultdict(dict)
    for r in rows:
        words = r["setting"].split()
        if r["codec"] in OURS and len(words) == 2 and words[0] == "quality":
            cells[int(float(words[1]))][r["codec"]] = r
    if not cells:
        return []
    cols = [c for c in OURS if any(c in v for v in cells.values())]
    out = ["bpvf / RMSE ×1e-4 per `--quality` (default encoder):", "",
           "| quality | " + " | ".join(cols) + " |", "|---|" + "---|" * len(cols)]
    for q in sorted(cells):
        row = cells[q]
        out.append(f"| {q} | " + " | ".join(
            "—" if c not in row else f"{row[c]['bpvf']:.3g} / {row[c]['rmse'] * 1e4:.3g}" for c in cols) + " |")
    return out + [""]


def variant_table(rows):
    """bpvf / RMSE x 1e-4 of each mcgv-video setting, one column per encoder variant."""
    cells, variants = defaultdict(dict), set()
    for r in rows:
        if ours(r["codec"]):
            base, variant = split(r["codec"])
            cells[(base, r["setting"])][variant] = r
            variants.add(variant)
    cols = sorted(variants, key=lambda v: (VARIANTS.index(v) if v in VARIANTS else len(VARIANTS), v))
    # Only the settings measured with a variant: the default sweep has more rates than the variants'.
    keys = [k for k in cells if any(v for v in cells[k])]

    def setting_key(k):
        number = k[1].split()[-1]
        try:
            number = float(number)
        except ValueError:
            number = 0.0
        return (OURS.index(k[0]) if k[0] in OURS else len(OURS), k[1].split()[0], number)
    names = {"": "default (affine, k-means)"}
    out = ["| codec, setting | " + " | ".join(names.get(v, v) for v in cols) + " |",
           "|---|" + "---|" * len(cols), ]
    for k in sorted(keys, key=setting_key):
        row = []
        for v in cols:
            r = cells[k].get(v)
            kg = "" if r is None or r["kg"] is None else f" / {r['kg']:.3g}"
            row.append("—" if r is None else f"{r['bpvf']:.3g} / {r['rmse'] * 1e4:.3g}{kg}")
        out.append(f"| {k[0]} {k[1]} | " + " | ".join(row) + " |")
    return ["bpvf / RMSE ×1e-4 / KG error per variant at the same settings:", ""] + out


def closing_line(fronts, lossless):
    mine_fronts = {c: f for c, f in fronts.items() if ours(c)}
    peers = {c: f for c, f in fronts.items() if not ours(c)}
    if not mine_fronts:
        return "No mcgv-video rows for this sequence."
    lo = min(f[0][0] for f in mine_fronts.values())
    hi = max(f[-1][0] for f in mine_fronts.values())
    wins, losses = [], defaultdict(lambda: (0.0, None))   # peer -> (largest factor, at rate)
    for rate in log_grid(lo, hi):
        mine = [v for v in (at_rate(f, rate) for f in mine_fronts.values()) if v is not None]
        if not mine:
            continue
        mine = min(mine)
        theirs = {p: at_rate(f, rate) for p, f in peers.items()}
        theirs = {p: v for p, v in theirs.items() if v is not None}
        if not theirs:
            continue    # no peer measured at this rate: no contest, no claim
        if all(mine <= v for v in theirs.values()):
            wins.append(rate)
        for p, v in theirs.items():
            if v < mine and mine / v > losses[p][0]:
                losses[p] = (mine / v, rate)
    text = []
    if wins:
        text.append("mcgv-video has the lowest RMSE of all codecs at "
                    + ", ".join(f"{a:.3g}–{b:.3g}" for a, b in spans_of(wins, lo, hi)) + " bpvf")
    else:
        text.append(f"mcgv-video ({lo:.3g}–{hi:.3g} bpvf measured) never has the lowest RMSE where a "
                    "peer is measured at the same rate")
    beaten = [f"{p} by up to {f:.3g}× lower RMSE (at {r:.3g} bpvf)" for p, (f, r) in
              sorted(losses.items(), key=lambda kv: -kv[1][0])]
    if beaten:
        text.append("beaten by " + "; ".join(beaten))
    if lossless is not None and hi >= lossless:
        text.append(f"above {lossless:.3g} bpvf zstd is lossless")
    return "; ".join(text) + "."


def speed_section(name, rows):
    out = [f"#### Speed and peak memory: {name} (V = {rows[0].get('vertices')}, "
           f"F = {rows[0].get('frames')}), whole process (GNU time)", "",
           "Frames per CPU-second (user + system, steadier than wall time on a shared machine) and per "
           "wall second:", "",
           "| codec | setting | bpvf | RMSE ×1e-4 | KG | encode frames/CPU s | decode frames/CPU s "
           "| encode frames/s | decode frames/s | encode peak MB | decode peak MB |",
           "|---|---|---|---|---|---|---|---|---|---|---|"]
    frames = float(rows[0]["frames"])
    for r in sorted(rows, key=lambda r: (order(r["codec"]), r["bpvf"])):
        def rate(key):
            s = float(r[key]) if r.get(key) else 0
            return f"{frames / s:.1f}" if s > 0 else "—"

        def mb(key):
            return f"{int(r[key]) / 1024:.0f}" if r.get(key) else "—"
        kg = "—" if r["kg"] is None else f"{r['kg']:.3g}"
        out.append(f"| {label(r['codec'])} | {r['setting']} | {r['bpvf']:.3g} | {e4(r['rmse'])} | {kg} | "
                   f"{rate('encode_cpu_s')} | {rate('decode_cpu_s')} | {rate('encode_s')} | "
                   f"{rate('decode_s')} | {mb('encode_rss_kb')} | {mb('decode_rss_kb')} |")
    return out + [""]


def equal_error(by_seq, targets=TARGETS):
    """Per sequence, the bits (bpvf) mcgv-video's best series and the strongest peer need to reach
    each target RMSE, and their ratio; then every codec's bits and KG error at those targets."""
    head = " | ".join(f"RMSE {t:.0e}: mcgv-video | strongest peer | peer / mcgv-video" for t in targets)
    out = ["#### Bits at equal error", "",
           "bpvf needed to reach an RMSE (fraction of the bbox diagonal) of " +
           " and ".join(f"{t:.0e}" for t in targets) + ", read off each codec's rate-distortion frontier "
           "(log-log interpolation between measured points, never extrapolated; — where a codec's "
           "points do not bracket the target). mcgv-video is its best series there (any image codec "
           "and encoder variant); the strongest peer is the peer needing the fewest bits. A ratio above 1 "
           "means mcgv-video needs fewer bits.", "",
           f"| sequence | {head} |", "|---|" + "---|---|---|" * len(targets)]
    detail = ["", "Every codec (bpvf, and KG error at that point where vertices correspond):", "",
              "| sequence | codec | " + " | ".join(f"bpvf at {t:.0e} (KG)" for t in targets) + " |",
              "|---|---|" + "---|" * len(targets)]
    for name in sorted(by_seq, key=str.lower):
        needs = codec_bits(by_seq[name], targets)
        cells = []
        for i in range(len(targets)):
            mine = best(needs, i, ours)
            peer = best(needs, i, lambda c: not ours(c))
            ratio = f"{peer[1] / mine[1]:.2f}" if mine and peer else "—"
            cells.append(f"{show(mine)} | {show(peer)} | {ratio}")
        out.append(f"| {name} | " + " | ".join(cells) + " |")
        for codec in sorted(needs, key=order):
            detail.append(f"| {name} | {label(codec)} | " + " | ".join(
                "—" if b is None else f"{b:.3g}" + ("" if k is None else f" ({k:.3g})") for b, k in needs[codec]) + " |")
    return out + detail + [""]


def codec_bits(rows, targets):
    """codec -> [(bpvf, KG there) or (None, None)] per target."""
    pts = defaultdict(list)
    for r in rows:
        if r["rmse"] > 0:
            pts[r["codec"]].append((r["bpvf"], r["rmse"], r["kg"]))
    needs = {}
    for codec, p in pts.items():
        front = frontier([q[:2] for q in p])
        bits = [bits_at_error(front, t) for t in targets]
        needs[codec] = [(b, None if b is None else kg_at_rate(p, b)) for b in bits]
    return needs


def best(needs, i, which):
    found = [(v[i][0], c) for c, v in needs.items() if which(c) and v[i][0] is not None]
    return None if not found else (min(found)[1], min(found)[0])


def show(pick):
    return "—" if pick is None else f"{pick[1]:.3g} ({pick[0]})"


def main():
    args = sys.argv[1:]
    speed = take_option(args, "--speed", None)
    if not args:
        sys.exit(__doc__)
    rows = read(args)
    by_seq = defaultdict(list)
    for r in rows:
        by_seq[r["sequence"]].append(r)
    lines = equal_error(by_seq)
    for name in sorted(by_seq, key=str.lower):
        lines += sequence_section(name, by_seq[name])
    if speed is None:
        sized = [(int(r.get("vertices") or 0) * int(r.get("frames") or 0), s) for s, rs in by_seq.items()
                 for r in rs[:1]]
        speed = max(sized)[1]
    if speed not in by_seq:
        die(f"--speed {speed}: no such sequence in the CSVs")
    lines += speed_section(speed, by_seq[speed])
    print("\n".join(lines))


if __name__ == "__main__":
    main()
