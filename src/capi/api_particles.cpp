// Particles in (spawn, lattice fills) and out (count, attribute copies).
#include <vector>

#include "../core/fcc_lattice.h"
#include "../physics/grid_hash.h"
#include "guard.h"
#include "handles.h"
#include "init_struct.h"
#include "struct_io.h"
#include "validate.h"

using sph::Error;
using sph::Status;

namespace {

// Float32 resolves a position x to steps of about |x| 2^-23. Beyond 2^16 particle spacings
// from the origin a step exceeds 1/128 of the spacing, and neighbour distances, densities and
// small moves turn to rounding noise (at 1e6 m with a 2 cm spacing the steps are 6 cm: silent
// garbage), so such positions are refused. The bound lies far inside the neighbour grid's
// cell-coordinate range (2^30 cells of h >= spacing).
constexpr float kMaxPositionInSpacings = 65536.0f;

void require_resolvable(const sph::Vec3& p, const sph::WorldConfig& c, const std::string& name) {
  const float limit = kMaxPositionInSpacings * c.particle_spacing;
  if (!(std::fabs(p.x) <= limit && std::fabs(p.y) <= limit && std::fabs(p.z) <= limit))
    throw Error(Status::InvalidArgument,
                name + ": (" + sph::describe(p.x) + ", " + sph::describe(p.y) + ", " + sph::describe(p.z) +
                    ") lies farther than " + sph::describe(limit) +
                    " m (65536 particle spacings) from the origin, where float32 positions no longer "
                    "resolve the spacing to 1/128; move the scene's origin closer or use a larger spacing");
}

sph::Vec3 read_vec3(const float* base, uint64_t stride, uint32_t i) {
  const unsigned char* p = reinterpret_cast<const unsigned char*>(base) + stride * i;
  float v[3];
  std::memcpy(v, p, sizeof v);
  return sph::Vec3{v[0], v[1], v[2]};
}

void require_finite_point(const sph::Vec3& p, const std::string& name) {
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
    throw Error(Status::InvalidArgument, name + ": is not finite");
}

void check_fill_fits(const sph_world* world, uint64_t count) {
  const uint32_t free = world->world->free_capacity();
  if (count > free)
    throw Error(Status::Capacity, "the fill makes " + std::to_string(count) + " particles but only " +
                                      std::to_string(free) + " of the world's capacity " +
                                      std::to_string(world->world->config().capacity) + " are free");
}

uint32_t add_lattice(sph_world* world, const std::vector<sph::Vec3>& points, const sph_vec3& velocity) {
  check_fill_fits(world, points.size());
  const sph::WorldConfig& c = world->world->config();
  for (const sph::Vec3& p : points) require_resolvable(p, c, "desc (a lattice point)");
  const std::vector<sph::Vec3> velocities(points.size(), sph::Vec3{velocity.x, velocity.y, velocity.z});
  world->world->spawn(points, &velocities);
  return static_cast<uint32_t>(points.size());
}

size_t element_size(sph_attribute a) {
  return (a == SPH_ATTRIBUTE_POSITION || a == SPH_ATTRIBUTE_VELOCITY) ? 3 * sizeof(float) : sizeof(float);
}

}  // namespace

