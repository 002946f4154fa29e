#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Generates bindings/api/sph_api.json, the machine-readable description of include/sph_c.h.

    python3 bindings/api/generate_api.py [--header H ...] [--out FILE] [--cc CC]

The headers are include/sph_c.h and then every other include/sph_*.h (the CUDA interop tier
sph_cuda.h; sph_vdb.h, whose functions live in the optional helper library libsph_vdb;
sph_mpi.h, whose functions live in libsph_mpi, loaded in place of libsph), unless --header
names them. Every declaration records its header, every function its library.

Two passes:

1. A parser for the header's regular dialect of C (no libclang needed): a lexer that keeps
   comments and preprocessor lines, a conditional pass that drops the C++-only lines
   (`extern "C" {`), and a declaration parser for `typedef enum {...} x;`, `typedef struct
   {...} x;`, opaque `typedef struct x x;`, type aliases, callback typedefs, `SPH_API`
   function declarations, `static inline` helpers, top-level `#define` constants and
   `SPH_STATIC_ASSERT(...)` lines. Doc text comes from the comment before a declaration
   (`/** ... */` or `/* ... */`) or after it on the same line. Section banners
   (`/* ---- name ---- */`) name the section of what follows. Anything it does not understand
   is an error with a line number, never silently skipped.

2. A check against the real C compiler: a probe program includes the header and prints
   sizeof/_Alignof of every struct and enum, offsetof/sizeof of every field and the value of
   every enum member and #define; it also asserts, with __builtin_types_compatible_p and typed
   function-pointer initialisers under -Werror, that every field and every function signature
   the parser read is exactly what the compiler sees. Sizes, offsets and values in the JSON
   come from the compiler, not from the parser.

New functions, structs, enums and constants need no edits here. The output is deterministic
(no timestamps, no compiler names), so `generate.py --check` can diff it.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
DEFAULT_HEADER = os.path.join(ROOT, "include", "sph_c.h")
DEFAULT_OUT = os.path.join(HERE, "sph_api.json")

# The shared library that exports a header's functions, when it is not libsph itself.
# (sph_vdb.h belongs to the optional OpenVDB helper library libsph_vdb; sph_mpi.h to libsph_mpi,
# which holds the whole of sph_c.h too and is loaded instead of libsph, never beside it.)
LIBRARY_OF_HEADER = {"sph_vdb.h": "sph_vdb", "sph_mpi.h": "sph_mpi"}

# C types the header may use directly (B2: fixed-width types only; the rest for robustness).
BUILTIN_TYPES = {
    "void", "char", "float", "double", "size_t", "ptrdiff_t", "intptr_t", "uintptr_t",
    "int8_t", "uint8_t", "int16_t", "uint16_t", "int32_t", "uint32_t", "int64_t", "uint64_t",
}
# Words the header may put around declarations that carry no type information.
EXPORT_MACROS = {"SPH_API", "SPH_CALL"}


class ParseError(Exception):
    pass


# ---------------------------------------------------------------------------------------------
# Lexer
# ---------------------------------------------------------------------------------------------
@dataclass
class Tok:
    kind: str  # ident, number, string, char, punct, comment, directive
    text: str
    line: int  # first line (1-based)
    end_line: int  # last line
    pos: int = 0  # offsets into the header text
    end: int = 0
    active: bool = True  # False inside a C++-only conditional branch


_PUNCT = sorted(
    ["...", "<<=", ">>=", "->", "++", "--", "<<", ">>", "<=", ">=", "==", "!=", "&&", "||", "+=", "-=",
     "*=", "/=", "%=", "&=", "|=", "^=", "##", "::"]
    + list("{}[]()<>;,*&=+-/%!~^|?:.#"),
    key=len, reverse=True)
_NUMBER = re.compile(r"(0[xX][0-9a-fA-F]+|[0-9]+\.?[0-9]*([eE][+-]?[0-9]+)?|\.[0-9]+([eE][+-]?[0-9]+)?)[uUlLfF]*")
_IDENT = re.compile(r"[A-Za-z_][A-Za-z_0-9]*")


