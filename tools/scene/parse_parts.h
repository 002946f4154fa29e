// SPDX-License-Identifier: MIT
// The parsers of each part of a scene file (one file each). Every parser validates what it
// reads and throws SceneError with the field's path; scene_parser.cpp puts them together.
#ifndef SPH_TOOLS_PARSE_PARTS_H
#define SPH_TOOLS_PARSE_PARTS_H

#include <string>

#include "json_node.h"
#include "scene_desc.h"

namespace sph_tools {

// {"axis": [x, y, z], "degrees": a} | {"axis": [...], "radians": a} | {"quaternion": [x, y, z, w]}
sph_quat parse_rotation(const JsonNode& node);
// {"position": [x, y, z], "rotation": {...}}, both optional; a missing node is the identity.
sph_transform parse_transform(const JsonNode& node);
// {"keyframes": [{"time": t, "position": ..., "rotation": ...}, ...], "interpolation": ...,
// "loop": ...}; a key's missing position or rotation is `base`'s.
Motion parse_motion(const JsonNode& node, const sph_transform& base);
// An analytic shape, {"type": "vdb", "file": ..., "grid": ...} or {"type": "mesh", "file":
// ..., ...} (files relative to base_dir; mesh files are read here).
ShapeDesc parse_shape(const JsonNode& node, const std::string& base_dir);

void parse_world(const JsonNode& node, sph_world_def* def);
void parse_params(const JsonNode& node, sph_world_params* params);
// "physics": {"<method>": {"<field>": value, ...}, ...} for the methods the world turns on.
std::vector<PhysicsDesc> parse_physics(const JsonNode& node, const sph_world_def& world);
// The fields of a params struct of `kind` that the object gives, written into `bytes` (a
// struct of that kind); `what` names the object in errors. Types only: the library checks
// ranges when the world is built.
void parse_params_fields(const JsonNode& node, sph_params_kind kind, const char* what, unsigned char* bytes);
// A method's name for a sph_world_def field that selects one (world.viscosity_method,
// world.equation_of_state, world.solver), and a list of feature names (world.features).
uint32_t parse_method(const JsonNode& node, sph_method_switch field);
uint32_t parse_features(const JsonNode& node);
void parse_time(const JsonNode& node, SceneDesc* scene);
FluidDesc parse_fluid(const JsonNode& node);
ColliderDesc parse_collider(const JsonNode& node, const std::string& base_dir);
SourceDesc parse_source(const JsonNode& node, const std::string& base_dir);
SinkDesc parse_sink(const JsonNode& node, const std::string& base_dir);
ForceFieldDesc parse_force_field(const JsonNode& node, const std::string& base_dir);
ProbeDesc parse_probe(const JsonNode& node);
OutputDesc parse_output(const JsonNode& node);

// Times of optional start/stop fields: start >= 0, stop > start.
void parse_start_stop(const JsonNode& node, double* start, double* stop);

}  // namespace sph_tools

#endif
