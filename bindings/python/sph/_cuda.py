# SPDX-License-Identifier: MIT
"""The zero-copy CUDA tier (sph_cuda.h): a CUDA world's particles where they live on the GPU."""
import ctypes

from . import _generated as _g
from ._errors import check
from ._loader import library
from ._struct import check_real

__all__ = ["CudaArray", "WorldCudaMixin"]

_TYPESTR = {"float32": "<f4", "uint32": "<u4", "int32": "<i4"}


class CudaArray:
    """One attribute of a CUDA world as a device array, without a copy.

    Implements ``__cuda_array_interface__`` (version 3), so CuPy, Numba and PyTorch can wrap
    it: ``cupy.asarray(world.cuda_array(sph.Attribute.POSITION))``. The memory is the
    world's: valid for the world's life, rewritten in place by every call that changes
    particles (check ``current``), never to be written or freed. It is flagged read-only;
    PyTorch refuses that flag, so for ``torch.as_tensor`` ask for
    ``world.cuda_array(attribute, readonly=False)`` (and still do not write).
    """

    def __init__(self, world, view, dtype, components, readonly=True):
        self.world = world
        self.view = view
        self.readonly = readonly
        self._typestr = _TYPESTR[str(dtype)]
        self._components = components

    @property
    def shape(self):
        return (self.view.count, self._components) if self._components > 1 else (self.view.count,)

    @property
    def current(self):
        """True while the world's data epoch is still the one the view was taken at."""
        return self.world.cuda_epoch == self.view.epoch

    @property
    def __cuda_array_interface__(self):
        item = int(self._typestr[-1])
        strides = (self.view.stride, item) if self._components > 1 else (self.view.stride,)
        return {"shape": self.shape, "typestr": self._typestr, "data": (self.view.device_address, self.readonly),
                "strides": strides, "version": 3, "stream": None}


class WorldCudaMixin:
    """World methods of the CUDA tier. On the CPU backend (or a library built without CUDA)
    each raises SphError(ERROR_UNSUPPORTED)."""

    def cuda_attribute(self, attribute):
        """Where an attribute lives in device memory (sph_cuda_world_get_attribute): a
        CudaAttributeView (device_address, stride, element_size, count, epoch, device_ordinal)."""
        v = _g.CudaAttributeView()
        check(library().sph_cuda_world_get_attribute(self.handle, int(_g.Attribute(attribute)), ctypes.byref(v)),
              "sph_cuda_world_get_attribute")
        return v

    def cuda_array(self, attribute, readonly=True):
        """The attribute as a CudaArray (``__cuda_array_interface__``) for CuPy/Numba/PyTorch;
        readonly=False for PyTorch, which rejects the read-only flag."""
        from ._core import attribute_format

        dtype, components = attribute_format(attribute)
        return CudaArray(self, self.cuda_attribute(attribute), dtype, components, readonly)

    @property
    def cuda_epoch(self):
        """The world's data epoch (sph_cuda_world_get_epoch): grows on every call that changes particles (past every earlier one at a restore)."""
        e = ctypes.c_uint64()
        check(library().sph_cuda_world_get_epoch(self.handle, ctypes.byref(e)), "sph_cuda_world_get_epoch")
        return e.value

    @property
    def cuda_device(self):
        """The CUDA device ordinal the world runs on (sph_cuda_world_get_device)."""
        d = ctypes.c_int32()
        check(library().sph_cuda_world_get_device(self.handle, ctypes.byref(d)), "sph_cuda_world_get_device")
        return d.value

    @property
    def cuda_stream(self):
        """The world's cudaStream_t as an int (sph_cuda_world_get_stream); e.g.
        ``cupy.cuda.ExternalStream(world.cuda_stream)``. Owned by the world."""
        s = ctypes.c_void_p()
        check(library().sph_cuda_world_get_stream(self.handle, ctypes.byref(s)), "sph_cuda_world_get_stream")
        return s.value or 0

    def cuda_record_event(self, event):
        """Records a cudaEvent_t (an int pointer you own) on the world's stream
        (sph_cuda_world_record_event)."""
        check(library().sph_cuda_world_record_event(self.handle, ctypes.c_void_p(event)),
              "sph_cuda_world_record_event")

    def cuda_wait_event(self, event):
        """Makes the world's later device work wait for a cudaEvent_t (sph_cuda_world_wait_event)."""
        check(library().sph_cuda_world_wait_event(self.handle, ctypes.c_void_p(event)), "sph_cuda_world_wait_event")

    def cuda_step_begin_on_stream(self, frame_dt, stream):
        """step_begin() ordered on your cudaStream_t (an int; 0: the legacy default stream): the
        frame runs after your stream's earlier work, and your stream's later work after the
        frame (sph_cuda_world_step_begin_on_stream). Collect it with step_wait()."""
        check(library().sph_cuda_world_step_begin_on_stream(self.handle, check_real(frame_dt, "frame_dt"),
                                                            ctypes.c_void_p(stream)),
              "sph_cuda_world_step_begin_on_stream")
        self._step_in_flight = True