def lex(text: str) -> list[Tok]:
    toks: list[Tok] = []
    i, n, line = 0, len(text), 1
    at_line_start = True
    while i < n:
        c = text[i]
        if c == "\n":
            line += 1
            i += 1
            at_line_start = True
            continue
        if c in " \t\r\f\v":
            i += 1
            continue
        if text.startswith("/*", i):
            j = text.find("*/", i + 2)
            if j < 0:
                raise ParseError(f"line {line}: unterminated comment")
            body = text[i:j + 2]
            toks.append(Tok("comment", body, line, line + body.count("\n")))
            line += body.count("\n")
            i = j + 2
            continue
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            toks.append(Tok("comment", text[i:j], line, line))
            i = j
            continue
        if c == "#" and at_line_start:
            # A directive runs to the end of the line, with backslash continuations; comments
            # inside it stay part of it.
            j, start_line = i, line
            while j < n:
                if text.startswith("/*", j):
                    k = text.find("*/", j + 2)
                    if k < 0:
                        raise ParseError(f"line {line}: unterminated comment")
                    line += text.count("\n", j, k)
                    j = k + 2
                    continue
                if text[j] == "\\" and j + 1 < n and text[j + 1] == "\n":
                    line += 1
                    j += 2
                    continue
                if text[j] == "\n":
                    break
                j += 1
            toks.append(Tok("directive", text[i:j], start_line, line))
            i = j
            continue
        at_line_start = False
        if c == '"' or c == "'":
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            toks.append(Tok("string" if c == '"' else "char", text[i:j + 1], line, line))
            i = j + 1
            continue
        m = _IDENT.match(text, i)
        if m:
            toks.append(Tok("ident", m.group(0), line, line))
            i = m.end()
            continue
        m = _NUMBER.match(text, i)
        if m and m.group(0):
            toks.append(Tok("number", m.group(0), line, line))
            i = m.end()
            continue
        for p in _PUNCT:
            if text.startswith(p, i):
                toks.append(Tok("punct", p, line, line))
                i += len(p)
                break
        else:
            raise ParseError(f"line {line}: unexpected character {c!r}")
    # Offsets: only whitespace lies between tokens, so each is found right after the last.
    cursor = 0
    for t in toks:
        t.pos = text.index(t.text, cursor)
        t.end = cursor = t.pos + len(t.text)
    return toks


# ---------------------------------------------------------------------------------------------
# Comments
# ---------------------------------------------------------------------------------------------
_SECTION = re.compile(r"^/\*\s*-{3,}\s*([^\n]*?)\s*-*\s*(\n(.*))?\*/$", re.S)


def is_section(comment: str) -> bool:
    return bool(_SECTION.match(comment))


def section_title(comment: str) -> str:
    return _SECTION.match(comment).group(1).strip()


def section_doc(comment: str) -> str:
    rest = _SECTION.match(comment).group(3)
    return clean_comment("/*" + rest + "*/") if rest else ""


def clean_comment(comment: str) -> str:
    """Comment text without the markers: wrapped lines joined with spaces, blank lines kept
    as paragraph breaks."""
    if comment.startswith("//"):
        body = comment.lstrip("/")
        return body.strip()
    body = comment[2:-2]
    if body.startswith("*") and not body.startswith("*/"):
        body = body[1:]  # /** doc */
    if body.startswith("<"):
        body = body[1:]  # /**< trailing doc */
    paragraphs, current = [], []
    for raw in body.split("\n"):
        s = raw.strip()
        if s.startswith("*"):
            s = s[1:].strip()
        if s:
            current.append(s)
        elif current:
            paragraphs.append(" ".join(current))
            current = []
    if current:
        paragraphs.append(" ".join(current))
    return "\n\n".join(paragraphs)


# ---------------------------------------------------------------------------------------------
# Preprocessor pass: conditionals, #define
# ---------------------------------------------------------------------------------------------
_DIRECTIVE = re.compile(r"#\s*(\w+)\s*(.*)", re.S)


def _strip_directive_comments(s: str) -> tuple[str, list[str]]:
    comments = re.findall(r"/\*.*?\*/|//[^\n]*", s, re.S)
    s = re.sub(r"/\*.*?\*/|//[^\n]*", " ", s, flags=re.S)
    return re.sub(r"\\\n", " ", s).strip(), comments


def preprocess(toks: list[Tok]):
    """Marks tokens inside C++-only branches inactive; returns (defines, macros, macro_names).

    Records #defines at the header's top level (inside the include guard, outside other
    conditionals): object-like ones as constants, function-like ones as macros. Every macro
    name defined anywhere is returned too, so declarations can skip annotation macros."""
    stack: list[dict] = []  # {"cpp": True if the branch is C++-only}
    guard = None
    defines, macros, macro_names = [], [], set()
    first_directive = True
    for idx, t in enumerate(toks):
        if t.kind != "directive":
            t.active = not any(f["cpp"] for f in stack)
            continue
        t.active = False
        text, comments = _strip_directive_comments(t.text)
        m = _DIRECTIVE.match(text)
        if not m:
            continue
        name, rest = m.group(1), m.group(2).strip()
        if name in ("if", "ifdef", "ifndef"):
            cpp_when_true = None
            if re.fullmatch(r"(defined\s*\(?\s*__cplusplus\s*\)?|__cplusplus)", rest) and name in ("if", "ifdef"):
                cpp_when_true = True
            elif (name == "ifndef" and rest == "__cplusplus") or \
                    re.fullmatch(r"!\s*defined\s*\(?\s*__cplusplus\s*\)?", rest):
                cpp_when_true = False
            if first_directive and name == "ifndef":
                guard = rest
            stack.append({"cpp": cpp_when_true is True, "cpp_when_true": cpp_when_true,
                          "guard": first_directive and name == "ifndef"})
        elif name in ("elif", "else"):
            if not stack:
                raise ParseError(f"line {t.line}: #{name} without #if")
            f = stack[-1]
            if f["cpp_when_true"] is not None:
                f["cpp"] = not f["cpp_when_true"] if name == "else" else False
        elif name == "endif":
            if not stack:
                raise ParseError(f"line {t.line}: #endif without #if")
            stack.pop()
        elif name == "define":
            dm = re.match(r"(\w+)(\(([^)]*)\))?\s*(.*)", rest, re.S)
            if not dm:
                raise ParseError(f"line {t.line}: cannot read #define")
            mname, is_fn, params, body = dm.group(1), dm.group(2), dm.group(3), dm.group(4).strip()
            macro_names.add(mname)
            top = len(stack) == (1 if guard else 0) and (not stack or stack[0]["guard"])
            if top and mname != guard:
                # A doc comment above and a comment on the line: both (the one above may
                # introduce a group of flags, the one on the line says what this one does).
                trailing = " ".join(x for x in (clean_comment(c) for c in comments) if x)
                doc = " ".join(x for x in (_leading_doc(toks, idx), trailing) if x)
                entry = {"name": mname, "doc": doc, "line": t.line}
                if is_fn is not None:
                    entry.update({"params": [p.strip() for p in params.split(",") if p.strip()], "body": body})
                    macros.append(entry)
                elif body:
                    entry["expression"] = body
                    defines.append(entry)
        first_directive = False
    if stack:
        raise ParseError("unterminated #if at end of header")
    return defines, macros, macro_names


