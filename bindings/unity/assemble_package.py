#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Assembles the Unity package (UPM layout) of the C# bindings and checks it.

    python3 bindings/unity/assemble_package.py --library build/libsph.so.0 --out dist/unity
    python3 bindings/unity/assemble_package.py --check dist/unity/org.sph.fluid

Writes OUT/org.sph.fluid/:

    package.json                  the UPM manifest (name, version from sph_api.json, unity, ...)
    README.md, LICENSE.md, CHANGELOG.md
    Runtime/Sph.asmdef            the assembly "Sph": no engine references, no unsafe code
    Runtime/Sph.Generated.cs      bindings/csharp (generated P/Invoke layer)
    Runtime/Sph.cs                Context, World, SphException
    Plugins/x86_64/libsph.so      the library, named for [DllImport("sph")] on Linux
    Samples~/Droplets/Droplets.cs the console sample (Samples~: not imported unless asked for)
    *.meta                        one per file and folder, with GUIDs derived from the path (a
                                  package Unity installs read-only ignores files without one),
                                  the plugin's enabling the Linux x86_64 editor and player

--check verifies a package folder: the manifest's required fields and their forms (a reverse-DNS
lower-case name, a SemVer version equal to the library's, "unity" as MAJOR.MINOR), the asmdef,
that every file and folder has a .meta with a unique GUID, and that the plugin is an ELF shared
object for x86-64. Compiling the Runtime sources with mcs and running the C# tests against the
package's copy of the library is scripts/test's part (bindings/unity/check_package.sh).
"""
import argparse
import hashlib
import json
import os
import re
import shutil
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
NAME = "org.sph.fluid"

FOLDER_META = """fileFormatVersion: 2
guid: {guid}
folderAsset: yes
DefaultImporter:
  externalObjects: {{}}
  userData: 
  assetBundleName: 
  assetBundleVariant: 
"""
SCRIPT_META = """fileFormatVersion: 2
guid: {guid}
MonoImporter:
  externalObjects: {{}}
  serializedVersion: 2
  defaultReferences: []
  executionOrder: 0
  icon: {{instanceID: 0}}
  userData: 
  assetBundleName: 
  assetBundleVariant: 
"""
ASMDEF_META = """fileFormatVersion: 2
guid: {guid}
AssemblyDefinitionImporter:
  externalObjects: {{}}
  userData: 
  assetBundleName: 
  assetBundleVariant: 
"""
TEXT_META = """fileFormatVersion: 2
guid: {guid}
TextScriptImporter:
  externalObjects: {{}}
  userData: 
  assetBundleName: 
  assetBundleVariant: 
"""
MANIFEST_META = """fileFormatVersion: 2
guid: {guid}
PackageManifestImporter:
  externalObjects: {{}}
  userData: 
  assetBundleName: 
  assetBundleVariant: 
"""
# The native library: the Linux editor and the Linux 64-bit player, x86_64 only.
PLUGIN_META = """fileFormatVersion: 2
guid: {guid}
PluginImporter:
  externalObjects: {{}}
  serializedVersion: 2
  iconMap: {{}}
  executionOrder: {{}}
  defineConstraints: []
  isPreloaded: 0
  isOverridable: 0
  isExplicitlyReferenced: 0
  validateReferences: 1
  platformData:
  - first:
      Any: 
    second:
      enabled: 0
      settings: {{}}
  - first:
      Editor: Editor
    second:
      enabled: 1
      settings:
        CPU: x86_64
        DefaultValueInitialized: true
        OS: Linux
  - first:
      Standalone: Linux64
    second:
      enabled: 1
      settings:
        CPU: x86_64
  - first:
      Standalone: Win64
    second:
      enabled: 0
      settings:
        CPU: None
  - first:
      Standalone: OSXUniversal
    second:
      enabled: 0
      settings:
        CPU: None
  userData: 
  assetBundleName: 
  assetBundleVariant: 
