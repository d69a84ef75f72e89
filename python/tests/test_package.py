"""The Python package against the command line and the library's promises: same bytes for the
same options, arrays in and out, errors that name the argument, damaged streams that raise, and
the interpreter's lock released while coding."""

from __future__ import annotations

import ast
import json
import pickle
import re
import subprocess
import threading
import time

import numpy as np
import pytest

import mcgv_video
from mcgv_video import (
    Animation,
    Decoder,
    InvalidOptionError,
    McgvError,
    SegmentedEncoder,
    StreamError,
    UsageError,
)

from conftest import REPO, cli_encode, cloth, media, write_pc2


def canonical(faces):
    """Triangles as a sorted list, each rotated to start at its smallest index."""
    rows = [tuple(int(v) for v in t) for t in faces]
    return sorted(min(t[i:] + t[:i] for i in range(3)) for t in rows)


# --- same bytes as the command line -------------------------------------------------------------


@pytest.mark.parametrize(
    "options, flags",
    [
        ({}, []),
        ({"quality": 70, "clusters": 4, "segmentation": "kmeans"},
         ["--quality", "70", "--clusters", "4", "--segmentation", "kmeans"]),
        ({"codec": "jpeg", "jpeg_quality": 80, "lattice": "64x64"},
         ["--codec", "jpeg", "--jpeg-quality", "80", "--lattice", "64x64"]),
        ({"codec": "mpeg4", "qscale": 3, "gop": 8, "predictor": "affine"},
         ["--codec", "mpeg4", "--qscale", "3", "--gop", "8", "--predictor", "affine"]),
        ({"segment_frames": 12, "reorder": True}, ["--segment-frames", "12", "--reorder"]),
    ],
    ids=["tdct-defaults", "tdct-kmeans", "jpeg", "mpeg4", "segments-reorder"],
)
def test_arrays_encode_to_the_bytes_the_cli_writes(tmp_path, cli, options, flags):
    positions, faces = cloth(n=12, frames=30)
    cache = write_pc2(tmp_path, positions, faces)
    expected = cli_encode(cli, cache, tmp_path / "cli.mcgv", *flags)
    # PC2 carries no frame rate; the arrays then carry none either.
    assert mcgv_video.encode(positions, faces, **options) == expected


def test_a_read_animation_encodes_to_the_bytes_the_cli_writes(tmp_path, cli):
    # A glTF with UVs and materials: they travel through Animation unchanged.
    # One predictor and segmentation, not the automatic choice's eight trials: a quarter of the time.
    path = media("CesiumMan.glb")
    options = dict(quality=60, segmentation="kmeans", clusters=20, predictor="affine")
    flags = ["--quality", "60", "--segmentation", "kmeans", "--clusters", "20", "--predictor", "affine"]
    expected = cli_encode(cli, path, tmp_path / "cli.mcgv", *flags)
    animation = mcgv_video.read_animation(path)
    assert animation.uvs is not None and animation.material_names and animation.fps
    assert mcgv_video.encode(animation, **options) == expected
    # A pickled animation (as a cluster ships it) still gives the same stream.
    assert mcgv_video.encode(pickle.loads(pickle.dumps(animation)), **options) == expected


def test_a_budget_is_met_with_the_bytes_and_report_the_cli_gives(tmp_path, cli):
    positions, faces = cloth(n=16, frames=40)
    cache = write_pc2(tmp_path, positions, faces)
    limit = int(len(mcgv_video.encode(positions, faces)) * 0.7)
    stream, report = mcgv_video.encode_to_budget(positions, faces, target_size=limit)
    assert len(stream) <= limit and report["achieved"] == len(stream)
    assert report["quality"] < 50 and report["encodes"] == len(report["trials"]) >= 2
    assert report["within_tolerance"] == (len(stream) >= limit * 0.97)
    out = tmp_path / "cli.mcgv"
    printed = subprocess.run(
        [cli, "encode", str(cache), "-o", str(out), "--quiet", "--json", "--target-size", str(limit)],
        check=True, capture_output=True, text=True,
    ).stdout
    assert out.read_bytes() == stream and json.loads(printed)["budget"] == report
    # An error bound: eval's vertex RMSE of the stream is within it.
    stream, report = mcgv_video.encode_to_budget(positions, faces, target_error=2e-4)
    measured = mcgv_video.eval(Animation(positions, faces), stream)["vertex_rmse"]
    assert measured <= 2e-4 and measured == pytest.approx(report["achieved"], rel=1e-6)
    for budgets, name in [({}, "target_size"), (dict(target_size=limit, target_error=1e-4), "target_size"),
                          (dict(target_size=limit, step=1e-3), "step"), (dict(target_size=0), "target_size")]:
        with pytest.raises(InvalidOptionError) as caught:
            mcgv_video.encode_to_budget(positions, faces, **budgets)
        assert caught.value.option == name, (budgets, caught.value)


