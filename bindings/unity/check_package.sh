#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# bindings/unity/check_package.sh PYTHON LIBSPH WORK_DIR
#
# The Unity package as CI checks it (ctest unity_package): assembles it from LIBSPH
# (assemble_package.py, which also checks the manifest, the asmdef, the .meta files and the
# plugin), compiles its Runtime/ sources alone into Sph.dll with mcs (warnings as errors, as
# Unity would compile the Sph assembly), compiles the C# tests and the sample against that
# Sph.dll, and runs the tests on mono with only the package's Plugins/x86_64 on the library path,
# so [DllImport("sph")] loads the package's libsph.so.
set -euo pipefail
[[ $# -eq 3 ]] || {
  echo "usage: $0 PYTHON LIBSPH WORK_DIR" >&2
  exit 2
}
python="$1"
lib="$2"
work="$3"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
rm -rf "${work}"
mkdir -p "${work}"
"${python}" "${root}/bindings/unity/assemble_package.py" --library "${lib}" --out "${work}"
pkg="${work}/org.sph.fluid"
mcs -nologo -warnaserror+ -target:library -doc:"${work}/Sph.xml" -nowarn:1591 -out:"${work}/Sph.dll" \
  "${pkg}"/Runtime/*.cs
mcs -nologo -warnaserror+ -r:"${work}/Sph.dll" -out:"${work}/SphTests.exe" "${root}/bindings/csharp/tests/SphTests.cs"
mcs -nologo -warnaserror+ -r:"${work}/Sph.dll" -out:"${work}/Droplets.exe" "${pkg}/Samples~/Droplets/Droplets.cs"
cd "${work}"
LD_LIBRARY_PATH="${pkg}/Plugins/x86_64" mono --debug SphTests.exe "${root}/bindings/csharp"
