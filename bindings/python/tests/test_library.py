# SPDX-License-Identifier: MIT
"""Library-wide calls: versions, result strings, the last error, live objects."""
import pytest

import sph


def test_result_strings():
    for r in sph.Result:
        assert sph.result_string(r).startswith("SPH_" + r.name)
    assert sph.result_string(12345) == "unknown sph_result"


def test_last_error_is_cleared_by_a_success(ctx):
    with pytest.raises(sph.SphError) as e:
        ctx.world(capacity=2**31)
    assert "capacity" in e.value.message
    assert sph.live_object_count() >= 1  # a successful fallible call
    assert sph.last_error() == ""


def test_sph_error_for_an_unknown_code():
    e = sph.SphError(-999, "boom", "sph_x")
    assert e.result == -999 and "sph_result -999" in str(e) and "boom" in str(e)
    e = sph.SphError(sph.Result.ERROR_CAPACITY, "", None)
    assert str(e) == "SPH_ERROR_CAPACITY"


def test_live_object_count_returns_to_its_start():
    before = sph.live_object_count()
    with sph.Context("cpu", cpu_worker_count=1) as c, c.world(capacity=10):
        assert sph.live_object_count() == before + 2
    assert sph.live_object_count() == before
