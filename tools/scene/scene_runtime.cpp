// SPDX-License-Identifier: MIT
#include "scene_runtime.h"

#include <algorithm>
#include <cstdio>

#include "lattice_fill.h"
#include "library_error.h"
#include "scene_error.h"
#include "sdf_factory.h"

namespace sph_tools {

namespace {

// Scheduled things happen at the first frame boundary at or after their time.
constexpr double kTimeTolerance = 1e-6;

bool due(double when, double now) { return when <= now + kTimeTolerance; }

// A params struct the library refused: its message ("sph_world_set_params: params->dt_max:
// 1e-07 is smaller than params->dt_min 1e-06") at the field's path in the file ("params.dt_max:
// 1e-07 is smaller than params.dt_min 1e-06").
void check_params(sph_result r, const std::string& path) {
  if (r >= 0) return;
  const std::string message = sph_get_last_error();
  const std::string marker = "params->";
  const size_t at = message.find(marker);
  if (at == std::string::npos)
    throw SceneError(path, std::string("the library rejected the parameters: ") + message);
  std::string rest = message.substr(at + marker.size());
  for (size_t k = rest.find(marker); k != std::string::npos; k = rest.find(marker, k))
    rest.replace(k, marker.size(), path + ".");
  const size_t colon = rest.find(": ");
  if (colon == std::string::npos) throw SceneError(path, rest);
  throw SceneError(path + "." + rest.substr(0, colon), rest.substr(colon + 2));
}

void check_object(sph_result r, const std::string& path, const char* what) {
  if (r < 0)
    throw SceneError(path, std::string("the library rejected the ") + what + ": " + sph_get_last_error());
}

}  // namespace

SceneRuntime::SceneRuntime(const SceneDesc& scene, sph_context* context, WorldMaker* maker)
    : scene_(scene), context_(context), maker_(maker) {
  try {
    sph_result r = maker ? maker->create_world(context, &scene.world, &world_)
                         : sph_world_create(context, &scene.world, &world_);
    if (r < 0) {
      if (r == SPH_ERROR_INVALID_ARGUMENT || r == SPH_ERROR_UNSUPPORTED)
        throw SceneError("world", std::string("the library rejected the world: ") + sph_get_last_error());
      throw LibraryError(r, "creating the world");
    }
    check_params(sph_world_set_params(world_, &scene.params), "params");
    for (const PhysicsDesc& p : scene.physics)
      check_params(sph_world_set_physics_params(world_, p.kind, p.bytes.data()), p.path);

    for (const ColliderDesc& c : scene.colliders) {
      Collider placed{&c, create_sdf(context, c.shape), sph_collider_id{0}};
      colliders_.push_back(placed);
      sph_collider_def def;
      sph_collider_def_init(&def);
      def.sdf = placed.sdf;
      def.transform = c.transform;
      def.flags = c.inverted ? SPH_COLLIDER_FLAG_INVERTED : 0u;
      def.restitution = c.restitution;
      def.friction = c.friction;
      def.stickiness = c.stickiness;
      check_object(sph_collider_create(world_, &def, &colliders_.back().id), c.path, "collider");
      if (c.loads) {
        check_object(sph_collider_set_load_point(world_, colliders_.back().id, &c.load_point),
                     c.path + ".loads", "load point");
        check_object(sph_collider_set_load_threshold(world_, colliders_.back().id, c.load_threshold),
                     c.path + ".loads.threshold", "load threshold");
      }
    }
    for (const SinkDesc& s : scene.sinks) {
      sph_sink_def def;
      sph_sink_def_init(&def);
      def.mode = s.mode;
      if (s.mode == SPH_SINK_REGION) {
        sink_sdfs_.push_back(create_sdf(context, s.shape));
        def.region = sink_sdfs_.back();
        def.transform = s.transform;
      } else {
        def.bounds_min = s.bounds_min;
        def.bounds_max = s.bounds_max;
      }
      sph_sink_id id;
      check_object(sph_sink_create(world_, &def, &id), s.path, "sink");
    }
    for (const ProbeDesc& p : scene.probes) {
      sph_probe_def def;
      sph_probe_def_init(&def);
      def.kind = p.kind;
      def.sampling = p.sampling;
      def.position = p.position;
      def.direction = p.direction;
      def.length = p.length;
      def.sample_spacing = p.sample_spacing;
      probes_.push_back(sph_probe_id{0});
      check_object(sph_probe_create(world_, &def, &probes_.back()), p.path, "probe");
      check_object(sph_probe_set_pressure_threshold(world_, probes_.back(), p.pressure_threshold),
                   p.path + ".pressure_threshold", "pressure threshold");
    }
    sources_.resize(scene.sources.size());
    fields_.resize(scene.force_fields.size());
    fluid_added_.assign(scene.fluids.size(), false);
    // Everything of time 0 exists before the first frame, so frame 0 shows it.
    apply_schedule(0.0, 0.0);
  } catch (...) {
    destroy_all();
    throw;
  }
}

SceneRuntime::~SceneRuntime() { destroy_all(); }

void SceneRuntime::destroy_all() {
  sph_world_destroy(world_);
  world_ = nullptr;
  for (Collider& c : colliders_) sph_sdf_destroy(c.sdf);
  colliders_.clear();
  probes_.clear();
  for (Source& s : sources_) sph_sdf_destroy(s.sdf);
  sources_.clear();
  for (sph_sdf* sdf : sink_sdfs_) sph_sdf_destroy(sdf);
  sink_sdfs_.clear();
  for (ForceField& f : fields_) sph_sdf_destroy(f.region);
  fields_.clear();
}

sph_transform SceneRuntime::collider_pose(size_t i) const {
  sph_transform t = colliders_[i].desc->transform;
  sph_collider_get_transform(world_, colliders_[i].id, &t);
  return t;
}

void SceneRuntime::add_fluid(const FluidDesc& f) {
  sph_result r;
  uint32_t added = 0;
  if (maker_) {
    std::vector<float> positions, velocities;
    r = lattice_fill(context_, scene_.world, f, &positions, &velocities);
    if (r >= 0)
      r = maker_->add_particles(world_, positions.data(), velocities.data(),
                                static_cast<uint32_t>(positions.size() / 3));
  } else if (f.kind == FluidDesc::Kind::kBox) {
    sph_fill_box_desc d;
    sph_fill_box_desc_init(&d);
    d.min = f.min;
    d.max = f.max;
    d.velocity = f.velocity;
    r = sph_world_fill_box(world_, &d, &added);
  } else if (f.kind == FluidDesc::Kind::kSphere) {
    sph_fill_sphere_desc d;
    sph_fill_sphere_desc_init(&d);
    d.center = f.center;
    d.radius = f.radius;
    d.velocity = f.velocity;
    r = sph_world_fill_sphere(world_, &d, &added);
  } else {
    sph_spawn_desc d;
    sph_spawn_desc_init(&d);
    d.count = static_cast<uint32_t>(f.positions.size() / 3);
    d.positions = f.positions.data();
    d.velocities = f.velocities.empty() ? nullptr : f.velocities.data();  // NULL: at rest
    r = sph_world_spawn(world_, &d, nullptr);
  }
  if (r == SPH_ERROR_CAPACITY) {
    uint32_t count = 0;
    sph_world_get_particle_count(world_, &count);
    throw SceneError(f.path, "the fluid body does not fit: the world holds " + std::to_string(count) +
                                 " of " + std::to_string(world_limit()) + " particles (" + raise_hint() +
                                 ")");
  }
  check_object(r, f.path, "fluid body");
}

void SceneRuntime::start_source(size_t i) {
  const SourceDesc& s = scene_.sources[i];
  Source& state = sources_[i];
  state.sdf = create_sdf(context_, s.shape);
  sph_source_def def;
  sph_source_def_init(&def);
  def.mode = s.mode;
  def.region = state.sdf;
  def.transform = s.transform;
  def.spacing = s.spacing;
  def.min_distance = s.min_distance;
  def.velocity = s.velocity;
  def.rate = s.rate;
  def.user_attribute = s.user_attribute;
  check_object(sph_source_create(world_, &def, &state.id), s.path, "source");
  state.started = true;
}

void SceneRuntime::start_force_field(size_t i) {
  const ForceFieldDesc& f = scene_.force_fields[i];
  ForceField& state = fields_[i];
  if (f.has_region) state.region = create_sdf(context_, f.region);
  sph_force_field_def def;
  sph_force_field_def_init(&def);
  def.kind = f.kind;
  def.region = state.region;
  def.transform = f.transform;
  def.vector = f.vector;
  def.strength = f.strength;
  def.falloff_radius = f.falloff_radius;
  check_object(sph_force_field_create(world_, &def, &state.id), f.path, "force field");
  state.started = true;
}

void SceneRuntime::apply_schedule(double t, double next_t) {
  for (size_t i = 0; i < scene_.fluids.size(); ++i)
    if (!fluid_added_[i] && due(scene_.fluids[i].time, t)) {
      add_fluid(scene_.fluids[i]);
      fluid_added_[i] = true;
    }
  for (size_t i = 0; i < scene_.sources.size(); ++i) {
    const SourceDesc& s = scene_.sources[i];
    Source& state = sources_[i];
    if (!state.started && !state.stopped && due(s.start, t)) start_source(i);
    if (state.started && !state.stopped && due(s.stop, t)) {
      sph_source_destroy(world_, state.id);
      state.stopped = true;
    }
    if (state.started && !state.stopped && !s.motion.empty()) {
      const sph_transform pose = s.motion.at(t);
      check_object(sph_source_set_transform(world_, state.id, &pose), s.path + ".motion", "source pose");
    }
  }
  for (size_t i = 0; i < scene_.force_fields.size(); ++i) {
    const ForceFieldDesc& f = scene_.force_fields[i];
    ForceField& state = fields_[i];
    if (!state.started && !state.stopped && due(f.start, t)) start_force_field(i);
    if (state.started && !state.stopped && due(f.stop, t)) {
      sph_force_field_destroy(world_, state.id);
      state.stopped = true;
    }
    if (state.started && !state.stopped && !f.motion.empty()) {
      const sph_transform pose = f.motion.at(t);
      check_object(sph_force_field_set_transform(world_, state.id, &pose), f.path + ".motion",
                   "force field pose");
    }
  }
  if (next_t > t)
    for (const Collider& c : colliders_)
      if (!c.desc->motion.empty()) {
        const sph_transform target = c.desc->motion.at(next_t);
        check_object(sph_collider_set_target_transform(world_, c.id, &target), c.desc->path + ".motion",
                     "collider target");
      }
}

void SceneRuntime::collect_events() {
  warnings_.clear();
  notices_.clear();
  uint32_t count = 0;
  if (sph_world_get_events(world_, nullptr, 0, &count) < 0 || count == 0) return;
  std::vector<sph_event> events(count);
  sph_world_get_events(world_, events.data(), count, &count);
  for (const sph_event& e : events) {
    if (e.type == SPH_EVENT_COLLIDER_LOAD_EXCEEDED) {
      for (size_t i = 0; i < colliders_.size(); ++i)
        if (colliders_[i].id.bits == e.object_bits)
          notices_.push_back({colliders_[i].desc->path + ": the fluid's force reached its loads.threshold",
                              colliders_[i].desc->path + ": the fluid's force " + std::to_string(e.count) +
                                  " N reached its loads.threshold",
                              e.count, ""});
      continue;
    }
    if (e.type == SPH_EVENT_PROBE_PRESSURE_EXCEEDED) {
      for (size_t i = 0; i < probes_.size(); ++i)
        if (probes_[i].bits == e.object_bits)
          notices_.push_back({scene_.probes[i].path + ": the peak pressure reached its pressure_threshold",
                              scene_.probes[i].path + ": the peak pressure " + std::to_string(e.count) +
                                  " Pa reached its pressure_threshold",
                              e.count, ""});
      continue;
    }
    if (e.type == SPH_EVENT_PRESSURE_SOLVE_CAPPED || e.type == SPH_EVENT_DIVERGENCE_SOLVE_CAPPED) {
      // Never silent (issue 16): the bound the scene asked for was not met in these substeps.
      const bool density = e.type == SPH_EVENT_PRESSURE_SOLVE_CAPPED;
      sph_dfsph_params p;
      sph_dfsph_params_init(&p);
      sph_world_get_dfsph_params(world_, &p);
      char text[320];
      if (density)
        std::snprintf(
            text, sizeof text,
            "the DFSPH density solve stopped at its cap of %u iterations above its bounds in %u of the "
            "frame's substeps (physics.dfsph.max_iterations; density_error %g, density_error_max %g)",
            p.max_iterations, e.count, static_cast<double>(p.density_error),  // (max_iterations >= 2)
            // (a largest-error bound below the mean's acts as the mean's: dfsph.h)
            static_cast<double>(std::max(p.density_error, p.density_error_max)));
      else
        std::snprintf(
            text, sizeof text,
            "the DFSPH divergence solve stopped at its cap of %u iteration%s above its bound in %u of "
            "the frame's substeps (physics.dfsph.max_divergence_iterations; divergence_error %g 1/s, "
            "divergence_error_per_step %g)",
            p.max_divergence_iterations, p.max_divergence_iterations == 1 ? "" : "s", e.count,
            static_cast<double>(p.divergence_error), static_cast<double>(p.divergence_error_per_step));
      warnings_.push_back({density ? "the DFSPH density solve stopped at its cap above its bounds"
                                   : "the DFSPH divergence solve stopped at its cap above its bound",
                           text, e.count, "substeps"});
      continue;
    }
    if (e.type != SPH_EVENT_SOURCE_CAPACITY_REACHED) continue;
    std::string path = "sources";
    for (size_t i = 0; i < sources_.size(); ++i)
      if (sources_[i].id.bits == e.object_bits) path = scene_.sources[i].path;
    warnings_.push_back({path + ": the world's capacity is reached",
                         path + ": the world's capacity (" + std::to_string(world_limit()) +
                             ") is reached; " + std::to_string(e.count) + " particles were not emitted (" +
                             raise_hint() + ")",
                         e.count, "particles not emitted"});
  }
}

sph_result SceneRuntime::step_frame() {
  const double dt = 1.0 / static_cast<double>(scene_.fps);
  const double t = time(), next_t = (frame_ + 1) * dt;
  apply_schedule(t, next_t);
  const sph_result r = sph_world_step(world_, static_cast<float>(dt));
  if (r < 0) throw LibraryError(r, "stepping frame " + std::to_string(frame_ + 1));
  ++frame_;
  collect_events();
  return r;
}

}  // namespace sph_tools