def test_the_type_stubs_name_the_keywords_the_binding_takes():
    # `encode`'s options are checked against `KEYWORDS` in python/src/options.rs; the stub lists
    # them again for editors and type checkers: the two must not drift apart.
    source = (REPO / "python" / "src" / "options.rs").read_text()
    listed = re.search(r"pub const KEYWORDS: \[&str; \d+\] = \[(.*?)\];", source, re.S)
    keywords = set(re.findall(r'"(\w+)"', listed.group(1)))
    stub = ast.parse((REPO / "python" / "mcgv_video" / "_native.pyi").read_text())
    functions = {f.name: f for f in stub.body if isinstance(f, ast.FunctionDef)}

    def keyword_names(name):
        return {a.arg for a in functions[name].args.kwonlyargs}

    call = {"fps", "uvs", "progress", "threads"}
    assert keyword_names("encode") - call == keywords
    targets = {"target_size", "target_bpvf", "target_error", "target_max_error"}
    # No `step`: the search chooses it.
    assert keyword_names("encode_to_budget") - call == (keywords - {"step"}) | targets


def test_segments_coded_out_of_order_join_into_encode_s_stream():
    positions, faces = cloth(n=10, frames=40)
    whole = mcgv_video.encode(positions, faces, segment_frames=16)
    animation = Animation(positions, faces)
    analysis_frames = mcgv_video.analysis_frames(40, 16)
    assert analysis_frames[0] == 0 and analysis_frames[-1] == 39 and len(analysis_frames) == 16
    analysis = Animation(positions[analysis_frames], faces)
    coder = SegmentedEncoder.start(analysis, 16)
    ranges = mcgv_video.segment_ranges(40, 16)
    assert ranges == [(0, 16), (16, 32), (32, 40)]
    # The analysis travels as bytes: workers and the joiner resume from it without redoing it.
    shared = coder.analysis()
    worker = SegmentedEncoder.resume(shared)
    coded = {a: worker.code_segment(a, positions[a:b]) for a, b in reversed(ranges)}
    assert coded[0] == coder.code_segment(0, positions[0:16])
    with pytest.raises(UsageError, match="other encoding options"):
        SegmentedEncoder.resume(shared, quality=70)
    joiner = SegmentedEncoder.resume(shared)
    with pytest.raises(UsageError, match="in order"):
        joiner.add(coded[16])
    for a, _ in ranges:
        joiner.add(coded[a])
    assert joiner.frames == 40
    assert joiner.finish() == whole
    # An encoder started from a pickled analysis clip makes the same analysis.
    assert SegmentedEncoder.start(pickle.loads(pickle.dumps(analysis)), 16).analysis() == shared
    with pytest.raises(UsageError, match="finished"):
        joiner.finish()
    assert len(animation) == 40


# --- arrays in and out --------------------------------------------------------------------------


