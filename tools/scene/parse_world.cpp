// The world (creation-time settings), its runtime parameters and the run's timing.
#include <limits>

#include "parse_parts.h"

namespace sph_tools {

void parse_world(const JsonNode& node, sph_world_def* def) {
  sph_world_def_init(def);
  if (node.missing()) return;
  node.expect_object("world",
                     {"capacity", "particle_spacing", "kernel_radius", "rest_density", "integrator"});
  def->capacity = node["capacity"].opt_count(def->capacity, 1, std::numeric_limits<uint32_t>::max());
  def->particle_spacing = node["particle_spacing"].opt_positive(def->particle_spacing);
  def->kernel_radius = node["kernel_radius"].opt_positive(def->kernel_radius);
  if (def->kernel_radius != 0.0f && def->kernel_radius < def->particle_spacing)
    node["kernel_radius"].fail("a radius >= particle_spacing (" + number_text(def->particle_spacing) + ")");
  def->rest_density = node["rest_density"].opt_positive(def->rest_density);
  if (!node["integrator"].missing())
    def->integrator = node["integrator"].choice({"symplectic_euler", "rk4"}) == 0
                          ? SPH_INTEGRATOR_SYMPLECTIC_EULER
                          : SPH_INTEGRATOR_RK4;
}

void parse_params(const JsonNode& node, sph_world_params* p) {
  sph_world_params_init(p);
  if (node.missing()) return;
  node.expect_object(
      "params", {"gravity", "stiffness", "viscosity", "step_factor", "dt_min", "dt_max", "max_substeps"});
  p->gravity = node["gravity"].opt_vec3(p->gravity);
  p->stiffness = node["stiffness"].opt_positive(p->stiffness);
  p->viscosity = node["viscosity"].opt_non_negative(p->viscosity);
  if (!node["step_factor"].missing()) {
    p->step_factor = node["step_factor"].positive();
    if (p->step_factor > 10.0f) node["step_factor"].fail("a number in (0, 10]");
  }
  p->dt_min = node["dt_min"].opt_positive(p->dt_min);
  p->dt_max = node["dt_max"].opt_positive(p->dt_max);
  if (p->dt_max < p->dt_min) {
    if (node.has("dt_max")) node["dt_max"].fail("a step >= dt_min (" + number_text(p->dt_min) + ")");
    node["dt_min"].fail("a step <= dt_max (" + number_text(p->dt_max) + ")");
  }
  p->max_substeps = node["max_substeps"].opt_count(p->max_substeps, 1, std::numeric_limits<uint32_t>::max());
}

void parse_time(const JsonNode& node, SceneDesc* scene) {
  if (node.missing()) return;
  node.expect_object("time", {"fps", "frames"});
  scene->fps = node["fps"].opt_positive(scene->fps);
  if (scene->fps > 100000.0f) node["fps"].fail("a frame rate in (0, 100000]");
  scene->frames = node["frames"].opt_count(scene->frames, 0, 10000000);
}

}  // namespace sph_tools
