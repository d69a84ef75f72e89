"""mcgv-video for Blender: File › Export › mcgv-video and File › Import › mcgv-video.

Export writes the active object's *evaluated* animation — armature, modifiers, shape keys,
simulations, as the viewport shows it — over the scene's frame range into a ``.mcgv`` stream,
with the codec and quality (or a size or error budget) chosen in the export panel. Import reads a ``.mcgv`` back as a mesh
whose frames play on the timeline through a Mesh Cache modifier fed from a PC2 point cache of
the decoded frames (``NAME.pc2`` beside the ``.mcgv``).

Why a mesh cache and not shape keys: the modifier (deform mode *overwrite*) puts the decoded
``float32`` positions on the vertices exactly, it reads one frame at a time from the file (shape
keys would hold every frame of the clip in the ``.blend`` and in memory: one key per frame,
each with every vertex, and one animated value per key), and a PC2 cache is what Blender's and
other tools' cache workflows exchange. The price is a side file, which must travel with the
``.blend`` (the modifier names it relative to a saved ``.blend``).

The coding is done by the ``mcgv_video`` Python package (a compiled wheel): it must be
importable from Blender's Python (see blender/README.md). Pure Python, no codec logic here.
"""

from __future__ import annotations

import os
import struct
from typing import Optional

import bpy
import numpy as np
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, StringProperty
from bpy_extras.io_utils import ExportHelper, ImportHelper

bl_info = {
    "name": "mcgv-video",
    "author": "mcgv-video",
    "version": (0, 1, 0),
    "blender": (4, 2, 0),
    "location": "File > Import-Export > mcgv-video (.mcgv)",
    "description": "Compress a mesh's evaluated animation into a .mcgv stream, and read one back",
    "category": "Import-Export",
}

CODECS = [
    ("tdct", "Temporal DCT", "Smallest at equal error (the default)"),
    ("jpeg", "JPEG", "Every frame decodes alone"),
    ("mpeg4", "MPEG-4", "Geometry images as MPEG-4 Part 2 video"),
    ("hevc", "HEVC", "Geometry images as HEVC video (10/12 bits)"),
    ("av1", "AV1", "Geometry images as AV1 video (10/12 bits)"),
]


class AnimationError(Exception):
    """The object's animation cannot be coded (no mesh, changing vertex count, …)."""


def _mcgv():
    try:
        import mcgv_video
    except ImportError as e:  # pragma: no cover - depends on the installation
        raise AnimationError(
            "the mcgv_video Python package is not installed in Blender's Python "
            f"({e}); see blender/README.md"
        ) from e
    return mcgv_video


def evaluated_animation(
    context, obj, frame_start: int, frame_end: int, world_space: bool = True
) -> tuple[np.ndarray, np.ndarray]:
    """The evaluated positions of ``obj`` at frames ``frame_start..frame_end`` (inclusive),
    ``float32`` ``(frames, vertices, 3)``, and its triangles ``(triangles, 3)`` (``int64``):
    what the depsgraph gives after every modifier, in world space unless ``world_space`` is
    false (then in the object's own space)."""
    if obj is None or obj.type not in {"MESH", "CURVE", "SURFACE", "META", "FONT"}:
        raise AnimationError("select a mesh object to export")
    if frame_end < frame_start:
        raise AnimationError(f"empty frame range {frame_start}..{frame_end}")
    scene = context.scene
    current = scene.frame_current
    frames, faces = [], None
    try:
        for f in range(frame_start, frame_end + 1):
            scene.frame_set(f)
            depsgraph = context.evaluated_depsgraph_get()
            evaluated = obj.evaluated_get(depsgraph)
            mesh = evaluated.to_mesh()
            try:
                count = len(mesh.vertices)
                if frames and count != frames[0].shape[0]:
                    raise AnimationError(
                        f"{obj.name}: {count} vertices at frame {f}, {frames[0].shape[0]} at frame "
                        f"{frame_start}: a modifier changes the topology over time"
                    )
                co = np.empty(count * 3, dtype=np.float32)
                mesh.vertices.foreach_get("co", co)
                co = co.reshape(count, 3)
                if world_space:
                    matrix = np.array(evaluated.matrix_world, dtype=np.float64)
                    co = (co @ matrix[:3, :3].T + matrix[:3, 3]).astype(np.float32)
                frames.append(co)
                if faces is None:
                    mesh.calc_loop_triangles()
                    tris = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int64)
                    mesh.loop_triangles.foreach_get("vertices", tris)
                    faces = tris.reshape(-1, 3)
            finally:
                evaluated.to_mesh_clear()
    finally:
        scene.frame_set(current)
    if faces is None or len(faces) == 0:
        raise AnimationError(f"{obj.name}: the evaluated mesh has no faces")
    return np.stack(frames), faces


