#!/usr/bin/env python3
"""What a Python caller pays over the Rust API: encode and decode of one input, timed in Rust
(examples/api_timing, one process per repetition) and in Python (the mcgv_video package), runs
interleaved so that both see the same machine load; medians of wall and of CPU seconds (the
process's, every thread's: steadier on a shared machine) and their ratios. Both sides are timed
warm — the Rust process encodes twice and reports the second, the Python process encodes and
decodes once before timing — as a first call also pays for growing the heap (page faults) and
starting the thread pool. Each repetition decodes --decodes times (Rust's CPU seconds come in
10 ms steps).

    scripts/python_overhead.py INPUT [--repeat N] [--decodes N] [--timing target/release/examples/api_timing]
    scripts/python_overhead.py --binding-only STREAM.mcgv [--repeat N]

--binding-only times, in one process, what the binding adds to a decode: ``Decoder.all()`` (the
frames copied into one NumPy array) against ``Decoder.animation()`` (the library's decode_all
kept as it is), alternated, CPU-second medians.

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
    parser.add_argument("--decodes", type=int, default=10)
    parser.add_argument("--timing", default="target/release/examples/api_timing")
    parser.add_argument("--binding-only", action="store_true")
    args = parser.parse_args()
    if args.binding_only:
        binding_only(args.input, args.repeat)
        return

    animation = mcgv_video.read_animation(args.input)
    positions, faces = animation.positions, animation.faces
    rust: dict = {"encode": [], "decode": []}
    python: dict = {"encode": [], "encode (Animation)": [], "decode": []}
    streams = set()

    def timed(name, call, times=1):
        wall, cpu = time.perf_counter(), time.process_time()
        for _ in range(times):
            result = call()
        python[name].append(((time.perf_counter() - wall) / times, (time.process_time() - cpu) / times))
        return result

    mcgv_video.Decoder(mcgv_video.encode(animation)).all()  # warm-up, not timed
    for _ in range(args.repeat):
        command = [args.timing, args.input, "2", str(args.decodes)]
        lines = subprocess.run(command, check=True, capture_output=True, text=True).stdout.splitlines()
        fields = lines[-1].split()
        rust["encode"].append((float(fields[1]), float(fields[3])))
        rust["decode"].append((float(fields[5]), float(fields[7])))
        rust_bytes = int(fields[9])

        stream = timed("encode", lambda: mcgv_video.encode(positions, faces, fps=animation.fps))
        stream_of_animation = timed("encode (Animation)", lambda: mcgv_video.encode(animation))
        every = timed("decode", lambda: mcgv_video.Decoder(stream).all(), args.decodes)
        assert every.shape == positions.shape
        streams.add((len(stream), len(stream_of_animation), rust_bytes))

    print(f"{args.input}: {animation.vertex_count} vertices x {animation.frame_count} frames, "
          f"{args.repeat} runs each, interleaved; stream bytes (arrays, Animation, Rust): {sorted(streams)}")
    print(f"{'call':<20} {'Rust wall s':>12} {'Python wall s':>14} {'ratio':>7} {'Rust CPU s':>11} "
          f"{'Python CPU s':>13} {'ratio':>7}")
    for call, times in python.items():
        base = rust["decode" if call == "decode" else "encode"]
        row = []
        for i in (0, 1):
            r, p = statistics.median(t[i] for t in base), statistics.median(t[i] for t in times)
            row += [r, p, p / r]
        print(f"{call:<20} {row[0]:>12.3f} {row[1]:>14.3f} {row[2]:>7.3f} {row[3]:>11.2f} {row[4]:>13.2f} {row[5]:>7.3f}")


def binding_only(path: str, repeat: int) -> None:
    with open(path, "rb") as f:
        stream = f.read()
    calls = {"Decoder.all()": lambda d: d.all(), "Decoder.animation()": lambda d: d.animation()}
    cpu: dict = {name: [] for name in calls}
    for _ in range(repeat):
        for name, call in calls.items():
            start = time.process_time()
            call(mcgv_video.Decoder(stream))
            cpu[name].append(time.process_time() - start)
    base = statistics.median(cpu["Decoder.animation()"])
    for name, times in cpu.items():
        print(f"{name:<22} median CPU s {statistics.median(times):.4f}  ratio {statistics.median(times) / base:.3f}")


if __name__ == "__main__":
    main()