def _leading_doc(toks: list[Tok], idx: int) -> str:
    """Doc comment directly before toks[idx]: the previous token, a comment that is not a
    section banner and not a trailing comment of the line before."""
    j = idx - 1
    if j < 0 or toks[j].kind != "comment" or is_section(toks[j].text):
        return ""
    c = toks[j]
    if j > 0 and toks[j - 1].end_line == c.line and toks[j - 1].kind != "comment":
        return ""  # trailing comment of the previous declaration
    if toks[idx].line - c.end_line > 1:
        return ""  # separated by a blank line
    return clean_comment(c.text)


# ---------------------------------------------------------------------------------------------
# Declaration parser
# ---------------------------------------------------------------------------------------------
class Parser:
    def __init__(self, toks: list[Tok], macro_names: set[str], text: str, api: dict, types: dict[str, str]):
        self.text = text
        self.all = toks
        # Code tokens with their index into self.all (for comment lookup).
        self.code = [(i, t) for i, t in enumerate(toks) if t.active and t.kind not in ("comment", "directive")]
        self.pos = 0
        self.macro_names = macro_names
        self.types = types  # name -> kind (enum, struct, opaque, alias, callback), across headers
        self.api = api
        self.section = ""
        self.sections_by_line: list[tuple[int, str]] = [
            (t.line, section_title(t.text)) for t in toks if t.kind == "comment" and is_section(t.text)]
        self.api["sections"] += [{"title": section_title(t.text), "doc": section_doc(t.text), "line": t.line}
                                 for t in toks if t.kind == "comment" and is_section(t.text)]

    # -- token helpers
    def peek(self, k: int = 0) -> Tok | None:
        p = self.pos + k
        return self.code[p][1] if p < len(self.code) else None

    def next(self) -> Tok:
        t = self.peek()
        if t is None:
            raise ParseError("unexpected end of header")
        self.pos += 1
        return t

    def expect(self, text: str) -> Tok:
        t = self.next()
        if t.text != text:
            raise ParseError(f"line {t.line}: expected {text!r}, found {t.text!r}")
        return t

    def accept(self, text: str) -> bool:
        t = self.peek()
        if t is not None and t.text == text:
            self.pos += 1
            return True
        return False

    def all_index(self, k: int = 0) -> int:
        return self.code[self.pos + k][0]

    def section_at(self, line: int) -> str:
        s = ""
        for ln, title in self.sections_by_line:
            if ln <= line:
                s = title
        return s

    def leading_doc(self, code_pos: int) -> str:
        return _leading_doc(self.all, self.code[code_pos][0])

    def trailing_doc(self, code_pos_of_last: int) -> str:
        """Comments that start on the line of the given code token, right after it."""
        idx = self.code[code_pos_of_last][0]
        line = self.all[idx].end_line
        docs = []
        j = idx + 1
        while j < len(self.all) and self.all[j].kind == "comment" and self.all[j].line == line:
            docs.append(clean_comment(self.all[j].text))
            j += 1
        return " ".join(d for d in docs if d)

    def source(self, toks: list[Tok]) -> str:
        """The header text from the first to the last token, whitespace collapsed."""
        if not toks:
            return ""
        return re.sub(r"\s+", " ", self.text[toks[0].pos:toks[-1].end])

    def skip_balanced(self, open_: str, close: str) -> list[Tok]:
        self.expect(open_)
        depth, out = 1, []
        while True:
            t = self.next()
            if t.text == open_:
                depth += 1
            elif t.text == close:
                depth -= 1
                if depth == 0:
                    return out
            out.append(t)

    def skip_annotations(self) -> list[str]:
        """Skips SPH_API/SPH_CALL and other macro words (SPH_DEPRECATED("...")); returns the
        ones other than the export macros."""
        notes = []
        while True:
            t = self.peek()
            if t is None or t.kind != "ident" or t.text not in self.macro_names:
                return notes
            self.pos += 1
            text = t.text
            if self.peek() is not None and self.peek().text == "(":
                inner = self.skip_balanced("(", ")")
                text += "(" + " ".join(x.text for x in inner) + ")"
            if t.text not in EXPORT_MACROS:
                notes.append(text)

    # -- types
    def parse_specifiers(self) -> dict:
        """const? (struct|enum)? NAME const?  ->  a type dict (without pointers)."""
        const = False
        while self.peek() is not None and self.peek().text in ("const", "volatile"):
            const = const or self.next().text == "const"
        self.skip_annotations()
        t = self.next()
        if t.text in ("struct", "enum"):
            t = self.next()
        if t.kind != "ident":
            raise ParseError(f"line {t.line}: expected a type name, found {t.text!r}")
        name = t.text
        if name in ("unsigned", "signed", "long", "short", "int", "_Bool", "bool"):
            raise ParseError(f"line {t.line}: type {name!r} is not allowed in the ABI (use fixed-width types)")
        while self.peek() is not None and self.peek().text in ("const", "volatile"):
            const = const or self.next().text == "const"
        return self.named_type(name, const, t.line)

    def named_type(self, name: str, const: bool, line: int) -> dict:
        if name in BUILTIN_TYPES:
            ty = {"kind": "void" if name == "void" else "builtin", "name": name}
        elif name in self.types:
            ty = {"kind": self.types[name], "name": name}
        else:
            raise ParseError(f"line {line}: unknown type {name!r}")
        if const:
            ty["const"] = True
        return ty

    def parse_pointers(self, base: dict) -> dict:
        ty = base
        while self.accept("*"):
            ty = {"kind": "pointer", "to": ty}
            while self.peek() is not None and self.peek().text in ("const", "volatile"):
                if self.next().text == "const":
                    ty["const"] = True
        return ty

    def parse_array_suffix(self, ty: dict) -> dict:
        dims = []
        while self.peek() is not None and self.peek().text == "[":
            inner = self.skip_balanced("[", "]")
            if not inner:
                raise ParseError(f"line {self.peek().line}: flexible arrays are not allowed in the ABI")
            dims.append(self.source(inner))
        for expr in reversed(dims):
            ty = {"kind": "array", "of": ty, "length_expression": expr}
        return ty

    def parse_params(self) -> list[dict]:
        """( params ) -> [{"name", "type"}]; (void) -> []."""
        self.expect("(")
        params = []
        if self.peek().text == "void" and self.peek(1).text == ")":
            self.pos += 2
            return params
        if self.accept(")"):
            raise ParseError(f"line {self.peek().line}: write (void) for an empty parameter list")
        while True:
            base = self.parse_specifiers()
            ty = self.parse_pointers(base)
            name_tok = self.peek()
            name = None
            if name_tok.kind == "ident":
                name = self.next().text
            ty = self.parse_array_suffix(ty)
            if name is None:
                name = f"arg{len(params)}"
            params.append({"name": name, "type": ty})
            if self.accept(")"):
                return params
            self.expect(",")

    # -- top level
    def parse(self) -> dict:
        while self.peek() is not None:
            start = self.pos
            t = self.peek()
            line = t.line
            self.section = self.section_at(line)
            if t.text == "typedef":
                self.parse_typedef()
            elif t.text == "static":
                self.parse_inline()
            elif t.kind == "ident" and t.text in self.macro_names and self.peek(1) is not None \
                    and self.peek(1).text == "(" and t.text not in EXPORT_MACROS:
                # A macro statement such as SPH_STATIC_ASSERT(...);
                self.next()
                self.skip_balanced("(", ")")
                self.expect(";")
            elif t.kind == "ident":
                self.parse_function()
            elif t.text == ";":
                self.next()
            else:
                raise ParseError(f"line {line}: unexpected {t.text!r} at top level")
            assert self.pos > start
        return self.api

    def parse_typedef(self):
        start = self.pos
        self.expect("typedef")
        t = self.peek()
        if t.text in ("enum", "struct") and (self.peek(1).text == "{" or self.peek(2).text == "{"):
            kind = self.next().text
            tag = self.next().text if self.peek().text != "{" else None
            if kind == "enum":
                members = self.parse_enum_body()
            else:
                fields = self.parse_struct_body()
            name_tok = self.next()
            name = name_tok.text
            if tag is not None and tag != name:
                raise ParseError(f"line {name_tok.line}: typedef name {name!r} differs from tag {tag!r}")
            self.expect(";")
            entry = {"name": name, "doc": self.leading_doc(start), "section": self.section, "line": t.line}
            if kind == "enum":
                entry["members"] = members
                self.api["enums"].append(entry)
                self.types[name] = "enum"
            else:
                entry["fields"] = fields
                self.api["structs"].append(entry)
                self.types[name] = "struct"
            return
        if t.text == "struct" and self.peek(1).kind == "ident" and self.peek(2).kind == "ident" \
                and self.peek(3).text == ";":
            self.next()
            tag = self.next().text
            name = self.next().text
            self.expect(";")
            if tag != name:
                raise ParseError(f"line {t.line}: typedef name {name!r} differs from tag {tag!r}")
            self.api["opaque_types"].append(
                {"name": name, "doc": self.leading_doc(start), "section": self.section, "line": t.line})
            self.types[name] = "opaque"
            return
        # Callback: typedef RET (SPH_CALL* name)(params);   or an alias: typedef TYPE name;
        ret = self.parse_pointers(self.parse_specifiers())
        if self.accept("("):
            self.skip_annotations()
            self.expect("*")
            name = self.next().text
            self.expect(")")
            params = self.parse_params()
            self.expect(";")
            self.api["callbacks"].append({"name": name, "doc": self.leading_doc(start), "section": self.section,
                                          "line": t.line, "return": ret, "params": params})
            self.types[name] = "callback"
            return
        name = self.next().text
        ty = self.parse_array_suffix(ret)
        self.expect(";")
        self.api["typedefs"].append({"name": name, "doc": self.leading_doc(start) or self.trailing_doc(self.pos - 1),
                                     "section": self.section, "line": t.line, "type": ty})
        self.types[name] = "alias"

    def parse_enum_body(self) -> list[dict]:
        self.expect("{")
        members = []
        while not self.accept("}"):
            name_pos = self.pos
            name = self.next()
            if name.kind != "ident":
                raise ParseError(f"line {name.line}: expected an enum member, found {name.text!r}")
            expr = None
            if self.accept("="):
                parts, depth = [], 0
                while True:
                    p = self.peek()
                    if depth == 0 and p.text in (",", "}"):
                        break
                    depth += {"(": 1, ")": -1}.get(p.text, 0)
                    parts.append(self.next())
                expr = self.source(parts)
            last = self.pos - 1
            if self.peek().text == ",":
                self.next()
                last = self.pos - 1
            doc = self.leading_doc(name_pos) or self.trailing_doc(last)
            members.append({"name": name.text, "expression": expr, "doc": doc})
        return members

    def parse_struct_body(self) -> list[dict]:
        self.expect("{")
        fields = []
        while not self.accept("}"):
            first = self.pos
            base = self.parse_specifiers()
            group = []
            while True:
                ty = self.parse_pointers(base)
                if self.peek().text == "(":
                    # Function-pointer field: RET (SPH_CALL* name)(params)
                    self.next()
                    self.skip_annotations()
                    self.expect("*")
                    name = self.next().text
                    self.expect(")")
                    params = self.parse_params()
                    ty = {"kind": "function_pointer", "return": ty, "params": params}
                else:
                    name_tok = self.next()
                    if name_tok.kind != "ident":
                        raise ParseError(f"line {name_tok.line}: expected a field name, found {name_tok.text!r}")
                    name = name_tok.text
                    if self.peek().text == ":":
                        raise ParseError(f"line {name_tok.line}: bitfields are not allowed in the ABI")
                    ty = self.parse_array_suffix(ty)
                group.append({"name": name, "type": ty})
                if self.accept(";"):
                    break
                self.expect(",")
            doc = self.leading_doc(first) or self.trailing_doc(self.pos - 1)
            # A comment that only continues on the next lines (a wrapped trailing comment) is
            # already part of the trailing comment token.
            for f in group:
                f["doc"] = doc
            fields.extend(group)
        return fields

    def parse_function(self):
        start = self.pos
        line = self.peek().line
        notes = self.skip_annotations()
        if self.code[start][1].text != "SPH_API":
            raise ParseError(f"line {line}: a declaration without SPH_API ({self.code[start][1].text!r})")
        ret = self.parse_pointers(self.parse_specifiers())
        notes += self.skip_annotations()
        name = self.next()
        if name.kind != "ident":
            raise ParseError(f"line {name.line}: expected a function name, found {name.text!r}")
        params = self.parse_params()
        notes += self.skip_annotations()
        self.expect(";")
        entry = {"name": name.text, "doc": self.leading_doc(start), "section": self.section, "line": line,
                 "return": ret, "params": params}
        if notes:
            entry["annotations"] = notes
        self.api["functions"].append(entry)

    def parse_inline(self):
        start = self.pos
        line = self.peek().line
        self.expect("static")
        self.expect("inline")
        ret = self.parse_pointers(self.parse_specifiers())
        self.skip_annotations()
        name = self.next().text
        params = self.parse_params()
        body = self.skip_balanced("{", "}")
        text = " ".join(t.text for t in body)  # token-spaced, for the pattern below
        calls = [body[i].text for i in range(len(body) - 1)
                 if body[i].kind == "ident" and body[i + 1].text == "(" and body[i].text.startswith("sph_")]
        assigns = {m.group(1): m.group(2) for m in re.finditer(r"-> (\w+) = (\w+) ;", text)}
        entry = {"name": name, "doc": self.leading_doc(start), "section": self.section, "line": line,
                 "return": ret, "params": params, "calls": calls, "assigns": assigns, "body": self.source(body)}
        self.api["inline_functions"].append(entry)


