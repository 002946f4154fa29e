#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Writes bindings/cffi/sph_cdef.h: the declarations of include/sph_c.h, sph_cuda.h and sph_vdb.h
in the subset of C that cffi's `ffi.cdef()` parses (pycparser: no preprocessor conditionals, no
static-assert typedefs, no function bodies), from bindings/api/sph_api.json.

    python3 bindings/api/generate_cdef.py [--api sph_api.json] [--out sph_cdef.h]

What it holds: the integer #defines, the enums, the opaque handle types, the structs with every
field, the callback types and every exported function (sph_vdb_* live in libsph_vdb, the rest in
libsph). The header's `static inline` *_init() helpers are not exported symbols: call their
*_init_sized(p, ffi.sizeof(p[0])) counterparts, as the inline bodies do, and set header_version
to SPH_VERSION where the struct has it. bindings/python/tests/test_cffi.py checks the file with
cffi: every struct's size and field offsets against the C compiler's (sph_api.json's layout)."""
from __future__ import annotations

import argparse
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import apimodel as am  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(HERE))
DEFAULT_OUT = os.path.join(ROOT, "bindings", "cffi", "sph_cdef.h")


def decl(ty: dict, name: str) -> str:
    """A C declarator: `float name[3]`, `const char* name`."""
    if ty["kind"] == "array":
        return f"{decl(ty['of'], name)}[{ty['length']}]"
    c = ty.get("c") or ty["name"]
    if ty["kind"] in ("struct", "enum", "builtin", "alias", "callback", "void", "opaque") and "c" not in ty:
        c = ("const " if ty.get("const") else "") + ty["name"]
    return f"{c} {name}" if name else c


def params(fn: dict) -> str:
    ps = fn["params"]
    return ", ".join(decl(p["type"], p["name"]) for p in ps) if ps else "void"


def generate(api: dict) -> str:
    out = am.header_banner(api, "generate_cdef.py", "//")
    out += ["// For cffi: ffi.cdef(open(\"sph_cdef.h\").read()); lib = ffi.dlopen(\"libsph.so.0\").",
            "// The static inline *_init() helpers of the header are not here (they are not exported):",
            "// call *_init_sized(p, ffi.sizeof(p[0])) instead.",
            "// One declaration a line, as generated: the format check leaves it alone.", "// clang-format off", ""]
    for d in api["defines"]:
        if isinstance(d.get("value"), int):
            out.append(f"#define {d['name']} {d['value']}")
    out.append("")
    for o in api["opaque_types"]:
        out.append(f"typedef struct {o['name']} {o['name']};")
    out.append("")
    for t in api["typedefs"]:
        out.append(f"typedef {decl(t['type'], t['name'])};")
    out.append("")
    for e in api["enums"]:
        out.append("typedef enum {")
        out += [f"  {m['name']} = {m['value']}," for m in e["members"]]
        out.append(f"}} {e['name']};")
    out.append("")
    for c in api["callbacks"]:
        out.append(f"typedef {decl(c['return'], '')} (*{c['name']})({params(c)});")
    out.append("")
    for s in api["structs"]:
        out.append(f"typedef struct {s['name']} {{")
        out += [f"  {decl(f['type'], f['name'])};" for f in s["fields"]]
        out.append(f"}} {s['name']};")
    out.append("")
    library = None
    for f in api["functions"]:
        if f.get("library") != library:
            library = f.get("library")
            out.append(f"// lib{library}")
        out.append(f"{decl(f['return'], f['name'])}({params(f)});")
    return "\n".join(out) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--api", default=am.DEFAULT_API)
    ap.add_argument("--out", default=DEFAULT_OUT)
    args = ap.parse_args(argv)
    text = generate(am.load(args.api))
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    with open(args.out, "w", encoding="utf-8") as f:
        f.write(text)
    print(f"generate_cdef.py: wrote {os.path.relpath(args.out, ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
