# SPDX-License-Identifier: MIT
"""The README's two-line example and its tour of the API run as written."""
import os
import re
import subprocess
import sys

README = os.path.join(os.path.dirname(__file__), "..", "README.md")


def test_readme_snippet_runs():
    text = open(README, encoding="utf-8").read()
    m = re.search(r"<!-- snippet: python[^>]*-->\s*```python\n(.*?)```", text, re.S)
    assert m, "README.md has no python snippet after the marker"
    code = m.group(1)
    assert len(code.strip().splitlines()) == 2
    env = dict(os.environ)
    if os.environ.get("SPH_TEST_INSTALLED") != "1":  # else the installed package (the wheel check)
        env["PYTHONPATH"] = os.path.join(os.path.dirname(__file__), "..")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stdout + out.stderr
    assert "[[" in out.stdout  # printed the (n, 3) positions


def test_readme_tour_runs():
    text = open(README, encoding="utf-8").read()
    m = re.search(r"<!-- snippet: python-tour[^>]*-->\s*```python\n(.*?)```", text, re.S)
    assert m, "README.md has no python-tour snippet after the marker"
    env = dict(os.environ)
    if os.environ.get("SPH_TEST_INSTALLED") != "1":
        env["PYTHONPATH"] = os.path.join(os.path.dirname(__file__), "..")
    out = subprocess.run([sys.executable, "-c", m.group(1)], env=env, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stdout + out.stderr
    assert "COLLIDER_LOAD_EXCEEDED" in out.stdout and "True" in out.stdout, out.stdout