# ---------------------------------------------------------------------------------------------
# Rendering types back to C (for the compiler probe and for the "c" strings in the JSON)
# ---------------------------------------------------------------------------------------------
def c_decl(ty: dict, name: str = "") -> str:
    """A C declaration of `name` with type `ty` (name may be empty: an abstract declarator)."""
    k = ty["kind"]
    if k in ("builtin", "void", "enum", "struct", "opaque", "alias", "callback"):
        base = ("const " if ty.get("const") else "") + ty["name"]
        return f"{base} {name}".rstrip() if name else base
    if k == "pointer":
        to = ty["to"]
        q = " const" if ty.get("const") else ""
        if to["kind"] in ("array", "function_pointer"):
            return c_decl(to, f"(*{q}{' ' if q and name else ''}{name})")
        s = c_decl(to) + "*" + q
        return f"{s} {name}" if name else s
    if k == "array":
        return c_decl(ty["of"], f"{name}[{ty['length_expression']}]")
    if k == "function_pointer":
        params = ", ".join(c_decl(p["type"]) for p in ty["params"]) or "void"
        return c_decl(ty["return"], f"(*{name})({params})")
    raise ValueError(k)


def add_c_strings(api: dict):
    def walk(obj):
        if isinstance(obj, dict):
            for key in ("type", "return"):
                if key in obj and isinstance(obj[key], dict) and "kind" in obj[key]:
                    obj[key]["c"] = c_decl(obj[key])
            for v in obj.values():
                walk(v)
        elif isinstance(obj, list):
            for v in obj:
                walk(v)
    walk(api)


