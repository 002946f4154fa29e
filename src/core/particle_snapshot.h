// SPDX-License-Identifier: MIT
// Everything a backend carries from one frame to the next, in storage order (the order of the
// last sort, which fixes the summation order of the next one): loading it into a fresh backend
// of the same kind continues bit for bit (checkpoints). The core state has fields; the methods'
// carried arrays (particle_arrays.h, role Carried) travel by name.
#pragma once

#include <stdint.h>

#include <cstring>
#include <string>
#include <vector>

#include "../physics/float4_types.h"
#include "host_memory.h"
#include "particle_arrays.h"

namespace sph {

// One carried array of a method: element_size bytes per element, in storage order (one element
// in all for a world word).
struct CarriedArray {
  std::string name;
  uint32_t element_size = 0;
  HostVector<unsigned char> bytes;
};

struct ParticleSnapshot {
  HostVector<Float4> position;  // w: pressure of the last density pass
  HostVector<Float4> velocity;  // w: 1 / density of the last density pass
  HostVector<uint32_t> id;
  HostVector<float> density;
  float max_speed = 0.0f;         // |v|max the next frame's first step is chosen from
  float max_acceleration = 0.0f;  // |a|max of the last force evaluation (the force step limit)
  HostVector<CarriedArray> carried;

  const CarriedArray* find(const char* name) const {
    for (const CarriedArray& a : carried)
      if (a.name == name) return &a;
    return nullptr;
  }
  // The elements of a carried array; empty when the snapshot has none of that name.
  template <class T>
  HostVector<T> carried_as(const char* name) const {
    const CarriedArray* a = find(name);
    HostVector<T> out;
    if (!a || a->element_size != sizeof(T)) return out;
    out.resize(a->bytes.size() / sizeof(T));
    if (!out.empty()) std::memcpy(out.data(), a->bytes.data(), out.size() * sizeof(T));
    return out;
  }
  template <class T, class Allocator>
  void set_carried(const char* name, const std::vector<T, Allocator>& values) {
    CarriedArray a;
    a.name = name;
    a.element_size = sizeof(T);
    a.bytes.resize(values.size() * sizeof(T));
    if (!values.empty()) std::memcpy(a.bytes.data(), values.data(), a.bytes.size());
    for (CarriedArray& existing : carried)
      if (existing.name == name) {
        existing = std::move(a);
        return;
      }
    carried.push_back(std::move(a));
  }
};

// Checks a snapshot of n particles against the carried arrays of a world (`specs`, the Carried
// ones count): every array it carries is one of them, with the right size. Throws Internal.
void check_carried_arrays(const ParticleSnapshot& s, const std::vector<ParticleArraySpec>& specs, uint32_t n);

// The bytes of a carried array for n particles from a checked snapshot; the record's initial
// value for every element when the snapshot has none (a checkpoint written before the method
// carried it starts its particles fresh).
HostVector<unsigned char> carried_bytes(const ParticleSnapshot& s, const ParticleArraySpec& spec, uint32_t n);

}  // namespace sph
