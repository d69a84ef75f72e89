"""Long clips and big batches on a Dask cluster.

* :func:`encode_segments` codes a long clip's temporal segments as tasks on the cluster's
  workers and joins them, in order, in one task into the stream ``mcgv-video encode`` writes on
  one machine, byte for byte. One task makes the analysis — every choice of the encoding, made on
  the frames spread over the clip (``SegmentedEncoder.start`` on ``FrameSource.analysis``), the
  costliest step of a clip of a few segments — and returns it as bytes; each worker resumes an
  encoder from those bytes once (``SegmentedEncoder.resume``) and codes each segment it is given
  (``code_segment``) into bytes; the join task adds them in order and finishes the stream.
* :func:`encode_batch` codes each file of a batch as a task and returns one row per file: bytes,
  bpvf, RMSE, seconds, or the error that file failed with (the others go on).

Tasks read their frames themselves (a PC2 cache by seeking, OBJ files one by one), so the files
must be where the workers can read them (a shared file system) — only coded bytes travel. A
worker that dies mid-run is replaced by its nanny and the scheduler gives its tasks to another
worker (up to ``distributed.scheduler.allowed-failures`` times, 3 by default); tasks that fail
with an exception are retried ``retries`` times.

Run as ``python -m mcgv_video.cluster`` for the demo (``make cluster-demo``); ``--scheduler
tcp://HOST:8786`` points it at a running cluster instead of a local one.
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import threading
import time
import uuid
from pathlib import Path
from typing import Any, Iterable, Optional, Sequence

from ._native import FrameSource, SegmentedEncoder, encode, eval, read_animation, segment_ranges
from .errors import McgvError

# Encoders resumed in this worker process, by job: each worker resumes one per job, the first
# time a segment of that job runs on it.
_ENCODERS: dict[str, SegmentedEncoder] = {}
_RESUMING = threading.Lock()


def _analyse(path: str, length: int, read: dict, threads: Optional[int], options: dict) -> bytes:
    """Task: the encoding's analysis, made once, as bytes (``SegmentedEncoder.analysis``)."""
    clip = FrameSource(path, **read).analysis(length)
    return SegmentedEncoder.start(clip, length, threads=threads, **options).analysis()


def _code_segment(
    job: str, analysis: bytes, path: str, start: int, end: int, read: dict, threads: Optional[int], options: dict
) -> bytes:
    """Task: frames ``start..end`` of the file coded as a segment's bytes."""
    with _RESUMING:
        encoder = _ENCODERS.get(job)
        if encoder is None:
            encoder = _ENCODERS[job] = SegmentedEncoder.resume(analysis, threads=threads, **options)
    positions = FrameSource(path, **read).read(start, end)
    return encoder.code_segment(start, positions)


def _join(analysis: bytes, threads: Optional[int], options: dict, *segments: bytes) -> bytes:
    """Task: the segments' bytes added in order into the stream."""
    encoder = SegmentedEncoder.resume(analysis, threads=threads, **options)
    for segment in segments:
        encoder.add(segment)
    return encoder.finish()


def _forget(job: str) -> None:
    with _RESUMING:
        _ENCODERS.pop(job, None)


def encode_segments(
    client: Any,
    path: str | os.PathLike[str],
    *,
    segment_frames: int = 128,
    threads: Optional[int] = None,
    analysis_threads: Optional[int] = None,
    retries: int = 1,
    read: Optional[dict] = None,
    **options: Any,
) -> bytes:
    """Encodes the clip at ``path`` in segments of ``segment_frames`` frames on ``client``'s
    cluster: the bytes ``encode`` (and ``mcgv-video encode --segment-frames N``) gives with the
    same options. ``read`` holds ``FrameSource``'s options (``clip``, ``fps``, ``base``);
    ``threads`` is each segment task's thread count (default: one per core of its worker);
    ``analysis_threads`` the analysis task's (default: one per core — it runs alone, before any
    segment can start, and is most of the work of a clip of a few segments)."""
    # Absolute: a worker's working folder is not the caller's (the files are on a shared folder).
    path = os.path.abspath(os.fspath(path))
    read = dict(read or {})
    frames = client.submit(_frame_count, path, read, pure=False).result()
    options = dict(options, segment_frames=segment_frames)
    job = uuid.uuid4().hex[:12]
    if frames <= segment_frames:
        # One segment: one task codes the whole clip, as encode does.
        future = client.submit(_encode_whole, path, read, threads, options, key=f"mcgv-whole-{job}", retries=retries)
        return future.result()
    length = segment_frames
    analysis = client.submit(_analyse, path, length, read, analysis_threads, options, key=f"mcgv-analysis-{job}",
                             retries=retries)
    segments = [
        client.submit(
            _code_segment, job, analysis, path, start, end, read, threads, options,
            key=f"mcgv-segment-{start:08d}-{job}", retries=retries,
        )
        for start, end in segment_ranges(frames, length)
    ]
    joined = client.submit(_join, analysis, threads, options, *segments, key=f"mcgv-join-{job}", retries=retries)
    try:
        return joined.result()
    finally:
        # A worker that died during the job took its encoders with it: the broadcast to it fails,
        # and that must not replace the finished stream with an error (seen once in CI).
        client.run(_forget, job, on_error="ignore")