# ---------------------------------------------------------------------------------------------
# Compiler check
# ---------------------------------------------------------------------------------------------
def build_probe(api: dict, header_names: list[str]) -> str:
    out = ["#include <stddef.h>", "#include <stdio.h>"] + [f'#include "{h}"' for h in header_names] + ["",
           "#define SPH_PROBE_SAME(expr, type) \\",
           "  _Static_assert(__builtin_types_compatible_p(__typeof__(expr), type), #expr \" is not \" #type)",
           ""]
    # Function signatures: the function's type must be the one the parser read; any difference
    # (a const, a pointer level, an integer width) fails the static assertion. Nothing is
    # referenced, so the probe links without the library.
    for i, f in enumerate(api["functions"] + api["inline_functions"]):
        params = ", ".join(c_decl(p["type"]) for p in f["params"]) or "void"
        out.append(f"SPH_PROBE_SAME({f['name']}, {c_decl(f['return'], f'({params})')});")
    for i, cb in enumerate(api["callbacks"]):
        params = ", ".join(c_decl(p["type"]) for p in cb["params"]) or "void"
        out.append(f"SPH_PROBE_SAME(*({cb['name']}*)0, {c_decl(cb['return'], f'(*)({params})')});")
    for td in api["typedefs"]:
        out.append(f"SPH_PROBE_SAME(*({td['name']}*)0, {c_decl(td['type'])});")
    out += ["", "static void num(const char* what, int is_float, int is_signed, long long s,",
            "                unsigned long long u, double d) {",
            "  if (is_float) printf(\"%s float %.17g\\n\", what, d);",
            "  else if (is_signed && s < 0) printf(\"%s int %lld\\n\", what, s);",
            "  else printf(\"%s int %llu\\n\", what, u);",
            "}",
            "#define SPH_PROBE_NUM(what, x) num(what, _Generic((x), float: 1, double: 1, default: 0), \\",
            "  (__typeof__(x))-1 < (__typeof__(x))0, (long long)(x), (unsigned long long)(x), (double)(x))",
            "#define SPH_PROBE_CTYPE(x) _Generic((x), int: \"int\", unsigned int: \"unsigned int\", \\",
            "  long: \"long\", unsigned long: \"unsigned long\", long long: \"long long\", \\",
            "  unsigned long long: \"unsigned long long\", float: \"float\", double: \"double\", default: \"other\")",
            "", "int main(void) {"]
    for s in api["structs"]:
        n = s["name"]
        out.append(f'  printf("struct {n} %zu %zu\\n", sizeof({n}), _Alignof({n}));')
        for f in s["fields"]:
            fn = f["name"]
            out.append(f"  SPH_PROBE_SAME((({n}*)0)->{fn}, {c_decl(f['type'])});")
            out.append(f'  printf("field {n} {fn} %zu %zu\\n", offsetof({n}, {fn}), sizeof((({n}*)0)->{fn}));')
    for e in api["enums"]:
        n = e["name"]
        out.append(f'  printf("enum {n} %zu\\n", sizeof({n}));')
        for m in e["members"]:
            out.append(f'  SPH_PROBE_NUM("member {n} {m["name"]}", {m["name"]});')
    for d in api["defines"]:
        if d["expression"].startswith('"'):
            continue
        out.append(f'  printf("dtype {d["name"]} %s\\n", SPH_PROBE_CTYPE({d["name"]}));')
        out.append(f'  SPH_PROBE_NUM("define {d["name"]}", {d["name"]});')
    out.append('  printf("pointer %zu\\n", sizeof(void*));')
    out += ["  return 0;", "}", ""]
    return "\n".join(out)


