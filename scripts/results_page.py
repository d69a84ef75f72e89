#!/usr/bin/env python3
"""docs/results.md, the current results page, from the bench's files (`make bench` runs it last).

Usage: results_page.py [--bench DIR] [--template FILE] [--speed SEQUENCE] CSV... > results.md

CSV...: the rate CSVs behind DIR/tables.md (scripts/sweep.sh and scripts/peers.py rows: sweep.csv,
sweep-variants.csv when the variant sweep ran, peers.csv), named as the page should print them.
DIR (default: the first CSV's folder) holds tables.md, peers.md, the plots and the temporal-segment
CSVs (segments-cost.csv, segments-memory.csv). FILE (default: results_template.md beside this
script) is the hand-written page; each {{name}} in it is replaced by what this script makes of the
files (the names are listed in BLOCKS below), then {{contents}} by the list of its "## " sections.
The rate tables use scripts/rd_table.py's functions (log-log interpolation on each codec's
frontier, never extrapolated), so they agree with DIR/tables.md. The page's links assume it lives
in docs/ and DIR is docs/bench. Only standard-library Python.
"""
import csv
import os
import re
import sys
from collections import defaultdict

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from rd_table import (OURS, PAPER_RATES, TARGETS, at_rate, best, codec_bits, e4, frontier, label,  # noqa: E402
                      order, ours, read, show, take_option)

# The default encoder's codecs, in the order of the codec tables.
CODECS = ("jpeg", "mpeg4", "tdct", "hevc", "hevc-intra", "av1", "av1-intra")
PAPER_CODECS = ("jpeg", "mpeg4", "tdct", "hevc", "av1")
LINK_DIR = "bench"   # DIR as seen from the page


def die(message):
    sys.exit(f"results_page.py: error: {message}")


def slug(heading):
    """GitHub's anchor of a Markdown heading."""
    text = re.sub(r"`", "", heading.strip().lower())
    return re.sub(r"[^\w\- ]", "", text).replace(" ", "-")


def table(head, rows):
    return ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)] + \
           ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]


def thousands(n):
    return f"{n:,}".replace(",", " ")


def signed(value):
    """`value` with its sign, a minus sign rather than a hyphen."""
    return f"{value:+.1f}".replace("-", "−")


def percent(ratio):
    """A ratio as a signed change in per cent: 0.983 → −1.7 %."""
    return f"{signed(100 * (ratio - 1))} %"


def span(values, fmt):
    lo, hi = min(values), max(values)
    return fmt(lo) if fmt(lo) == fmt(hi) else f"{fmt(lo)}–{fmt(hi)}"


def by_sequence(rows):
    seqs = defaultdict(list)
    for r in rows:
        seqs[r["sequence"]].append(r)
    return dict(sorted(seqs.items(), key=lambda kv: kv[0].lower()))


def front_of(rows, codec):
    return frontier([(r["bpvf"], r["rmse"]) for r in rows if r["codec"] == codec and r["rmse"] > 0])


def provenance(bench):
    """The paragraph of tables.md that names the run (a line starting "This copy"), if any."""
    path = os.path.join(bench, "tables.md")
    if not os.path.exists(path):
        return ""
    lines, keep = [], False
    for line in open(path, encoding="utf-8"):
        if line.startswith("This copy"):
            keep = True
        if keep:
            if not line.strip() or line.startswith("#"):
                break
            lines.append(line.rstrip("\n"))
    text = "\n".join(lines).replace("](../", "](")
    return re.sub(r"^This copy:\s*", "**The files of `docs/bench/`**: ", text)


