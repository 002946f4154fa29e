#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Generates bindings/python/sph/_generated.py (ctypes declarations) from sph_api.json.

    python3 bindings/api/generate_python.py [--api sph_api.json] [--out FILE]

The output holds, in header order: #define constants, enums (the C names as ctypes integer
types and constants, plus an IntEnum per enum with short member names), type aliases, opaque
types, callback types (CFUNCTYPE), structs (SphStruct subclasses carrying the compiler's size
and offsets, and the name of their sized init function), and a FUNCTIONS table of every
exported function's restype/argtypes that bind(lib) applies to a loaded library.
"""
from __future__ import annotations

import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import apimodel as am  # noqa: E402

ROOT = os.path.normpath(os.path.join(am.HERE, "..", ".."))
DEFAULT_OUT = os.path.join(ROOT, "bindings", "python", "sph", "_generated.py")

CTYPES = {
    "char": "_c.c_char", "float": "_c.c_float", "double": "_c.c_double",
    "int8_t": "_c.c_int8", "uint8_t": "_c.c_uint8", "int16_t": "_c.c_int16", "uint16_t": "_c.c_uint16",
    "int32_t": "_c.c_int32", "uint32_t": "_c.c_uint32", "int64_t": "_c.c_int64", "uint64_t": "_c.c_uint64",
    "size_t": "_c.c_size_t", "ptrdiff_t": "_c.c_ssize_t", "intptr_t": "_c.c_ssize_t", "uintptr_t": "_c.c_size_t",
}
ENUM_CTYPE = {1: "_c.c_int8", 2: "_c.c_int16", 4: "_c.c_int32", 8: "_c.c_int64"}


def ctype(ty: dict) -> str:
    k = ty["kind"]
    if k == "void":
        return "None"
    if k == "builtin":
        return CTYPES[ty["name"]]
    if k in ("enum", "alias", "callback", "struct"):
        return ty["name"]
    if k == "pointer":
        to = ty["to"]
        if to["kind"] == "void":
            return "_c.c_void_p"
        if am.is_char_ptr(ty):
            return "_c.c_char_p"
        if to["kind"] == "function_pointer":
            return function_pointer(to)
        return f"_c.POINTER({ctype(to) if to['kind'] != 'opaque' else to['name']})"
    if k == "opaque":
        raise ValueError(f"opaque type {ty['name']} used by value")
    if k == "array":
        return f"({ctype(ty['of'])} * {ty['length']})"
    if k == "function_pointer":
        return function_pointer(ty)
    raise ValueError(k)


def param_ctype(ty: dict) -> str:
    """Arrays in parameter lists are pointers."""
    if ty["kind"] == "array":
        return f"_c.POINTER({ctype(ty['of'])})"
    return ctype(ty)


def function_pointer(ty: dict) -> str:
    args = ", ".join([ctype(ty["return"])] + [param_ctype(p["type"]) for p in ty["params"]])
    return f"_c.CFUNCTYPE({args})"


def docstring(text: str, indent: str) -> list[str]:
    if not text:
        return []
    text = text.replace("\\", "\\\\").replace('"""', '\\"\\"\\"')
    lines = text.split("\n")
    if len(lines) == 1 and len(lines[0]) + len(indent) < 95:
        return [f'{indent}"""{lines[0]}"""']
    out = [f'{indent}"""']
    out += [f"{indent}{ln}".rstrip() for ln in wrap_lines(lines, 96 - len(indent))]
    out.append(f'{indent}"""')
    return out


def wrap_lines(lines: list[str], width: int) -> list[str]:
    import textwrap
    out = []
    for ln in lines:
        out += textwrap.wrap(ln, width) or [""]
    return out


def comment(text: str, indent: str = "") -> list[str]:
    if not text:
        return []
    return [f"{indent}#: {ln}" for ln in wrap_lines(text.split("\n"), 96 - len(indent))]


