#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Generates bindings/csharp/Sph.Generated.cs (P/Invoke declarations) from sph_api.json.

    python3 bindings/api/generate_csharp.py [--api sph_api.json] [--out FILE]

Unity-style and IL2CPP-friendly: blittable [StructLayout(LayoutKind.Sequential)] structs
(fixed C arrays become small blittable structs with an indexer, pointers become IntPtr),
int-backed enums, Cdecl [DllImport] externs, and a SafeHandle subclass per opaque type that
releases it with its _destroy function. No `unsafe` code, so the files compile without
/unsafe. Every function gets a typed extern (SafeHandles, ref/out, arrays) and, when it has
pointer parameters, a raw overload taking IntPtr for each pointer (NativeArray pointers, NULL).

Parameter rules for the typed extern:
    sph_x* / const sph_x* (opaque)      -> XHandle          (IntPtr in sph_x_destroy)
    sph_x** (opaque out)                -> out XHandle
    T* / const T* followed by a count   -> T[]              (capacity/count parameter next)
    T* named out_* (struct, no struct_size) -> out T
    T* / const T* (struct)              -> ref T
    T* named out_* (number or enum)     -> out T
    T[N] (number)                       -> ref FixedTN      (exactly N elements: a shorter T[] would
                                                             let the library read past its end)
    const T* (number)                   -> T[]
    T* (number)                         -> ref T
    void** named out_*                  -> out IntPtr
    void*, const char*, anything else   -> IntPtr / byte[] (NUL-terminated UTF-8)