def test_decoder_gives_float32_arrays_and_frames_agree():
    positions, faces = cloth(n=14, frames=25)
    stream = mcgv_video.encode(positions, faces, quality=60, fps=24.0, segment_frames=10)
    decoder = Decoder(bytearray(stream))
    header = decoder.header
    assert (header["codec"], header["vertices"], header["frames"], header["fps"]) == ("tdct", 196, 25, 24.0)
    assert header["bytes"] == len(stream) and header["segments"] == 3
    assert len(decoder) == 25 and decoder.segments() == [(0, 10), (10, 20), (20, 25)]
    every = decoder.all()
    assert every.dtype == np.float32 and every.shape == (25, 196, 3)
    assert np.array_equal(decoder.frames(7, 18), every[7:18])
    assert decoder.frames(3, 3).shape == (0, 196, 3)
    assert np.allclose(decoder.frame(-1), every[24], atol=1e-6)
    # The same triangles (the stream may store them in another order, each rotated).
    assert canonical(decoder.faces) == canonical(faces)
    # Within the step of quality 60 (about 1/1000 of the diagonal, √2 · 1.5): far below 1 %.
    assert np.abs(every - positions).max() < 0.01
    with pytest.raises(IndexError, match="frame 25"):
        decoder.frame(25)
    with pytest.raises(UsageError, match="frames 20..26"):
        decoder.frames(20, 26)
    assert "bands" in decoder.describe()
    assert sum(size for _, size in decoder.parts()) == len(stream)


def test_eval_measures_a_stream_arrays_and_animations_alike():
    positions, faces = cloth(n=12, frames=20)
    stream = mcgv_video.encode(positions, faces, quality=40)
    original = Animation(positions, faces)
    of_stream = mcgv_video.eval(original, stream)
    decoded = Decoder(stream).all()
    of_arrays = mcgv_video.eval(positions, decoded, faces=faces)
    assert of_stream["bpvf"] == pytest.approx(len(stream) * 8 / (144 * 20))
    assert of_arrays["bpvf"] is None
    for key in ("rmse", "vertex_rmse", "kg_error", "hausdorff"):
        assert of_stream[key] == pytest.approx(of_arrays[key]), key
    assert 0 < of_stream["rmse"] < 1e-3 and of_stream["frame_rmse"].shape == (20,)
    assert mcgv_video.eval(original, original)["rmse"] == 0.0


def test_eval_samples_long_runs_as_the_command_does_and_every_frame_on_request():
    positions, faces = cloth(n=12, frames=48)
    stream = mcgv_video.encode(positions, faces, quality=40)
    original = Animation(positions, faces)
    sampled = mcgv_video.eval(original, stream)
    every = mcgv_video.eval(original, stream, every_frame=True)
    assert sampled["rmse"] == pytest.approx(every["rmse"], rel=0.01)
    for key in ("vertex_rmse", "kg_error", "hausdorff", "bpvf"):
        assert sampled[key] == every[key], key
    assert every["frame_rmse"].shape == sampled["frame_rmse"].shape == (48,)


def test_progress_reports_frames_and_a_raising_callback_stops_the_call():
    positions, faces = cloth(n=10, frames=30)
    reports = []
    mcgv_video.encode(positions, faces, progress=lambda done, total: reports.append((done, total)))
    assert reports and all(b[0] >= a[0] for a, b in zip(reports, reports[1:]))
    assert all(done <= total for done, total in reports) and reports[-1][0] >= 30

    def fail(done, total):
        raise KeyError("stop here")

    with pytest.raises(KeyError, match="stop here"):
        mcgv_video.encode(positions, faces, progress=fail)


# --- errors name the argument -------------------------------------------------------------------


def test_dtype_and_shape_errors_name_the_argument():
    positions, faces = cloth(n=6, frames=4)
    cases = [
        (dict(positions=positions.astype(np.float64)), TypeError, r"positions: .*float32.*got a float64.*astype"),
        (dict(positions=positions[0]), TypeError, r"positions: expected .*\(frames, vertices, 3\)"),
        (dict(positions=positions[..., :2].copy()), ValueError, r"positions: .*shape \(4, 36, 2\)"),
        (dict(positions=positions.tolist()), TypeError, r"positions: expected a numpy .* got list"),
        (dict(faces=faces.astype(np.float32)), TypeError, r"faces: expected an integer .*float32"),
        (dict(faces=faces[:, :2]), ValueError, r"faces: .*shape \(50, 2\)"),
        (dict(faces=faces + 100), ValueError, r"faces: triangle 0 has vertex index 100, outside 0..36"),
        (dict(faces=-faces - 1), ValueError, r"faces: triangle 0 has vertex index -1"),
        (dict(faces=None), TypeError, r"faces: required"),
        (dict(uvs=np.zeros((36, 3), np.float32)), ValueError, r"uvs: .*\(36, 2\)"),
        (dict(uvs=np.zeros((36, 2))), TypeError, r"uvs: .*float64"),
        (dict(fps=-1.0), ValueError, r"fps: -1"),
    ]
    for changes, error, pattern in cases:
        arguments = dict(positions=positions, faces=faces) | changes
        with pytest.raises(error, match=pattern):
            mcgv_video.encode(arguments.pop("positions"), arguments.pop("faces"), **arguments)


