# SPDX-License-Identifier: MIT
"""Finding and loading the sph shared library, and checking that it matches these bindings.

Search order:
1. the SPH_LIBRARY environment variable (a full path; no fallback when it is set);
2. next to this package (a wheel or a copy may ship libsph.so.0 / sph.dll / libsph.dylib);
3. ctypes.util.find_library("sph"), then "libsph.so.0" through the dynamic loader.

At load, before anything else is called: sph_get_abi_version() must equal the ABI version the
bindings were generated for, every function in the generated table must be exported, and
every struct's ctypes.sizeof and field offsets must equal what the C compiler measured when
sph_api.json was generated.
"""
import ctypes
import ctypes.util
import os
import sys
import threading

from . import _generated as _g
from ._errors import SphLoadError

ENV_VAR = "SPH_LIBRARY"
_PACKAGE_DIR = os.path.dirname(os.path.abspath(__file__))
_LOCAL_NAMES = {"win32": ["sph.dll"], "darwin": ["libsph.0.dylib", "libsph.dylib"]}.get(
    sys.platform, ["libsph.so.0", "libsph.so"])

#: Libraries that hold the whole of sph_c.h and more, loaded as the core library in place of
#: libsph (SPH_LIBRARY=.../libsph_mpi.so), never beside it: each keeps its own registry of
#: worlds. Their own functions are bound on the core library when it exports them (sph.mpi).
CORE_VARIANTS = ("sph_mpi",)

_lock = threading.Lock()
_library = None
_library_path = None


def candidates():
    """The paths or names tried, in order (without SPH_LIBRARY)."""
    out = [os.path.join(_PACKAGE_DIR, n) for n in _LOCAL_NAMES if os.path.exists(os.path.join(_PACKAGE_DIR, n))]
    found = ctypes.util.find_library("sph")
    if found:
        out.append(found)
    out.append("libsph.so.0" if sys.platform.startswith("linux") else _LOCAL_NAMES[0])
    return out


def check_abi(lib, expected=_g.ABI_VERSION):
    abi = lib.sph_get_abi_version()
    if abi != expected:
        raise SphLoadError(f"the sph library has ABI version {abi}, but these bindings were generated for "
                           f"ABI {expected} (sph {'.'.join(map(str, _g.VERSION))}); use a matching library")


def check_layouts(structs=_g.STRUCTS, pointer_size=_g.POINTER_SIZE):
    """Every struct's ctypes size and offsets against the C compiler's (from sph_api.json)."""
    if ctypes.sizeof(ctypes.c_void_p) != pointer_size:
        raise SphLoadError(f"these bindings were generated for {pointer_size * 8}-bit pointers; this Python "
                           f"has {ctypes.sizeof(ctypes.c_void_p) * 8}-bit pointers: regenerate them")
    problems = []
    for s in structs:
        if ctypes.sizeof(s) != s._sph_size_:
            problems.append(f"{s.__name__}: ctypes.sizeof {ctypes.sizeof(s)} != C sizeof {s._sph_size_}")
        for name, offset in s._sph_offsets_:
            got = getattr(s, name).offset
            if got != offset:
                problems.append(f"{s.__name__}.{name}: ctypes offset {got} != C offsetof {offset}")
    if problems:
        raise SphLoadError("struct layouts differ from the C library's: " + "; ".join(problems))


def check_integer_arguments(lib, library_name="sph"):
    """Integer arguments refuse values that do not fit their C type (ctypes would pass them
    modulo 2^bits: first=2**32 + 5 as 5): OverflowError, reported as ctypes.ArgumentError."""
    from ._struct import checked_argtype

    for name, (_restype, argtypes, _names, _doc, lib_name) in _g.FUNCTIONS.items():
        if lib_name == library_name and hasattr(lib, name):
            getattr(lib, name).argtypes = tuple(checked_argtype(t) for t in argtypes)


def load(path=None):
    """Loads and checks a library (path, or the search order above). Returns the CDLL; does
    not replace the library the package uses (see library())."""
    env = os.environ.get(ENV_VAR)
    tried = []
    if path is None and env:
        path = env
    paths = [path] if path else candidates()
    lib = None
    for p in paths:
        try:
            lib = ctypes.CDLL(p)
            path = p
            break
        except OSError as e:
            tried.append(f"{p}: {e}")
    if lib is None:
        how = f"{ENV_VAR}={env!r}" if env and paths == [env] else "searched " + ", ".join(paths)
        raise SphLoadError(f"cannot load the sph library ({how}); set {ENV_VAR} to the full path of "
                           f"libsph.so. Tried: " + "; ".join(tried))
    for required in ("sph_get_abi_version", "sph_get_last_error"):
        if not hasattr(lib, required):
            raise SphLoadError(f"{path} is not the sph library (it does not export {required})")
    lib.sph_get_abi_version.restype = ctypes.c_uint32
    lib.sph_get_abi_version.argtypes = ()
    check_abi(lib)
    missing = _g.bind(lib)
    if missing:
        raise SphLoadError(f"{path} does not export {', '.join(missing)}: it is older than the header these "
                           f"bindings were generated from (sph {'.'.join(map(str, _g.VERSION))})")
    check_integer_arguments(lib)
    for variant in CORE_VARIANTS:
        own = [name for name, entry in _g.FUNCTIONS.items() if entry[4] == variant]
        if own and all(hasattr(lib, name) for name in own):
            _g.bind(lib, variant)
            check_integer_arguments(lib, variant)
    check_layouts()
    lib._sph_path = path
    return lib


def library():
    """The library the package uses, loaded and checked on first use."""
    global _library, _library_path
    if _library is None:
        with _lock:
            if _library is None:
                lib = load()
                _library_path = lib._sph_path
                _library = lib
    return _library


def library_path():
    """The path or name the package's library was loaded from."""
    library()
    return _library_path


_helpers = {}


def helper_library(name="sph_vdb"):
    """An optional helper library (libsph_vdb for sph_vdb.h), loaded on first use after the
    core library: <NAME>_LIBRARY (e.g. SPH_VDB_LIBRARY, a full path), else next to the core
    library, next to this package, ctypes.util.find_library, then lib<name>.so.0. Raises
    SphLoadError when it is not there (it is only built where its dependency, OpenVDB, is)."""
    with _lock:
        if name in _helpers:
            return _helpers[name]
    core = library()
    env = os.environ.get(name.upper() + "_LIBRARY")
    if env:
        paths = [env]
    else:
        stem = {"win32": [f"{name}.dll"], "darwin": [f"lib{name}.0.dylib", f"lib{name}.dylib"]}.get(
            sys.platform, [f"lib{name}.so.0", f"lib{name}.so"])
        core_dir = os.path.dirname(getattr(core, "_sph_path", "") or "")
        paths = [os.path.join(d, n) for d in (core_dir, _PACKAGE_DIR) if d for n in stem
                 if os.path.exists(os.path.join(d, n))]
        found = ctypes.util.find_library(name)
        paths += ([found] if found else []) + [stem[0]]
    tried = []
    for p in paths:
        try:
            lib = ctypes.CDLL(p)
        except OSError as e:
            tried.append(f"{p}: {e}")
            continue
        missing = _g.bind(lib, name)
        if missing:
            raise SphLoadError(f"{p} does not export {', '.join(missing)}")
        check_integer_arguments(lib, name)
        lib._sph_path = p
        with _lock:
            _helpers.setdefault(name, lib)
            return _helpers[name]
    raise SphLoadError(f"the optional library lib{name} is not available (set {name.upper()}_LIBRARY); "
                       "tried: " + "; ".join(tried))
