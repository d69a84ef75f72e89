"""Segments and batches on a local Dask cluster of two worker processes: the joined stream is the
command line's byte for byte, also when a worker is killed in the middle of the job. A small
clip keeps `make test` short; the full-size measurement (20 000 vertices × 1 000 frames) is
scripts/cluster_bench.py's."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time

import pytest

from dask.distributed import get_task_stream

import mcgv_video
from mcgv_video import cluster

from conftest import cli_encode, cloth, media, write_pc2

SEGMENT = 40


@pytest.fixture(scope="module")
def client():
    client = cluster.local_cluster(workers=2)
    yield client
    client.close()
    client.cluster.close()


@pytest.fixture(scope="module")
def clip(tmp_path_factory):
    folder = tmp_path_factory.mktemp("clip")
    positions, faces = cloth(n=40, frames=200)
    return write_pc2(folder, positions, faces)


def test_segments_coded_on_two_workers_join_into_the_cli_s_stream(tmp_path, client, cli, clip):
    expected = cli_encode(cli, clip, tmp_path / "cli.mcgv", "--segment-frames", str(SEGMENT))
    assert len(client.scheduler_info()["workers"]) == 2
    with get_task_stream(client) as tasks:
        stream = cluster.encode_segments(client, clip, segment_frames=SEGMENT, threads=1)
    assert stream == expected
    # Both workers coded segments (each started its encoder from the shared analysis clip).
    ran = {t["key"]: t["worker"] for t in tasks.data if str(t["key"]).startswith("mcgv-segment-")}
    assert len(ran) == 5 and len(set(ran.values())) == 2, ran


def test_a_killed_worker_s_segment_is_retried_and_the_stream_is_the_same(tmp_path, client, cli, clip):
    expected = cli_encode(cli, clip, tmp_path / "cli.mcgv", "--segment-frames", str(SEGMENT), "--quality", "55")
    pids = client.run(os.getpid)
    outcome = {}

    def run():
        try:
            outcome["stream"] = cluster.encode_segments(client, clip, segment_frames=SEGMENT, threads=1, quality=55)
        except BaseException as e:  # reported below
            outcome["error"] = e

    job = threading.Thread(target=run)
    job.start()
    victim = killed = None
    deadline = time.monotonic() + 120
    while victim is None and time.monotonic() < deadline and job.is_alive():
        for address, keys in client.processing().items():
            segments = [k for k in keys if str(k).startswith("mcgv-segment-")]
            if segments:
                victim, killed = address, segments
                break
        time.sleep(0.05)
    assert victim is not None, "no segment was seen running"
    os.kill(pids[victim], signal.SIGKILL)
    job.join(timeout=300)
    assert "error" not in outcome, outcome.get("error")
    assert outcome["stream"] == expected
    # A segment the dead worker was coding went to processing a second time, unless it had
    # finished before the kill landed (a segment of this small clip codes in a fraction of a second:
    # a run on the loaded machine saw that once, the stream still the same).
    states = client.run_on_scheduler(_states, keys=killed)
    assert all(_retried_or_done_first(s) for s in states.values()), states


def test_the_demo_run_as_a_module_gives_the_cli_s_bytes(cli, clip):
    # With -m the module is __main__, whose functions would travel to the workers by value,
    # with the lock they use, which does not pickle: the tasks must be the imported module's.
    command = [sys.executable, "-m", "mcgv_video.cluster", "--workers", "2", "--clip", str(clip),
               "--segment-frames", str(SEGMENT), "--compare-with", cli]
    result = subprocess.run(command, capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr[-3000:]
    assert "same bytes: yes" in result.stdout, result.stdout


def test_a_batch_gives_one_row_per_file_and_a_bad_file_its_error(tmp_path, client):
    bad = tmp_path / "broken.glb"
    bad.write_bytes(b"glTF not really")
    paths = [media("RiggedSimple.glb"), str(bad), media("RiggedFigure.glb")]
    # One predictor and segmentation rather than the automatic choice's trials: a shorter test.
    options = dict(quality=50, segmentation="kmeans", predictor="affine")
    rows = cluster.encode_batch(client, paths, out_dir=tmp_path / "out", **options)
    assert [r["file"] for r in rows] == paths
    good = [rows[0], rows[2]]
    for row in good:
        assert row["error"] is None and row["bytes"] > 0 and 0 < row["rmse"] < 1e-3
        stream = (tmp_path / "out" / (os.path.basename(row["file"])[:-4] + ".mcgv")).read_bytes()
        assert len(stream) == row["bytes"]
        assert row["bpvf"] == pytest.approx(row["bytes"] * 8 / (row["vertices"] * row["frames"]))
        assert stream == mcgv_video.encode(mcgv_video.read_animation(row["file"]), **options)
    assert rows[1]["bytes"] is None and "Error" in rows[1]["error"]
    table = cluster.format_table(rows)
    assert "RiggedSimple.glb" in table and "broken.glb" in table


def _states(dask_scheduler, keys):
    """The states each key went to, in order."""
    return {str(k): [t.finish for t in dask_scheduler.transition_log if t.key == k] for k in keys}


def _retried_or_done_first(states):
    """Whether a key went to processing twice, or its first run ended in memory."""
    if "processing" not in states:
        return False
    first = states.index("processing")
    return states.count("processing") >= 2 or states[first + 1 : first + 2] == ["memory"]
