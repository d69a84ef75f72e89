"""The exceptions of mcgv_video: one per kind of the library's ``Error``.

Every one derives from :class:`McgvError`; those caused by bad input also derive from
``ValueError`` (and file errors from ``OSError``), so ``except ValueError`` catches them too.
"""

from __future__ import annotations


class McgvError(Exception):
    """Anything that can go wrong in mcgv-video."""


class FileError(McgvError, OSError):
    """Reading or writing a file failed (``filename`` names it)."""


class MeshError(McgvError, ValueError):
    """A mesh or mesh sequence is malformed."""


class StreamError(McgvError, ValueError):
    """A ``.mcgv`` stream is malformed, truncated or corrupt."""


class CodecError(McgvError, RuntimeError):
    """An image or video codec failed."""


class InvalidOptionError(McgvError, ValueError):
    """An option is out of range or does not apply; ``option`` is its keyword's name."""

    option: str = ""


class UsageError(McgvError, ValueError):
    """The caller asked for something the input cannot give (a frame past the end, …)."""


class AtlasError(McgvError):
    """The atlas of a picture codec could not be built."""


class PaddingError(McgvError):
    """Padding the free pixels of a geometry image failed."""


__all__ = [
    "McgvError",
    "FileError",
    "MeshError",
    "StreamError",
    "CodecError",
    "InvalidOptionError",
    "UsageError",
    "AtlasError",
    "PaddingError",
]