def test_option_errors_are_typed_and_name_the_option():
    positions, faces = cloth(n=6, frames=4)
    cases = [
        (dict(quality=0), "quality"),
        (dict(quality=1000), "quality"),
        (dict(codec="png"), "codec"),
        (dict(qscale=3), "qscale"),  # tdct has no qscale: MPEG-4's
        (dict(codec="jpeg", qp=30), "qp"),
        (dict(lattice="64"), "lattice"),
        (dict(segmentation="decimation", clusters=5), "clusters"),
        (dict(threads=0), "threads"),
    ]
    for options, name in cases:
        with pytest.raises(InvalidOptionError) as caught:
            mcgv_video.encode(positions, faces, **options)
        assert caught.value.option == name, (options, caught.value)
        assert isinstance(caught.value, ValueError)
    with pytest.raises(InvalidOptionError, match="applies to the mpeg4 codec only"):
        mcgv_video.encode(positions, faces, qscale=3)
    with pytest.raises(TypeError, match="unexpected keyword argument 'qualty'"):
        mcgv_video.encode(positions, faces, qualty=3)
    with pytest.raises(TypeError, match="quality: expected an int, got str"):
        mcgv_video.encode(positions, faces, quality="high")


def test_missing_files_raise_file_errors():
    with pytest.raises(mcgv_video.FileError) as caught:
        mcgv_video.read_animation("no/such/file.pc2")
    assert isinstance(caught.value, OSError) and isinstance(caught.value, McgvError)


# --- damaged streams raise ----------------------------------------------------------------------


def test_damaged_streams_raise_stream_errors_never_crash():
    positions, faces = cloth(n=10, frames=16)
    stream = mcgv_video.encode(positions, faces, codec="jpeg")
    for garbage in (b"", b"MCGV", stream[:40], bytes(200), b"\xff" * 1000):
        with pytest.raises(StreamError):
            Decoder(garbage).all()
    # Every part is checksummed: a flipped byte anywhere is refused, at open or at decode.
    rng = np.random.default_rng(1)
    for at in sorted(rng.choice(len(stream), size=40, replace=False)):
        damaged = bytearray(stream)
        damaged[at] ^= 0x5A
        with pytest.raises(StreamError):
            Decoder(bytes(damaged)).all()
    with pytest.raises(TypeError, match="stream: expected the bytes"):
        Decoder(12)


# --- the interpreter's lock is released ---------------------------------------------------------


def test_other_threads_run_while_one_encodes_and_decodes():
    positions, faces = cloth(n=60, frames=60)
    done = threading.Event()
    result = {}

    def code():
        start = time.perf_counter()
        stream = mcgv_video.encode(positions, faces, segmentation="kmeans", predictor="affine")
        result["encode"] = time.perf_counter() - start
        result["stream"] = stream
        done.set()

    worker = threading.Thread(target=code)
    ticks = []
    worker.start()
    while not done.is_set():
        ticks.append(time.perf_counter())
        sum(range(200))  # pure Python work, which needs the lock
    worker.join()
    assert result["encode"] > 0.2, "the encoding is too short to tell"
    gaps = np.diff(ticks)
    # With the lock held for the whole encoding this thread would stall for all of it.
    assert len(ticks) > 100 and gaps.max() < result["encode"] / 4, (len(ticks), gaps.max(), result["encode"])
