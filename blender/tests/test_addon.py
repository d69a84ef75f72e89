"""The Blender add-on, headless with `bpy` from PyPI: a generated armature-driven mesh exported
through File › Export › mcgv-video, imported back through File › Import, and the imported
object's evaluated positions compared frame for frame with the stream's decode."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

import bpy  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
import io_mesh_mcgv  # noqa: E402

import mcgv_video  # noqa: E402

FRAMES = (1, 30)


def rigged_tube():
    """A tube of 24 rings × 16 vertices bent by a two-bone armature whose second bone swings over
    the frame range: the mesh moves only through the armature modifier."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = FRAMES
    rings, sides, length = 24, 16, 4.0
    verts = [
        (0.4 * math.cos(2 * math.pi * s / sides), 0.4 * math.sin(2 * math.pi * s / sides), length * r / (rings - 1))
        for r in range(rings)
        for s in range(sides)
    ]
    quads = [
        (r * sides + s, r * sides + (s + 1) % sides, (r + 1) * sides + (s + 1) % sides, (r + 1) * sides + s)
        for r in range(rings - 1)
        for s in range(sides)
    ]
    mesh = bpy.data.meshes.new("tube")
    mesh.from_pydata(verts, [], quads)
    tube = bpy.data.objects.new("tube", mesh)
    scene.collection.objects.link(tube)

    armature = bpy.data.armatures.new("rig")
    rig = bpy.data.objects.new("rig", armature)
    scene.collection.objects.link(rig)
    bpy.context.view_layer.objects.active = rig
    bpy.ops.object.mode_set(mode="EDIT")
    lower = armature.edit_bones.new("lower")
    lower.head, lower.tail = (0, 0, 0), (0, 0, length / 2)
    upper = armature.edit_bones.new("upper")
    upper.head, upper.tail = (0, 0, length / 2), (0, 0, length)
    upper.parent = lower
    bpy.ops.object.mode_set(mode="OBJECT")

    groups = {name: tube.vertex_groups.new(name=name) for name in ("lower", "upper")}
    for i, (_, _, z) in enumerate(verts):
        w = min(max((z - length / 2) / 1.0 + 0.5, 0.0), 1.0)  # a smooth blend around the joint
        groups["lower"].add([i], 1.0 - w, "REPLACE")
        groups["upper"].add([i], w, "REPLACE")
    modifier = tube.modifiers.new("rig", "ARMATURE")
    modifier.object = rig

    pose = rig.pose.bones["upper"]
    pose.rotation_mode = "XYZ"
    for frame, angle in ((FRAMES[0], 0.0), (15, 1.1), (FRAMES[1], -0.6)):
        pose.rotation_euler = (angle, 0.3 * angle, 0.0)
        pose.keyframe_insert("rotation_euler", frame=frame)
    rig.location = (0.0, 0.0, 0.0)
    for obj in scene.objects:
        obj.select_set(obj is tube)
    bpy.context.view_layer.objects.active = tube
    return tube


@pytest.fixture(scope="module")
def addon():
    io_mesh_mcgv.register()
    yield io_mesh_mcgv
    io_mesh_mcgv.unregister()


def evaluated(obj, frame):
    scene = bpy.context.scene
    scene.frame_set(frame)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    ev = obj.evaluated_get(depsgraph)
    mesh = ev.to_mesh()
    co = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("co", co)
    ev.to_mesh_clear()
    return co.reshape(-1, 3)


def test_export_then_import_plays_the_stream_s_frames(tmp_path, addon):
    tube = rigged_tube()
    source = np.stack([evaluated(tube, f) for f in range(FRAMES[0], FRAMES[1] + 1)])
    # The armature moves the tube: frames differ by far more than the coding error.
    assert np.abs(source[15] - source[0]).max() > 0.5

    path = tmp_path / "tube.mcgv"
    assert bpy.ops.export_scene.mcgv(filepath=str(path), codec="tdct", quality=60) == {"FINISHED"}
    stream = path.read_bytes()
    decoder = mcgv_video.Decoder(stream)
    decoded = decoder.all()
    assert decoder.header["frames"] == 30 and decoder.header["vertices"] == 24 * 16
    assert decoder.header["fps"] == pytest.approx(24.0)
    diagonal = np.linalg.norm(source[0].max(0) - source[0].min(0))
    assert np.abs(decoded - source).max() < 0.01 * diagonal
    assert mcgv_video.eval(source, stream, faces=decoder.faces)["rmse"] < 1e-3

    assert bpy.ops.import_scene.mcgv(filepath=str(path)) == {"FINISHED"}
    imported = bpy.context.view_layer.objects.active
    assert imported is not tube and imported.modifiers[0].type == "MESH_CACHE"
    assert (tmp_path / "tube.pc2").stat().st_size == 32 + 30 * 24 * 16 * 12
    for f in range(30):
        positions = evaluated(imported, FRAMES[0] + f)
        # The cache puts the decoded float32 positions on the vertices as they are.
        assert np.array_equal(positions, decoded[f]), f"frame {f}"
    faces = np.empty(len(imported.data.polygons) * 3, np.int64)
    imported.data.polygons.foreach_get("vertices", faces)
    assert np.array_equal(faces.reshape(-1, 3), decoder.faces)


def test_export_codec_and_quality_come_from_the_panel(tmp_path, addon):
    rigged_tube()
    low, high = tmp_path / "low.mcgv", tmp_path / "high.mcgv"
    bpy.ops.export_scene.mcgv(filepath=str(low), codec="jpeg", quality=20)
    bpy.ops.export_scene.mcgv(filepath=str(high), codec="jpeg", quality=90)
    assert mcgv_video.Decoder(low.read_bytes()).header["codec"] == "jpeg"
    assert mcgv_video.Decoder(high.read_bytes()).header["quality"] == 90
    assert low.stat().st_size < high.stat().st_size


def test_export_to_a_size_or_an_error_budget(tmp_path, addon):
    rigged_tube()
    full, small, bounded = tmp_path / "full.mcgv", tmp_path / "small.mcgv", tmp_path / "bound.mcgv"
    bpy.ops.export_scene.mcgv(filepath=str(full))
    kb = full.stat().st_size * 0.7 / 1000
    assert bpy.ops.export_scene.mcgv(filepath=str(small), budget="SIZE", target_kb=kb) == {"FINISHED"}
    assert small.stat().st_size <= int(kb * 1000)
    assert mcgv_video.Decoder(small.read_bytes()).header["quality"] < 50
    written = io_mesh_mcgv.export_mcgv(
        bpy.context, bpy.context.active_object, str(bounded), target_error=2e-4
    )
    assert written["encodes"] >= 2 and written["quality"] != 50
    positions, _ = io_mesh_mcgv.evaluated_animation(bpy.context, bpy.context.active_object, *FRAMES, True)
    positions = positions.astype(np.float64)
    decoded = mcgv_video.Decoder(bounded.read_bytes()).all().astype(np.float64)
    diagonal = np.linalg.norm(positions[0].max(axis=0) - positions[0].min(axis=0))
    rmse = np.sqrt(np.mean(np.sum((decoded - positions) ** 2, axis=2))) / diagonal
    assert rmse <= 2e-4 * (1 + 1e-6), rmse


def test_nothing_to_export_is_reported_not_raised(tmp_path, addon):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    with pytest.raises(RuntimeError, match="select a mesh"):
        bpy.ops.export_scene.mcgv(filepath=str(tmp_path / "none.mcgv"))
    assert not (tmp_path / "none.mcgv").exists()
