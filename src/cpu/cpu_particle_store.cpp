// SPDX-License-Identifier: MIT
#include "cpu_particle_store.h"

#include <algorithm>
#include <cstring>
#include <string>

#include "../core/status.h"

namespace sph {
namespace {

// new[i] = old[order[i]] for i in [first, last), elements of `size` bytes, `per` per particle.
template <size_t kSize>
void gather_fixed(unsigned char* out, const unsigned char* in, const uint32_t* order, size_t first,
                  size_t last, size_t per) {
  struct Element {
    unsigned char b[kSize];
  };
  Element* o = reinterpret_cast<Element*>(out);
  const Element* s = reinterpret_cast<const Element*>(in);
  for (size_t i = first; i < last; ++i)
    for (size_t k = 0; k < per; ++k) o[i * per + k] = s[static_cast<size_t>(order[i]) * per + k];
}

void gather(unsigned char* out, const unsigned char* in, const uint32_t* order, size_t first, size_t last,
            size_t per, size_t size) {
  switch (size) {
    case 4:
      return gather_fixed<4>(out, in, order, first, last, per);
    case 16:
      return gather_fixed<16>(out, in, order, first, last, per);
    case 24:
      return gather_fixed<24>(out, in, order, first, last, per);
    default: {
      const size_t stride = per * size;
      for (size_t i = first; i < last; ++i) std::memcpy(out + i * stride, in + order[i] * stride, stride);
    }
  }
}

// Particles per share of the reorder: 4096 records are 16-64 KiB of each array.
constexpr size_t kPermuteBlock = 4096;

bool reordered(const CpuParticleArray& a) {
  return a.spec.role != ParticleArrayRole::Scratch && a.spec.elements_per_particle != 0;
}

}  // namespace

CpuParticleArray& CpuParticleStore::add(const ParticleArraySpec& spec) {
  if (CpuParticleArray* existing = find(spec.name)) {
    if (existing->spec.element_size != spec.element_size ||
        existing->spec.elements_per_particle != spec.elements_per_particle)
      throw Error(Status::Internal,
                  std::string("particle store: ") + spec.name + " registered with two sizes");
    if (spec.role > existing->spec.role) existing->spec.role = spec.role;
    return *existing;
  }
  auto a = std::make_unique<CpuParticleArray>();
  a->spec = spec;
  if (spec.elements_per_particle == 0) {  // a world word: one element, from its initial value
    a->bytes.resize(spec.element_size, 0);
    if (spec.initial) std::memcpy(a->bytes.data(), spec.initial, spec.element_size);
  } else {
    a->bytes.resize(a->elements(particles_) * spec.element_size, 0);
  }
  arrays_.push_back(std::move(a));
  CpuParticleArray& added = *arrays_.back();
  if (spec.elements_per_particle != 0 && spec.initial)
    for (size_t e = 0; e < added.elements(particles_); ++e)
      std::memcpy(added.bytes.data() + e * spec.element_size, spec.initial, spec.element_size);
  return added;
}

CpuParticleArray* CpuParticleStore::find(const char* name) const {
  for (const auto& a : arrays_)
    if (std::strcmp(a->spec.name, name) == 0) return a.get();
  return nullptr;
}

void CpuParticleStore::check_element_size(const CpuParticleArray& a, size_t size) {
  if (a.spec.element_size != size)
    throw Error(Status::Internal, std::string("particle store: ") + a.spec.name + " has elements of " +
                                      std::to_string(a.spec.element_size) + " bytes, not " +
                                      std::to_string(size));
}

void CpuParticleStore::resize(size_t n) {
  for (auto& a : arrays_) {
    if (a->spec.elements_per_particle == 0) continue;
    const size_t size = a->spec.element_size;
    const size_t old_elements = a->bytes.size() / size;
    a->bytes.resize(a->elements(n) * size, 0);
    if (a->spec.initial)
      for (size_t e = old_elements; e < a->elements(n); ++e)
        std::memcpy(a->bytes.data() + e * size, a->spec.initial, size);
  }
  particles_ = n;
}

// The workers share the particles in blocks, and each gathers its block of every array (the old
// elements were swapped into scratch first, so data() is the new order throughout) and then hands
// the block to after_block. The inverse order, which a rewritten index may look up anywhere, is
// complete before any block is gathered (its own loop, when some array rewrites indices).
void CpuParticleStore::permute(const uint32_t* order, size_t n, const CpuParallel& parallel,
                               const BlockHook& after_block) {
  bool rewrites = false;
  for (auto& a : arrays_) {
    if (!reordered(*a)) continue;
    a->scratch.resize(a->bytes.size());  // (allocations before the parallel loops, which must not throw)
    a->bytes.swap(a->scratch);
    rewrites = rewrites || a->spec.rewrite_indices != nullptr;
  }
  if (rewrites) {
    inverse_.assign(particles_, 0xffffffffu);
    uint32_t* inverse = inverse_.data();
    parallel.for_blocks(n, kPermuteBlock, [&](size_t first, size_t last) {
      for (size_t i = first; i < last; ++i) inverse[order[i]] = static_cast<uint32_t>(i);
    });
  }
  parallel.for_blocks(n, kPermuteBlock, [&](size_t first, size_t last) {
    for (auto& a : arrays_) {
      if (!reordered(*a)) continue;
      const size_t size = a->spec.element_size;
      const size_t per = a->spec.elements_per_particle;
      gather(a->bytes.data(), a->scratch.data(), order, first, last, per, size);
      if (a->spec.rewrite_indices)
        for (size_t e = first * per; e < last * per; ++e)
          a->spec.rewrite_indices(a->bytes.data() + e * size, inverse_.data());
    }
    if (after_block) after_block(first, last);
  });
}

HostVector<HostVector<unsigned char>> CpuParticleStore::snapshot() const {
  HostVector<HostVector<unsigned char>> copy;
  for (const auto& a : arrays_)
    if (a->spec.role == ParticleArrayRole::Carried) copy.push_back(a->bytes);
  return copy;
}

void CpuParticleStore::restore(const HostVector<HostVector<unsigned char>>& copy) {
  size_t k = 0;
  for (auto& a : arrays_) {
    if (a->spec.role != ParticleArrayRole::Carried) continue;
    a->bytes.assign(copy[k].begin(), copy[k].end());
    ++k;
  }
}

size_t CpuParticleStore::bytes() const {
  size_t total = 0;
  for (const auto& a : arrays_) total += a->bytes.capacity() + a->scratch.capacity();
  return total + inverse_.capacity() * sizeof(uint32_t);
}

}  // namespace sph
