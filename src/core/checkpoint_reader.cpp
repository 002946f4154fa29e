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
#include "checkpoint_particles_reader.h"
#include "checkpoint_scene_reader.h"
#include "fcc_lattice.h"
#include "field_error.h"
#include "kernel_radius_rule.h"
#include "number_text.h"
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
  if (const char* fault = kernel_radius_fault(c.particle_spacing, c.kernel_radius))
    corrupt(r.what() + ": kernel radius " + number_text(c.kernel_radius) + " (particle spacing " +
            number_text(c.particle_spacing) + ") " + fault + "; no world can be made so");
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

struct Clock {
  uint32_t next_id = 0;
  uint16_t id_tag = 0;  // the object ids' world tag (0 before version 15)
  double simulated_time = 0.0;
  float last_step_ms = 0.0f;
  FrameReport report;
  HostVector<Event> events;
};

SolveReport read_solve(ByteReader& r, const std::string& name, uint32_t version) {
  SolveReport s;
  s.iterations = r.u32();
  s.iterations_max = r.u32();
  s.capped = r.u32();
  s.error_mean = non_negative(r, name + " mean error");
  s.error_max = non_negative(r, name + " largest error");
  if (version >= kFirstLargestErrorVersion) s.largest_max = non_negative(r, name + " largest particle error");
  if (version >= kFirstGuardedVersion) s.guarded = r.u32();
  if (s.iterations_max > s.iterations || s.capped > s.iterations || s.guarded > s.iterations)
    corrupt(r.what() + ": " + name +
            " counts more in one substep, or more capped or guarded solves, than iterations");
  return s;
}

Clock read_clock(ByteReader& r, uint32_t version) {
  Clock c;
  c.next_id = r.u32();
  if (version >= kFirstWorldTagVersion) {
    const uint32_t tag = r.u32();
    if (tag > 0xffffu) corrupt(r.what() + ": the ids' world tag " + std::to_string(tag) + " is above 65535");
    c.id_tag = static_cast<uint16_t>(tag);
  } else {
    zero(r, "reserved");
  }
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
    f.pressure_solve = read_solve(r, "density solve", version);
    f.divergence_solve = read_solve(r, "divergence solve", version);
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

// SPH_MAKE_VERSION's packing: (major << 22) | (minor << 12) | patch.
std::string library_version_text(uint32_t packed) {
  return std::to_string(packed >> 22) + "." + std::to_string((packed >> 12) & 0x3ffu) + "." +
         std::to_string(packed & 0xfffu);
}

// The header checked (magic, version, sizes, checksum, flags): the payload and its version.
struct Opened {
  uint32_t version = 0;
  ByteReader payload;
};

Opened open_checkpoint(const uint8_t* data, size_t size, bool rank_part) {
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
  return Opened{version, ByteReader(data + kHeaderSize, static_cast<size_t>(payload_size), "payload")};
}

ByteReader next_section(ByteReader& payload, uint32_t k) {
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
}

// The sections before the scene: the config, the parameters, the clock and the particles.
struct Front {
  RuntimeParams params;
  float last_step_ms = 0.0f;
  CheckpointPart part;
};

Front read_front(ByteReader& payload, uint32_t version, bool rank_part) {
  Front f;
  ByteReader conf = next_section(payload, 0);
  f.part.config = read_config(conf, version);
  conf.expect_end();
  const WorldConfig& config = f.part.config;
  ByteReader parm = next_section(payload, 1);
  f.params = version == 1 ? read_params_v1(parm, config) : read_params(parm, config);
  parm.expect_end();
  // A dt_min above the stability ceiling is accepted, as sph_world_set_params accepts it (the
  // caller's fixed step wins over the ceiling; a step that then fails says so and rolls back).
  ByteReader time = next_section(payload, 2);
  Clock clock = read_clock(time, version);
  time.expect_end();
  f.part.next_id = clock.next_id;
  f.part.id_tag = clock.id_tag;
  f.part.simulated_time = clock.simulated_time;
  f.part.report = std::move(clock.report);
  f.part.events = std::move(clock.events);
  f.last_step_ms = clock.last_step_ms;
  ByteReader part = next_section(payload, 3);
  ParticleSnapshot& particles = f.part.particles;
  particles = read_checkpoint_particles(part, config, clock.next_id);
  if (config.features & kFeatureSprings)
    read_checkpoint_springs(part, config, clock.next_id, rank_part, particles);
  if (rank_part) {
    // Any value is a valid order (keys only order the next sort); the count is checked first.
    part.need_elements(particles.id.size(), sizeof(uint64_t), "sort keys");
    HostVector<uint64_t> keys(particles.id.size());
    for (uint64_t& key : keys) key = part.u64();
    particles.set_carried(kArrayDistributedSortKey, keys);
  }
  part.expect_end();
  return f;
}

}  // namespace

CheckpointPart read_checkpoint_part(const uint8_t* data, size_t size) {
  Opened o = open_checkpoint(data, size, true);
  return read_front(o.payload, o.version, true).part;
}

std::unique_ptr<World> read_checkpoint(const uint8_t* data, size_t size, const BackendMaker& make_backend,
                                       bool rank_part, const CheckpointAdjust& adjust) {
  Opened o = open_checkpoint(data, size, rank_part);
  const uint32_t version = o.version;
  ByteReader& payload = o.payload;
  Front front = read_front(payload, version, rank_part);
  if (adjust) adjust(front.part);
  const WorldConfig& config = front.part.config;
  ParticleSnapshot& particles = front.part.particles;

  ByteReader sdfa = next_section(payload, 4);
  const CheckpointAssets assets = read_checkpoint_assets(sdfa);
  sdfa.expect_end();
  ByteReader coll = next_section(payload, 5);
  auto colliders = read_checkpoint_colliders(coll, assets, version);
  coll.expect_end();
  ByteReader srce = next_section(payload, 6);
  auto sources = read_checkpoint_sources(srce, assets, config, version);
  srce.expect_end();
  ByteReader sink = next_section(payload, 7);
  auto sinks = read_checkpoint_sinks(sink, assets);
  sink.expect_end();
  ByteReader ffld = next_section(payload, 8);
  auto fields = read_checkpoint_force_fields(ffld, assets);
  ffld.expect_end();
  SlotTable<Probe> probes;
  if (version >= kFirstProbeVersion) {
    ByteReader prob = next_section(payload, 9);
    probes = read_checkpoint_probes(prob, version);
    prob.expect_end();
  }
  payload.expect_end();

  // Everything is valid: build the world.
  std::unique_ptr<Backend> backend = make_backend(config);
  backend->import_particles(particles);
  auto world = std::make_unique<World>(config, std::move(backend));
  world->set_id_tag(front.part.id_tag);
  world->set_params(front.params);
  world->restore_counters(front.part.next_id, front.part.simulated_time, front.part.report,
                          front.last_step_ms, front.part.events);
  world->restore_scene(
      SceneTables{std::move(colliders), std::move(sources), std::move(sinks), std::move(fields)});
  world->restore_probes(std::move(probes));
  return world;
}

}  // namespace sph
