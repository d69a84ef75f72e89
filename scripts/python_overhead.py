#!/usr/bin/env python3
"""What a Python caller pays over the Rust API: encode and decode of one input, timed in Rust
(examples/api_timing, one process per repetition) and in Python (the mcgv_video package), runs
interleaved so that both see the same machine load; medians and their ratio.

    scripts/python_overhead.py INPUT [--repeat N] [--timing target/release/examples/api_timing]

Build both first, from the same source and profile:
    cargo build --release --example api_timing && make python
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import time

import mcgv_video


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("input")
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--timing", default="target/release/examples/api_timing")
    args = parser.parse_args()

    animation = mcgv_video.read_animation(args.input)
    positions, faces = animation.positions, animation.faces
    rust = {"encode": [], "decode": []}
    python = {"encode": [], "encode (Animation)": [], "decode": []}
    streams = set()
    for _ in range(args.repeat):
        line = subprocess.run([args.timing, args.input, "1"], check=True, capture_output=True, text=True).stdout
        fields = line.split()
        rust["encode"].append(float(fields[1]))
        rust["decode"].append(float(fields[3]))
        rust_bytes = int(fields[5])

        start = time.perf_counter()
        stream = mcgv_video.encode(positions, faces, fps=animation.fps)
        python["encode"].append(time.perf_counter() - start)
        start = time.perf_counter()
        stream_of_animation = mcgv_video.encode(animation)
        python["encode (Animation)"].append(time.perf_counter() - start)
        start = time.perf_counter()
        every = mcgv_video.Decoder(stream).all()
        python["decode"].append(time.perf_counter() - start)
        assert every.shape == positions.shape
        streams.add((len(stream), len(stream_of_animation), rust_bytes))

    print(f"{args.input}: {animation.vertex_count} vertices x {animation.frame_count} frames, "
          f"{args.repeat} runs each, interleaved; stream bytes (arrays, Animation, Rust): {sorted(streams)}")
    print(f"{'call':<28} {'Rust median s':>14} {'Python median s':>16} {'Python / Rust':>14}")
    for call, times in python.items():
        base = statistics.median(rust["decode" if call == "decode" else "encode"])
        median = statistics.median(times)
        print(f"{call:<28} {base:>14.3f} {median:>16.3f} {median / base:>14.3f}")


if __name__ == "__main__":
    main()