def _frame_count(path: str, read: dict) -> int:
    return FrameSource(path, **read).frame_count


def _encode_whole(path: str, read: dict, threads: Optional[int], options: dict) -> bytes:
    source = FrameSource(path, **read)
    return encode(source.clip(0, source.frame_count), threads=threads, **options)


def _encode_file(path: str, out_dir: Optional[str], threads: Optional[int], options: dict) -> dict:
    """Task: one file of a batch encoded, measured and (with ``out_dir``) written."""
    row: dict[str, Any] = {"file": path, "frames": None, "vertices": None, "bytes": None,
                           "bpvf": None, "rmse": None, "seconds": None, "error": None}
    start = time.perf_counter()
    try:
        animation = read_animation(path)
        stream = encode(animation, threads=threads, **options)
        measures = eval(animation, stream)
        if out_dir is not None:
            target = Path(out_dir) / (Path(path).stem + ".mcgv")
            target.parent.mkdir(parents=True, exist_ok=True)
            with tempfile.NamedTemporaryFile(dir=target.parent, delete=False) as part:
                part.write(stream)
            os.replace(part.name, target)
        row.update(frames=animation.frame_count, vertices=animation.vertex_count, bytes=len(stream),
                   bpvf=measures["bpvf"], rmse=measures["rmse"])
    except (McgvError, OSError) as e:
        row["error"] = f"{type(e).__name__}: {e}"
    row["seconds"] = time.perf_counter() - start
    return row


def batch_inputs(folder: str | os.PathLike[str]) -> list[str]:
    """The animations in ``folder``: glTF/GLB files, PC2 caches, and sub-folders of OBJ frames."""
    folder = Path(folder)
    found = []
    for entry in sorted(folder.iterdir()):
        if entry.is_file() and entry.suffix.lower() in (".glb", ".gltf", ".pc2"):
            found.append(str(entry))
        elif entry.is_dir() and any(p.suffix.lower() == ".obj" for p in entry.iterdir()):
            found.append(str(entry))
    return found


def encode_batch(
    client: Any,
    paths: Iterable[str | os.PathLike[str]],
    *,
    out_dir: Optional[str | os.PathLike[str]] = None,
    threads: Optional[int] = None,
    retries: int = 1,
    **options: Any,
) -> list[dict]:
    """Encodes each file as a task; one row per file, in the order given: ``file`` (absolute), ``frames``,
    ``vertices``, ``bytes``, ``bpvf``, ``rmse`` (a fraction of the bounding-box diagonal),
    ``seconds``, and ``error`` (the exception a file failed with, else ``None``)."""
    out = None if out_dir is None else os.path.abspath(os.fspath(out_dir))
    futures = [
        client.submit(_encode_file, os.path.abspath(os.fspath(p)), out, threads, options, key=f"mcgv-file-{i:05d}-{uuid.uuid4().hex[:8]}",
                      retries=retries)
        for i, p in enumerate(paths)
    ]
    return client.gather(futures)


def format_table(rows: Sequence[dict]) -> str:
    """The batch's rows as a text table (RMSE in the papers' unit, 10⁻⁴ of the diagonal)."""
    lines = [f"{'file':<28} {'frames':>6} {'vertices':>8} {'bytes':>9} {'bpvf':>7} {'RMSE(1e-4)':>10} {'s':>6}  error"]
    for r in rows:
        num = lambda v, f: "-" if v is None else format(v, f)  # noqa: E731
        rmse = None if r["rmse"] is None else r["rmse"] * 1e4
        lines.append(
            f"{Path(r['file']).name[:28]:<28} {num(r['frames'], 'd'):>6} {num(r['vertices'], 'd'):>8} "
            f"{num(r['bytes'], 'd'):>9} {num(r['bpvf'], '.3f'):>7} {num(rmse, '.3f'):>10} "
            f"{num(r['seconds'], '.2f'):>6}  {r['error'] or ''}"
        )
    return "\n".join(lines)