def files(bench, csvs):
    known = [
        ("sweep.csv", "mcgv-video, default encoder (automatic motion model): every codec at the bench's qualities",
         "`scripts/sweep.sh`"),
        ("sweep-variants.csv", "the encoder variants (skinning, decimation, both) at quality 10 and 50",
         "`scripts/sweep.sh` with `VARIANTS`"),
        ("peers.csv", "the peer codecs (Draco, zstd, PCA, Dynapack-style, gltfpack, meshoptimizer)",
         "`scripts/peers.py run`"),
        ("tables.md", "every rate–distortion table: bits at equal error, per sequence, speed",
         "`scripts/rd_table.py`"),
        ("peers.md", "the peers page: what each peer is, commands, tool versions, the same tables",
         "`scripts/peers_page.sh`"),
        ("SEQUENCE.png", "RMSE against bpvf, one line per codec (and variant)", "`examples/rd_plot.rs`"),
        ("segments-cost.csv", "temporal segments: bits against one segment", "`examples/segment_cost.rs`"),
        ("segments-memory.csv", "temporal segments: peak memory and time on a generated long clip",
         "`scripts/segments_memory.sh`"),
    ]
    used = {os.path.basename(c) for c in csvs}
    rows = []
    for name, what, maker in known:
        if name == "SEQUENCE.png":
            present = any(f.endswith(".png") for f in os.listdir(bench))
        else:
            present = os.path.exists(os.path.join(bench, name))
        if not present or (name.endswith(".csv") and name.startswith("sweep") and name not in used):
            continue
        link = f"[`{name}`]({LINK_DIR}/{name})" if name != "SEQUENCE.png" else "`SEQUENCE.png`"
        rows.append((link, what, maker))
    return "\n".join(table(("file in `docs/bench/`", "what", "written by"), rows))


def sequences(seqs, bench):
    out = []
    for name, rows in seqs.items():
        v, f = rows[0].get("vertices", "?"), rows[0].get("frames", "?")
        heading = f"{name} (V = {v}, F = {f})"
        tables = f"[tables]({LINK_DIR}/tables.md#{slug(heading)})"
        peers = f"[peers]({LINK_DIR}/peers.md#{slug(heading)})"
        plot = f"[plot]({LINK_DIR}/{name}.png)" if os.path.exists(os.path.join(bench, f"{name}.png")) else "—"
        mine = sorted({r["codec"] for r in rows if ours(r["codec"])}, key=order)
        theirs = sorted({r["codec"] for r in rows if not ours(r["codec"])})
        out.append((name, v, f, len(mine), len(theirs), f"{tables}, {peers}, {plot}"))
    return "\n".join(table(("sequence", "V", "F", "mcgv-video series", "peers", "per-sequence"), out))


def equal_error(seqs):
    head = ["sequence"]
    for t in TARGETS:
        head += [f"RMSE {t:.0e}: mcgv-video", "strongest peer", "peer / mcgv-video"]
    rows, wins, total = [], [0] * len(TARGETS), [0] * len(TARGETS)
    for name, r in seqs.items():
        needs = codec_bits(r, TARGETS)
        cells = [name]
        for i in range(len(TARGETS)):
            mine, peer = best(needs, i, ours), best(needs, i, lambda c: not ours(c))
            if mine and peer:
                total[i] += 1
                wins[i] += peer[1] > mine[1]
            cells += [show(mine), show(peer), f"{peer[1] / mine[1]:.2f}" if mine and peer else "—"]
        rows.append(cells)
    said = "; ".join(f"at RMSE {t:.0e} on {wins[i]} of the {total[i]} sequences both reach"
                     for i, t in enumerate(TARGETS))
    return "\n".join(table(head, rows) + ["", f"mcgv-video needs fewer bits than the strongest peer {said}."])


def codecs_at_equal_error(seqs):
    present = [c for c in CODECS if any(r["codec"] == c for rows in seqs.values() for r in rows)]
    head = ["sequence"] + present + ["strongest peer"]
    rows, firsts = [], defaultdict(int)
    for name, r in seqs.items():
        needs = codec_bits(r, TARGETS)
        cells = [name]
        for c in present:
            bits = needs.get(c, [(None, None)] * len(TARGETS))
            cells.append(" / ".join("—" if b is None else f"{b:.3g}" for b, _k in bits))
        peer = [best(needs, i, lambda c: not ours(c)) for i in range(len(TARGETS))]
        cells.append(" / ".join(show(p) for p in peer))
        rows.append(cells)
        fewest = best({c: v for c, v in needs.items() if c in present}, 0, lambda c: True)
        if fewest:
            firsts[fewest[0]] += 1
    said = ", ".join(f"{c} on {n}" for c, n in sorted(firsts.items(), key=lambda kv: -kv[1]))
    return "\n".join(table(head, rows) + ["", f"Fewest bits at RMSE {TARGETS[0]:.0e} among these codecs: {said}."])


def papers_rates(seqs):
    present = [c for c in PAPER_CODECS if any(r["codec"] == c for rows in seqs.values() for r in rows)]
    rows = []
    for name, r in seqs.items():
        cells = [name]
        for c in present:
            front = front_of(r, c)
            cells.append(" / ".join(e4(at_rate(front, rate)) for rate in PAPER_RATES))
        rows.append(cells)
    return "\n".join(table(["sequence"] + present, rows))


