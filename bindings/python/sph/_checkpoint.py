# SPDX-License-Identifier: MIT
"""Checkpoints: a world's whole state as bytes or a file (sph_world_save, _save_file,
sph_world_load, _load_file, sph_world_restore). docs/checkpoint.md describes the format."""
import ctypes
import os

from ._errors import check
from ._loader import library
from ._scene import context_handle

__all__ = ["WorldCheckpointMixin", "load_world", "load_world_file"]


def _path_bytes(path):
    return os.fsencode(os.fspath(path))


def _buffer(data):
    """(pointer, size, keep-alive) for bytes-like data, without a copy where ctypes allows."""
    data = memoryview(data).cast("B")
    if data.readonly:
        keep = ctypes.create_string_buffer(data.tobytes(), len(data))
    else:
        keep = (ctypes.c_ubyte * len(data)).from_buffer(data)
    return ctypes.cast(keep, ctypes.c_void_p), len(data), keep


def load_world(world_class, context, data):
    """A new world of world_class on context from checkpoint bytes (sph_world_load)."""
    ptr, size, _keep = _buffer(data)
    out = ctypes.POINTER(world_class._sph_type_)()
    check(library().sph_world_load(context_handle(context), ptr, size, ctypes.byref(out)), "sph_world_load")
    return world_class._adopt(context, out)


def load_world_file(world_class, context, path):
    """A new world of world_class on context from a checkpoint file (sph_world_load_file)."""
    out = ctypes.POINTER(world_class._sph_type_)()
    check(library().sph_world_load_file(context_handle(context), _path_bytes(path), ctypes.byref(out)),
          "sph_world_load_file")
    return world_class._adopt(context, out)


class WorldCheckpointMixin:
    """World methods for checkpoints. A loaded world continues bit for bit as the saved one on
    the same backend; ids of colliders, sources, sinks and force fields stay valid."""

    def save(self):
        """The world as checkpoint bytes (sph_world_save: a size query, then the save)."""
        size = ctypes.c_uint64()
        check(library().sph_world_save(self.handle, None, 0, ctypes.byref(size)), "sph_world_save")
        buf = ctypes.create_string_buffer(size.value)
        check(library().sph_world_save(self.handle, buf, size.value, ctypes.byref(size)), "sph_world_save")
        return buf.raw[:size.value]

    def save_file(self, path):
        """Saves the world to a file atomically (sph_world_save_file): a temporary file next to
        path, flushed, then renamed over it; on error a file at path is untouched."""
        check(library().sph_world_save_file(self.handle, _path_bytes(path)), "sph_world_save_file")

    def restore(self, data):
        """Replaces the whole world with a checkpoint's (sph_world_restore; all-or-nothing)."""
        ptr, size, _keep = _buffer(data)
        check(library().sph_world_restore(self.handle, ptr, size), "sph_world_restore")
