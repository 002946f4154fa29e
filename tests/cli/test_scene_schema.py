#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""docs/scene.schema.json against the scene files and the loader (issue 22, item 5).

usage: test_scene_schema.py SPH_RUN     (SPH_LIBRARY and PYTHONPATH=bindings/python set by ctest)

- the schema is a valid draft-07 schema and is what tools/scene/scene_schema.py writes;
- every scene in samples/scenes and tests/cli/scenes validates;
- broken copies of a scene (an unknown key, a misspelt choice, a string for a number, a shape
  without its radius, ...) fail the schema AND make sph-run exit with 3 (scene error), so the
  schema is not looser than the loader on these points;
- the params keys, their fields and types, and the method names the schema lists are exactly the
  library's (sph_params_get_info, sph_params_get_field_info, sph_get_physics_method_info), so a
  method or field added to the library fails this test until the schema is regenerated.
"""
import copy
import glob
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SPH_RUN = sys.argv[1]
sys.path.insert(0, os.path.join(ROOT, "tools", "scene"))
import scene_schema  # noqa: E402

failures, passed = [], 0


def check(name, condition, detail=""):
    global passed
    if condition:
        passed += 1
        print(f"ok   {name}")
    else:
        failures.append(name)
        print(f"FAIL {name} {detail}")


try:
    import jsonschema
except ImportError:
    # Exit 77: ctest reports the test as skipped (SKIP_RETURN_CODE), not as passed with nothing checked.
    print("skip: no jsonschema module (Debian: python3-jsonschema)")
    print("0 passed, 0 failed, 1 skipped")
    sys.exit(77)

with open(os.path.join(ROOT, "docs", "scene.schema.json")) as f:
    schema = json.load(f)
jsonschema.Draft7Validator.check_schema(schema)
validator = jsonschema.Draft7Validator(schema)
check("schema file is what scene_schema.py writes", schema == scene_schema.build())

scenes = sorted(glob.glob(os.path.join(ROOT, "samples", "scenes", "*.json")) +
                glob.glob(os.path.join(ROOT, "tests", "cli", "scenes", "*.json")))
check("scenes found", len(scenes) >= 5, scenes)
for path in scenes:
    with open(path) as f:
        errors = [f"{'/'.join(map(str, e.path))}: {e.message}" for e in validator.iter_errors(json.load(f))]
    check(f"{os.path.relpath(path, ROOT)} validates", not errors, errors[:3])

# ---- broken scenes: the schema and sph-run both refuse them ----
with open(os.path.join(ROOT, "tests", "cli", "scenes", "tiny.json")) as f:
    tiny = json.load(f)


def broken(description, change):
    scene = copy.deepcopy(tiny)
    change(scene)
    schema_ok = validator.is_valid(scene)
    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
        json.dump(scene, f)
    try:
        with tempfile.TemporaryDirectory() as out:
            p = subprocess.run([SPH_RUN, f.name, "--frames", "0", "--format", "none", "--backend", "cpu", "--quiet",
                                "--out", out], capture_output=True, text=True, timeout=120)
    finally:
        os.unlink(f.name)
    check(f"{description}: schema refuses, sph-run exits 3", not schema_ok and p.returncode == 3,
          f"(schema {'accepts' if schema_ok else 'refuses'}, sph-run exit {p.returncode}: {p.stderr.strip()})")


broken("unknown top-level key", lambda s: s.update(colour="blue"))
broken("unknown world key", lambda s: s["world"].update(spacing=0.02))
broken("misspelt output format", lambda s: s["output"].update(format="vtk"))
broken("unknown shape type", lambda s: s["colliders"][0]["shape"].update(type="cone"))
broken("sphere shape without radius", lambda s: s["sources"][0]["shape"].pop("radius"))
broken("string for a number", lambda s: s["time"].update(fps="50"))
broken("vec3 of two numbers", lambda s: s["fluids"][0].update(max=[0.0, 0.12]))
broken("unknown feature", lambda s: s["world"].update(features=["surface_tensions"]))
broken("unknown params field", lambda s: s["params"].update(stifness=60))
broken("restitution above 1", lambda s: s["colliders"][0].update(restitution=1.5))
broken("unknown preview style", lambda s: s["output"].update(preview={"style": "points"}))
broken("fluid type missing", lambda s: s["fluids"][0].pop("type"))
broken("comment that is not a string", lambda s: s["world"].update(comment=[1, 2]))
broken("output format listed twice", lambda s: s["output"].update(format=["csv", "ply", "csv"]))
broken("empty list of output formats", lambda s: s["output"].update(format=[]))
broken("capacity above 2^30", lambda s: s["world"].update(capacity=2 ** 30 + 1))

# ---- the lists that come from the library ----
try:
    import sph
except (ImportError, OSError) as e:
    failures.append(f"import sph ({e})")
else:
    kinds = {}
    for kind in sph.ParamsKind:
        if kind.name.endswith("COUNT") or kind.name.endswith("FORCE32"):
            continue
        name = sph.params_info(kind).name.decode()
        fields = {}
        for field in sph.param_fields(kind):
            t = {sph.ParamType.FLOAT: "float", sph.ParamType.VEC3: "vec3"}.get(sph.ParamType(field.type), "uint")
            fields[field.name.decode()] = t
        kinds[name] = fields
    world = kinds.pop("world", None)
    check("params fields are the library's sph_world_params", world == scene_schema.WORLD_PARAMS,
          f"library {world}")
    check("physics sections are the library's params structs", kinds == scene_schema.PHYSICS_PARAMS,
          f"library {kinds}")
    by_switch = {}
    for m in sph.methods():
        by_switch.setdefault(int(m.switch_by), []).append(m.name.decode())
    S = sph.MethodSwitch
    check("features are the library's", sorted(by_switch.get(int(S.FEATURE), [])) == sorted(scene_schema.FEATURES),
          by_switch)
    check("viscosity methods are the library's",
          sorted(by_switch.get(int(S.VISCOSITY), [])) == sorted(scene_schema.VISCOSITY_METHODS), by_switch)
    check("equations of state are the library's",
          sorted(by_switch.get(int(S.EQUATION_OF_STATE), [])) == sorted(scene_schema.EQUATIONS_OF_STATE), by_switch)
    check("solvers are the library's", sorted(by_switch.get(int(S.SOLVER), [])) == sorted(scene_schema.SOLVERS),
          by_switch)

print(f"{passed} passed, {len(failures)} failed, 0 skipped")
sys.exit(1 if failures else 0)
