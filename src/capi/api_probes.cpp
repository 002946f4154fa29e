// SPDX-License-Identifier: MIT
// Probes and gauges: user points and lines where the backends sample the fluid inside the step
// (physics/probe_sampling.h); the world keeps each probe's reading of the last step
// (core/world_probes.cpp), which the calls here read.
#include "../core/field_error.h"
#include "guard.h"
#include "handles.h"
#include "init_struct.h"
#include "public_vec3.h"
#include "struct_io.h"
#include "validate.h"

using sph::Error;
using sph::Status;
using sph::to_public;
using sph::vec3_from_public;

extern "C" {

SPH_API sph_result SPH_CALL sph_probe_def_init_sized(sph_probe_def* def, uint32_t size) {
  return sph::init_user_struct("sph_probe_def_init", "def", def, size, [](sph_probe_def& d) {
    d.kind = SPH_PROBE_POINT;
    d.sampling = SPH_PROBE_EVERY_FRAME;
  });
}

SPH_API sph_result SPH_CALL sph_probe_create(sph_world* world, const sph_probe_def* def,
                                             sph_probe_id* out_id) {
  return sph::guarded("sph_probe_create", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    if (!out_id) throw Error(Status::InvalidArgument, "out_id: is NULL");
    const sph_probe_def d = sph::read_user_struct(def, "def");
    const uint32_t kind = sph::enum_bits(d.kind);
    if (kind != SPH_PROBE_POINT && kind != SPH_PROBE_GAUGE)
      throw Error(Status::Unsupported, "def->kind: " + std::to_string(static_cast<int32_t>(kind)) +
                                           " is not an sph_probe_kind value");
    const uint32_t sampling = sph::enum_bits(d.sampling);
    if (sampling != SPH_PROBE_EVERY_FRAME && sampling != SPH_PROBE_EVERY_SUBSTEP)
      throw Error(Status::Unsupported, "def->sampling: " + std::to_string(static_cast<int32_t>(sampling)) +
                                           " is not an sph_probe_sampling value");
    sph::require_zero(d.reserved0, "def->reserved0");
    out_id->bits = sph::with_field_prefix("def->", [&] {
      sph::ProbeSpec spec;
      spec.gauge = kind == SPH_PROBE_GAUGE;
      spec.every_substep = sampling == SPH_PROBE_EVERY_SUBSTEP;
      spec.position = vec3_from_public(d.position);
      // A point reads only its position (the gauge fields are ignored, as documented).
      if (spec.gauge) {
        spec.direction = vec3_from_public(d.direction);
        spec.length = d.length;
        spec.sample_spacing = d.sample_spacing;
      }
      return world->world->add_probe(spec);
    });
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_probe_destroy(sph_world* world, sph_probe_id id) {
  return sph::guarded("sph_probe_destroy", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    world->world->remove_probe(id.bits);
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_probe_reading_init_sized(sph_probe_reading* reading, uint32_t size) {
  return sph::init_user_struct("sph_probe_reading_init", "reading", reading, size);
}

SPH_API sph_result SPH_CALL sph_probe_get_reading(const sph_world* world, sph_probe_id id,
                                                  sph_probe_reading* out) {
  return sph::guarded("sph_probe_get_reading", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    const sph::ProbeReading& r = world->world->probe(id.bits).reading;
    sph_probe_reading o = sph::zeroed_struct<sph_probe_reading>();
    o.samples = r.samples;
    o.density = r.density;
    o.pressure = r.pressure;
    o.velocity = to_public(r.velocity);
    o.pressure_max = r.pressure_max;
    o.kernel_sum = r.kernel_sum;
    o.water_height = r.water_height;
    o.time = r.time;
    sph::write_output_struct(out, o, "out");
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_probe_set_pressure_threshold(sph_world* world, sph_probe_id id,
                                                             float pressure) {
  return sph::guarded("sph_probe_set_pressure_threshold", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    world->world->set_probe_pressure_threshold(id.bits, pressure);
    return SPH_OK;
  });
}

}  // extern "C"
