# SPDX-License-Identifier: MIT
"""The zero-copy CUDA tier on a real GPU (skipped without a CUDA build and device).

Device memory is read back through the CUDA runtime (libcudart, loaded with ctypes) and
compared with what sph_world_copy_attribute returns, so no CuPy or PyTorch is needed.
"""
import ctypes
import ctypes.util
import glob

import numpy as np
import pytest

import sph


def _cuda_context():
    if "cuda" not in sph.build_info():
        pytest.skip("the library was built without the CUDA backend")
    try:
        return sph.Context("cuda")
    except sph.SphError as e:
        pytest.skip(f"no CUDA device: {e}")


def _cudart():
    names = [ctypes.util.find_library("cudart")] + sorted(glob.glob("/usr/local/cuda*/lib64/libcudart.so*"))
    for name in filter(None, names):
        try:
            return ctypes.CDLL(name)
        except OSError:
            continue
    pytest.skip("libcudart is not available to read device memory")


@pytest.fixture
def gpu_world():
    ctx = _cuda_context()
    with ctx, ctx.world(capacity=20000, particle_spacing=0.02) as w:
        w.fill_sphere((0, 0, 0), 0.1, velocity=(0.5, 0, 0))
        w.step(1 / 60)
        yield w


def _read(cudart, view, dtype, components):
    """The view's elements copied to the host with cudaMemcpy (kind 2 = device to host)."""
    raw = np.empty(view.count * view.stride, np.uint8)
    assert cudart.cudaMemcpy(ctypes.c_void_p(raw.ctypes.data), ctypes.c_void_p(view.device_address),
                             ctypes.c_size_t(raw.nbytes), 2) == 0
    item = np.dtype(dtype).itemsize
    rows = raw.reshape(view.count, view.stride)[:, :components * item]
    out = np.ascontiguousarray(rows).view(dtype)
    return out.reshape(view.count, components) if components > 1 else out.reshape(view.count)


def test_device_views_match_the_copies(gpu_world):
    cudart = _cudart()
    w = gpu_world
    assert w.context.backend == sph.Backend.CUDA
    for attribute in sph.Attribute:
        dtype, comps = sph.attribute_format(attribute)
        view = w.cuda_attribute(attribute)
        assert view.attribute == attribute and view.count == len(w)
        assert view.element_size == comps * dtype.itemsize and view.stride >= view.element_size
        assert view.device_ordinal == w.cuda_device == 0
        np.testing.assert_array_equal(_read(cudart, view, dtype, comps), w.copy_attribute(attribute))


def test_epochs_streams_and_events(gpu_world):
    cudart = _cudart()
    w = gpu_world
    array = w.cuda_array(sph.Attribute.POSITION)
    cai = array.__cuda_array_interface__
    assert cai["shape"] == (len(w), 3) and cai["typestr"] == "<f4" and cai["data"][0] != 0
    assert array.current
    epoch = w.cuda_epoch
    w.step(1 / 60)
    assert w.cuda_epoch > epoch and not array.current
    assert w.cuda_stream != 0
    event = ctypes.c_void_p()
    assert cudart.cudaEventCreate(ctypes.byref(event)) == 0
    try:
        w.cuda_record_event(event.value)
        assert cudart.cudaEventSynchronize(event) == 0
        w.cuda_wait_event(event.value)
        w.step(1 / 60)
    finally:
        cudart.cudaEventDestroy(event)
    with pytest.raises(sph.SphError) as e:
        w.cuda_record_event(0)
    assert e.value.result == sph.Result.ERROR_INVALID_ARGUMENT


def test_gpu_world_through_the_bindings(gpu_world):
    w = gpu_world
    first = w.spawn(np.array([[1.0, 1.0, 1.0]]))
    ids = w.ids()
    assert first in ids
    np.testing.assert_allclose(w.positions()[ids == first][0], (1, 1, 1))
    s = w.stats()
    assert s.substeps > 0 and s.particle_count == len(w)


def test_pytorch_reads_particles_in_place(gpu_world):
    torch = pytest.importorskip("torch")
    if not torch.cuda.is_available():
        pytest.skip("PyTorch without CUDA")
    w = gpu_world
    # PyTorch rejects the read-only flag of __cuda_array_interface__.
    positions = torch.as_tensor(w.cuda_array(sph.Attribute.POSITION, readonly=False), device="cuda")
    assert positions.shape == (len(w), 3) and positions.stride() == (4, 1)  # 16-byte records
    assert positions.data_ptr() == w.cuda_attribute(sph.Attribute.POSITION).device_address  # no copy
    np.testing.assert_array_equal(positions.cpu().numpy(), w.positions())
    try:
        ids = torch.as_tensor(w.cuda_array(sph.Attribute.ID, readonly=False), device="cuda")
    except (TypeError, RuntimeError):
        return  # this PyTorch has no uint32 tensors
    np.testing.assert_array_equal(ids.cpu().numpy().astype(np.uint32), w.ids())