"""


def guid(relpath):
    """A stable GUID for a path in the package: the same file keeps its GUID across builds, so
    projects' references to it survive an update."""
    return hashlib.md5(f"{NAME}/{relpath}".encode()).hexdigest()


def meta_for(relpath, is_dir):
    if is_dir:
        return FOLDER_META
    if relpath == "package.json":
        return MANIFEST_META
    if relpath.endswith(".cs"):
        return SCRIPT_META
    if relpath.endswith(".asmdef"):
        return ASMDEF_META
    if relpath.startswith("Plugins/"):
        return PLUGIN_META
    return TEXT_META


def assemble(library, out):
    api = json.load(open(os.path.join(ROOT, "bindings", "api", "sph_api.json")))
    v = api["version"]
    version = f"{v['major']}.{v['minor']}.{v['patch']}"
    pkg = os.path.join(out, NAME)
    if os.path.exists(pkg):
        shutil.rmtree(pkg)
    for d in ("Runtime", "Plugins/x86_64", "Samples~/Droplets"):
        os.makedirs(os.path.join(pkg, d))
    manifest = {
        "name": NAME,
        "version": version,
        "displayName": "sph fluids",
        "description": "SPH fluid simulation (the sph library, CPU and CUDA backends) for Unity: C# bindings over "
                       "the C ABI with the Linux x86_64 native library. Particles in and out in bulk; colliders, "
                       "sources, sinks and force fields; checkpoints.",
        "unity": "2021.3",
        "license": "MIT",
        "keywords": ["fluid", "sph", "simulation", "physics", "particles"],
        "author": {"name": "the sph authors"},
        "samples": [{"displayName": "Droplets", "description": "A console sample: a box of fluid falls and splashes.",
                     "path": "Samples~/Droplets"}],
    }
    with open(os.path.join(pkg, "package.json"), "w") as f:
        json.dump(manifest, f, indent=2)
        f.write("\n")
    asmdef = {"name": "Sph", "rootNamespace": "Sph", "references": [], "includePlatforms": [], "excludePlatforms": [],
              "allowUnsafeCode": False, "overrideReferences": False, "precompiledReferences": [],
              "autoReferenced": True, "defineConstraints": [], "versionDefines": [], "noEngineReferences": True}
    with open(os.path.join(pkg, "Runtime", "Sph.asmdef"), "w") as f:
        json.dump(asmdef, f, indent=2)
        f.write("\n")
    cs = os.path.join(ROOT, "bindings", "csharp")
    shutil.copy(os.path.join(cs, "Sph.Generated.cs"), os.path.join(pkg, "Runtime"))
    shutil.copy(os.path.join(cs, "Sph.cs"), os.path.join(pkg, "Runtime"))
    shutil.copy(os.path.join(cs, "samples", "Droplets.cs"), os.path.join(pkg, "Samples~", "Droplets"))
    shutil.copy(library, os.path.join(pkg, "Plugins", "x86_64", "libsph.so"))
    shutil.copy(os.path.join(ROOT, "LICENSE"), os.path.join(pkg, "LICENSE.md"))
    shutil.copy(os.path.join(ROOT, "CHANGELOG.md"), os.path.join(pkg, "CHANGELOG.md"))
    with open(os.path.join(pkg, "README.md"), "w") as f:
        f.write(f"# sph fluids for Unity ({version})\n\n"
                "The C# bindings of the sph SPH fluid library with its Linux x86_64 native library.\n"
                "Add it with *Window > Package Manager > + > Add package from disk...* (this folder's\n"
                "package.json) or from a tarball. `Runtime/` is the assembly `Sph` (no engine references);\n"
                "`Plugins/x86_64/libsph.so` is enabled for the Linux editor and player. UNITY.md of the\n"
                "sph sources explains the API in Unity (IL2CPP, the log callback, bulk particle copies).\n")
    # Samples~ is hidden from Unity's import: its files get no .meta (Unity copies them into the
    # project when the user imports the sample, and makes them there).
    for base, dirs, files in os.walk(pkg):
        dirs[:] = [d for d in dirs if not d.endswith("~")]
        for name in dirs + files:
            if name.endswith(".meta"):
                continue
            path = os.path.join(base, name)
            rel = os.path.relpath(path, pkg)
            with open(path + ".meta", "w") as f:
                f.write(meta_for(rel, os.path.isdir(path)).format(guid=guid(rel)))
    return pkg