extern "C" {

SPH_API sph_result SPH_CALL sph_spawn_desc_init_sized(sph_spawn_desc* desc, uint32_t size) {
  return sph::init_user_struct("sph_spawn_desc_init", "desc", desc, size);
}

SPH_API sph_result SPH_CALL sph_fill_box_desc_init_sized(sph_fill_box_desc* desc, uint32_t size) {
  return sph::init_user_struct("sph_fill_box_desc_init", "desc", desc, size);
}

SPH_API sph_result SPH_CALL sph_fill_sphere_desc_init_sized(sph_fill_sphere_desc* desc, uint32_t size) {
  return sph::init_user_struct("sph_fill_sphere_desc_init", "desc", desc, size);
}

SPH_API sph_result SPH_CALL sph_world_spawn(sph_world* world, const sph_spawn_desc* desc,
                                            uint32_t* out_first_id) {
  return sph::guarded("sph_world_spawn", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    const sph_spawn_desc d = sph::read_user_struct(desc, "desc");
    if (d.count > 0 && !d.positions) throw Error(Status::InvalidArgument, "desc->positions: is NULL");
    const uint64_t pstride = d.position_stride == 0 ? 12 : d.position_stride;
    const uint64_t vstride = d.velocity_stride == 0 ? 12 : d.velocity_stride;
    if (pstride < 12) throw Error(Status::InvalidArgument, "desc->position_stride: must be 0 or >= 12");
    if (d.velocities && vstride < 12)
      throw Error(Status::InvalidArgument, "desc->velocity_stride: must be 0 or >= 12");
    if (d.count > world->world->free_capacity())
      throw Error(Status::Capacity, "desc->count: " + std::to_string(d.count) + " particles do not fit; " +
                                        std::to_string(world->world->free_capacity()) + " of the capacity " +
                                        std::to_string(world->world->config().capacity) + " are free");
    const sph::WorldConfig& config = world->world->config();
    std::vector<sph::Vec3> positions(d.count);
    std::vector<sph::Vec3> velocities;
    for (uint32_t i = 0; i < d.count; ++i) {
      positions[i] = read_vec3(d.positions, pstride, i);
      const std::string name = "desc->positions[" + std::to_string(i) + "]";
      require_finite_point(positions[i], name);
      require_resolvable(positions[i], config, name);
    }
    if (d.velocities) {
      velocities.resize(d.count);
      for (uint32_t i = 0; i < d.count; ++i) {
        velocities[i] = read_vec3(d.velocities, vstride, i);
        require_finite_point(velocities[i], "desc->velocities[" + std::to_string(i) + "]");
      }
    }
    const uint32_t first = world->world->spawn(positions, d.velocities ? &velocities : nullptr);
    if (out_first_id) *out_first_id = first;
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_world_fill_box(sph_world* world, const sph_fill_box_desc* desc,
                                               uint32_t* out_count) {
  return sph::guarded("sph_world_fill_box", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    const sph_fill_box_desc d = sph::read_user_struct(desc, "desc");
    sph::require_zero(d.reserved0, "desc->reserved0");
    sph::require_finite_vec3(d.min, "desc->min");
    sph::require_finite_vec3(d.max, "desc->max");
    sph::require_finite_vec3(d.velocity, "desc->velocity");
    if (!(d.max.x > d.min.x && d.max.y > d.min.y && d.max.z > d.min.z))
      throw Error(Status::InvalidArgument, "desc->max: every component must be greater than desc->min's");
    const float s = world->world->config().particle_spacing;
    const sph::Vec3 lo{d.min.x, d.min.y, d.min.z}, hi{d.max.x, d.max.y, d.max.z};
    check_fill_fits(world, sph::fcc_box_point_count(lo, hi, s));
    const uint32_t n = add_lattice(world, sph::fcc_points_in_box(lo, hi, s), d.velocity);
    if (out_count) *out_count = n;
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_world_fill_sphere(sph_world* world, const sph_fill_sphere_desc* desc,
                                                  uint32_t* out_count) {
  return sph::guarded("sph_world_fill_sphere", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    const sph_fill_sphere_desc d = sph::read_user_struct(desc, "desc");
    sph::require_zero(d.reserved0, "desc->reserved0");
    sph::require_finite_vec3(d.center, "desc->center");
    sph::require_positive(d.radius, "desc->radius");
    sph::require_finite_vec3(d.velocity, "desc->velocity");
    const float s = world->world->config().particle_spacing;
    // Refuse before generating anything when the lattice cannot possibly fit (the estimate
    // is within a few percent of the exact count for any sphere larger than a few spacings).
    const double estimate = sph::fcc_sphere_point_estimate(d.radius, s);
    if (estimate > 2.0 * world->world->free_capacity() + 4096.0)
      check_fill_fits(world, static_cast<uint64_t>(std::min(estimate, 1.8e19)));
    const uint32_t n = add_lattice(
        world, sph::fcc_points_in_sphere(sph::Vec3{d.center.x, d.center.y, d.center.z}, d.radius, s),
        d.velocity);
    if (out_count) *out_count = n;
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_world_get_particle_count(const sph_world* world, uint32_t* out_count) {
  return sph::guarded("sph_world_get_particle_count", sph::context_of(world), [&] {
    sph::require_world(world);
    if (!out_count) throw Error(Status::InvalidArgument, "out_count: is NULL");
    *out_count = world->world->particle_count();
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_world_copy_attribute(const sph_world* world, sph_attribute attribute,
                                                     void* dst, uint64_t dst_size, uint64_t dst_stride,
                                                     uint32_t first, uint32_t count, uint32_t* out_written) {
  return sph::guarded("sph_world_copy_attribute", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    if (sph::enum_bits(attribute) >= SPH_ATTRIBUTE_COUNT)
      throw Error(Status::Unsupported,
                  "attribute: " + std::to_string(static_cast<int32_t>(sph::enum_bits(attribute))) +
                      " is not an sph_attribute value");
    if (!dst) throw Error(Status::InvalidArgument, "dst: is NULL");
    const uint64_t element = element_size(attribute);
    const uint64_t stride = dst_stride == 0 ? element : dst_stride;
    if (stride < element)
      throw Error(Status::InvalidArgument, "dst_stride: " + std::to_string(dst_stride) +
                                               " is smaller than the element size " +
                                               std::to_string(element));
    const uint32_t total = world->world->particle_count();
    if (first > total)
      throw Error(Status::InvalidArgument, "first: " + std::to_string(first) +
                                               " is beyond the particle count " + std::to_string(total));
    const uint32_t n = std::min(count, total - first);
    // (n - 1) * stride + element bytes, saturated: a huge stride must not wrap around 64 bits
    // and pass the size check.
    const uint64_t span = n == 0 ? 0 : static_cast<uint64_t>(n - 1);
    const bool overflows = span != 0 && stride > (UINT64_MAX - element) / span;
    const uint64_t needed = n == 0 ? 0 : (overflows ? UINT64_MAX : span * stride + element);
    if (dst_size < needed)
      throw Error(Status::BufferTooSmall, "dst_size: " + std::to_string(dst_size) + " bytes cannot hold " +
                                              std::to_string(n) + " elements at stride " +
                                              std::to_string(stride) + " (" + std::to_string(needed) +
                                              " bytes needed)");
    if (n > 0)
      world->world->backend().copy_attribute(static_cast<sph::AttributeKind>(attribute), first, n, dst,
                                             stride);
    if (out_written) *out_written = n;
    return SPH_OK;
  });
}

}  // extern "C"