def peak_memory(client: Any) -> dict[str, int]:
    """Each worker process's peak resident memory so far, in bytes, by worker address."""
    return client.run(lambda: resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024)


def local_cluster(workers: int = 2, threads_per_worker: int = 1) -> Any:
    """A client of a cluster of ``workers`` worker processes on this machine (each behind a nanny
    that restarts it if it dies)."""
    from dask.distributed import Client, LocalCluster

    cluster = LocalCluster(n_workers=workers, threads_per_worker=threads_per_worker, processes=True,
                           dashboard_address=None)
    return Client(cluster)


def _main(argv: Optional[Sequence[str]] = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m mcgv_video.cluster",
        description="Code a long clip's segments and a batch of files on a Dask cluster "
                    "(a local one of --workers processes unless --scheduler is given).",
    )
    parser.add_argument("--scheduler", default=os.environ.get("MCGV_SCHEDULER"),
                        help="address of a running scheduler, e.g. tcp://HOST:8786 (default: $MCGV_SCHEDULER, "
                             "else a local cluster)")
    parser.add_argument("--workers", type=int, default=2, help="worker processes of the local cluster")
    parser.add_argument("--threads", type=int, default=1, help="threads per task")
    parser.add_argument("--clip", help="a long clip (PC2, OBJ folder, glTF) to code in segments")
    parser.add_argument("--segment-frames", type=int, default=128)
    parser.add_argument("--compare-with", help="the mcgv-video binary: encode the clip in one process too, "
                                               "and compare bytes and wall time")
    parser.add_argument("--batch", help="a folder of animations to code one task each")
    parser.add_argument("--out", help="folder for the batch's streams")
    parser.add_argument("--codec", default="tdct")
    parser.add_argument("--quality", type=int, default=50)
    args = parser.parse_args(argv)
    from dask.distributed import Client

    client = Client(args.scheduler) if args.scheduler else local_cluster(args.workers, 1)
    workers = len(client.scheduler_info()["workers"])
    print(f"cluster: {workers} workers ({args.scheduler or 'local processes'})")
    options = dict(codec=args.codec, quality=args.quality)
    status = 0
    if args.clip:
        start = time.perf_counter()
        stream = encode_segments(client, args.clip, segment_frames=args.segment_frames, threads=args.threads, **options)
        cluster_s = time.perf_counter() - start
        print(f"segments: {args.clip}: {len(stream)} bytes in {cluster_s:.1f} s on the cluster")
        for address, peak in sorted(peak_memory(client).items()):
            print(f"  worker {address}: peak {peak / 2**20:.0f} MiB")
        if args.compare_with:
            with tempfile.TemporaryDirectory() as tmp:
                single = Path(tmp) / "single.mcgv"
                start = time.perf_counter()
                subprocess.run([args.compare_with, "encode", args.clip, "-o", str(single), "--quiet",
                                "--codec", args.codec, "--quality", str(args.quality),
                                "--segment-frames", str(args.segment_frames)], check=True)
                single_s = time.perf_counter() - start
                same = single.read_bytes() == stream
            print(f"  one process (mcgv-video encode): {single_s:.1f} s; cluster / one process = "
                  f"{cluster_s / single_s:.2f}; same bytes: {'yes' if same else 'NO'}")
            status |= 0 if same else 1
    if args.batch:
        paths = batch_inputs(args.batch)
        start = time.perf_counter()
        rows = encode_batch(client, paths, out_dir=args.out, threads=args.threads, **options)
        print(f"batch: {len(rows)} files in {time.perf_counter() - start:.1f} s")
        print(format_table(rows))
    client.close()
    return status


if __name__ == "__main__":
    # Run with -m this file is __main__, whose functions cloudpickle ships to the workers by value,
    # globals and all (the encoders' lock cannot be pickled); the imported module's are shipped
    # by reference, as when a program imports mcgv_video.cluster.
    from mcgv_video.cluster import _main as main

    sys.exit(main())
