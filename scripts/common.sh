# SPDX-License-Identifier: MIT
# shellcheck shell=bash
# Shared set-up for scripts/demo and scripts/test (sourced, not run).
#
# Provides:
#   SPH_ROOT                      the repository root (the scripts cd there)
#   sph_log / sph_warn / sph_die  messages on stderr, prefixed with the calling script's name
#   sph_install_packages          apt-get installs whatever of SPH_PACKAGES is missing
#   sph_configure DIR [ARGS...]   cmake -G Ninja into DIR (Release unless ARGS say otherwise)
#   sph_configure_sanitizer_tree DIR [ARGS...]   the clang ASan + UBSan + libFuzzer tree
#                                 (build-sanitize/; without MPI unless ARGS say -DSPH_WITH_MPI=ON)
#   sph_build DIR [TARGETS...]    ninja in DIR
#
# Environment knobs:
#   SPH_SKIP_PACKAGES=1   do not check or install Debian packages (a machine set up by hand)
#   SPH_BUILD_JOBS=N      parallel compile jobs (default: ninja's own choice)

SPH_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
SPH_SCRIPT_NAME="$(basename "${0}")"

# The Debian 12 packages the build, the tests and the tools need. libclang-rt-14-dev is what
# clang's Recommends would bring in; it holds libFuzzer and the sanitizer runtimes for clang;
# libomp-dev is OpenMP for clang (the fuzz build). libxsimd-dev: the CPU backend's SIMD passes.
# Python (numpy, pytest, matplotlib) and mono run the binding tests; libpng-dev gives sph-run
# its preview images. python3-vtk9 reads sph-run's .vtp frames back, python3-jsonschema checks
# the scene files against docs/scene.schema.json, python3-cffi parses bindings/cffi/sph_cdef.h;
# python3-setuptools, -wheel and -venv build the Python wheel and install it into a clean
# virtual environment offline (scripts/build-wheel, scripts/test). libegl-dev, libgl-dev and
# libgles-dev (EGL and glvnd, the EGL/GL/GLES headers) build samples/gpu_draw; libegl-mesa0 and
# libgl1-mesa-dri (Mesa's EGL driver and llvmpipe) let gl_draw_host draw without a GPU; the
# kit for a GPU machine without them comes from scripts/devkit-interop. libopenmpi-dev and
# openmpi-bin build libsph_mpi and run the mpi tests; python3-mpi4py drives it from Python.
# python3-openvdb (pyopenvdb, the same OpenVDB 10.0.1) writes the level set that the Python
# binding's VDB test loads (bindings/python/tests/test_vdb.py; without it that test skips).
SPH_PACKAGES=(
  cmake ninja-build g++ pkg-config git
  libcmocka-dev libeigen3-dev libxsimd-dev
  libopenvdb-dev libboost-iostreams-dev libtbb-dev nlohmann-json3-dev libopenmpi-dev openmpi-bin python3-mpi4py
  python3-openvdb
  clang libclang-rt-14-dev libomp-dev clang-format
  python3 python3-numpy python3-pytest python3-matplotlib mono-mcs mono-runtime
  libpng-dev libegl-dev libgl-dev libgles-dev libegl-mesa0 libgl1-mesa-dri
  python3-vtk9 python3-jsonschema python3-cffi python3-setuptools python3-wheel python3-venv
)

sph_log() { printf '[%s] %s\n' "${SPH_SCRIPT_NAME}" "$*" >&2; }
sph_warn() { printf '[%s] warning: %s\n' "${SPH_SCRIPT_NAME}" "$*" >&2; }
sph_die() {
  printf '[%s] error: %s\n' "${SPH_SCRIPT_NAME}" "$*" >&2
  exit 1
}

# True when the Debian package is installed (not merely known or half-removed).
sph_package_installed() {
  [[ "$(dpkg-query -W -f='${db:Status-Status}' "$1" 2>/dev/null)" == "installed" ]]
}