def run_probe(api: dict, headers: list[str], cc: str) -> dict:
    """Compiles and runs the probe; returns its printed facts."""
    work = tempfile.mkdtemp(prefix="sph_api_probe.")
    try:
        src = os.path.join(work, "probe.c")
        exe = os.path.join(work, "probe")
        with open(src, "w") as f:
            f.write(build_probe(api, [os.path.basename(h) for h in headers]))
        cmd = cc.split() + ["-std=gnu11", "-Wall", "-Wextra", "-Werror", "-Wno-unused-variable",
                            "-Wno-unused-const-variable", "-Wno-unused-function", "-Wno-type-limits",
                            ] + [x for h in headers for x in ("-I", os.path.dirname(os.path.abspath(h)))] + [
                            src, "-o", exe]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            raise ParseError("the compiler check failed: the parsed declarations differ from what "
                             f"{cc} sees (or the probe is broken)\n$ {' '.join(cmd)}\n{r.stderr}")
        r = subprocess.run([exe], capture_output=True, text=True, check=True)
        facts = {"struct": {}, "field": {}, "enum": {}, "member": {}, "define": {}, "dtype": {}}
        for line in r.stdout.splitlines():
            parts = line.split()
            if parts[0] == "struct":
                facts["struct"][parts[1]] = (int(parts[2]), int(parts[3]))
            elif parts[0] == "field":
                facts["field"][(parts[1], parts[2])] = (int(parts[3]), int(parts[4]))
            elif parts[0] == "enum":
                facts["enum"][parts[1]] = int(parts[2])
            elif parts[0] in ("member", "define"):
                key = (parts[1], parts[2]) if parts[0] == "member" else parts[1]
                val = parts[-1]
                facts[parts[0]][key] = float(val) if parts[-2] == "float" else int(val)
            elif parts[0] == "dtype":
                facts["dtype"][parts[1]] = " ".join(parts[2:])
            elif parts[0] == "pointer":
                facts["pointer"] = int(parts[1])
        return facts
    finally:
        shutil.rmtree(work, ignore_errors=True)


