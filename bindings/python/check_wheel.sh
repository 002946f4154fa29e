#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# bindings/python/check_wheel.sh PYTHON BUILD_DIR WORK_DIR
#
# The wheel as CI checks it (ctest python_wheel), offline: scripts/build-wheel makes it from
# BUILD_DIR's libsph; PYTHON makes a new virtual environment in WORK_DIR; pip installs the
# wheel there from the file alone (--no-index --no-deps: no network, no PyPI); and the binding
# tests run with that environment's python from outside the checkout, with SPH_LIBRARY and
# LD_LIBRARY_PATH unset, so `import sph` and its library can only come from the wheel
# (test_installed.py checks both). The environment sees the system's site-packages for numpy
# and pytest, the package's dependencies, which cannot be fetched offline; sph is not there.
set -euo pipefail
[[ $# -eq 3 ]] || {
  echo "usage: $0 PYTHON BUILD_DIR WORK_DIR" >&2
  exit 2
}
python="$1"
build="$(cd "$2" && pwd)"
work="$3"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
rm -rf "${work}"
mkdir -p "${work}"
work="$(cd "${work}" && pwd)"
wheel="$("${root}/scripts/build-wheel" --build-dir "${build}" --out "${work}/dist" | tail -n 1)"
echo "check_wheel: built ${wheel}"
"${python}" -c "import sph" 2>/dev/null && {
  echo "check_wheel: ${python} already imports an sph package; the check would prove nothing" >&2
  exit 1
}
# Without its own pip (ensurepip takes most of this check's time): the system's pip installs into
# the environment through --python (pip >= 22.3; Debian 12 has 23.0).
"${python}" -m venv --system-site-packages --without-pip "${work}/venv"
PIP_NO_INDEX=1 PIP_NO_CACHE_DIR=1 PIP_DISABLE_PIP_VERSION_CHECK=1 \
  "${python}" -m pip --python "${work}/venv/bin/python" install --no-index --no-deps "${wheel}"
"${work}/venv/bin/python" -c "import sph, sys; assert sph.__file__.startswith(sys.prefix), sph.__file__"
cd "${work}"
env -u SPH_LIBRARY -u LD_LIBRARY_PATH SPH_TEST_INSTALLED=1 PYTHONDONTWRITEBYTECODE=1 MPLBACKEND=Agg \
  "${work}/venv/bin/python" -m pytest -q -p no:cacheprovider "${root}/bindings/python/tests"