def generate(api: dict) -> str:
    out = ["# flake8: noqa", "# fmt: off"] + am.header_banner(api, "generate_python.py", "#")
    out += ['"""Low-level ctypes declarations of sph_c.h, generated; the package\'s classes are built on these."""',
            "import ctypes as _c",
            "import enum as _enum",
            "",
            "from ._struct import Opaque as _Opaque, SphStruct as _SphStruct",
            "",
            "#: The headers these declarations come from, with their SHA-256.",
            f"HEADERS = {dict((h['path'], h['sha256']) for h in api['headers'])!r}",
            f"VERSION = ({api['version']['major']}, {api['version']['minor']}, {api['version']['patch']})",
            f"VERSION_STRING = \"{api['version']['major']}.{api['version']['minor']}.{api['version']['patch']}\"",
            f"ABI_VERSION = {api['version']['abi']}",
            f"POINTER_SIZE = {api['layout']['pointer_size']}",
            ""]
    taken = set()

    def pyname(c_name: str) -> str:
        n = am.camel(c_name)
        if n in taken:
            raise SystemExit(f"generate_python.py: two declarations map to the Python name {n}")
        taken.add(n)
        return n

    out += ["# ---- constants (#define) " + "-" * 70, ""]
    for d in api["defines"]:
        out += comment(d["doc"])
        out.append(f"{d['name']} = {d['value']!r}")
    for m in api["macros"]:
        out.append(f"# {m['name']}({', '.join(m['params'])}) is a function-like macro: not generated.")
    out.append("")

    out += ["# ---- enums " + "-" * 84, ""]
    enum_py = {}
    for e in api["enums"]:
        out.append(f"{e['name']} = {ENUM_CTYPE[e['size']]}")
        for m in e["members"]:
            out.append(f"{m['name']} = {m['value']}" + (f"  # {m['doc']}" if m["doc"] else ""))
        cls = pyname(e["name"])
        enum_py[e["name"]] = cls
        out += ["", "", f"class {cls}(_enum.IntEnum):"]
        out += docstring(f"{e['name']}" + (f": {e['doc']}" if e["doc"] else ""), "    ")
        for m in e["members"]:
            if am.is_sentinel(e, m):
                continue
            out += comment(m["doc"], "    ")
            out.append(f"    {am.short_member(e, m)} = {m['value']}")
        out += ["", ""]

    out.append("#: Doc text of every enum member, by C name (e.g. the element format of an attribute).")
    out.append("ENUM_MEMBER_DOCS = {")
    for e in api["enums"]:
        for m in e["members"]:
            if m["doc"]:
                out.append(f"    {m['name']!r}: {m['doc']!r},")
    out += ["}", ""]

    out += ["# ---- type aliases " + "-" * 77, ""]
    for td in api["typedefs"]:
        out += comment(td["doc"])
        out.append(f"{td['name']} = {ctype(td['type'])}")
    out.append("")

    out += ["# ---- opaque objects " + "-" * 75, ""]
    for o in api["opaque_types"]:
        out += ["", f"class {o['name']}(_Opaque):"]
        out += docstring(o["doc"] or f"Opaque {o['name']} (used through pointers).", "    ")
        out.append(f"    _sph_destroy_ = {o['destroy']!r}")
    out += ["", ""]

    out += ["# ---- callbacks " + "-" * 80, ""]
    for cb in api["callbacks"]:
        out += comment(cb["doc"])
        out.append(f"{cb['name']} = {function_pointer(cb)}")
    out.append("")

    out += ["# ---- structs " + "-" * 82, ""]
    struct_py = []
    for s in api["structs"]:
        c_name = s["name"]
        cls = pyname(c_name)
        struct_py.append((c_name, cls))
        doc = s["doc"] or f"{s['name']}."
        doc += "\n\nFields:"
        fields_doc = "\n".join(f"    {f['name']} ({f['type']['c']}): {f['doc']}".rstrip(": ") for f in s["fields"])
        out += ["", f"class {cls}(_SphStruct):"]
        ds = docstring(doc, "    ")
        out += ds[:-1] + [f"    {ln}".rstrip() for ln in fields_doc.split("\n")] + ds[-1:] if ds else []
        out.append("    _fields_ = [")
        for f in s["fields"]:
            out.append(f"        ({f['name']!r}, {ctype(f['type'])}),")
        out.append("    ]")
        out.append(f"    _sph_c_name_ = {c_name!r}")
        out.append(f"    _sph_size_ = {s['size']}")
        out.append(f"    _sph_offsets_ = {tuple((f['name'], f['offset']) for f in s['fields'])!r}")
        init = s.get("init")
        out.append(f"    _sph_init_ = {init['function'] if init else None!r}")
        if s.get("default"):
            out.append(f"    _sph_default_ = {s['default']['function']!r}")
        if init and init["assigns"]:
            assigns = ", ".join(f"{k!r}: {v}" for k, v in init["assigns"].items())
            out.append(f"    _sph_assigns_ = {{{assigns}}}")
        enums = {f["name"]: enum_py[f["type"]["name"]] for f in s["fields"] if f["type"]["kind"] == "enum"}
        if enums:
            out.append("    _sph_enums_ = {" + ", ".join(f"{k!r}: {v}" for k, v in enums.items()) + "}")
        out.append("")
        out.append("")
        out.append(f"{c_name} = {cls}")
        out.append("")
    out.append("")
    out.append("STRUCTS = (" + "".join(f"{p}, " for _, p in struct_py) + ")")
    out.append("")

    out += ["# ---- functions " + "-" * 80, ""]
    out.append("#: name -> (restype, argtypes, parameter names, doc, library: 'sph' or an optional helper)")
    out.append("FUNCTIONS = {")
    for f in api["functions"]:
        args = ", ".join(param_ctype(p["type"]) for p in f["params"])
        names = tuple(p["name"] for p in f["params"])
        out.append(f"    {f['name']!r}: ({ctype(f['return'])}, ({args}{',' if len(f['params']) == 1 else ''}), "
                   f"{names!r},")
        out.append(f"        {f['doc']!r}, {f['library']!r}),")
    out.append("}")
    libs = sorted({f["library"] for f in api["functions"]}, key=lambda n: (n != "sph", n))
    out.append(f"LIBRARIES = {tuple(libs)!r}")
    out += ["", "",
            "def bind(lib, library=\"sph\"):",
            '    """Sets restype/argtypes (and __doc__) on the functions of `library` in a loaded',
            '    shared library; returns the names it does not export."""',
            "    missing = []",
            "    for name, (restype, argtypes, _names, doc, lib_name) in FUNCTIONS.items():",
            "        if lib_name != library:",
            "            continue",
            "        try:",
            "            fn = getattr(lib, name)",
            "        except AttributeError:",
            "            missing.append(name)",
            "            continue",
            "        fn.restype = restype",
            "        fn.argtypes = argtypes",
            "        fn.__doc__ = doc",
            "    return missing",
            ""]
    return "\n".join(out)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--api", default=am.DEFAULT_API)
    ap.add_argument("--out", default=DEFAULT_OUT)
    args = ap.parse_args(argv)
    text = generate(am.load(args.api))
    with open(args.out, "w", encoding="utf-8", newline="\n") as f:
        f.write(text)
    print(f"generate_python.py: wrote {os.path.relpath(args.out)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
