// SPDX-License-Identifier: MIT
#include "rank_part_join.h"

#include <algorithm>
#include <cstring>
#include <string>

#include "../core/status.h"
#include "../physics/methods.h"

namespace sph {
namespace {

[[noreturn]] void corrupt(const std::string& message) {
  throw Error(Status::CorruptData, "manifest: the rank files are not parts of one save: " + message);
}

bool same_world(const WorldConfig& a, const WorldConfig& b) {
  return a.max_capacity == b.max_capacity && a.features == b.features && a.integrator == b.integrator &&
         a.viscosity_method == b.viscosity_method && a.equation_of_state == b.equation_of_state &&
         a.solver == b.solver && std::memcmp(&a.particle_spacing, &b.particle_spacing, sizeof(float)) == 0 &&
         std::memcmp(&a.kernel_radius, &b.kernel_radius, sizeof(float)) == 0 &&
         std::memcmp(&a.rest_density, &b.rest_density, sizeof(float)) == 0 &&
         std::memcmp(&a.particle_mass, &b.particle_mass, sizeof(float)) == 0;
}

// A carried array of one element per world, not per particle (springs' lowest waiting id).
bool world_word(const CarriedArray& a) { return a.name == kArraySpringLinkFrom; }

void drop_particles(ParticleSnapshot& s) {
  s.position.clear();
  s.velocity.clear();
  s.id.clear();
  s.density.clear();
  for (CarriedArray& a : s.carried)
    if (!world_word(a)) a.bytes.clear();
}

template <class T>
void append(HostVector<T>& to, const HostVector<T>& from) {
  to.insert(to.end(), from.begin(), from.end());
}

void add_sink_removals(HostVector<Event>& events, const Event& e) {
  for (Event& mine : events)
    if (mine.type == EventType::SinkRemoved && mine.object_id == e.object_id) {
      mine.count += e.count;
      return;
    }
  events.push_back(e);
}

}  // namespace

RankFileBlock rank_file_block(uint32_t saved, int rank, int ranks) {
  const uint64_t n = saved;
  return RankFileBlock{
      static_cast<uint32_t>(n * static_cast<uint64_t>(rank) / static_cast<uint64_t>(ranks)),
      static_cast<uint32_t>(n * static_cast<uint64_t>(rank + 1) / static_cast<uint64_t>(ranks))};
}

void join_rank_parts(CheckpointPart& into, bool keep_own, const std::vector<CheckpointPart>& others) {
  ParticleSnapshot& s = into.particles;
  if (!keep_own) {
    drop_particles(s);
    into.report.removed_ids.clear();
    into.events.erase(std::remove_if(into.events.begin(), into.events.end(),
                                     [](const Event& e) { return e.type == EventType::SinkRemoved; }),
                      into.events.end());
  }
  uint32_t capacity = into.config.capacity;
  for (const CheckpointPart& o : others) {
    if (!same_world(into.config, o.config)) corrupt("their worlds' settings differ");
    if (o.next_id != into.next_id ||
        std::memcmp(&o.simulated_time, &into.simulated_time, sizeof(double)) != 0)
      corrupt("their next ids or simulated times differ");
    const ParticleSnapshot& p = o.particles;
    if (p.carried.size() != s.carried.size()) corrupt("they carry different per-particle arrays");
    for (CarriedArray& a : s.carried) {
      const CarriedArray* b = p.find(a.name.c_str());
      if (world_word(a)) {
        // Springs' lowest waiting id: the smallest of the parts (the ranks reduce it again at the
        // next substep; spring lists name partners by id, so they join as they are).
        uint32_t mine = 0, theirs = 0;
        if (!b || a.bytes.size() != sizeof mine || b->bytes.size() != sizeof theirs)
          corrupt("they carry different per-world words ('" + a.name + "')");
        std::memcpy(&mine, a.bytes.data(), sizeof mine);
        std::memcpy(&theirs, b->bytes.data(), sizeof theirs);
        if (theirs < mine) std::memcpy(a.bytes.data(), &theirs, sizeof theirs);
        continue;
      }
      if (!b || b->element_size != a.element_size || b->bytes.size() != p.id.size() * b->element_size)
        corrupt("they carry different per-particle arrays ('" + a.name + "')");
      a.bytes.insert(a.bytes.end(), b->bytes.begin(), b->bytes.end());
    }
    append(s.position, p.position);
    append(s.velocity, p.velocity);
    append(s.id, p.id);
    append(s.density, p.density);
    // Every rank reduced them at the saved substep's end: equal, the largest kept all the same.
    s.max_speed = std::max(s.max_speed, p.max_speed);
    s.max_acceleration = std::max(s.max_acceleration, p.max_acceleration);
    append(into.report.removed_ids, o.report.removed_ids);
    for (const Event& e : o.events)
      if (e.type == EventType::SinkRemoved) add_sink_removals(into.events, e);
    capacity = std::max(capacity, o.config.capacity);
  }
  const size_t n = s.id.size();
  HostVector<uint32_t> sorted(s.id);
  std::sort(sorted.begin(), sorted.end());
  const auto dup = std::adjacent_find(sorted.begin(), sorted.end());
  if (dup != sorted.end()) corrupt("particle id " + std::to_string(*dup) + " is in two of them");
  if (n > into.config.max_capacity)
    throw Error(Status::Capacity,
                "capacity: this rank takes " + std::to_string(n) +
                    " particles of the saved ranks' files, past the world's max_capacity " +
                    std::to_string(into.config.max_capacity) +
                    " (per rank; load on more ranks, or save a world of a larger max_capacity)");
  into.config.capacity = std::max(capacity, static_cast<uint32_t>(n));
}

}  // namespace sph
