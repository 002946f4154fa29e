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
#include "checkpoint_format.h"
#include "checkpoint_params.h"
#include "fcc_lattice.h"
#include "field_error.h"
#include "pose_rules.h"
#include "scene_build.h"

namespace sph {
namespace {

using namespace checkpoint;

[[noreturn]] void corrupt(const std::string& message) {
  throw Error(Status::CorruptData, "checkpoint: " + message);
}

std::string hex32(uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08x", v);
  return buf;
}

// Field readers that validate as they go; `name` is the field's path in messages.
float finite(ByteReader& r, const std::string& name) {
  const float v = r.f32();
  if (!std::isfinite(v)) corrupt(r.what() + ": " + name + " is not finite");
  return v;
}

float non_negative(ByteReader& r, const std::string& name) {
  const float v = finite(r, name);
  if (v < 0.0f) corrupt(r.what() + ": " + name + " is negative (" + std::to_string(v) + ")");
  return v;
}

// A maximum of |v| or |a| over finite vectors: non-negative, and +infinity when a squared
// length overflows float32 (a particle spawned at 2e19 m/s has finite components but an
// infinite |v|^2); never NaN. The writer saves what the world carries, so this accepts
// exactly that.
float magnitude_max(ByteReader& r, const std::string& name) {
  const float v = r.f32();
  if (std::isnan(v) || v < 0.0f) corrupt(r.what() + ": " + name + " is negative or not a number");
  return v;
}

float positive(ByteReader& r, const std::string& name) {
  const float v = finite(r, name);
  if (!(v > 0.0f)) corrupt(r.what() + ": " + name + " must be > 0, is " + std::to_string(v));
  return v;
}

uint32_t flag(ByteReader& r, const std::string& name) {
  const uint32_t v = r.u32();
  if (v > 1) corrupt(r.what() + ": " + name + " is " + std::to_string(v) + ", not 0 or 1");
  return v;
}

uint32_t below(ByteReader& r, uint32_t limit, const std::string& name) {
  const uint32_t v = r.u32();
  if (v >= limit)
    corrupt(r.what() + ": " + name + " is " + std::to_string(v) + ", not below " + std::to_string(limit));
  return v;
}

// A value of a world-def field that selects one method of the list (physics/methods.h).
uint32_t method(ByteReader& r, SwitchKind kind, const std::string& name) {
  const uint32_t v = r.u32();
  if (!selects_a_method(kind, v))
    corrupt(r.what() + ": " + name + " is " + std::to_string(v) + ", no method of this library");
  return v;
}

void zero(ByteReader& r, const std::string& name) {
  if (r.u32() != 0) corrupt(r.what() + ": " + name + " is reserved and must be 0");
}

// A pose as stored; the scene's rules (pose_rules.h) check it where the object is made.
RigidTransform raw_pose(ByteReader& r) {
  RigidTransform t;
  t.position.x = r.f32();
  t.position.y = r.f32();
  t.position.z = r.f32();
  t.rotation.x = r.f32();
  t.rotation.y = r.f32();
  t.rotation.z = r.f32();
  t.rotation.w = r.f32();
  return t;
}

Vec3 raw_vec3(ByteReader& r) {
  Vec3 v;
  v.x = r.f32();
  v.y = r.f32();
  v.z = r.f32();
  return v;
}

// Bulk floats: the message is built only on failure (a checkpoint may hold millions).
float bulk_finite(ByteReader& r, const char* what, uint32_t index) {
  const float v = r.f32();
  if (!std::isfinite(v)) corrupt(r.what() + ": " + what + " " + std::to_string(index) + " is not finite");
  return v;
}

Float4 float4(ByteReader& r, const char* what, uint32_t index) {
  Float4 v;
  v.x = bulk_finite(r, what, index);
  v.y = bulk_finite(r, what, index);
  v.z = bulk_finite(r, what, index);
  v.w = bulk_finite(r, what, index);
  return v;
}

Vec3 bulk_vec3(ByteReader& r, const char* what, uint32_t index) {
  Vec3 v;
  v.x = bulk_finite(r, what, index);
  v.y = bulk_finite(r, what, index);
  v.z = bulk_finite(r, what, index);
  return v;
}

WorldConfig read_config(ByteReader& r) {
  WorldConfig c;
  c.capacity = r.u32();
  if (c.capacity == 0 || c.capacity > (1u << 30))
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
  std::vector<SpringList> springs(n);
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
  s.set_carried(kArraySpringLinkFrom, std::vector<uint32_t>{link_from});
}

struct Clock {
  uint32_t next_id = 0;
  double simulated_time = 0.0;
  float last_step_ms = 0.0f;
  FrameReport report;
  std::vector<Event> events;
};

Clock read_clock(ByteReader& r) {
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
  const uint32_t events = r.u32();
  r.need_elements(events, 16, "events");
  c.events.resize(events);
  for (Event& e : c.events) {
    const uint32_t type = r.u32();
    if (type != static_cast<uint32_t>(EventType::SourceCapacityReached) &&
        type != static_cast<uint32_t>(EventType::SinkRemoved))
      corrupt(r.what() + ": unknown event type " + std::to_string(type));
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
    std::vector<float> factors(n);
    for (uint32_t i = 0; i < n; ++i) {
      const float d = r.f32();
      if (!std::isnan(d) && !(d > 0.0f && std::isfinite(d)))
        corrupt(r.what() + ": density factor of particle " + std::to_string(i) + " is " + std::to_string(d) +
                ", not positive and finite");
      factors[i] = d;
    }
    s.set_carried(kArrayDensityFactor, factors);
  }
  std::vector<uint32_t> sorted(s.id);
  std::sort(sorted.begin(), sorted.end());
  const auto dup = std::adjacent_find(sorted.begin(), sorted.end());
  if (dup != sorted.end()) corrupt(r.what() + ": particle id " + std::to_string(*dup) + " appears twice");
  return s;
}

std::shared_ptr<SdfAsset> read_asset(ByteReader& r, uint32_t index) {
  const std::string name = "asset " + std::to_string(index);
  uint32_t dims[3];
  for (uint32_t& d : dims) {
    d = r.u32();
    if (d == 0 || d > kMaxAssetDim)
      corrupt(r.what() + ": " + name + " has a dimension of " + std::to_string(d));
  }
  const uint64_t n = uint64_t{dims[0]} * dims[1] * dims[2];
  if (n > kMaxAssetVoxels) corrupt(r.what() + ": " + name + " has more than 2^31 voxels");
  const uint32_t channels = r.u32();
  if (channels & ~(kAssetHasVelocity | kAssetHasFriction))
    corrupt(r.what() + ": " + name + " has unknown channel bits " + hex32(channels));
  Affine3x4 affine;
  for (float& m : affine.m) m = finite(r, name + " index_to_local");
  const uint64_t floats_per_voxel =
      1 + ((channels & kAssetHasVelocity) ? 3 : 0) + ((channels & kAssetHasFriction) ? 1 : 0);
  r.need_elements(n, floats_per_voxel * sizeof(float), "voxels");  // before any allocation
  std::shared_ptr<SdfAsset> asset;
  try {
    asset = std::make_shared<SdfAsset>(static_cast<int32_t>(dims[0]), static_cast<int32_t>(dims[1]),
                                       static_cast<int32_t>(dims[2]), affine);
  } catch (const Error& e) {
    corrupt(r.what() + ": " + name + ": " + e.what());
  }
  const std::string where = name + ": voxel";
  std::vector<float>& distance = asset->distance();
  for (uint64_t i = 0; i < n; ++i) distance[i] = bulk_finite(r, where.c_str(), static_cast<uint32_t>(i));
  if (channels & kAssetHasVelocity) {
    asset->velocity().resize(n);
    std::vector<Vec3>& velocity = asset->velocity();
    for (uint64_t i = 0; i < n; ++i) velocity[i] = bulk_vec3(r, where.c_str(), static_cast<uint32_t>(i));
  }
  if (channels & kAssetHasFriction) {
    asset->friction().resize(n);
    std::vector<float>& friction = asset->friction();
    for (uint64_t i = 0; i < n; ++i) {
      friction[i] = bulk_finite(r, where.c_str(), static_cast<uint32_t>(i));
      if (friction[i] < 0.0f)
        corrupt(r.what() + ": " + where + " " + std::to_string(i) + " has a negative friction");
    }
  }
  return asset;
}

using Assets = std::vector<std::shared_ptr<SdfAsset>>;

// An asset of the table, or none; whether the object needs one is the scene's rule.
std::shared_ptr<const SdfAsset> asset_ref(ByteReader& r, const Assets& assets, const std::string& name) {
  const uint32_t k = r.u32();
  if (k == kNoAsset) return nullptr;
  if (k >= assets.size())
    corrupt(r.what() + ": " + name + " refers to asset " + std::to_string(k) + " of " +
            std::to_string(assets.size()));
  return assets[k];
}

// The slot table of one kind of object (see write_slots); read_value reads one live body.
template <class T, class ReadValue>
SlotTable<T> read_slots(ByteReader& r, ReadValue&& read_value) {
  SlotTable<T> t;
  const uint32_t slots = r.u32();
  if (slots > kMaxObjectSlots) corrupt(r.what() + ": " + std::to_string(slots) + " slots, more than 65536");
  r.need_elements(slots, 2 * sizeof(uint32_t), "slots");
  t.generations.resize(slots);
  t.values.resize(slots);
  uint32_t dead = 0;
  for (uint32_t i = 0; i < slots; ++i) {
    const std::string name = "slot " + std::to_string(i);
    t.generations[i] = r.u32();
    if (t.generations[i] == 0 || t.generations[i] > 0xffffffu)
      corrupt(r.what() + ": " + name + " has generation " + std::to_string(t.generations[i]));
    if (flag(r, name + " live"))
      t.values[i] = read_value(name);
    else
      ++dead;
  }
  const uint32_t free_count = r.u32();
  if (free_count != dead)
    corrupt(r.what() + ": the free list has " + std::to_string(free_count) + " slots, but " +
            std::to_string(dead) + " slots are empty");
  std::vector<char> seen(slots, 0);
  t.free_list.resize(free_count);
  for (uint32_t& slot : t.free_list) {
    slot = r.u32();
    if (slot >= slots || t.values[slot] || seen[slot])
      corrupt(r.what() + ": the free list names slot " + std::to_string(slot) +
              ", which is not a distinct empty slot");
    seen[slot] = 1;
  }
  return t;
}

// Runs one of the scene's rules (scene_build.h, pose_rules.h: the same the world's entry
// points apply to callers) on what the file holds; a violation is corrupt data, named by slot.
template <class Check>
auto by_scene_rules(ByteReader& r, const std::string& name, Check&& check) -> decltype(check()) {
  try {
    return with_field_prefix(name + " ", std::forward<Check>(check));
  } catch (const Error& e) {
    corrupt(r.what() + ": " + e.what());
  }
}

Collider read_collider(ByteReader& r, const Assets& assets, const std::string& name) {
  ColliderSpec spec;
  spec.sdf = asset_ref(r, assets, name + " SDF");
  spec.pose = raw_pose(r);
  std::optional<RigidTransform> target;
  if (flag(r, name + " has target")) target = raw_pose(r);
  spec.material.restitution = r.f32();
  spec.material.friction = r.f32();
  spec.material.stickiness = r.f32();
  spec.inverted = flag(r, name + " inverted") != 0;
  Collider c = by_scene_rules(r, name, [&] { return make_collider(spec); });
  if (target) by_scene_rules(r, name, [&] { require_pose(*target, "target"); });
  c.target = target;
  return c;
}

Source read_source(ByteReader& r, const Assets& assets, const WorldConfig& config, const std::string& name) {
  SourceSpec spec;
  spec.region = asset_ref(r, assets, name + " region");
  spec.pose = raw_pose(r);
  spec.mode = static_cast<SourceMode>(below(r, 2, name + " mode"));
  spec.spacing = r.f32();
  spec.min_distance = r.f32();
  spec.velocity = raw_vec3(r);
  spec.velocity_from_field = flag(r, name + " velocity from field") != 0;
  spec.rate = r.f32();
  // Stored values are resolved: a zero here would be read as "the default" by the rules.
  if (spec.spacing == 0.0f || spec.min_distance == 0.0f)
    corrupt(r.what() + ": " + name + " spacing or min distance is 0 (never written)");
  Source s = by_scene_rules(r, name, [&] { return make_source(spec, config); });
  s.rate_budget = r.f64();
  // A budget grows by at most rate x frame time per step; far below the size_t range.
  if (!std::isfinite(s.rate_budget) || s.rate_budget < 0.0 || s.rate_budget > 1e15)
    corrupt(r.what() + ": " + name + " rate budget is outside [0, 1e15]");
  s.done = flag(r, name + " done") != 0;
  const uint32_t points = r.u32();
  r.need_elements(points, 3 * sizeof(float), "lattice points");
  s.lattice.resize(points);
  const std::string where = name + " lattice point";
  for (uint32_t i = 0; i < points; ++i) s.lattice[i] = bulk_vec3(r, where.c_str(), i);
  return s;
}

Sink read_sink(ByteReader& r, const Assets& assets, const std::string& name) {
  SinkSpec spec;
  spec.mode = static_cast<SinkMode>(below(r, 2, name + " mode"));
  spec.region = asset_ref(r, assets, name + " region");
  spec.pose = raw_pose(r);
  spec.bounds_min = raw_vec3(r);
  spec.bounds_max = raw_vec3(r);
  return by_scene_rules(r, name, [&] { return make_sink(spec); });
}

ForceField read_force_field(ByteReader& r, const Assets& assets, const std::string& name) {
  ForceFieldSpec spec;
  spec.kind = static_cast<ForceFieldKind>(below(r, 4, name + " kind"));
  spec.region = asset_ref(r, assets, name + " region");
  spec.grid = asset_ref(r, assets, name + " grid");
  spec.pose = raw_pose(r);
  spec.vector = raw_vec3(r);
  spec.strength = r.f32();
  spec.falloff_radius = r.f32();
  return by_scene_rules(r, name, [&] { return make_force_field(spec); });
}

}  // namespace

std::unique_ptr<World> read_checkpoint(const uint8_t* data, size_t size, const BackendMaker& make_backend) {
  // Header: magic and version first (a later version may lay out the rest differently), then
  // the sizes, then the checksum over everything.
  if (size < kHeaderSize)
    corrupt("truncated: " + std::to_string(size) + " bytes, shorter than the " + std::to_string(kHeaderSize) +
            "-byte header");
  if (std::memcmp(data, kMagic, sizeof kMagic) != 0) corrupt("not a checkpoint (wrong magic bytes)");
  ByteReader h(data + sizeof kMagic, kHeaderSize - sizeof kMagic, "header");
  const uint32_t version = h.u32();
  if (version < kOldestReadableVersion || version > kFormatVersion)
    throw Error(Status::VersionMismatch,
                "checkpoint: format version " + std::to_string(version) + "; this library reads versions " +
                    std::to_string(kOldestReadableVersion) + " to " + std::to_string(kFormatVersion));
  const uint32_t flags = h.u32();
  h.u32();  // writer backend: informational
  h.u32();  // writer library version: informational
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
  if (flags != 0) corrupt("unknown flags " + hex32(flags));
  if (reserved != 0) corrupt("a reserved header field is not 0");
  if (section_count != kSectionCount)
    corrupt(std::to_string(section_count) + " sections; version " + std::to_string(version) + " has " +
            std::to_string(kSectionCount));

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
  const WorldConfig config = read_config(conf);
  conf.expect_end();
  ByteReader parm = next_section(1);
  const RuntimeParams params = version == 1 ? read_params_v1(parm, config) : read_params(parm, config);
  parm.expect_end();
  // A dt_min above the stability ceiling is accepted, as sph_world_set_params accepts it (the
  // caller's fixed step wins over the ceiling; a step that then fails says so and rolls back).
  ByteReader time = next_section(2);
  const Clock clock = read_clock(time);
  time.expect_end();
  ByteReader part = next_section(3);
  ParticleSnapshot particles = read_particles(part, config, clock.next_id);
  if (config.features & kFeatureSprings) read_springs(part, config, clock.next_id, particles);
  part.expect_end();

  ByteReader sdfa = next_section(4);
  const uint32_t asset_count = sdfa.u32();
  sdfa.need_elements(asset_count, 16 + 12 * sizeof(float) + sizeof(float), "assets");
  Assets assets;
  for (uint32_t k = 0; k < asset_count; ++k) assets.push_back(read_asset(sdfa, k));
  sdfa.expect_end();

  ByteReader coll = next_section(5);
  auto colliders = read_slots<Collider>(
      coll, [&](const std::string& n) { return read_collider(coll, assets, "collider " + n); });
  coll.expect_end();
  ByteReader srce = next_section(6);
  auto sources = read_slots<Source>(
      srce, [&](const std::string& n) { return read_source(srce, assets, config, "source " + n); });
  srce.expect_end();
  ByteReader sink = next_section(7);
  auto sinks =
      read_slots<Sink>(sink, [&](const std::string& n) { return read_sink(sink, assets, "sink " + n); });
  sink.expect_end();
  ByteReader ffld = next_section(8);
  auto fields = read_slots<ForceField>(
      ffld, [&](const std::string& n) { return read_force_field(ffld, assets, "force field " + n); });
  ffld.expect_end();
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
  return world;
}

}  // namespace sph
