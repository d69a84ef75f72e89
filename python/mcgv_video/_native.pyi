"""Type stubs of the compiled module (src/*.rs); the docstrings there say the rest."""

from __future__ import annotations

import os
from typing import Callable, Literal, Optional, Sequence, Tuple, TypedDict, Union, overload

import numpy as np
import numpy.typing as npt

Positions = npt.NDArray[np.float32]
"""Vertex positions, ``float32`` of shape ``(frames, vertices, 3)``."""
Faces = npt.NDArray[np.integer]
"""Triangles, an integer array of shape ``(triangles, 3)`` of vertex indices."""
Progress = Callable[[int, int], object]
"""``progress(done, total)``, in frames."""
Codec = Literal["tdct", "jpeg", "mpeg4", "hevc", "av1"]
StreamBytes = Union[bytes, bytearray, memoryview]

class Header(TypedDict):
    codec: Codec
    vertices: int
    frames: int
    triangles: int
    clusters: int
    requested_clusters: int
    quality: int
    affine_precision: float
    first_frame_bits: int
    reorder: bool
    fps: float
    predictor: Literal["affine", "skinning"]
    segments: int
    bytes: int

class Measures(TypedDict):
    rmse: float
    vertex_rmse: Optional[float]
    kg_error: Optional[float]
    hausdorff: float
    bpvf: Optional[float]
    frames: int
    vertices: int
    frame_rmse: npt.NDArray[np.float64]

class Animation:
    """An animated triangle mesh: one connectivity, a position per vertex and frame."""

    def __init__(
        self,
        positions: Positions,
        faces: Faces,
        *,
        fps: Optional[float] = None,
        uvs: Optional[npt.NDArray[np.float32]] = None,
    ) -> None: ...
    @property
    def positions(self) -> Positions:
        """A new ``float32`` array ``(frames, vertices, 3)``."""
    @property
    def faces(self) -> npt.NDArray[np.uint32]: ...
    @property
    def uvs(self) -> Optional[npt.NDArray[np.float32]]: ...
    @property
    def fps(self) -> Optional[float]: ...
    @property
    def frame_count(self) -> int: ...
    @property
    def vertex_count(self) -> int: ...
    @property
    def material_names(self) -> list[str]: ...
    def clip(self, start: int, end: int) -> Animation: ...
    def __len__(self) -> int: ...

def encode(
    positions: Union[Positions, Animation],
    faces: Optional[Faces] = None,
    *,
    codec: Codec = "tdct",
    quality: int = 50,
    fps: Optional[float] = None,
    uvs: Optional[npt.NDArray[np.float32]] = None,
    progress: Optional[Progress] = None,
    threads: Optional[int] = None,
    step: Optional[float] = None,
    clusters: int = 20,
    segmentation: Literal["auto", "kmeans", "decimation"] = "auto",
    e0: Optional[float] = None,
    predictor: Literal["auto", "affine", "skinning"] = "auto",
    weight_bits: int = 16,
    affine_precision: Optional[float] = None,
    first_frame_bits: Optional[int] = None,
    reorder: bool = False,
    uv_bits: int = 12,
    segment_frames: Optional[int] = 128,
    qscale: Optional[int] = None,
    qp: Optional[int] = None,
    jpeg_quality: Optional[int] = None,
    gop: Optional[int] = None,
    bit_depth: Union[int, Literal["auto"], None] = None,
    lattice: Union[str, Tuple[int, int], None] = None,
    padding: Optional[str] = None,
) -> bytes:
    """Encodes an animation into the bytes of a ``.mcgv`` stream (same options, same bytes as
    ``mcgv-video encode``); the interpreter's lock is released while coding."""

