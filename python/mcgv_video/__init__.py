"""mcgv_video: compress animated triangle meshes into ``.mcgv`` streams, and back.

An animation is one connectivity (``faces``, triangles) and a position per vertex and frame
(``positions``, a NumPy ``float32`` array of shape ``(frames, vertices, 3)``)::

    import mcgv_video
    stream = mcgv_video.encode(positions, faces, quality=60)       # bytes of a .mcgv file
    small, report = mcgv_video.encode_to_budget(positions, faces, target_size=200_000)
    decoder = mcgv_video.Decoder(stream)
    frame_37 = decoder.frame(37)                                    # (vertices, 3)
    every = decoder.all()                                           # (frames, vertices, 3)
    print(mcgv_video.eval(mcgv_video.Animation(positions, faces), stream)["rmse"])

The work is done by the Rust library ``mcgv-video``, with the interpreter's lock released, so
other Python threads run meanwhile. Errors are the exceptions of :mod:`mcgv_video.errors`.
:mod:`mcgv_video.cluster` codes long clips' segments and batches of files on Dask.
"""

from __future__ import annotations

from . import errors
from ._native import (
    Animation,
    Decoder,
    FrameSource,
    SegmentedEncoder,
    analysis_frames,
    codecs,
    encode,
    encode_to_budget,
    eval,
    read_animation,
    segment_ranges,
)
from .errors import (
    AtlasError,
    CodecError,
    FileError,
    InvalidOptionError,
    McgvError,
    MeshError,
    PaddingError,
    StreamError,
    UsageError,
)

__version__ = "0.1.0"

__all__ = [
    "Animation",
    "Decoder",
    "FrameSource",
    "SegmentedEncoder",
    "analysis_frames",
    "codecs",
    "encode",
    "encode_to_budget",
    "eval",
    "read_animation",
    "segment_ranges",
    "errors",
    "AtlasError",
    "CodecError",
    "FileError",
    "InvalidOptionError",
    "McgvError",
    "MeshError",
    "PaddingError",
    "StreamError",
    "UsageError",
]