# ---------------------------------------------------------------------------------------------
# Assembly
# ---------------------------------------------------------------------------------------------
def resolve_lengths(ty: dict, consts: dict):
    if ty.get("kind") == "array":
        expr = ty["length_expression"]
        if expr not in consts and not re.fullmatch(r"[0-9]+[uU]?", expr):
            raise ParseError(f"array length {expr!r} is neither a number nor a known constant")
        ty["length"] = consts[expr] if expr in consts else int(expr.rstrip("uU"))
        resolve_lengths(ty["of"], consts)
    elif ty.get("kind") == "pointer":
        resolve_lengths(ty["to"], consts)


KINDS = ("sections", "defines", "macros", "enums", "typedefs", "opaque_types", "callbacks", "structs", "functions",
         "inline_functions")


def rel_path(header: str) -> str:
    rel = os.path.relpath(os.path.abspath(header), ROOT)
    if rel.startswith(".."):
        rel = os.path.join("include", os.path.basename(header))
    return rel.replace(os.sep, "/")


# Headers the bindings do not cover (none now: sph_mpi.h's functions are recorded with their
# library, sph_mpi, and Python reaches them through sph.mpi with mpi4py).
NOT_BOUND: set[str] = set()


def default_headers() -> list[str]:
    inc = os.path.dirname(DEFAULT_HEADER)
    others = sorted(f for f in os.listdir(inc)
                    if f.startswith("sph_") and f.endswith(".h") and f != "sph_c.h" and f not in NOT_BOUND)
    return [DEFAULT_HEADER] + [os.path.join(inc, f) for f in others]


