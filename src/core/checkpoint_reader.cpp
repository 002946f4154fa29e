// SPDX-License-Identifier: MIT
// Reads a checkpoint into a new world. Everything is parsed and validated before the backend
// is created, so a damaged file allocates nothing beyond what its own bytes describe and
// leaves nothing behind. Scene objects are made by the same rules as a caller's
// (scene_build.h); their slot layouts are restored as saved, so ids stay valid.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>

#include "../physics/kernels.h"
#include "byte_io.h"
#include "checkpoint.h"
#include "checkpoint_fields.h"
#include "checkpoint_format.h"
#include "checkpoint_params.h"
#include "checkpoint_scene_reader.h"
#include "fcc_lattice.h"
#include "field_error.h"
#include "pose_rules.h"
#include "scene_build.h"

namespace sph {
namespace {

using namespace checkpoint;
using namespace checkpoint_read;

// The event types a library of checkpoint format `version` could report.
bool event_type_known(uint32_t type, uint32_t version) {
  switch (static_cast<EventType>(type)) {
    case EventType::SourceCapacityReached:
    case EventType::SinkRemoved:
    case EventType::PressureSolveCapped:
    case EventType::DivergenceSolveCapped:
      return true;
    case EventType::CapacityGrown:
      return version >= kFirstGrowableVersion;
    case EventType::ColliderLoadExceeded:
    case EventType::ProbePressureExceeded:
      return version >= kFirstThresholdVersion;
  }
  return false;
}

WorldConfig read_config(ByteReader& r, uint32_t version) {
  WorldConfig c;
  c.capacity = r.u32();
  if (c.capacity == 0 || c.capacity > kMaxWorldCapacity)
    corrupt(r.what() + ": capacity " + std::to_string(c.capacity) + " is outside [1, 2^30]");
  c.features = r.u32();
  if (c.features & ~static_cast<uint32_t>(kFeatureAll))
    corrupt(r.what() + ": unknown feature bits " + hex32(c.features));
  c.integrator = static_cast<Integrator>(below(r, 2, "integrator"));
  c.viscosity_method = static_cast<ViscosityMethod>(method(r, SwitchKind::Viscosity, "viscosity method"));
  c.equation_of_state =
      static_cast<EquationOfState>(method(r, SwitchKind::EquationOfState, "equation of state"));
  c.particle_spacing = positive(r, "particle spacing");
  c.kernel_radius = positive(r, "kernel radius");
  c.rest_density = positive(r, "rest density");
  c.particle_mass = positive(r, "particle mass");
  if (version >= kFirstSolverVersion) {
    c.solver = static_cast<Solver>(method(r, SwitchKind::Solver, "solver"));
    if (c.solver == Solver::Dfsph &&
        (c.integrator == Integrator::Rk4 || c.equation_of_state != EquationOfState::IdealGas ||
         (c.features & kFeatureNormalizedDensity)))
      corrupt(r.what() +
              ": the DFSPH solver with RK4, an equation of state other than the ideal gas, or "
              "the normalised density (no world can be made so)");
  }
  c.max_capacity = c.capacity;  // before version 5 every world was fixed
  if (version >= kFirstGrowableVersion) {
    c.max_capacity = r.u32();
    if (c.max_capacity < c.capacity || c.max_capacity > kMaxWorldCapacity)
      corrupt(r.what() + ": max_capacity " + std::to_string(c.max_capacity) + " is outside [capacity " +
              std::to_string(c.capacity) + ", 2^30]");
  }
  if ((c.features & kFeatureDensityDiffusion) &&
      (!(c.features & kFeatureNormalizedDensity) || c.solver == Solver::Dfsph))
    corrupt(r.what() +
            ": density diffusion without the normalised density, or with DFSPH (no world can be made so)");
  if (c.kernel_radius < c.particle_spacing || c.kernel_radius > 5.0f * c.particle_spacing)
    corrupt(r.what() + ": kernel radius is outside [1, 5] x the particle spacing");
  const KernelCoefficients k = make_kernel_coefficients(c.kernel_radius);
  if (!std::isfinite(k.poly6) || !std::isfinite(k.spiky_grad) || !(k.poly6 > 0.0f) || !(k.visc_lap > 0.0f) ||
      !std::isnormal(k.h2) || !std::isnormal(c.particle_mass))
    corrupt(r.what() + ": kernel radius or particle mass not representable in float32");
  c.spiky_scale = fcc_spiky_scale(c.particle_spacing, c.kernel_radius);
  c.density_self_weight = fcc_density_self_weight(c.particle_spacing, c.kernel_radius, c.rest_density,
                                                  c.particle_mass, c.spiky_scale);
  if (!std::isfinite(c.density_self_weight) || !(c.density_self_weight > 0.0f))
    corrupt(r.what() + ": the particle mass " + std::to_string(c.particle_mass) +
            " does not fit the spacing and kernel radius (no positive density self term)");
  return c;
}

// The spring lists: every partner an index of another particle, every rest length in
// [0, h], and every spring stored at both ends with the same rest length (bit for bit), as
// the solver keeps them.
void read_springs(ByteReader& r, const WorldConfig& config, uint32_t next_id, ParticleSnapshot& s) {
  const uint32_t n = static_cast<uint32_t>(s.id.size());
  const uint32_t link_from = r.u32();
  if (link_from != kNoPendingLinks && link_from > next_id)
    corrupt(r.what() + ": the first id waiting for springs, " + std::to_string(link_from) +
            ", was never issued");
  if (r.u32() != kSpringSlots)
    corrupt(r.what() + ": spring lists do not have " + std::to_string(kSpringSlots) + " slots");
  r.need_elements(n, kSpringSlots * 8, "spring lists");
  HostVector<SpringList> springs(n);
  for (uint32_t i = 0; i < n; ++i) {
    SpringList& list = springs[i];
    for (uint32_t k = 0; k < kSpringSlots; ++k) {
      list.partner[k] = r.u32();
      list.rest[k] = bulk_finite(r, "spring rest length of particle", i);
      const uint32_t j = list.partner[k];
      if (j == kNoSpring) {
        if (list.rest[k] != 0.0f)
          corrupt(r.what() + ": an empty spring slot of particle " + std::to_string(i) +
                  " has a rest length");
        continue;
      }
      if (j >= n || j == i)
        corrupt(r.what() + ": particle " + std::to_string(i) + " has a spring to " + std::to_string(j) +
                ", which is not another particle");
      if (list.rest[k] < 0.0f || list.rest[k] > config.kernel_radius)
        corrupt(r.what() + ": a spring rest length of particle " + std::to_string(i) + " is outside [0, h]");
    }
  }
  for (uint32_t i = 0; i < n; ++i)
    for (uint32_t k = 0; k < kSpringSlots; ++k) {
      const uint32_t j = springs[i].partner[k];
      if (j == kNoSpring) continue;
      uint32_t matches = 0;
      for (uint32_t m = 0; m < kSpringSlots; ++m)
        if (springs[j].partner[m] == i &&
            std::memcmp(&springs[j].rest[m], &springs[i].rest[k], sizeof(float)) == 0)
          ++matches;
      uint32_t copies = 0;
      for (uint32_t m = 0; m < kSpringSlots; ++m) copies += springs[i].partner[m] == j ? 1u : 0u;
      if (matches != 1 || copies != 1)
        corrupt(r.what() + ": the spring between particles " + std::to_string(i) + " and " +
                std::to_string(j) + " is not stored once at each end with one rest length");
    }
  s.set_carried(kArraySprings, springs);
  s.set_carried(kArraySpringLinkFrom, HostVector<uint32_t>{link_from});
}

struct Clock {
  uint32_t next_id = 0;
  double simulated_time = 0.0;
  float last_step_ms = 0.0f;
  FrameReport report;
  HostVector<Event> events;
};

SolveReport read_solve(ByteReader& r, const std::string& name) {
  SolveReport s;
  s.iterations = r.u32();
  s.iterations_max = r.u32();
  s.capped = r.u32();
  s.error_mean = non_negative(r, name + " mean error");
  s.error_max = non_negative(r, name + " largest error");
  if (s.iterations_max > s.iterations || s.capped > s.iterations)
    corrupt(r.what() + ": " + name + " counts more in one substep or more capped solves than iterations");
  return s;
}

Clock read_clock(ByteReader& r, uint32_t version) {
  Clock c;
  c.next_id = r.u32();
  zero(r, "reserved");
  c.simulated_time = r.f64();
  if (!std::isfinite(c.simulated_time) || c.simulated_time < 0.0)
    corrupt(r.what() + ": simulated time is negative or not finite");
  c.last_step_ms = non_negative(r, "last step time");
  FrameReport& f = c.report;
  f.substeps = r.u32();
  f.completed = flag(r, "completed") != 0;
  f.time_advanced = r.f64();
  if (!std::isfinite(f.time_advanced) || f.time_advanced < 0.0)
    corrupt(r.what() + ": frame time is negative or not finite");
  f.dt_min = non_negative(r, "dt_min");
  f.dt_max = non_negative(r, "dt_max");
  f.max_speed = magnitude_max(r, "max speed");
  f.density_min = finite(r, "density min");
  f.density_mean = finite(r, "density mean");
  f.density_max = finite(r, "density max");
  f.neighbors_mean = non_negative(r, "neighbours mean");
  f.neighbors_max = r.u32();
  for (int k = 0; k < kStageCount; ++k) f.stage_ms[k] = non_negative(r, "stage time");
  if (version >= kFirstSolverVersion) {
    f.pressure_solve = read_solve(r, "density solve");
    f.divergence_solve = read_solve(r, "divergence solve");
  }
  const uint32_t events = r.u32();
  r.need_elements(events, 16, "events");
  c.events.resize(events);
  for (Event& e : c.events) {
    const uint32_t type = r.u32();
    if (!event_type_known(type, version)) corrupt(r.what() + ": unknown event type " + std::to_string(type));
    e.type = static_cast<EventType>(type);
    e.count = r.u32();
    e.object_id = r.u64();
  }
  const uint32_t removed = r.u32();
  r.need_elements(removed, 4, "removed ids");
  f.removed_ids.resize(removed);
  for (uint32_t& id : f.removed_ids) id = r.u32();
  return c;
}

ParticleSnapshot read_particles(ByteReader& r, const WorldConfig& config, uint32_t next_id) {
  ParticleSnapshot s;
  const uint32_t n = r.u32();
  zero(r, "reserved");
  s.max_speed = magnitude_max(r, "max speed");
  s.max_acceleration = magnitude_max(r, "max acceleration");
  if (n > config.capacity)
    corrupt(r.what() + ": " + std::to_string(n) + " particles exceed the capacity " +
            std::to_string(config.capacity));
  r.need_elements(n, 2 * sizeof(Float4) + 2 * sizeof(uint32_t), "particles");
  s.position.resize(n);
  s.velocity.resize(n);
  s.id.resize(n);
  s.density.resize(n);
  for (uint32_t i = 0; i < n; ++i) s.position[i] = float4(r, "position of particle", i);
  for (uint32_t i = 0; i < n; ++i) s.velocity[i] = float4(r, "velocity of particle", i);
  for (uint32_t i = 0; i < n; ++i) {
    s.id[i] = r.u32();
    if (s.id[i] >= next_id)
      corrupt(r.what() + ": particle id " + std::to_string(s.id[i]) + " was never issued (next id " +
              std::to_string(next_id) + ")");
  }
  for (uint32_t i = 0; i < n; ++i) s.density[i] = bulk_finite(r, "density of particle", i);
  // Normalised density: the carried factors, positive and finite, or NaN (a particle spawned
  // since its last density pass). A checkpoint written before the factors existed ends here:
  // its particles start fresh.
  if ((config.features & kFeatureNormalizedDensity) && r.remaining() != 0) {
    r.need_elements(n, sizeof(float), "density factors");
    HostVector<float> factors(n);
    for (uint32_t i = 0; i < n; ++i) {
      const float d = r.f32();
      if (!std::isnan(d) && !(d > 0.0f && std::isfinite(d)))
        corrupt(r.what() + ": density factor of particle " + std::to_string(i) + " is " + std::to_string(d) +
                ", not positive and finite");
      factors[i] = d;
    }
    s.set_carried(kArrayDensityFactor, factors);
  }
  // DFSPH: the warm starts of its two solves (finite; the density solve's pressure is never
  // negative). Every DFSPH checkpoint has them (DFSPH came with version 3).
  if (config.solver == Solver::Dfsph) {
    r.need_elements(n, 2 * sizeof(float), "DFSPH warm starts");
    HostVector<float> pressure(n), divergence(n);
    for (uint32_t i = 0; i < n; ++i) {
      pressure[i] = bulk_finite(r, "DFSPH pressure of particle", i);
      if (pressure[i] < 0.0f)
        corrupt(r.what() + ": DFSPH pressure of particle " + std::to_string(i) + " is negative");
    }
    for (uint32_t i = 0; i < n; ++i)
      divergence[i] = bulk_finite(r, "DFSPH divergence pressure of particle", i);
    s.set_carried(kArrayDfsphPressure, pressure);
    s.set_carried(kArrayDfsphDivergencePressure, divergence);
  }
  // The user attribute: any uint32 (the library never reads it). Every checkpoint of a world
  // with the feature has it (the feature came with it, in version 3).
  if (config.features & kFeatureUserAttribute) {
    r.need_elements(n, sizeof(uint32_t), "user attributes");
    HostVector<uint32_t> attribute(n);
    for (uint32_t& a : attribute) a = r.u32();
    s.set_carried(kArrayUserAttribute, attribute);
  }
  HostVector<uint32_t> sorted(s.id);
  std::sort(sorted.begin(), sorted.end());
  const auto dup = std::adjacent_find(sorted.begin(), sorted.end());
  if (dup != sorted.end()) corrupt(r.what() + ": particle id " + std::to_string(*dup) + " appears twice");
  return s;
}

// SPH_MAKE_VERSION's packing: (major << 22) | (minor << 12) | patch.
std::string library_version_text(uint32_t packed) {
  return std::to_string(packed >> 22) + "." + std::to_string((packed >> 12) & 0x3ffu) + "." +
         std::to_string(packed & 0xfffu);
}

}  // namespace

std::unique_ptr<World> read_checkpoint(const uint8_t* data, size_t size, const BackendMaker& make_backend,
                                       bool rank_part) {
  // Header: magic and version first (a later version may lay out the rest differently), then
  // the sizes, then the checksum over everything.
  if (size < kHeaderSize)
    corrupt("truncated: " + std::to_string(size) + " bytes, shorter than the " + std::to_string(kHeaderSize) +
            "-byte header");
  if (std::memcmp(data, kMagic, sizeof kMagic) != 0) corrupt("not a checkpoint (wrong magic bytes)");
  ByteReader h(data + sizeof kMagic, kHeaderSize - sizeof kMagic, "header");
  const uint32_t version = h.u32();
  const uint32_t flags = h.u32();
  h.u32();                                  // writer backend: informational
  const uint32_t writer_library = h.u32();  // informational, but named when refusing a version
  if (version > kFormatVersion)
    throw Error(Status::VersionMismatch,
                "checkpoint: format version " + std::to_string(version) +
                    " is newer than this library reads (versions " + std::to_string(kOldestReadableVersion) +
                    " to " + std::to_string(kFormatVersion) + "); it was written by sph " +
                    library_version_text(writer_library) + ": load it with that library or a later one");
  if (version < kOldestReadableVersion)
    throw Error(Status::VersionMismatch, "checkpoint: format version " + std::to_string(version) +
                                             " is older than the oldest this library reads (" +
                                             std::to_string(kOldestReadableVersion) + ")");
  const uint64_t payload_size = h.u64();
  const uint64_t checksum = h.u64();
  const uint32_t section_count = h.u32();
  const uint32_t reserved = h.u32();
  const uint64_t present = size - kHeaderSize;
  if (payload_size > present)
    corrupt("truncated: the header promises " + std::to_string(payload_size) + " payload bytes, " +
            std::to_string(present) + " are present");
  if (payload_size < present)
    corrupt(std::to_string(present - payload_size) + " bytes follow the end of the checkpoint");
  Fnv1a64 sum;
  sum.add(data, kChecksumOffset);
  sum.add(data + kChecksumOffset + 8, size - kChecksumOffset - 8);
  if (sum.value() != checksum) corrupt("checksum mismatch: the data is damaged");
  if ((flags & ~kFlagRankPart) != 0) corrupt("unknown flags " + hex32(flags));
  if ((flags & kFlagRankPart) && !rank_part)
    throw Error(
        Status::InvalidArgument,
        "checkpoint: it is one rank's part of a distributed world; load it on its ranks with its manifest "
        "(sph_mpi_world_load_file)");
  if (rank_part && !(flags & kFlagRankPart))
    corrupt("not one rank's part of a distributed world (the manifest names a world's checkpoint)");
  if (reserved != 0) corrupt("a reserved header field is not 0");
  if (section_count != section_count_of(version))
    corrupt(std::to_string(section_count) + " sections; version " + std::to_string(version) + " has " +
            std::to_string(section_count_of(version)));

  ByteReader payload(data + kHeaderSize, static_cast<size_t>(payload_size), "payload");
  auto next_section = [&](uint32_t k) {
    const SectionInfo& info = kSectionOrder[k];
    const std::string what = std::string("section '") + info.name + "'";
    if (payload.remaining() < kSectionHeaderSize) payload.need(kSectionHeaderSize);
    const uint32_t found = payload.u32();
    if (found != info.tag)
      corrupt("section " + std::to_string(k) + " has tag " + hex32(found) + ", expected " + what);
    if (payload.u32() != 0) corrupt(what + ": a reserved field is not 0");
    const uint64_t length = payload.u64();
    if (length > payload.remaining())
      corrupt("truncated in " + what + " (needs " + std::to_string(length) + " bytes, " +
              std::to_string(payload.remaining()) + " left)");
    return payload.sub(length, what);
  };

  ByteReader conf = next_section(0);
  const WorldConfig config = read_config(conf, version);
  conf.expect_end();
  ByteReader parm = next_section(1);
  const RuntimeParams params = version == 1 ? read_params_v1(parm, config) : read_params(parm, config);
  parm.expect_end();
  // A dt_min above the stability ceiling is accepted, as sph_world_set_params accepts it (the
  // caller's fixed step wins over the ceiling; a step that then fails says so and rolls back).
  ByteReader time = next_section(2);
  const Clock clock = read_clock(time, version);
  time.expect_end();
  ByteReader part = next_section(3);
  ParticleSnapshot particles = read_particles(part, config, clock.next_id);
  if (config.features & kFeatureSprings) read_springs(part, config, clock.next_id, particles);
  if (rank_part) {
    // Any value is a valid order (keys only order the next sort); the count is checked first.
    part.need_elements(particles.id.size(), sizeof(uint64_t), "sort keys");
    HostVector<uint64_t> keys(particles.id.size());
    for (uint64_t& key : keys) key = part.u64();
    particles.set_carried(kArrayDistributedSortKey, keys);
  }
  part.expect_end();

  ByteReader sdfa = next_section(4);
  const CheckpointAssets assets = read_checkpoint_assets(sdfa);
  sdfa.expect_end();
  ByteReader coll = next_section(5);
  auto colliders = read_checkpoint_colliders(coll, assets, version);
  coll.expect_end();
  ByteReader srce = next_section(6);
  auto sources = read_checkpoint_sources(srce, assets, config);
  srce.expect_end();
  ByteReader sink = next_section(7);
  auto sinks = read_checkpoint_sinks(sink, assets);
  sink.expect_end();
  ByteReader ffld = next_section(8);
  auto fields = read_checkpoint_force_fields(ffld, assets);
  ffld.expect_end();
  SlotTable<Probe> probes;
  if (version >= kFirstProbeVersion) {
    ByteReader prob = next_section(9);
    probes = read_checkpoint_probes(prob, config, version);
    prob.expect_end();
  }
  payload.expect_end();

  // Everything is valid: build the world.
  std::unique_ptr<Backend> backend = make_backend(config);
  backend->import_particles(particles);
  auto world = std::make_unique<World>(config, std::move(backend));
  world->set_params(params);
  world->restore_counters(clock.next_id, clock.simulated_time, clock.report, clock.last_step_ms,
                          clock.events);
  world->restore_scene(
      SceneTables{std::move(colliders), std::move(sources), std::move(sinks), std::move(fields)});
  world->restore_probes(std::move(probes));
  return world;
}

}  // namespace sph