def encode_to_budget(
    positions: Union[Positions, Animation],
    faces: Optional[Faces] = None,
    *,
    target_size: Optional[int] = None,
    target_bpvf: Optional[float] = None,
    target_error: Optional[float] = None,
    target_max_error: Optional[float] = None,
    codec: Codec = "tdct",
    quality: int = 50,
    fps: Optional[float] = None,
    uvs: Optional[npt.NDArray[np.float32]] = None,
    progress: Optional[Progress] = None,
    threads: Optional[int] = None,
    clusters: int = 20,
    segmentation: Literal["auto", "kmeans", "decimation"] = "auto",
    e0: Optional[float] = None,
    predictor: Literal["auto", "affine", "skinning"] = "auto",
    weight_bits: int = 16,
    affine_precision: Optional[float] = None,
    first_frame_bits: Optional[int] = None,
    reorder: bool = False,
    uv_bits: int = 12,
    segment_frames: Optional[int] = 128,
    qscale: Optional[int] = None,
    qp: Optional[int] = None,
    jpeg_quality: Optional[int] = None,
    gop: Optional[int] = None,
    bit_depth: Union[int, Literal["auto"], None] = None,
    lattice: Union[str, Tuple[int, int], None] = None,
    padding: Optional[str] = None,
) -> Tuple[bytes, dict[str, object]]:
    """Encodes an animation at the quality whose stream fits one budget (``target_size`` bytes,
    ``target_bpvf``, ``target_error`` vertex RMSE or ``target_max_error``, errors over the first
    frame's bounding-box diagonal): never over it, within 3 % under it when the qualities allow.
    Returns the stream and the search's report (the command line's ``--json`` ``budget``: the
    ``quality`` found, ``achieved``, ``encodes``, ``trials``, …); same options, same bytes as
    ``mcgv-video encode --target-*``."""

def read_animation(
    path: Union[str, os.PathLike[str]],
    clip: Union[str, int, None] = None,
    *,
    fps: Optional[float] = None,
    base: Union[str, os.PathLike[str], None] = None,
    max_positions: Optional[int] = None,
) -> Animation:
    """Reads an OBJ folder or glob, a PC2 cache with its base OBJ, or a glTF/GLB clip."""

@overload
def eval(
    original: Animation, decoded: Union[Animation, Positions, bytes], *, every_frame: bool = False
) -> Measures: ...
@overload
def eval(
    original: Positions,
    decoded: Union[Animation, Positions, bytes],
    *,
    faces: Faces,
    every_frame: bool = False,
) -> Measures: ...

class Decoder:
    """A ``.mcgv`` stream opened from its bytes; frames come out as ``float32`` arrays."""

    def __init__(
        self,
        stream: StreamBytes,
        *,
        max_bands: Optional[int] = None,
        max_positions: Optional[int] = None,
    ) -> None: ...
    @property
    def header(self) -> Header: ...
    @property
    def faces(self) -> npt.NDArray[np.uint32]: ...
    @property
    def uvs(self) -> Optional[npt.NDArray[np.float32]]: ...
    def segments(self) -> list[Tuple[int, int]]: ...
    def parts(self) -> list[Tuple[str, int]]: ...
    def describe(self) -> dict[str, object]: ...
    def frame(self, i: int) -> npt.NDArray[np.float32]:
        """Frame ``i`` (negative counts from the end), ``(vertices, 3)``."""
    def frames(self, start: int, end: int) -> Positions:
        """Frames ``start`` to ``end - 1``: the values of ``all()[start:end]``."""
    def all(self) -> Positions: ...
    def animation(self) -> Animation: ...
    def __len__(self) -> int: ...

class FrameSource:
    """An animation file read a run of frames at a time."""

    def __init__(
        self,
        path: Union[str, os.PathLike[str]],
        clip: Union[str, int, None] = None,
        *,
        fps: Optional[float] = None,
        base: Union[str, os.PathLike[str], None] = None,
        max_positions: Optional[int] = None,
    ) -> None: ...
    @property
    def frame_count(self) -> int: ...
    @property
    def vertex_count(self) -> int: ...
    def read(self, start: int, end: int) -> Positions: ...
    def clip(self, start: int, end: int) -> Animation: ...
    def analysis(self, length: int) -> Animation: ...
    def __len__(self) -> int: ...

class SegmentedEncoder:
    """An encoding in temporal segments, coded anywhere and joined in order."""

    @staticmethod
    def start(
        analysis: Animation,
        length: int,
        *,
        threads: Optional[int] = None,
        progress: Optional[Progress] = None,
        **options: object,
    ) -> SegmentedEncoder: ...
    @staticmethod
    def resume(analysis: bytes, *, threads: Optional[int] = None, **options: object) -> SegmentedEncoder:
        """An encoder from ``analysis()``'s bytes and the same options."""
    def analysis(self) -> bytes:
        """The analysis ``start`` made, for ``resume`` elsewhere."""
    @property
    def frames(self) -> int: ...
    def code_segment(
        self, first_frame: int, positions: Positions, *, progress: Optional[Progress] = None
    ) -> bytes: ...
    def add(self, segment: bytes) -> None: ...
    def finish(self) -> bytes: ...

def analysis_frames(frames: int, length: int) -> list[int]: ...
def segment_ranges(frames: int, length: int) -> list[Tuple[int, int]]: ...
def codecs() -> list[str]: ...

__all__: Sequence[str]