def export_mcgv(
    context,
    obj,
    filepath: str,
    *,
    codec: str = "tdct",
    quality: int = 50,
    target_size: Optional[int] = None,
    target_error: Optional[float] = None,
    world_space: bool = True,
    frame_start: Optional[int] = None,
    frame_end: Optional[int] = None,
) -> dict:
    """Writes ``obj``'s evaluated animation over the scene's frame range (or the one given) to
    ``filepath``; returns what it wrote: ``bytes``, ``frames``, ``vertices``, ``bpvf``, the
    ``quality`` coded and the ``encodes`` it took. With a budget (``target_size`` bytes or
    ``target_error``, the vertex RMSE over the bounding-box diagonal; not both) the quality is the
    one found by ``mcgv_video.encode_to_budget``, starting from ``quality``."""
    mcgv_video = _mcgv()
    scene = context.scene
    start = scene.frame_start if frame_start is None else frame_start
    end = scene.frame_end if frame_end is None else frame_end
    positions, faces = evaluated_animation(context, obj, start, end, world_space)
    fps = scene.render.fps / scene.render.fps_base
    options = dict(codec=codec, quality=quality, fps=fps)
    if target_size is None and target_error is None:
        stream = mcgv_video.encode(positions, faces, **options)
        found = {"quality": quality, "encodes": 1}
    else:
        stream, search = mcgv_video.encode_to_budget(
            positions, faces, target_size=target_size, target_error=target_error, **options
        )
        found = {"quality": search["quality"], "encodes": search["encodes"]}
    folder = os.path.dirname(os.path.abspath(filepath))
    os.makedirs(folder, exist_ok=True)
    partial = filepath + ".part"
    with open(partial, "wb") as out:
        out.write(stream)
    os.replace(partial, filepath)
    frames, vertices = positions.shape[:2]
    return {
        "bytes": len(stream),
        "frames": frames,
        "vertices": vertices,
        "bpvf": len(stream) * 8 / (frames * vertices),
        **found,
    }


def write_pc2(path: str, decoder) -> None:
    """The decoder's frames as a PC2 point cache, a segment at a time (the whole clip is never
    held at once)."""
    header = decoder.header
    partial = path + ".part"
    with open(partial, "wb") as out:
        out.write(b"POINTCACHE2\0")
        out.write(struct.pack("<iiffi", 1, header["vertices"], 0.0, 1.0, header["frames"]))
        for start, end in decoder.segments():
            out.write(np.ascontiguousarray(decoder.frames(start, end), dtype="<f4").tobytes())
    os.replace(partial, path)


def import_mcgv(
    context,
    filepath: str,
    *,
    cache_path: Optional[str] = None,
    frame_start: Optional[int] = None,
    set_frame_range: bool = True,
):
    """Reads ``filepath`` as a new mesh object whose frames play from ``frame_start`` (default:
    the scene's start) through a Mesh Cache modifier on ``cache_path`` (default: the stream's
    name with ``.pc2``); returns the object."""
    mcgv_video = _mcgv()
    with open(filepath, "rb") as f:
        decoder = mcgv_video.Decoder(f.read())
    header = decoder.header
    frames, vertices = header["frames"], header["vertices"]
    first = decoder.frame(0)
    faces = decoder.faces.astype(np.int32)
    name = os.path.splitext(os.path.basename(filepath))[0]
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(vertices)
    mesh.vertices.foreach_set("co", first.ravel())
    mesh.loops.add(faces.size)
    mesh.loops.foreach_set("vertex_index", faces.ravel())
    mesh.polygons.add(len(faces))
    mesh.polygons.foreach_set("loop_start", np.arange(0, faces.size, 3, dtype=np.int32))
    uvs = decoder.uvs
    if uvs is not None:
        layer = mesh.uv_layers.new(name="UVMap")
        layer.data.foreach_set("uv", uvs[faces.ravel()].ravel())
    mesh.update()
    mesh.validate()
    obj = bpy.data.objects.new(name, mesh)
    context.collection.objects.link(obj)

    cache = cache_path or os.path.splitext(filepath)[0] + ".pc2"
    write_pc2(cache, decoder)
    scene = context.scene
    start = scene.frame_start if frame_start is None else frame_start
    modifier = obj.modifiers.new("mcgv-video", "MESH_CACHE")
    modifier.cache_format = "PC2"
    modifier.filepath = bpy.path.relpath(cache) if bpy.data.filepath else cache
    modifier.deform_mode = "OVERWRITE"
    modifier.interpolation = "NONE"
    modifier.time_mode = "FRAME"
    modifier.play_mode = "SCENE"
    modifier.frame_start = start
    modifier.frame_scale = 1.0
    modifier.forward_axis = "POS_Y"
    modifier.up_axis = "POS_Z"
    if set_frame_range:
        scene.frame_start = start
        scene.frame_end = start + frames - 1
        if header["fps"] > 0:
            scene.render.fps = max(1, round(header["fps"]))
            scene.render.fps_base = scene.render.fps / header["fps"]
    for other in context.selected_objects:
        other.select_set(False)
    obj.select_set(True)
    context.view_layer.objects.active = obj
    return obj