def peers(seqs, bench):
    strongest = defaultdict(lambda: [0] * len(TARGETS))
    beats = defaultdict(lambda: [0] * len(TARGETS))
    measured = defaultdict(set)
    for name, r in seqs.items():
        needs = codec_bits(r, TARGETS)
        for c in needs:
            if not ours(c):
                measured[c].add(name)
        for i in range(len(TARGETS)):
            peer, mine = best(needs, i, lambda c: not ours(c)), best(needs, i, ours)
            if peer:
                strongest[peer[0]][i] += 1
                if mine and peer[1] < mine[1]:
                    beats[peer[0]][i] += 1
    rows = [(c, len(measured[c]), " / ".join(map(str, strongest[c])), " / ".join(map(str, beats[c])))
            for c in sorted(measured)]
    out = table(("peer", "sequences measured",
                 "strongest peer on (" + " / ".join(f"{t:.0e}" for t in TARGETS) + ")",
                 "fewer bits than mcgv-video on"), rows)
    path = os.path.join(bench, "peers.md")
    if os.path.exists(path):
        text = open(path, encoding="utf-8").read()
        m = re.search(r"Tool versions:\s*(.*?)\n\n", text, re.S)
        if m:
            out += ["", "Tool versions (peers.md): " + " ".join(m.group(1).split())]
    return "\n".join(out)


def speed(seqs, name):
    rows = seqs[name]
    frames = float(rows[0]["frames"])
    groups = defaultdict(list)
    for r in rows:
        groups[r["codec"]].append(r)

    def rate(r, key):
        s = float(r[key]) if r.get(key) else 0.0
        return frames / s if s > 0 else None

    def mb(r, key):
        return int(r[key]) / 1024 if r.get(key) else None
    out = []
    for codec in sorted(groups, key=order):
        g = groups[codec]
        at50 = [r for r in g if r["setting"] == "quality 50"]
        enc = [v for v in (rate(r, "encode_cpu_s") for r in g) if v]
        dec = [v for v in (rate(r, "decode_cpu_s") for r in g) if v]
        enc_mb = [v for v in (mb(r, "encode_rss_kb") for r in g) if v]
        dec_mb = [v for v in (mb(r, "decode_rss_kb") for r in g) if v]
        q50 = "—"
        if at50 and rate(at50[0], "encode_cpu_s"):
            q50 = f"{rate(at50[0], 'encode_cpu_s'):.1f} / {rate(at50[0], 'decode_cpu_s') or 0:.0f}"
        out.append((label(codec), len(g), q50,
                    span(enc, lambda v: f"{v:.1f}") if enc else "—",
                    span(dec, lambda v: f"{v:.0f}") if dec else "—",
                    f"{max(enc_mb):.0f} / {max(dec_mb):.0f}" if enc_mb and dec_mb else "—"))
    head = (f"{name} (V = {rows[0].get('vertices')}, F = {rows[0].get('frames')})", "settings",
            "quality 50: encode / decode frames per CPU-s", "encode frames per CPU-s", "decode frames per CPU-s",
            "peak MB encode / decode (largest)")
    return "\n".join(table(head, out))