def generate(headers: list[str], cc: str) -> dict:
    api = {k: [] for k in KINDS}
    types: dict[str, str] = {}
    macro_names: set[str] = set()
    header_info = []
    for header in headers:
        with open(header, encoding="utf-8") as f:
            text = f.read()
        try:
            toks = lex(text)
            defines, macros, names_here = preprocess(toks)
        except ParseError as e:
            raise ParseError(f"{rel_path(header)}: {e}") from None
        macro_names |= names_here
        label = rel_path(header)
        library = LIBRARY_OF_HEADER.get(os.path.basename(header), "sph")
        before = {k: len(api[k]) for k in KINDS}
        try:
            Parser(toks, macro_names, text, api, types).parse()
        except ParseError as e:
            raise ParseError(f"{label}: {e}") from None
        api["defines"] += defines
        api["macros"] += macros
        for k in KINDS:
            for entry in api[k][before[k]:]:
                entry["header"] = label
        for entry in api["functions"][before["functions"]:]:
            entry["library"] = library
        header_info.append({"path": label, "library": library,
                            "sha256": hashlib.sha256(text.encode("utf-8")).hexdigest()})

    names = [x["name"] for key in ("defines", "macros", "enums", "typedefs", "opaque_types", "callbacks",
                                   "structs", "functions", "inline_functions") for x in api[key]]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise ParseError(f"declared more than once: {', '.join(dup)}")

    facts = run_probe(api, headers, cc)
    consts = {}
    for d in api["defines"]:
        if d["expression"].startswith('"'):
            d["type"], d["value"] = "string", json.loads(d["expression"])
        else:
            d["value"] = facts["define"][d["name"]]
            d["type"] = {"int": "int32", "unsigned int": "uint32", "long": "int64", "unsigned long": "uint64",
                         "long long": "int64", "unsigned long long": "uint64", "float": "float",
                         "double": "double"}.get(facts["dtype"][d["name"]], "other")
            consts[d["name"]] = d["value"]
    for e in api["enums"]:
        e["size"] = facts["enum"][e["name"]]
        for m in e["members"]:
            m["value"] = facts["member"][(e["name"], m["name"])]
            consts[m["name"]] = m["value"]
            if not -2**31 <= m["value"] < 2**31:
                raise ParseError(f"{m['name']} = {m['value']} does not fit in int32")
    for s in api["structs"]:
        s["size"], s["align"] = facts["struct"][s["name"]]
        for f in s["fields"]:
            f["offset"], f["size"] = facts["field"][(s["name"], f["name"])]
            resolve_lengths(f["type"], consts)
    for td in api["typedefs"]:
        resolve_lengths(td["type"], consts)
    for f in api["functions"] + api["inline_functions"] + api["callbacks"]:
        for p in f["params"]:
            resolve_lengths(p["type"], consts)

    # Links the bindings use: a struct's sized init (and what its inline init adds), an
    # opaque type's destroy function.
    fnames = {f["name"] for f in api["functions"]}
    inlines = {f["name"]: f for f in api["inline_functions"]}
    for s in api["structs"]:
        init = s["name"] + "_init_sized"
        if init in fnames:
            inline = inlines.get(s["name"] + "_init")
            s["init"] = {"function": init, "inline": inline["name"] if inline else None,
                         "assigns": inline["assigns"] if inline else {}}
        elif not any(f["name"] == "struct_size" for f in s["fields"]):
            # A value struct may have an exported constant instead (sph_transform_identity).
            for f in api["functions"]:
                if f["name"].startswith(s["name"] + "_") and not f["params"] and \
                        f["return"].get("kind") == "struct" and f["return"]["name"] == s["name"]:
                    s["default"] = {"function": f["name"]}
                    break
    for o in api["opaque_types"]:
        destroy = o["name"] + "_destroy"
        o["destroy"] = destroy if destroy in fnames else None
    for f in api["functions"] + api["inline_functions"]:
        if f["name"] in inlines and f in api["functions"]:
            raise ParseError(f"{f['name']} is both exported and inline")

    add_c_strings(api)
    by_name = {d["name"]: d["value"] for d in api["defines"] if "value" in d}
    doc = {
        "generator": "bindings/api/generate_api.py",
        "headers": header_info,
        "version": {"major": by_name.get("SPH_VERSION_MAJOR"), "minor": by_name.get("SPH_VERSION_MINOR"),
                    "patch": by_name.get("SPH_VERSION_PATCH"), "packed": by_name.get("SPH_VERSION"),
                    "abi": by_name.get("SPH_ABI_VERSION")},
        "layout": {"pointer_size": facts["pointer"],
                   "note": "sizes and offsets measured by the C compiler for this pointer size"},
    }
    for key in KINDS:
        doc[key] = api[key]
    return doc


def dump(doc: dict) -> str:
    return json.dumps(doc, indent=1, ensure_ascii=False) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--header", action="append", help="a header to read (repeatable); default: sph_c.h, then "
                    "the other include/sph_*.h")
    ap.add_argument("--out", default=DEFAULT_OUT)
    ap.add_argument("--cc", default=os.environ.get("CC", "cc"))
    args = ap.parse_args(argv)
    headers = args.header or default_headers()
    try:
        doc = generate(headers, args.cc)
    except ParseError as e:
        print(f"generate_api.py: {e}", file=sys.stderr)
        return 1
    with open(args.out, "w", encoding="utf-8", newline="\n") as f:
        f.write(dump(doc))
    print(f"generate_api.py: wrote {os.path.relpath(args.out)}: {len(doc['functions'])} functions, "
          f"{len(doc['structs'])} structs, {len(doc['enums'])} enums, {len(doc['defines'])} constants "
          f"from {', '.join(h['path'] for h in doc['headers'])}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