class EXPORT_SCENE_OT_mcgv(bpy.types.Operator, ExportHelper):
    """Write the active object's evaluated animation (scene frame range) as a .mcgv stream"""

    bl_idname = "export_scene.mcgv"
    bl_label = "Export mcgv-video"
    bl_options = {"PRESET"}

    filename_ext = ".mcgv"
    filter_glob: StringProperty(default="*.mcgv", options={"HIDDEN"})
    codec: EnumProperty(name="Codec", items=CODECS, default="tdct")
    quality: IntProperty(
        name="Quality", description="1..100, higher is better (50: 1/1000 of the diagonal)",
        default=50, min=1, max=100,
    )
    budget: EnumProperty(
        name="Budget",
        items=[
            ("QUALITY", "Quality", "Code at the quality above"),
            ("SIZE", "Size", "The quality whose file fits the size below (a few encodes)"),
            ("ERROR", "Error", "The quality whose vertex error stays under the bound below"),
        ],
        default="QUALITY",
    )
    target_kb: FloatProperty(
        name="Size (kB)", description="Largest file, in kilobytes (1000 bytes)", default=200.0,
        min=0.001,
    )
    target_error: FloatProperty(
        name="Error", description="Largest vertex RMSE, as a fraction of the bounding-box diagonal",
        default=2e-4, min=1e-8, max=1.0, precision=6,
    )
    world_space: BoolProperty(
        name="World Space", description="Positions with the object's transform applied", default=True
    )

    def execute(self, context):
        obj = context.active_object
        budget = {
            "QUALITY": {},
            "SIZE": {"target_size": int(self.target_kb * 1000)},
            "ERROR": {"target_error": self.target_error},
        }[self.budget]
        try:
            written = export_mcgv(
                context, obj, self.filepath, codec=self.codec, quality=self.quality,
                world_space=self.world_space, **budget,
            )
        except Exception as e:  # every failure is reported in the UI, none crashes Blender
            self.report({"ERROR"}, f"mcgv-video: {e}")
            return {"CANCELLED"}
        searched = f", quality {written['quality']} in {written['encodes']} encodes" if budget else ""
        self.report(
            {"INFO"},
            f"mcgv-video: {written['bytes']} bytes, {written['bpvf']:.3f} bpvf "
            f"({written['vertices']} vertices x {written['frames']} frames{searched})",
        )
        return {"FINISHED"}


class IMPORT_SCENE_OT_mcgv(bpy.types.Operator, ImportHelper):
    """Read a .mcgv stream as a mesh animated by a Mesh Cache modifier (PC2 beside the file)"""

    bl_idname = "import_scene.mcgv"
    bl_label = "Import mcgv-video"
    bl_options = {"UNDO"}

    filename_ext = ".mcgv"
    filter_glob: StringProperty(default="*.mcgv", options={"HIDDEN"})
    set_frame_range: BoolProperty(
        name="Set Frame Range", description="Scene frame range and rate from the stream", default=True
    )

    def execute(self, context):
        try:
            import_mcgv(context, self.filepath, set_frame_range=self.set_frame_range)
        except Exception as e:
            self.report({"ERROR"}, f"mcgv-video: {e}")
            return {"CANCELLED"}
        return {"FINISHED"}


def _menu_export(self, context):
    self.layout.operator(EXPORT_SCENE_OT_mcgv.bl_idname, text="mcgv-video (.mcgv)")


def _menu_import(self, context):
    self.layout.operator(IMPORT_SCENE_OT_mcgv.bl_idname, text="mcgv-video (.mcgv)")


_CLASSES = (EXPORT_SCENE_OT_mcgv, IMPORT_SCENE_OT_mcgv)


def register():
    for cls in _CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.TOPBAR_MT_file_export.append(_menu_export)
    bpy.types.TOPBAR_MT_file_import.append(_menu_import)


def unregister():
    bpy.types.TOPBAR_MT_file_import.remove(_menu_import)
    bpy.types.TOPBAR_MT_file_export.remove(_menu_export)
    for cls in reversed(_CLASSES):
        bpy.utils.unregister_class(cls)
