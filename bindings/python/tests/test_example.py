# SPDX-License-Identifier: MIT
"""The example runs (coarse and short) and writes its plot."""
import os
import subprocess
import sys

import pytest

EXAMPLE = os.path.join(os.path.dirname(__file__), "..", "examples", "dam_break.py")


def test_dam_break_example_runs(tmp_path):
    pytest.importorskip("matplotlib")
    png = tmp_path / "dam_break.png"
    out = subprocess.run([sys.executable, EXAMPLE, "--quick", "--threads", "1", "--backend", "cpu", "--out", str(png)],
                         capture_output=True, text=True, timeout=120, env=dict(os.environ, MPLBACKEND="Agg"))
    assert out.returncode == 0, out.stdout + out.stderr
    assert png.stat().st_size > 10_000
    assert "dam break" in out.stdout and "surge front" in out.stdout
