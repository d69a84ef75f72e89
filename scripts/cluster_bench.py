#!/usr/bin/env python3
"""The cluster measurement: a long clip coded in segments by `mcgv-video encode` in one process
and by mcgv_video.cluster on a fresh local Dask cluster of WORKERS worker processes (one thread
each); wall times, their ratio, each process's peak memory, and whether the bytes are the same.
Then the same job again with one worker killed (SIGKILL) while it codes a segment: which segments
were coded twice, and the bytes.

    scripts/cluster_bench.py CLIP.pc2 [--segment-frames 125] [--workers 2] [--cli target/release/mcgv-video]

The clip: `cargo run --release --example long_clip -- DIR 20000 1000` writes DIR/cloth.pc2.
"""

from __future__ import annotations

import argparse
import os
import resource
import signal
import subprocess
import tempfile
import threading
import time
from pathlib import Path

from mcgv_video import cluster


def one_process(cli: str, clip: str, segment_frames: int, out: Path) -> tuple[float, float, int, bytes]:
    """Wall seconds, CPU seconds, peak resident bytes and the stream of `mcgv-video encode`."""
    timing = out.with_suffix(".time")
    start = time.perf_counter()
    subprocess.run(["/usr/bin/time", "-f", "%U %S %M", "-o", str(timing), cli, "encode", clip, "-o", str(out),
                    "--quiet", "--segment-frames", str(segment_frames)], check=True)
    seconds = time.perf_counter() - start
    user, system, peak = timing.read_text().split()[-3:]
    return seconds, float(user) + float(system), int(peak) * 1024, out.read_bytes()


def _cpu_seconds() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def on_cluster(clip: str, segment_frames: int, workers: int, kill: bool) -> dict:
    client = cluster.local_cluster(workers)
    try:
        client.wait_for_workers(workers)
        base = cluster.peak_memory(client)
        cpu = client.run(_cpu_seconds)
        pids = client.run(os.getpid)
        outcome: dict = {}

        def run():
            start = time.perf_counter()
            outcome["stream"] = cluster.encode_segments(client, clip, segment_frames=segment_frames, threads=1)
            outcome["seconds"] = time.perf_counter() - start

        job = threading.Thread(target=run)
        job.start()
        killed: list = []
        while kill and not killed and job.is_alive():
            for address, keys in client.processing().items():
                segments = [k for k in keys if str(k).startswith("mcgv-segment-")]
                if segments:
                    os.kill(pids[address], signal.SIGKILL)
                    killed = segments
                    outcome["killed"] = (address, segments, time.monotonic())
                    break
            time.sleep(0.05)
        job.join()
        outcome["peaks"] = cluster.peak_memory(client)
        outcome["cpu"] = {a: s - cpu.get(a, 0.0) for a, s in client.run(_cpu_seconds).items()}
        outcome["idle"] = base
        if killed:
            outcome["runs"] = client.run_on_scheduler(_processing_runs, keys=tuple(killed))
        return outcome
    finally:
        client.close()
        client.cluster.close()


def _processing_runs(dask_scheduler, keys) -> dict:
    """How many times each killed segment, and the analysis (lost too if the dead worker held its
    only copy), went to processing."""
    runs: dict = {}
    for t in dask_scheduler.transition_log:
        name = str(t.key)
        if t.finish == "processing" and (t.key in keys or name.startswith("mcgv-analysis-")):
            runs[name] = runs.get(name, 0) + 1
    return runs


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("clip")
    parser.add_argument("--segment-frames", type=int, default=125)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--cli", default="target/release/mcgv-video")
    args = parser.parse_args()
    mib = lambda b: f"{b / 2**20:.0f} MiB"  # noqa: E731
    with tempfile.TemporaryDirectory() as tmp:
        single_s, single_cpu, single_peak, expected = one_process(args.cli, args.clip, args.segment_frames,
                                                                  Path(tmp) / "one.mcgv")
    print(f"one process (mcgv-video encode): {single_s:.1f} s wall, {single_cpu:.1f} CPU-s, "
          f"peak {mib(single_peak)}, {len(expected)} bytes")
    plain = on_cluster(args.clip, args.segment_frames, args.workers, kill=False)
    print(f"cluster of {args.workers} workers: {plain['seconds']:.1f} s (cluster / one process = "
          f"{plain['seconds'] / single_s:.2f}); {sum(plain['cpu'].values()):.1f} CPU-s in the workers; "
          f"same bytes: {plain['stream'] == expected}")
    for address in sorted(plain["peaks"]):
        print(f"  worker {address}: peak {mib(plain['peaks'][address])} (idle {mib(plain['idle'][address])})")
    killed = on_cluster(args.clip, args.segment_frames, args.workers, kill=True)
    address, segments, _ = killed["killed"]
    print(f"with worker {address} killed while coding {', '.join(map(str, segments))}: {killed['seconds']:.1f} s; "
          f"times each went to processing: {killed['runs']}; same bytes: {killed['stream'] == expected}")


if __name__ == "__main__":
    main()
