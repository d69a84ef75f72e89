#!/usr/bin/env python3
"""`make bench-speed`: what the default encode of each codec costs, against the same codec with every
choice fixed to what the default chose (one encode, no trials), side by side in one run.

For each input and codec it runs `mcgv-video encode --json` twice under GNU time: the default, then
`--predictor P --segmentation S --clusters K --first-frame-bits B` set to the default's choices. It
prints CPU seconds (user + system, all threads) and wall seconds of both, their ratio, the bytes of
both (equal when the fixed run reproduces the choice), and the default's seconds per stage from its
report. Stages that run side by side on rayon's threads (the automatic choice's jobs, segments)
report their own wall time each, so they may sum to more than the run's wall time.

The machine is shared and noisy: compare the ratios, which come from runs made back to back.

    scripts/bench_speed.py BIN OUT.md INPUT[:FLAGS]...
e.g. scripts/bench_speed.py target/release/mcgv-video bench-out/speed.md media/CesiumMan.glb \
     'BrainStem.glb:--fps 5'
CODECS (space-separated) limits the codecs (default: tdct jpeg mpeg4 hevc av1).
"""
import json
import os
import subprocess
import sys
import tempfile


def timed(cmd):
    """Runs cmd under GNU time: (stdout, cpu seconds, wall seconds)."""
    with tempfile.NamedTemporaryFile("r", suffix=".time") as t:
        full = ["/usr/bin/time", "-f", "%U %S %e", "-o", t.name] + cmd
        run = subprocess.run(full, capture_output=True, text=True)
        if run.returncode != 0:
            raise RuntimeError(f"{' '.join(cmd)}: {run.stderr.strip()}")
        user, system, wall = (float(x) for x in t.read().split()[-3:])
    return run.stdout, user + system, wall


def encode(binary, source, flags, extra, out):
    if os.path.exists(out):
        os.remove(out)
    cmd = [binary, "encode", source, "-o", out, "--quiet", "--json"] + flags + extra
    stdout, cpu, wall = timed(cmd)
    return json.loads(stdout), cpu, wall


def fixed_flags(report):
    """The flags that fix every choice the default encode made."""
    header = report["header"]
    segmentation = report["segmentation"]["method"]
    flags = ["--predictor", header["predictor"], "--segmentation", segmentation,
             "--first-frame-bits", str(header["first_frame_bits"])]
    if segmentation == "kmeans":
        flags += ["--clusters", str(header["requested_clusters"])]
    return flags


def stages(report):
    parts = [f"{name} {seconds:.2f}" for name, seconds in report["stage_seconds"]]
    return "; ".join(parts)


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    binary, out_path = sys.argv[1], sys.argv[2]
    codecs = os.environ.get("CODECS", "tdct jpeg mpeg4 hevc av1").split()
    rows, details = [], []
    with tempfile.TemporaryDirectory() as work:
        for spec in sys.argv[3:]:
            source, _, extra = spec.partition(":")
            extra = extra.split()
            name = os.path.basename(source.rstrip("/"))
            for codec in codecs:
                stream = os.path.join(work, f"{codec}.mcgv")
                flags = ["--codec", codec]
                report, cpu, wall = encode(binary, source, flags, extra, stream)
                fixed, fcpu, fwall = encode(binary, source, flags + fixed_flags(report),
                                            extra, stream)
                rows.append(f"| {name} | {codec} | {cpu:.2f} | {wall:.2f} | {fcpu:.2f} | "
                            f"{fwall:.2f} | {cpu / max(fcpu, 1e-9):.2f} | {report['bytes']} | "
                            f"{fixed['bytes']} |")
                details.append(f"- {name}, {codec}: {stages(report)}")
                print(rows[-1], flush=True)
    with open(out_path, "w") as f:
        f.write("| input | codec | default CPU s | wall s | fixed CPU s | wall s | CPU ratio | "
                "bytes | fixed bytes |\n|---|---|---|---|---|---|---|---|---|\n")
        f.write("\n".join(rows) + "\n\nSeconds per stage of the default encodes (wall, each "
                "stage's own; side-by-side stages overlap):\n\n")
        f.write("\n".join(details) + "\n")


if __name__ == "__main__":
    main()