# Installs the packages of SPH_PACKAGES that are missing: one `apt-get update`, then one
# `apt-get install`, non-interactive, through sudo only when not already root.
sph_install_packages() {
  if [[ "${SPH_SKIP_PACKAGES:-0}" == "1" ]]; then
    sph_log "SPH_SKIP_PACKAGES=1: not checking Debian packages"
    return 0
  fi
  command -v dpkg-query >/dev/null 2>&1 ||
    sph_die "dpkg-query not found: these scripts set up Debian 12; install the packages by hand (${SPH_PACKAGES[*]}) and run with SPH_SKIP_PACKAGES=1"

  local missing=() pkg
  for pkg in "${SPH_PACKAGES[@]}"; do
    sph_package_installed "${pkg}" || missing+=("${pkg}")
  done
  if [[ ${#missing[@]} -eq 0 ]]; then
    sph_log "all ${#SPH_PACKAGES[@]} required Debian packages are installed"
    return 0
  fi

  local sudo=()
  if [[ "$(id -u)" -ne 0 ]]; then
    command -v sudo >/dev/null 2>&1 ||
      sph_die "missing packages (${missing[*]}) and not root, and sudo is not installed"
    sudo=(sudo)
  fi
  sph_log "installing missing Debian packages: ${missing[*]}"
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -q </dev/null ||
    sph_die "apt-get update failed"
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends \
    "${missing[@]}" </dev/null || sph_die "apt-get install failed for: ${missing[*]}"
  for pkg in "${missing[@]}"; do
    sph_package_installed "${pkg}" || sph_die "package ${pkg} is still not installed after apt-get"
  done
}

# Reports what the build will find, so a log says which backend was built.
sph_describe_toolchain() {
  if [[ -x /usr/local/cuda/bin/nvcc ]]; then
    sph_log "nvcc found at /usr/local/cuda/bin/nvcc: the CUDA backend is compiled too"
  else
    sph_log "no /usr/local/cuda/bin/nvcc: building the CPU backend alone"
  fi
}

# sph_configure DIR [CMAKE ARGS...]: configures DIR with Ninja. A cache left by another
# generator (say a Makefile build in the same folder) is dropped first; a cache made from
# another source tree is refused rather than reused.
sph_configure() {
  local dir="$1"
  shift
  local cache="${dir}/CMakeCache.txt"
  if [[ -f "${cache}" ]]; then
    local generator home
    generator="$(sed -n 's/^CMAKE_GENERATOR:INTERNAL=//p' "${cache}")"
    home="$(sed -n 's/^CMAKE_HOME_DIRECTORY:INTERNAL=//p' "${cache}")"
    if [[ -n "${home}" && "$(cd "${home}" 2>/dev/null && pwd -P)" != "$(cd "${SPH_ROOT}" && pwd -P)" ]]; then
      sph_die "${dir} was configured from another source tree (${home}); remove it or choose another folder"
    fi
    if [[ "${generator}" != "Ninja" ]]; then
      sph_log "${dir} was configured with '${generator}', not Ninja: starting it afresh"
      rm -rf "${cache}" "${dir}/CMakeFiles"
    fi
  fi
  sph_log "configuring ${dir}: cmake -G Ninja -DCMAKE_BUILD_TYPE=Release $*"
  cmake -S "${SPH_ROOT}" -B "${dir}" -G Ninja -DCMAKE_BUILD_TYPE=Release "$@"
}

# sph_configure_sanitizer_tree DIR [CMAKE ARGS...]: the one sanitizer tree of scripts/test and
# scripts/fuzz (extra arguments go to CMake after the tree's own, so they can override them).
# clang with ASan + UBSan (SPH_SANITIZE: the tests' sanitizer settings) and libFuzzer's coverage
# instrumentation in every library object (SPH_FUZZ): the sanitizer ctest stage and the fuzz
# harnesses share one build instead of compiling the library twice (once with GCC for the tests,
# once with clang for libFuzzer). -O2 with line tables: the tests run at the speed of the former
# GCC -O2 build and the reports keep function names and line numbers. Without CUDA, the
# benchmarks and sph-run's OpenVDB outputs (the slowest code to compile; the Release build tests
# them); with libsph_vdb, which fuzz_vdb needs. Warnings are not errors here: build/ enforces them.
# Without libsph_mpi (SPH_WITH_MPI=OFF): neither the sanitizer ctest stage (it leaves label mpi out)
# nor the fuzz harnesses use it, and it compiles the distributed code for nothing; scripts/
# sanitize-mpi passes -DSPH_WITH_MPI=ON (an extra argument wins) to build and run the mpi tests here.
# CMake keeps the value in the cache, so each script states it and the tree follows the last one.
# The library's C++ files compile in unity batches of 8 (SPH_UNITY_LIBRARY): on 2 cores the
# library's objects took 97 s one file at a time and 67 s batched (2026-12-04); the Release tree
# still compiles each file alone, which is where a missing include shows.
sph_configure_sanitizer_tree() {
  local dir="$1"
  command -v clang++ >/dev/null 2>&1 || sph_die "clang++ not found (Debian: apt-get install clang libclang-rt-14-dev)"
  # A tree configured with another compiler (GCC, before the two trees became one) starts afresh.
  if [[ -f "${dir}/CMakeCache.txt" ]] && ! grep -q '^CMAKE_CXX_COMPILER:[A-Z]*=.*clang++' "${dir}/CMakeCache.txt"; then
    sph_log "${dir} was configured with another compiler: starting it afresh"
    rm -rf "${dir}/CMakeCache.txt" "${dir}/CMakeFiles"
  fi
  sph_configure "${dir}" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
    "-DCMAKE_C_FLAGS_RELWITHDEBINFO=-O2 -gline-tables-only -DNDEBUG" \
    "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -gline-tables-only -DNDEBUG" \
    -DSPH_SANITIZE=ON -DSPH_FUZZ=ON -DSPH_WITH_CUDA=OFF -DSPH_RUN_WITH_OPENVDB=OFF -DSPH_BUILD_BENCH=OFF \
    -DSPH_WARNINGS_AS_ERRORS=OFF -DSPH_WITH_MPI=OFF -DSPH_UNITY_LIBRARY=8 "${@:2}"
}

# sph_build DIR [TARGETS...]
sph_build() {
  local dir="$1"
  shift
  local jobs=()
  [[ -n "${SPH_BUILD_JOBS:-}" ]] && jobs=(-j "${SPH_BUILD_JOBS}")
  sph_log "building ${dir}${*:+ (targets: $*)}"
  ninja -C "${dir}" "${jobs[@]}" "$@"
}

# sph_has_target DIR TARGET: true when the configured build in DIR defines TARGET.
sph_has_target() {
  ninja -C "$1" -t query "$2" >/dev/null 2>&1
}

# The tests a ctest log lists as skipped (exit 77, SKIP_RETURN_CODE: what they need is missing
# there), comma-separated: ctest's "tests passed" line counts them as passed, so the scripts name
# them beside it. Empty when none.
sph_ctest_skipped() {
  grep -E '^\s+[0-9]+ - .*\(Skipped\)' "$1" | awk '{print $3}' | paste -sd, - || true
}
