# SPDX-License-Identifier: MIT
"""Contexts: creation, backend, errors with the right sph_result, closing, logging."""
import ctypes
import gc
import weakref

import numpy as np
import pytest

import sph
from sph import _generated as _g


def test_cpu_context(ctx):
    assert ctx.backend == sph.Backend.CPU
    assert "CPU" in repr(ctx)


def test_backend_by_name_and_enum():
    for backend in ("cpu", sph.Backend.CPU, 1):
        with sph.Context(backend, cpu_worker_count=1) as c:
            assert c.backend == sph.Backend.CPU


def test_auto_resolves_to_a_real_backend():
    with sph.Context() as c:
        assert c.backend in (sph.Backend.CPU, sph.Backend.CUDA)


def test_cuda_without_cuda_is_unsupported():
    if "cuda" in sph.build_info():
        pytest.skip("this library has the CUDA backend")
    with pytest.raises(sph.SphError) as e:
        sph.Context("cuda")
    assert e.value.result == sph.Result.ERROR_UNSUPPORTED
    assert e.value.function == "sph_context_create"
    assert e.value.message and e.value.message in str(e.value)


def test_cuda_allocator_rules():
    """Half a device allocator is refused naming the missing half; a CPU context has none."""
    with sph.Context("cpu") as c:
        alloc = _g.sph_cuda_alloc_fn(lambda size, device, user: None)
        with pytest.raises(sph.SphError) as e:
            c.set_cuda_allocator(alloc_fn=alloc)
        assert e.value.result == sph.Result.ERROR_INVALID_ARGUMENT
        assert "allocator->free_fn" in e.value.message
        with pytest.raises(sph.SphError) as e:
            c.set_cuda_allocator()
        assert e.value.result == sph.Result.ERROR_UNSUPPORTED


@pytest.mark.parametrize("field, value, result", [
    ("struct_size", 4, sph.Result.ERROR_VERSION_MISMATCH),
    ("header_version", sph.make_version(sph.BINDINGS_VERSION[0] + 1, 0, 0), sph.Result.ERROR_VERSION_MISMATCH),
    ("backend", 7, sph.Result.ERROR_UNSUPPORTED),
    ("cuda_particle_lanes", 3, sph.Result.ERROR_INVALID_ARGUMENT),
    ("cuda_dfsph_masks", 3, sph.Result.ERROR_INVALID_ARGUMENT),
])
def test_bad_context_def(field, value, result):
    d = sph.ContextDef(backend=sph.Backend.CPU)
    setattr(d, field, value)
    with pytest.raises(sph.SphError) as e:
        sph.Context(definition=d)
    assert e.value.result == result, e.value


@pytest.mark.parametrize("value", [0, 1, 2])
def test_cuda_dfsph_masks_values(value):
    """Every named value is accepted (a CPU context checks and ignores it)."""
    d = sph.ContextDef(backend=sph.Backend.CPU, cuda_dfsph_masks=value)
    with sph.Context(definition=d) as c:
        assert c.backend == sph.Backend.CPU


def test_close_closes_the_worlds_and_assets_created_on_it():
    before = sph.live_object_count()
    c = sph.Context("cpu", cpu_worker_count=1)
    w = c.world(capacity=10)
    s = c.shape("sphere", radius=0.1, voxel_size=0.05)
    w.add_collider(s)
    assert sph.live_object_count() == before + 3
    # The C library itself refuses while they live:
    assert sph.library().sph_context_destroy(c.handle) == sph.Result.ERROR_BUSY
    c.close()
    c.close()
    assert c.closed and w.closed and repr(s) == "<sph.Sdf closed>"
    assert sph.live_object_count() == before
    assert repr(c) == "<sph.Context closed>"


def test_closed_context_is_an_invalid_handle():
    c = sph.Context("cpu", cpu_worker_count=1)
    c.close()
    with pytest.raises(sph.SphError) as e:
        c.backend
    assert e.value.result == sph.Result.ERROR_INVALID_HANDLE
    with pytest.raises(sph.SphError) as e:
        c.world()
    assert e.value.result == sph.Result.ERROR_INVALID_HANDLE


def test_world_keeps_its_context_alive():
    before = sph.live_object_count()
    w = sph.Context("cpu", cpu_worker_count=1).world(capacity=100)
    assert sph.live_object_count() == before + 2
    assert w.context.backend == sph.Backend.CPU
    w.close()
    w.context.close()
    assert sph.live_object_count() == before


def test_log_callback_gets_failures():
    messages = []
    with sph.Context("cpu", cpu_worker_count=1, log=lambda *m: messages.append(m)) as c:
        with pytest.raises(sph.SphError):
            c.world(capacity=2**31)
    assert messages, "the log callback was called"
    level, code, text = messages[-1]
    assert level == sph.LogLevel.ERROR and code == sph.Result.ERROR_INVALID_ARGUMENT
    assert "capacity" in text


def test_log_callback_exceptions_do_not_escape(capsys):
    def bad_log(*_):
        raise RuntimeError("from the log callback")
    with sph.Context("cpu", cpu_worker_count=1, log=bad_log) as c:
        with pytest.raises(sph.SphError) as e:
            c.world(capacity=2**31)
    assert e.value.result == sph.Result.ERROR_INVALID_ARGUMENT
    assert "from the log callback" in capsys.readouterr().err


def test_context_keeps_the_callbacks_of_an_inline_definition():
    """A ContextDef made inline with Python allocator callbacks: the context keeps ctypes'
    callback objects (their thunks, and the callables behind them) alive, not only the function
    pointers copied from them; the library calls them for the context's life."""
    buffers = {}
    calls = {"alloc": 0, "free": 0}
    refs = []

    def make():
        def alloc(size, alignment, _user):
            calls["alloc"] += 1
            raw = ctypes.create_string_buffer(size + alignment)
            address = (ctypes.addressof(raw) + alignment - 1) // alignment * alignment
            buffers[address] = raw
            return address

        def free(memory, _size, _user):
            calls["free"] += 1
            del buffers[memory]

        refs.extend([weakref.ref(alloc), weakref.ref(free)])
        return sph.Context("cpu", cpu_worker_count=1,
                           definition=sph.ContextDef(alloc_fn=_g.sph_alloc_fn(alloc), free_fn=_g.sph_free_fn(free)))

    c = make()
    gc.collect()
    junk = [ctypes.CFUNCTYPE(ctypes.c_void_p)(lambda: None) for _ in range(1000)]  # reuses freed thunks
    assert all(r() is not None for r in refs), "the context keeps its definition's callbacks"
    with c:
        with c.world(capacity=1000, particle_spacing=0.02) as w:
            assert w.fill_box((0, 0, 0), (0.1, 0.1, 0.1)) > 0
            assert w.step(1.0 / 60.0) == sph.Result.OK
            assert np.isfinite(w.positions()).all()
        assert calls["alloc"] > 0, "the allocator was called"
    assert calls["free"] == calls["alloc"] and not buffers, "everything given back"
    del junk
