#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Regenerates everything derived from include/sph_c.h, or checks that it is up to date.

    python3 bindings/api/generate.py            # rewrite the generated files in place
    python3 bindings/api/generate.py --check    # regenerate into a temporary folder and diff

Generated files (all committed):
    bindings/api/sph_api.json             <- include/sph_c.h, then the other include/sph_*.h
                                             (generate_api.py; needs a C compiler)
    bindings/python/sph/_generated.py     <- sph_api.json    (generate_python.py)
    bindings/csharp/Sph.Generated.cs      <- sph_api.json    (generate_csharp.py)
    bindings/cffi/sph_cdef.h              <- sph_api.json    (generate_cdef.py; for cffi's cdef)

--check exits 1 and prints a unified diff when any committed file differs from what the
current header produces: run this script without --check and commit the result.
"""
from __future__ import annotations

import argparse
import difflib
import os
import shutil
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import generate_api  # noqa: E402
import generate_cdef  # noqa: E402
import generate_csharp  # noqa: E402
import generate_python  # noqa: E402

ROOT = generate_api.ROOT
TARGETS = {
    "json": os.path.join("bindings", "api", "sph_api.json"),
    "python": os.path.join("bindings", "python", "sph", "_generated.py"),
    "csharp": os.path.join("bindings", "csharp", "Sph.Generated.cs"),
    "cdef": os.path.join("bindings", "cffi", "sph_cdef.h"),
}


def generate_into(out_root: str, headers: list[str], cc: str) -> None:
    paths = {k: os.path.join(out_root, v) for k, v in TARGETS.items()}
    for p in paths.values():
        os.makedirs(os.path.dirname(p), exist_ok=True)
    rc = generate_api.main([x for h in headers for x in ("--header", h)] + ["--out", paths["json"], "--cc", cc])
    if rc != 0:
        raise SystemExit(rc)
    generate_python.main(["--api", paths["json"], "--out", paths["python"]])
    generate_csharp.main(["--api", paths["json"], "--out", paths["csharp"]])
    generate_cdef.main(["--api", paths["json"], "--out", paths["cdef"]])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--check", action="store_true", help="diff against the committed files instead of writing")
    ap.add_argument("--header", action="append", help="a header (repeatable); default: include/sph_c.h, then "
                    "the other include/sph_*.h")
    ap.add_argument("--cc", default=os.environ.get("CC", "cc"))
    args = ap.parse_args(argv)
    headers = args.header or generate_api.default_headers()
    names = ", ".join(generate_api.rel_path(h) for h in headers)
    if not args.check:
        generate_into(ROOT, headers, args.cc)
        return 0
    tmp = tempfile.mkdtemp(prefix="sph_generate_check.")
    try:
        generate_into(tmp, headers, args.cc)
        stale = []
        for rel in TARGETS.values():
            fresh_path, committed_path = os.path.join(tmp, rel), os.path.join(ROOT, rel)
            with open(fresh_path, encoding="utf-8") as f:
                fresh = f.readlines()
            committed = []
            if os.path.exists(committed_path):
                with open(committed_path, encoding="utf-8") as f:
                    committed = f.readlines()
            if fresh != committed:
                stale.append(rel)
                diff = list(difflib.unified_diff(committed, fresh, f"a/{rel}", f"b/{rel}", n=2))
                sys.stdout.writelines(diff[:200])
                if len(diff) > 200:
                    print(f"... ({len(diff) - 200} more diff lines)")
        if stale:
            print(f"\ngenerate.py --check: STALE: {', '.join(stale)} do not match {names}.\n"
                  "Run `python3 bindings/api/generate.py` and commit the result.")
            return 1
        print(f"generate.py --check: {', '.join(TARGETS.values())} are up to date with {names}")
        return 0
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
