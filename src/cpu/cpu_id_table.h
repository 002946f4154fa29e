// SPDX-License-Identifier: MIT
// A rank's particle ids to their storage indices (cpu_halo_springs.cpp): open addressing with
// linear probing over at least twice as many slots as entries, so a lookup touches one or two
// cache lines where a binary search over the sorted ids touched fifteen (measured: the spring
// lists' translation took 46 ms a substep of 25,000 particles with binary searches).
#pragma once

#include <stdint.h>

#include "../core/host_memory.h"

namespace sph {

class CpuIdTable {
 public:
  static constexpr uint32_t kAbsent = 0xffffffffu;

  // Empties the table and sizes it for `entries` (allocates when it grows).
  void reset(uint32_t entries) {
    uint64_t slots = 16;
    shift_ = 60;
    while (slots < 2ull * entries) {
      slots *= 2;
      --shift_;
    }
    slots_.assign(slots, kEmpty);
    mask_ = slots - 1;
  }
  // Ids are unique (no id twice) and never 0xffffffff (no world issues it).
  void insert(uint32_t id, uint32_t index) {
    uint64_t s = slot_of(id);
    while (slots_[s] != kEmpty) s = (s + 1) & mask_;
    slots_[s] = (static_cast<uint64_t>(id) << 32) | index;
  }
  // The index of `id`, or kAbsent. Read-only: any number of threads may look up at once.
  uint32_t find(uint32_t id) const {
    for (uint64_t s = slot_of(id);; s = (s + 1) & mask_) {
      const uint64_t e = slots_[s];
      if (e == kEmpty) return kAbsent;
      if (static_cast<uint32_t>(e >> 32) == id) return static_cast<uint32_t>(e);
    }
  }

 private:
  static constexpr uint64_t kEmpty = ~0ull;  // (id 0xffffffff: never issued)
  // Fibonacci hashing: the product's top bits.
  uint64_t slot_of(uint32_t id) const { return static_cast<uint64_t>(id) * 0x9E3779B97F4A7C15ull >> shift_; }

  HostVector<uint64_t> slots_;
  uint64_t mask_ = 0;
  int shift_ = 60;
};

}  // namespace sph
