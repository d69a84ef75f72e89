"""A rigged character from a .blend file through the add-on, headless: media/CesiumMan.glb is
imported with Blender's glTF importer and saved as a .blend; that file is opened, the skinned
mesh exported with File › Export › mcgv-video, the stream imported back with File › Import, and
the figures printed: sizes, error against the evaluated source, and the imported frames against
the stream's decode. For comparison it also builds the shape-key form of the same frames (one
key per frame) and saves both .blend files.

    .venv/bin/python blender/examples/rigged_character.py [OUT_DIR]     (bpy and mcgv_video installed)
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

import bpy  # first: it puts Blender's own modules (addon_utils) on the path
import numpy as np

import addon_utils  # noqa: E402

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
import io_mesh_mcgv  # noqa: E402

import mcgv_video  # noqa: E402


def evaluated(obj, frame: int, world: bool) -> np.ndarray:
    bpy.context.scene.frame_set(frame)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    ev = obj.evaluated_get(depsgraph)
    mesh = ev.to_mesh()
    co = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("co", co)
    co = co.reshape(-1, 3)
    if world:
        m = np.array(ev.matrix_world, dtype=np.float64)
        co = (co @ m[:3, :3].T + m[:3, 3]).astype(np.float32)
    ev.to_mesh_clear()
    return co


def shape_key_copy(name: str, decoded: np.ndarray, faces: np.ndarray, start: int):
    """The decoded frames as relative shape keys: key f at value 1 on frame start + f only."""
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(decoded[0].tolist(), [], faces.tolist())
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.collection.objects.link(obj)
    obj.shape_key_add(name="basis", from_mix=False)
    for f, frame in enumerate(decoded):
        key = obj.shape_key_add(name=f"frame {f}", from_mix=False)
        key.data.foreach_set("co", frame.ravel())
        for at, value in ((start + f - 1, 0.0), (start + f, 1.0), (start + f + 1, 0.0)):
            key.value = value
            key.keyframe_insert("value", frame=at)
    return obj


def main(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon_utils.enable("io_scene_gltf2", default_set=True)
    bpy.ops.import_scene.gltf(filepath=str(HERE.parents[1] / "media" / "CesiumMan.glb"))
    action = next(a for a in bpy.data.actions)
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = (int(round(v)) for v in action.frame_range)
    source_blend = out / "CesiumMan.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(source_blend))

    # From here on, everything comes from the .blend file.
    bpy.ops.wm.open_mainfile(filepath=str(source_blend))
    io_mesh_mcgv.register()
    scene = bpy.context.scene
    character = next(o for o in scene.objects if o.type == "MESH" and any(m.type == "ARMATURE" for m in o.modifiers))
    for o in scene.objects:
        o.select_set(o is character)
    bpy.context.view_layer.objects.active = character
    frames = range(scene.frame_start, scene.frame_end + 1)
    source = np.stack([evaluated(character, f, world=True) for f in frames])

    stream_path = out / "CesiumMan.mcgv"
    start = time.perf_counter()
    assert bpy.ops.export_scene.mcgv(filepath=str(stream_path), codec="tdct", quality=50) == {"FINISHED"}
    export_s = time.perf_counter() - start
    stream = stream_path.read_bytes()
    decoder = mcgv_video.Decoder(stream)
    decoded = decoder.all()
    measures = mcgv_video.eval(source, stream, faces=decoder.faces)

    start = time.perf_counter()
    assert bpy.ops.import_scene.mcgv(filepath=str(stream_path)) == {"FINISHED"}
    import_s = time.perf_counter() - start
    imported = bpy.context.view_layer.objects.active
    played = np.stack([evaluated(imported, scene.frame_start + f, world=False) for f in range(len(decoded))])
    cache_blend = out / "CesiumMan-imported.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(cache_blend), relative_remap=True)

    keys = shape_key_copy("CesiumMan-shape-keys", decoded, decoder.faces, scene.frame_start)
    bpy.data.objects.remove(imported)
    by_keys = np.stack([evaluated(keys, scene.frame_start + f, world=False) for f in range(len(decoded))])
    keys_blend = out / "CesiumMan-shape-keys.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(keys_blend))

    h = decoder.header
    kib = lambda p: os.path.getsize(p) / 1024  # noqa: E731
    print(f"CesiumMan from {source_blend.name}: {h['vertices']} vertices, {h['triangles']} triangles, "
          f"{h['frames']} frames at {h['fps']:g} fps (scene frames {scene.frame_start}..{scene.frame_end})")
    print(f"export (tdct, quality 50): {len(stream)} bytes, {measures['bpvf']:.3f} bpvf, "
          f"RMSE {measures['rmse'] * 1e4:.3f}e-4, Hausdorff {measures['hausdorff']:.5f}, "
          f"vertex RMSE {measures['vertex_rmse'] * 1e4:.3f}e-4 of the diagonal; {export_s:.1f} s")
    print(f"uncompressed positions: {source.nbytes} bytes ({source.nbytes / len(stream):.0f} x the stream)")
    print(f"import: {import_s:.1f} s; PC2 cache {kib(stream_path.with_suffix('.pc2')):.0f} KiB, "
          f".blend {kib(cache_blend):.0f} KiB; imported frames vs decode: max |diff| "
          f"{np.abs(played - decoded).max():.3g}")
    print(f"shape keys instead: .blend {kib(keys_blend):.0f} KiB; frames vs decode: max |diff| "
          f"{np.abs(by_keys - decoded).max():.3g}")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp(prefix="mcgv-blender-")))
    # bpy 4.2 from PyPI crashes (SIGSEGV) at interpreter exit once its glTF importer has run, with
    # or without this add-on (`import_scene.gltf` then exit is enough): leave before that teardown.
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(0)