"""
from __future__ import annotations

import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import apimodel as am  # noqa: E402

ROOT = os.path.normpath(os.path.join(am.HERE, "..", ".."))
DEFAULT_OUT = os.path.join(ROOT, "bindings", "csharp", "Sph.Generated.cs")

CS = {
    "char": "byte", "float": "float", "double": "double",
    "int8_t": "sbyte", "uint8_t": "byte", "int16_t": "short", "uint16_t": "ushort",
    "int32_t": "int", "uint32_t": "uint", "int64_t": "long", "uint64_t": "ulong",
    "size_t": "UIntPtr", "ptrdiff_t": "IntPtr", "intptr_t": "IntPtr", "uintptr_t": "UIntPtr",
}
CS_KEYWORDS = {
    "abstract", "as", "base", "bool", "break", "byte", "case", "catch", "char", "checked", "class", "const",
    "continue", "decimal", "default", "delegate", "do", "double", "else", "enum", "event", "explicit", "extern",
    "false", "finally", "fixed", "float", "for", "foreach", "goto", "if", "implicit", "in", "int", "interface",
    "internal", "is", "lock", "long", "namespace", "new", "null", "object", "operator", "out", "override",
    "params", "private", "protected", "public", "readonly", "ref", "return", "sbyte", "sealed", "short",
    "sizeof", "stackalloc", "static", "string", "struct", "switch", "this", "throw", "true", "try", "typeof",
    "uint", "ulong", "unchecked", "unsafe", "ushort", "using", "virtual", "void", "volatile", "while",
}
# Types of namespace System that a C# name must not shadow: a user file with `using System;`
# and `using Sph;` would see an ambiguous reference. Such names get an "Sph" prefix
# (sph_attribute -> SphAttribute).
SYSTEM_TYPES = {"Action", "Activator", "Array", "Attribute", "Buffer", "Console", "Convert", "Delegate", "Enum",
                "Environment", "Exception", "Func", "GC", "Guid", "Math", "Object", "Random", "Single",
                "String", "Tuple", "Type", "Version", "TimeSpan", "DateTime", "Index", "Range", "Half"}
# Libraries that hold the whole of sph_c.h and more, loaded in place of libsph, never beside it
# (each keeps its own registry of worlds; bindings/python/sph/_loader.py's CORE_VARIANTS). The
# bindings compiled with the define each names (-define:SPH_MPI) send every call to it.
CORE_VARIANTS = {"sph_mpi": "SPH_MPI"}
CONST_TYPES = {"int32": "int", "uint32": "uint", "int64": "long", "uint64": "ulong", "float": "float",
               "double": "double", "string": "string"}


class Gen:
    def __init__(self, api: dict):
        self.api = api
        self.aliases = {td["name"]: td["type"] for td in api["typedefs"]}
        self.structs = {s["name"]: s for s in api["structs"]}
        self.libraries = sorted({f["library"] for f in api["functions"]}, key=lambda n: (n != "sph", n))
        self.arrays: dict[tuple[str, int], str] = {}  # (element C# type, length) -> struct name
        self.enum_names = {e["name"]: self.type_name(e["name"]) for e in api["enums"]}
        self.struct_names = {s["name"]: self.type_name(s["name"]) for s in api["structs"]}
        self.handle_names = {o["name"]: am.camel(o["name"]) + "Handle" for o in api["opaque_types"]}
        self.callback_names = {c["name"]: self.type_name(c["name"]) for c in api["callbacks"]}
        names = list(self.enum_names.values()) + list(self.struct_names.values()) + \
            list(self.handle_names.values()) + list(self.callback_names.values())
        clash = {n for n in names if names.count(n) > 1} | (set(names) & {"Native", "Constants", "Layout"})
        if clash:
            raise SystemExit(f"generate_csharp.py: C# name clash: {sorted(clash)}")

    @staticmethod
    def type_name(c_name: str) -> str:
        n = am.camel(c_name)
        return "Sph" + n if n in SYSTEM_TYPES else n

    # -- types
    def resolve(self, ty: dict) -> dict:
        while ty["kind"] == "alias":
            ty = self.aliases[ty["name"]]
        return ty

    def value_type(self, ty: dict) -> str:
        """C# type of a struct field, callback parameter or return value."""
        ty = self.resolve(ty)
        k = ty["kind"]
        if k == "void":
            return "void"
        if k == "builtin":
            return CS[ty["name"]]
        if k == "enum":
            return self.enum_names[ty["name"]]
        if k == "struct":
            return self.struct_names[ty["name"]]
        if k in ("pointer", "callback", "function_pointer"):
            return "IntPtr"
        if k == "array":
            elem = self.value_type(ty["of"])
            key = (elem, ty["length"])
            if key not in self.arrays:
                self.arrays[key] = f"Fixed{elem[:1].upper() + elem[1:]}{ty['length']}"
            return self.arrays[key]
        raise ValueError(f"no C# value type for {ty}")

    def is_count_param(self, p: dict | None) -> bool:
        if p is None:
            return False
        t = self.resolve(p["type"])
        return t["kind"] == "builtin" and t["name"] in ("uint32_t", "uint64_t", "size_t", "int32_t") and \
            (p["name"] in ("count", "capacity") or p["name"].endswith("_count") or p["name"].endswith("_capacity"))

    def typed_param(self, fn: dict, i: int) -> str:
        p = fn["params"][i]
        nxt = fn["params"][i + 1] if i + 1 < len(fn["params"]) else None
        name = self.param_name(p["name"])
        ty = self.resolve(p["type"])
        k = ty["kind"]
        if k == "callback":
            return f"{self.callback_names[ty['name']]} {name}"
        if k == "array":
            elem = self.resolve(ty["of"])
            if elem["kind"] in ("builtin", "enum") and ty.get("length"):
                return f"ref {self.value_type(ty)} {name}"
            if elem["kind"] in ("builtin", "enum", "struct"):
                attr = "[In] " if elem.get("const") else "[In, Out] "
                return f"{attr}{self.value_type(elem)}[] {name}"
            return f"IntPtr {name}"
        if k != "pointer":
            return f"{self.value_type(ty)} {name}"
        to = self.resolve(ty["to"])
        if to["kind"] == "opaque":
            destroy = next((o["destroy"] for o in self.api["opaque_types"] if o["name"] == to["name"]), None)
            if fn["name"] == destroy:
                return f"IntPtr {name}"
            return f"{self.handle_names[to['name']]} {name}"
        if am.is_opaque_ptr(to):
            return f"out {self.handle_names[to['to']['name']]} {name}"
        if am.is_char_ptr(ty):
            return f"byte[] {name}"
        if to["kind"] == "pointer" and to["to"]["kind"] == "void" and p["name"].startswith("out"):
            return f"out IntPtr {name}"
        if to["kind"] in ("builtin", "enum", "struct") and not am.is_char_ptr(ty):
            cs = self.value_type(to)
            const = bool(to.get("const"))
            if self.is_count_param(nxt):
                return f"{'[In] ' if const else '[In, Out] '}{cs}[] {name}"
            if to["kind"] == "struct":
                versioned = any(f["name"] == "struct_size" for f in self.structs[to["name"]]["fields"])
                if not const and p["name"].startswith("out") and not versioned:
                    return f"out {cs} {name}"  # a plain value the call writes (an id, a transform)
                return f"ref {cs} {name}"  # versioned structs need struct_size set by the caller
            if not const and p["name"].startswith("out"):
                return f"out {cs} {name}"
            if const:
                return f"[In] {cs}[] {name}"
            return f"ref {cs} {name}"
        return f"IntPtr {name}"

    def raw_param(self, p: dict) -> str:
        ty = self.resolve(p["type"])
        name = self.param_name(p["name"])
        if ty["kind"] in ("pointer", "array"):
            return f"IntPtr {name}"
        if ty["kind"] == "callback":
            return f"IntPtr {name}"
        return f"{self.value_type(ty)} {name}"

    @staticmethod
    def param_name(c_name: str) -> str:
        n = am.lower_camel(c_name) if "_" in c_name else c_name
        return "@" + n if n in CS_KEYWORDS else n

    @staticmethod
    def xml(text: str) -> str:
        return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")

    def summary(self, text: str, indent: str) -> list[str]:
        if not text:
            return []
        import textwrap
        lines = []
        for para in self.xml(text).split("\n\n"):
            if lines:
                lines.append("<para/>")
            lines += textwrap.wrap(para, 100 - len(indent))
        if len(lines) == 1:
            return [f"{indent}/// <summary>{lines[0]}</summary>"]
        return [f"{indent}/// <summary>"] + [f"{indent}/// {ln}" for ln in lines] + [f"{indent}/// </summary>"]

    # -- output
    def generate(self) -> str:
        api = self.api
        out = ["// <auto-generated>"] + am.header_banner(api, "generate_csharp.py", "//") + ["// </auto-generated>",
               "using System;",
               "using System.Collections.Generic;",
               "using System.Runtime.InteropServices;",
               "",
               "namespace Sph",
               "{"]
        out += self.constants()
        for e in api["enums"]:
            out += self.enum(e)
        for cb in api["callbacks"]:
            out += self.callback(cb)
        structs = []
        for s in api["structs"]:
            structs += self.struct(s)
        handles = []
        for o in api["opaque_types"]:
            handles += self.handle(o)
        native = self.native()  # before the arrays: parameters may name fixed arrays too
        arrays = []
        for (elem, length), name in self.arrays.items():
            arrays += self.fixed_array(name, elem, length)
        out += arrays + structs + handles + native
        out += self.layout()
        out.append("}")
        return "\n".join(out) + "\n"

    def constants(self) -> list[str]:
        out = ["    /// <summary>The #define constants of sph_c.h, and the enum sentinels (FORCE32, COUNT).</summary>",
               "    public static class Constants", "    {"]
        for d in self.api["defines"]:
            cs = CONST_TYPES.get(d["type"])
            if cs is None:
                out.append(f"        // {d['name']}: a constant of unsupported type, not generated")
                continue
            out += self.summary(d["doc"], "        ")
            value = d["value"]
            lit = f"\"{value}\"" if cs == "string" else (f"{value}u" if cs == "uint" else
                                                          f"{value}UL" if cs == "ulong" else
                                                          f"{value}L" if cs == "long" else
                                                          f"{value}f" if cs == "float" else f"{value}")
            out.append(f"        public const {cs} {d['name']} = {lit};")
        for e in self.api["enums"]:
            for m in e["members"]:
                if am.is_sentinel(e, m):
                    out.append(f"        public const int {m['name']} = {m['value']};")
        for m in self.api["macros"]:
            out.append(f"        // {m['name']}({', '.join(m['params'])}) is a function-like macro: not generated.")
        out += ["    }", ""]
        return out

    def enum(self, e: dict) -> list[str]:
        out = self.summary(f"{e['name']}" + (f": {e['doc']}" if e["doc"] else ""), "    ")
        base = {1: "sbyte", 2: "short", 4: "int", 8: "long"}[e["size"]]
        out += [f"    public enum {self.enum_names[e['name']]} : {base}", "    {"]
        for m in e["members"]:
            if am.is_sentinel(e, m):
                continue
            out += self.summary(m["doc"], "        ")
            out.append(f"        {am.pascal_member(e, m)} = {m['value']},")
        out += ["    }", ""]
        return out

    def callback(self, cb: dict) -> list[str]:
        out = self.summary(f"{cb['name']}: {cb['doc']}", "    ")
        params = ", ".join(f"{self.value_type(p['type'])} {self.param_name(p['name'])}" for p in cb["params"])
        out += ["    [UnmanagedFunctionPointer(CallingConvention.Cdecl)]",
                f"    public delegate {self.value_type(cb['return'])} {self.callback_names[cb['name']]}({params});", ""]
        return out

    def fixed_array(self, name: str, elem: str, length: int) -> list[str]:
        out = [f"    /// <summary>A C array {elem}[{length}], blittable (no unsafe fixed buffer).</summary>",
               "    [StructLayout(LayoutKind.Sequential)]",
               f"    public struct {name}", "    {"]
        out.append("        public " + elem + " " + ", ".join(f"E{i}" for i in range(length)) + ";")
        out += [f"        public const int Length = {length};", "",
                f"        public {elem} this[int index]", "        {", "            get", "            {",
                "                switch (index)", "                {"]
        out += [f"                    case {i}: return E{i};" for i in range(length)]
        out += ["                    default: throw new IndexOutOfRangeException();", "                }",
                "            }", "            set", "            {",
                "                switch (index)", "                {"]
        out += [f"                    case {i}: E{i} = value; break;" for i in range(length)]
        out += ["                    default: throw new IndexOutOfRangeException();", "                }",
                "            }", "        }", "",
                f"        public {elem}[] ToArray()", "        {",
                f"            return new {elem}[] {{ " + ", ".join(f"E{i}" for i in range(length)) + " };",
                "        }", "",
                f"        public static {name} From({elem}[] values)", "        {",
                "            if (values == null || values.Length != Length)",
                f"                throw new ArgumentException(\"expected {length} values\");",
                f"            var a = new {name}();",
                "            for (int i = 0; i < Length; ++i) a[i] = values[i];",
                "            return a;", "        }",
                "    }", ""]
        return out

    def struct(self, s: dict) -> list[str]:
        name = self.struct_names[s["name"]]
        out = self.summary(f"{s['name']} ({s['size']} bytes)" + (f": {s['doc']}" if s["doc"] else ""), "    ")
        # partial: Sph.cs may add typed views of fields (flag enums over uint fields, ...).
        out += ["    [StructLayout(LayoutKind.Sequential)]", f"    public partial struct {name}", "    {"]
        for f in s["fields"]:
            doc = f"{f['type']['c']} {f['name']}" + (f": {f['doc']}" if f["doc"] else "")
            out += self.summary(doc, "        ")
            out.append(f"        public {self.value_type(f['type'])} {am.pascal_field(f['name'])};")
        init = s.get("init")
        if init:
            out += ["",
                    f"        /// <summary>A {name} with the library's defaults ({init['function']}).</summary>",
                    f"        public static {name} Default()", "        {",
                    f"            var value = new {name}();",
                    f"            uint size = (uint)Marshal.SizeOf(typeof({name}));",
                    f"            SphException.Check(Native.{init['function']}(ref value, size), \"{init['function']}\");"]
            fields = {f["name"]: f for f in s["fields"]}
            for field, const in init["assigns"].items():
                out.append(f"            value.{am.pascal_field(field)} = ({self.value_type(fields[field]['type'])})"
                           f"Constants.{const};")
            out += ["            return value;", "        }"]
        elif s.get("default"):
            fn = s["default"]["function"]
            out += ["", f"        /// <summary>The library's default {name} ({fn}).</summary>",
                    f"        public static {name} Default()", "        {",
                    f"            return Native.{fn}();", "        }"]
        if not init and not any(f["name"] == "struct_size" for f in s["fields"]) and len(s["fields"]) <= 4 and all(
                self.resolve(f["type"])["kind"] in ("builtin", "struct") for f in s["fields"]):
            params = ", ".join(f"{self.value_type(f['type'])} {self.param_name(f['name'])}" for f in s["fields"])
            out += ["", f"        public {name}({params})", "        {"]
            out += [f"            {am.pascal_field(f['name'])} = {self.param_name(f['name'])};" for f in s["fields"]]
            out += ["        }"]
        out += ["    }", ""]
        return out

    def handle(self, o: dict) -> list[str]:
        name = self.handle_names[o["name"]]
        destroy = o["destroy"]
        out = self.summary(f"Owns an {o['name']}*" + (f", released with {destroy}" if destroy else "") +
                           (f". {o['doc']}" if o["doc"] else "."), "    ")
        out += [f"    public sealed partial class {name} : SafeHandle", "    {",
                "        private SafeHandle parent;", "",
                f"        public {name}() : base(IntPtr.Zero, {'true' if destroy else 'false'}) {{ }}", "",
                "        public override bool IsInvalid { get { return handle == IntPtr.Zero; } }", "",
                "        /// <summary>Keeps `owner` (e.g. a world's context) alive until this handle is released.</summary>",
                "        public void SetParent(SafeHandle owner)", "        {",
                "            bool added = false;",
                "            owner.DangerousAddRef(ref added);",
                "            if (added) parent = owner;",
                "        }", "",
                "        partial void OnReleased();", "",
                "        // Sets keep to leave the object alive and unreleased (WorldHandle: an asynchronous",
                "        // step holds the world).",
                "        partial void OnReleasing(ref bool keep);", "",
                "        // A SafeHandle is closed whatever this returns: when the object must live on (kept, or",
                "        // its destroy refused), it is leaked with its parent reference, never freed under a",
                "        // call that still uses it.",
                "        protected override bool ReleaseHandle()", "        {",
                "            bool keep = false;",
                "            OnReleasing(ref keep);",
                "            if (keep) return false;"]
        if destroy:
            out += [f"            Result result = Native.{destroy}(handle);",
                    "            if ((int)result < 0) return false;"]
        out += ["            OnReleased();",
                "            if (parent != null)", "            {", "                parent.DangerousRelease();",
                "                parent = null;", "            }",
                "            return true;", "        }", "    }", ""]
        return out

    def native(self) -> list[str]:
        out = ["    /// <summary>The C functions, one extern per function (plus a raw IntPtr overload).</summary>",
               "    public static partial class Native", "    {",
               "#if (UNITY_IOS || UNITY_WEBGL) && !UNITY_EDITOR",
               "        public const string Library = \"__Internal\";"] + [
               f"        public const string Library{am.camel('sph_' + lib) if lib != 'sph' else ''} = \"__Internal\";"
               for lib in self.libraries if lib != "sph"]
        for core, define in CORE_VARIANTS.items():
            if core not in self.libraries:
                continue
            out += [f"#elif {define}",
                    f"        // {define}: every function from lib{core}, which holds sph_c.h too (one registry).",
                    f"        public const string Library = \"{core}\";"] + [
                    f"        public const string Library{am.camel('sph_' + lib)} = \"{lib}\";"
                    for lib in self.libraries if lib != "sph"]
        out += ["#else",
                "        public const string Library = \"sph\";"] + [
                f"        public const string Library{am.camel('sph_' + lib)} = \"{lib}\";"
                for lib in self.libraries if lib != "sph"] + [
                "#endif", ""]
        for f in self.api["functions"]:
            ret = self.value_type(f["return"])
            doc = f["doc"] or f["name"]
            typed = ", ".join(self.typed_param(f, i) for i in range(len(f["params"])))
            raw = ", ".join(self.raw_param(p) for p in f["params"])
            out += self.summary(doc, "        ")
            lib = "Library" + (am.camel("sph_" + f["library"]) if f["library"] != "sph" else "")
            out.append(f"        [DllImport({lib}, CallingConvention = CallingConvention.Cdecl)]")
            out.append(f"        public static extern {ret} {f['name']}({typed});")
            if self.strip_attrs(typed) != raw:
                out.append(f"        [DllImport({lib}, CallingConvention = CallingConvention.Cdecl, "
                           f"EntryPoint = \"{f['name']}\")]")
                out.append(f"        public static extern {ret} {f['name']}({raw});")
            out.append("")
        out += ["    }", ""]
        return out

    @staticmethod
    def strip_attrs(params: str) -> str:
        return params.replace("[In, Out] ", "").replace("[In] ", "")

    def layout(self) -> list[str]:
        api = self.api
        structs = api["structs"]
        out = ["    /// <summary>What the C compiler measured when sph_api.json was generated.</summary>",
               "    public static class Layout", "    {",
               f"        public const uint AbiVersion = {api['version']['abi']};",
               f"        public const uint Version = {api['version']['packed']};",
               f"        public const int PointerSize = {api['layout']['pointer_size']};",
               "        public static readonly string[] Headers = { " +
               ", ".join(f"\"{h['path']}\"" for h in api["headers"]) + " };", "",
               "        public static readonly Type[] StructTypes = {"]
        out += [f"            typeof({self.struct_names[s['name']]})," for s in structs]
        out += ["        };", "        public static readonly string[] StructNames = {"]
        out += [f"            \"{s['name']}\"," for s in structs]
        out += ["        };", "        public static readonly int[] StructSizes = {"]
        out += [f"            {s['size']}," for s in structs]
        out += ["        };", "", "        // One entry per field: struct type, C# field name, C offset.",
                "        public static readonly Type[] FieldStructs = {"]
        out += [f"            typeof({self.struct_names[s['name']]})," for s in structs for _ in s["fields"]]
        out += ["        };", "        public static readonly string[] FieldNames = {"]
        out += [f"            \"{am.pascal_field(f['name'])}\"," for s in structs for f in s["fields"]]
        out += ["        };", "        public static readonly int[] FieldOffsets = {"]
        out += [f"            {f['offset']}," for s in structs for f in s["fields"]]
        out += ["        };", "", "        /// <summary>Every exported function of the header.</summary>",
                "        public static readonly string[] Functions = {"]
        out += [f"            \"{f['name']}\"," for f in api["functions"]]
        out += ["        };", "        /// <summary>The shared library of each function (\"sph\", or an optional helper).</summary>",
                "        public static readonly string[] FunctionLibraries = {"]
        out += [f"            \"{f['library']}\"," for f in api["functions"]]
        out += ["        };", "", "        /// <summary>Doc text of enum members by C name (e.g. an attribute's element format).</summary>",
                "        public static readonly Dictionary<string, string> EnumMemberDocs = new Dictionary<string, string>",
                "        {"]
        for e in api["enums"]:
            for m in e["members"]:
                if m["doc"]:
                    doc = m["doc"].replace("\\", "\\\\").replace('"', '\\"')
                    out.append(f"            {{ \"{m['name']}\", \"{doc}\" }},")
        out += ["        };", "    }"]
        return out


def generate(api: dict) -> str:
    return Gen(api).generate()


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--api", default=am.DEFAULT_API)
    ap.add_argument("--out", default=DEFAULT_OUT)
    args = ap.parse_args(argv)
    text = generate(am.load(args.api))
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with open(args.out, "w", encoding="utf-8", newline="\n") as f:
        f.write(text)
    print(f"generate_csharp.py: wrote {os.path.relpath(args.out)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
