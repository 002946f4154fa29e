#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Writes docs/scene.schema.json, the JSON Schema (draft-07) of sph-run's scene files
(docs/scenes.md), from this description of the loader (tools/scene/parse_*.cpp).

    python3 tools/scene/scene_schema.py            # rewrites docs/scene.schema.json
    python3 tools/scene/scene_schema.py --check    # exits 1 if the file is not what this writes

The schema says what the loader accepts structurally: the keys of every object ("comment" is
allowed everywhere), their JSON types, the choices of every "type"/"mode"/"format" string, and
the simple bounds the loader checks by itself. Physical ranges of the params (stiffness > 0 and
the like) are the library's to check when the world is built, and are left out. The names of
the physics methods and the fields of the params structs come from the library at run time; the
lists below are today's, and tests/cli/test_scene_schema.py checks them against the library.
"""
import json
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OUT = os.path.join(ROOT, "docs", "scene.schema.json")

NUMBER = {"type": "number"}
POSITIVE = {"type": "number", "exclusiveMinimum": 0}
NON_NEGATIVE = {"type": "number", "minimum": 0}
BOOLEAN = {"type": "boolean"}
STRING = {"type": "string"}
VEC3 = {"$ref": "#/definitions/vec3"}
COUNT = {"type": "integer", "minimum": 0, "maximum": 4294967295}

# The params structs, by scene-file key (sph_params_get_info's name): field -> kind.
WORLD_PARAMS = {"max_substeps": "uint", "gravity": "vec3", "stiffness": "float", "viscosity": "float",
                "step_factor": "float", "dt_min": "float", "dt_max": "float", "step_limits": "uint",
                "tension_ratio": "float"}
PHYSICS_PARAMS = {
    "surface_tension": {"coefficient": "float", "normal_threshold": "float"},
    "clavet": {"linear": "float", "quadratic": "float"},
    "tait": {"speed_of_sound": "float"},
    "springs": {"stiffness": "float", "link_radius": "float", "yield_ratio": "float", "plasticity": "float",
                "damping": "float"},
    "dfsph": {"density_error": "float", "divergence_error": "float", "max_iterations": "uint",
              "max_divergence_iterations": "uint", "flags": "uint", "linear_solver": "uint",
              "density_error_max": "float", "depth_step_factor": "float",
              "divergence_error_per_step": "float"},
    "density_diffusion": {"delta": "float"},
}
FEATURES = ["surface_tension", "normalized_density", "springs", "boundary_density", "collider_loads",
            "density_diffusion"]
VISCOSITY_METHODS = ["mueller", "clavet"]
EQUATIONS_OF_STATE = ["ideal_gas", "tait"]
SOLVERS = ["wcsph", "dfsph"]
FORMATS = ["vdb", "ply", "csv", "vtp"]
FIELD_KINDS = {"float": NUMBER, "vec3": VEC3, "uint": COUNT}


def obj(properties, required=(), description=None):
    """An object with exactly these keys (and "comment")."""
    o = {"type": "object", "properties": dict(properties, comment={"type": "string"}),
         "additionalProperties": False}
    if required:
        o["required"] = list(required)
    if description:
        o["description"] = description
    return o


def const_type(name):
    return {"const": name}


def shape_schema():
    grid = {"voxel_size": POSITIVE, "padding_voxels": {"type": "integer", "minimum": 1, "maximum": 1024}}
    variants = [
        obj({"type": const_type("plane"), "half_extents": VEC3, **grid}, ["type", "half_extents"]),
        obj({"type": const_type("box"), "half_extents": VEC3, "wall_thickness": NON_NEGATIVE, "open_top": BOOLEAN,
             **grid}, ["type", "half_extents"]),
        obj({"type": const_type("sphere"), "radius": POSITIVE, **grid}, ["type", "radius"]),
        obj({"type": const_type("capsule"), "radius": POSITIVE, "half_height": POSITIVE, **grid},
            ["type", "radius", "half_height"]),
        obj({"type": const_type("cylinder"), "radius": POSITIVE, "half_height": POSITIVE, **grid},
            ["type", "radius", "half_height"]),
        obj({"type": const_type("cup"), "radius": POSITIVE, "half_height": POSITIVE, "wall_thickness": POSITIVE,
             **grid}, ["type", "radius", "half_height", "wall_thickness"]),
        obj({"type": const_type("vdb"), "file": {"type": "string", "minLength": 1}, "grid": STRING},
            ["type", "file"]),
        obj({"type": const_type("mesh"), "file": {"type": "string", "minLength": 1}, "scale": POSITIVE,
             "voxel_size": POSITIVE, "band_width": POSITIVE,
             "padding_voxels": {"type": "integer", "minimum": 1, "maximum": 1024}}, ["type", "file"]),
    ]
    return {"description": "An SDF asset: an analytic shape centred at its local origin (y up), a level set "
                           "from a .vdb file or a triangle mesh from an .obj or .stl file (docs/scenes.md, Shapes).",
            "type": "object", "required": ["type"],
            "properties": {"type": {"enum": [v["properties"]["type"]["const"] for v in variants]}},
            "oneOf": variants}


def build():
    placed = {"transform": {"$ref": "#/definitions/transform"}, "motion": {"$ref": "#/definitions/motion"}}
    span = {"start": NON_NEGATIVE, "stop": NUMBER}
    params_object = lambda fields: obj({k: FIELD_KINDS[v] for k, v in fields.items()})  # noqa: E731
    fluid = [
        obj({"type": const_type("box"), "min": VEC3, "max": VEC3, "velocity": VEC3, "time": NON_NEGATIVE},
            ["type", "min", "max"]),
        obj({"type": const_type("sphere"), "center": VEC3, "radius": POSITIVE, "velocity": VEC3,
             "time": NON_NEGATIVE}, ["type", "center", "radius"]),
        obj({"type": const_type("particles"), "positions": {"type": "array", "items": VEC3},
             "velocities": {"type": "array", "items": VEC3}, "time": NON_NEGATIVE}, ["type", "positions"]),
    ]
    field_common = {"name": STRING, "region": {"$ref": "#/definitions/shape"}, **placed, **span}
    force_field = [
        obj({"type": const_type("uniform"), "vector": VEC3, **field_common}, ["type", "vector"]),
        obj({"type": const_type("radial"), "strength": NUMBER, "falloff_radius": POSITIVE, **field_common},
            ["type", "strength"]),
        obj({"type": const_type("vortex"), "axis": VEC3, "strength": NUMBER, "falloff_radius": POSITIVE,
             **field_common}, ["type", "axis", "strength"]),
    ]
    sink = [
        obj({"type": const_type("region"), "name": STRING, "shape": {"$ref": "#/definitions/shape"},
             "transform": {"$ref": "#/definitions/transform"}}, ["type", "shape"]),
        obj({"type": const_type("outside_bounds"), "name": STRING, "min": VEC3, "max": VEC3},
            ["type", "min", "max"]),
    ]
    sampling = {"enum": ["frame", "substep"]}
    probe = [
        obj({"type": const_type("point"), "name": STRING, "position": VEC3, "sampling": sampling,
             "pressure_threshold": NON_NEGATIVE}, ["type", "position"]),
        obj({"type": const_type("gauge"), "name": STRING, "position": VEC3, "direction": VEC3, "length": POSITIVE,
             "sample_spacing": POSITIVE, "sampling": sampling, "pressure_threshold": NON_NEGATIVE},
            ["type", "position", "length"]),
    ]
    tagged = lambda variants, what: {  # noqa: E731
        "type": "object", "required": ["type"], "description": what,
        "properties": {"type": {"enum": [v["properties"]["type"]["const"] for v in variants]}},
        "oneOf": variants}
    camera = {"oneOf": [{"const": "auto"},
                        obj({"position": VEC3, "target": VEC3, "up": VEC3,
                             "fov_degrees": {"type": "number", "minimum": 1, "maximum": 170}},
                            ["position", "target"])]}
    fmt = {"enum": FORMATS}
    output = obj({
        "directory": STRING,
        "format": {"oneOf": [fmt, {"type": "array", "items": fmt, "minItems": 1, "uniqueItems": True}]},
        "surface": {"oneOf": [BOOLEAN, obj({"enabled": BOOLEAN, "particle_radius": POSITIVE,
                                             "voxel_size": POSITIVE})]},
        "preview": {"oneOf": [BOOLEAN, obj({
            "enabled": BOOLEAN, "style": {"enum": ["particles", "surface"]}, "camera": camera,
            "width": {"type": "integer", "minimum": 16, "maximum": 8192},
            "height": {"type": "integer", "minimum": 16, "maximum": 8192}, "speed_max": POSITIVE})]},
    })
    rotation = {"oneOf": [
        obj({"quaternion": {"type": "array", "items": NUMBER, "minItems": 4, "maxItems": 4}}, ["quaternion"]),
        obj({"axis": VEC3, "degrees": NUMBER}, ["axis", "degrees"]),
        obj({"axis": VEC3, "radians": NUMBER}, ["axis", "radians"]),
    ]}
    schema = {
        "$schema": "http://json-schema.org/draft-07/schema#",
        "title": "sph-run scene file",
        "description": "A scene for sph-run (docs/scenes.md). Generated by tools/scene/scene_schema.py; "
                       "\"comment\" is allowed in every object.",
        "definitions": {
            "vec3": {"type": "array", "items": NUMBER, "minItems": 3, "maxItems": 3},
            "shape": shape_schema(),
            "rotation": rotation,
            "transform": obj({"position": VEC3, "rotation": {"$ref": "#/definitions/rotation"}}),
            "motion": obj({
                "keyframes": {"type": "array", "minItems": 1, "items": obj(
                    {"time": NUMBER, "position": VEC3, "rotation": {"$ref": "#/definitions/rotation"}}, ["time"])},
                "interpolation": {"enum": ["linear", "smooth"]}, "loop": BOOLEAN}, ["keyframes"]),
        },
        **obj({
            "version": {"const": 1},
            "name": STRING,
            "description": STRING,
            "world": obj({
                "capacity": {"type": "integer", "minimum": 1, "maximum": 1073741824},
                "max_capacity": {"type": "integer", "minimum": 1, "maximum": 1073741824},
                "particle_spacing": POSITIVE, "kernel_radius": POSITIVE, "rest_density": POSITIVE,
                "integrator": {"enum": ["symplectic_euler", "rk4"]},
                "features": {"type": "array", "items": {"enum": FEATURES}},
                "viscosity_method": {"enum": VISCOSITY_METHODS},
                "equation_of_state": {"enum": EQUATIONS_OF_STATE},
                "solver": {"enum": SOLVERS}}),
            "params": params_object(WORLD_PARAMS),
            "physics": obj({k: params_object(v) for k, v in PHYSICS_PARAMS.items()}),
            "time": obj({"fps": {"type": "number", "minimum": 0.001, "maximum": 100000},
                         "frames": COUNT}),
            "fluids": {"type": "array", "items": tagged(fluid, "A fluid body (docs/scenes.md, fluids).")},
            "colliders": {"type": "array", "items": obj({
                "name": STRING, "shape": {"$ref": "#/definitions/shape"}, **placed, "inverted": BOOLEAN,
                "restitution": {"type": "number", "minimum": 0, "maximum": 1}, "friction": NON_NEGATIVE,
                "stickiness": NON_NEGATIVE, "loads": obj({"point": VEC3, "threshold": NON_NEGATIVE})}, ["shape"])},
            "sources": {"type": "array", "items": obj({
                "name": STRING, "shape": {"$ref": "#/definitions/shape"}, **placed,
                "mode": {"enum": ["once", "continuous"]}, "velocity": VEC3, "spacing": POSITIVE,
                "min_distance": POSITIVE, "rate": POSITIVE, "user_attribute": COUNT, **span},
                ["shape"])},
            "sinks": {"type": "array", "items": tagged(sink, "A sink (docs/scenes.md, sinks).")},
            "force_fields": {"type": "array", "items": tagged(force_field, "A force field.")},
            "probes": {"type": "array", "items": tagged(probe, "A probe or gauge (docs/scenes.md, probes).")},
            "output": output,
        }),
    }
    return schema


def main(argv):
    text = json.dumps(build(), indent=2) + "\n"
    if "--check" in argv:
        with open(OUT) as f:
            if f.read() != text:
                print(f"{OUT} is stale: run python3 tools/scene/scene_schema.py", file=sys.stderr)
                return 1
        return 0
    with open(OUT, "w") as f:
        f.write(text)
    print(f"wrote {os.path.relpath(OUT, ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