def check(pkg):
    problems = []
    manifest = json.load(open(os.path.join(pkg, "package.json")))
    api = json.load(open(os.path.join(ROOT, "bindings", "api", "sph_api.json")))
    v = api["version"]
    for field in ("name", "version", "displayName", "description", "unity", "license"):
        if not manifest.get(field):
            problems.append(f"package.json: no {field}")
    if not re.fullmatch(r"[a-z0-9]+(\.[a-z0-9-]+){2,}", manifest.get("name", "")) or len(manifest["name"]) > 214:
        problems.append(f"package.json: name {manifest.get('name')!r} is not a lower-case reverse-DNS name")
    if manifest.get("version") != f"{v['major']}.{v['minor']}.{v['patch']}":
        problems.append(f"package.json: version {manifest.get('version')!r} is not the library's")
    if not re.fullmatch(r"\d{4}\.\d+", manifest.get("unity", "")):
        problems.append(f"package.json: unity {manifest.get('unity')!r} is not MAJOR.MINOR")
    asmdef = json.load(open(os.path.join(pkg, "Runtime", "Sph.asmdef")))
    if asmdef.get("name") != "Sph" or asmdef.get("allowUnsafeCode") or not asmdef.get("noEngineReferences"):
        problems.append(f"Runtime/Sph.asmdef: {asmdef}")
    for required in ("Runtime/Sph.cs", "Runtime/Sph.Generated.cs", "Plugins/x86_64/libsph.so", "LICENSE.md"):
        if not os.path.isfile(os.path.join(pkg, required)):
            problems.append(f"missing {required}")
    guids = {}
    for base, dirs, files in os.walk(pkg):
        dirs[:] = [d for d in dirs if not d.endswith("~")]
        for name in dirs + files:
            if name.endswith(".meta"):
                continue
            meta = os.path.join(base, name) + ".meta"
            rel = os.path.relpath(os.path.join(base, name), pkg)
            if not os.path.isfile(meta):
                problems.append(f"{rel}: no .meta (Unity ignores it in a read-only package)")
                continue
            m = re.search(r"^guid: ([0-9a-f]{32})$", open(meta).read(), re.M)
            if not m:
                problems.append(f"{rel}.meta: no guid")
            elif m.group(1) in guids:
                problems.append(f"{rel}.meta: guid also used by {guids[m.group(1)]}")
            else:
                guids[m.group(1)] = rel
    with open(os.path.join(pkg, "Plugins", "x86_64", "libsph.so"), "rb") as f:
        head = f.read(20)
    # ELF, 64-bit, little-endian, e_type ET_DYN (3), e_machine EM_X86_64 (62).
    if head[:4] != b"\x7fELF" or head[4] != 2 or head[5] != 1 or head[16] != 3 or head[18] != 62:
        problems.append("Plugins/x86_64/libsph.so: not an x86-64 ELF shared object")
    for p in problems:
        print(f"unity package: {p}", file=sys.stderr)
    if not problems:
        print(f"unity package {manifest['name']} {manifest['version']}: manifest, asmdef, {len(guids)} .meta files "
              f"and the x86-64 plugin check out")
    return 1 if problems else 0


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--library", help="libsph.so.0 to ship")
    ap.add_argument("--out", default=os.path.join(ROOT, "dist", "unity"))
    ap.add_argument("--check", metavar="PACKAGE_DIR")
    args = ap.parse_args(argv)
    if args.check:
        return check(args.check)
    if not args.library:
        ap.error("--library is required to assemble")
    pkg = assemble(args.library, args.out)
    print(pkg)
    return check(pkg)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