def read_csv(path):
    if not os.path.exists(path):
        return None
    with open(path, newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def segments_cost(bench):
    rows = read_csv(os.path.join(bench, "segments-cost.csv"))
    if not rows:
        return "(no `segments-cost.csv`: `make bench` was run with `SKIP_SEGMENTS=1`)"
    lengths = sorted({int(r["segment_frames"]) for r in rows} - {0})
    codecs = list(dict.fromkeys(r["codec"] for r in rows))
    cells, frames = defaultdict(dict), {}
    for r in rows:
        frames[r["input"]] = int(r["frames"])
        if int(r["segment_frames"]):
            cells[r["input"]][(r["codec"], int(r["segment_frames"]))] = float(r["at_equal_error"])
    out = []
    for name in dict.fromkeys(r["input"] for r in rows):
        row = [f"{name} ({frames[name]})"]
        for n in lengths:
            got = [cells[name].get((c, n)) for c in codecs]
            row.append("—" if all(g is None for g in got) else
                       " / ".join("—" if g is None else percent(g) for g in got))
        out.append(row)
    at = {}
    for n in lengths:
        vals = [100 * (v - 1) for name, c in cells.items() for (codec, m), v in c.items()
                if m == n and frames[name] > n]
        if vals:
            at[n] = (min(vals), max(vals))
    said = "; ".join(f"{n} frames {signed(lo)} to {signed(hi)} %" for n, (lo, hi) in at.items())
    head = ["sequence (frames)"] + [f"{n} frames: " + " / ".join(codecs) for n in lengths]
    return "\n".join(table(head, out) + ["", "Range over the codecs and the sequences longer than a "
                                          f"segment: {said}."])


def segments_memory(bench):
    rows = read_csv(os.path.join(bench, "segments-memory.csv"))
    if not rows:
        return "(no `segments-memory.csv`: `make bench` was run with `SKIP_SEGMENTS=1`)"
    groups = defaultdict(lambda: defaultdict(list))
    for r in rows:
        key = (int(r["frames"]), int(r["segments"]), int(r["segment_frames"]))
        command = r["command"]
        if command.startswith("encode "):   # encode with options, e.g. --threads 2: a row of its own
            key = key + (command[len("encode "):],)
            command = "encode"
        groups[key][command].append(r)

    def cell(rs):
        if not rs:
            return ""
        mb = span([int(r["peak_rss_kb"]) / 1000 for r in rs], lambda v: thousands(round(v)))
        s = span([float(r["seconds"]) for r in rs], lambda v: f"{v:.0f}")
        return f"{mb} MB, {s} s"
    out = []
    for key in sorted(groups, key=lambda k: (-k[0], k[1], len(k))):
        g = groups[key]
        what = f"{key[1]} × {key[2]}" + (f", `{key[3]}`" if len(key) > 3 else "")
        bytes_ = {r["bytes"] for rs in g.values() for r in rs}
        out.append((f"{key[0]} frames", what, cell(g.get("encode")), cell(g.get("decode")), cell(g.get("eval")),
                    ", ".join(thousands(int(b)) for b in sorted(bytes_, key=int))))
    return "\n".join(table(("clip", "segments × frames", "encode", "decode (OBJ folder)", "eval",
                            "stream bytes"), out))


BLOCKS = ("provenance", "files", "sequences", "equal_error", "codecs_at_equal_error", "papers_rates",
          "peers", "speed", "speed_sequence", "segments_cost", "segments_memory", "csvs")


def contents(page):
    out, fence = [], False
    for line in page.split("\n"):
        if line.startswith("```"):
            fence = not fence
        elif not fence and line.startswith("## ") and line != "## Contents":
            out.append(f"- [{line[3:]}](#{slug(line[3:])})")
    return "\n".join(out)


def main():
    args = sys.argv[1:]
    speed_name = take_option(args, "--speed", None)
    bench = take_option(args, "--bench", None)
    template = take_option(args, "--template",
                           os.path.join(os.path.dirname(os.path.abspath(__file__)), "results_template.md"))
    if not args:
        sys.exit(__doc__)
    bench = bench or os.path.dirname(args[0]) or "."
    seqs = by_sequence(read(args))
    if speed_name is None:
        speed_name = max(seqs, key=lambda s: int(seqs[s][0].get("vertices") or 0) * int(seqs[s][0].get("frames") or 0))
    if speed_name not in seqs:
        die(f"--speed {speed_name}: no such sequence in the CSVs")
    made = {
        "provenance": provenance(bench),
        "files": files(bench, args),
        "sequences": sequences(seqs, bench),
        "equal_error": equal_error(seqs),
        "codecs_at_equal_error": codecs_at_equal_error(seqs),
        "papers_rates": papers_rates(seqs),
        "peers": peers(seqs, bench),
        "speed": speed(seqs, speed_name),
        "speed_sequence": speed_name,
        "segments_cost": segments_cost(bench),
        "segments_memory": segments_memory(bench),
        "csvs": " ".join(args),
    }
    page = open(template, encoding="utf-8").read()
    for name, text in made.items():
        page = page.replace("{{" + name + "}}", text)
    page = page.replace("{{contents}}", contents(page))
    left = re.findall(r"\{\{\w+\}\}", page)
    if left:
        die(f"{template}: unknown placeholders {sorted(set(left))} (known: {', '.join(BLOCKS)}, contents)")
    sys.stdout.write(re.sub(r"\n{3,}", "\n\n", page).rstrip("\n") + "\n")


if __name__ == "__main__":
    main()
