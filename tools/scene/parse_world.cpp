// SPDX-License-Identifier: MIT
// The world (creation-time settings and the methods it runs), its runtime parameters and the
// run's timing.
#include "parse_parts.h"

namespace sph_tools {

namespace {
// sph_world_def's capacity and max_capacity are "at most 2^30" (sph_c.h): refused here, with the
// key's path, rather than by sph_world_create after the scene has been read.
constexpr uint32_t kCapacityLimit = 1u << 30;
}  // namespace

void parse_world(const JsonNode& node, sph_world_def* def) {
  sph_world_def_init(def);
  if (node.missing()) return;
  node.expect_object(
      "world", {"capacity", "particle_spacing", "kernel_radius", "rest_density", "integrator", "features",
                "viscosity_method", "equation_of_state", "solver", "max_capacity"});
  def->capacity = node["capacity"].opt_count(def->capacity, 1, kCapacityLimit);
  // A growable world (docs/api.md, "Growable worlds"); the library checks it against capacity.
  def->max_capacity = node["max_capacity"].opt_count(def->max_capacity, 1, kCapacityLimit);
  def->particle_spacing = node["particle_spacing"].opt_positive(def->particle_spacing);
  def->kernel_radius = node["kernel_radius"].opt_positive(def->kernel_radius);
  if (def->kernel_radius != 0.0f && def->kernel_radius < def->particle_spacing)
    node["kernel_radius"].fail("a radius >= particle_spacing (" + number_text(def->particle_spacing) + ")");
  def->rest_density = node["rest_density"].opt_positive(def->rest_density);
  if (!node["integrator"].missing())
    def->integrator = node["integrator"].choice({"symplectic_euler", "rk4"}) == 0
                          ? SPH_INTEGRATOR_SYMPLECTIC_EULER
                          : SPH_INTEGRATOR_RK4;
  if (!node["features"].missing()) def->features = parse_features(node["features"]);
  if (!node["viscosity_method"].missing())
    def->viscosity_method = static_cast<sph_viscosity_method>(
        parse_method(node["viscosity_method"], SPH_METHOD_SWITCH_VISCOSITY));
  if (!node["equation_of_state"].missing())
    def->equation_of_state = static_cast<sph_equation_of_state>(
        parse_method(node["equation_of_state"], SPH_METHOD_SWITCH_EQUATION_OF_STATE));
  if (!node["solver"].missing())
    def->solver = static_cast<sph_solver>(parse_method(node["solver"], SPH_METHOD_SWITCH_SOLVER));
}

// The world's runtime parameters: the fields of sph_world_params by the library's description
// of them; the library checks their values when the world is built.
void parse_params(const JsonNode& node, sph_world_params* p) {
  sph_world_params_init(p);
  if (node.missing()) return;
  parse_params_fields(node, SPH_PARAMS_WORLD, "params", reinterpret_cast<unsigned char*>(p));
}

void parse_time(const JsonNode& node, SceneDesc* scene) {
  if (node.missing()) return;
  node.expect_object("time", {"fps", "frames"});
  scene->fps = node["fps"].opt_positive(scene->fps);
  // A frame of 1 / fps seconds: below 0.001 fps (a frame of more than 1000 s) the frame time
  // leaves what the library's step takes (1 / 1e-40 is +Inf in float32).
  if (scene->fps > 100000.0f || scene->fps < 0.001f) node["fps"].fail("a frame rate in [0.001, 100000]");
  scene->frames = node["frames"].opt_count(scene->frames, 0, 10000000);
}

}  // namespace sph_tools
