// SPDX-License-Identifier: MIT
// The CPU backend's per-particle arrays, each allocated from a registration
// (src/core/particle_arrays.h: name, element size, role) and given its role's bookkeeping: after
// the neighbour sort or a sink's removal, permute() reorders every Sorted and Carried array in
// one pass (rewriting stored indices where the record says so); the rollback snapshot copies the
// Carried ones. So a method that adds an array never has to remember to sort, snapshot or resize
// it. The twin of cuda/device_particle_store.h.
#pragma once

#include <stddef.h>
#include <stdint.h>

#include <functional>
#include <memory>
#include <vector>

#include "../core/particle_arrays.h"
#include "cpu_parallel.h"

namespace sph {

// One registered array: raw elements (16-byte aligned storage), element_size bytes each.
struct CpuParticleArray {
  ParticleArraySpec spec;
  HostVector<unsigned char> bytes;
  HostVector<unsigned char> scratch;  // the reorder's target, swapped in

  size_t elements(size_t particles) const {
    return spec.elements_per_particle == 0 ? 1 : particles * spec.elements_per_particle;
  }
};

// Typed access to one array of the store; null when the array is not registered. Pointers from
// data() stay valid until the store resizes, permutes or restores.
template <class T>
class CpuArrayRef {
 public:
  CpuArrayRef() = default;
  explicit CpuArrayRef(CpuParticleArray* array) : array_(array) {}
  explicit operator bool() const { return array_ != nullptr; }
  T* data() const { return array_ ? reinterpret_cast<T*>(array_->bytes.data()) : nullptr; }
  T& operator[](size_t i) const { return data()[i]; }
  CpuParticleArray* array() const { return array_; }

 private:
  CpuParticleArray* array_ = nullptr;
};

class CpuParticleStore {
 public:
  // Registers an array and returns it. A name registered again is the same array, with the
  // larger of the two roles (two methods may share one: the neighbour counts, say).
  CpuParticleArray& add(const ParticleArraySpec& spec);
  CpuParticleArray* find(const char* name) const;

  template <class T>
  CpuArrayRef<T> add_typed(const ParticleArraySpec& spec) {
    CpuParticleArray& a = add(spec);
    check_element_size(a, sizeof(T));
    return CpuArrayRef<T>(&a);
  }
  template <class T>
  CpuArrayRef<T> find_typed(const char* name) const {
    CpuParticleArray* a = find(name);
    if (a) check_element_size(*a, sizeof(T));
    return CpuArrayRef<T>(a);
  }

  // Every per-particle array to n particles; new elements start as their record's initial value.
  void resize(size_t n);
  // Sorted and Carried arrays: new[i] = old[order[i]] for i < n (the rest is dropped by the
  // next resize); elements with stored indices rewrite them to the new order. Runs on
  // `parallel`'s workers; the result does not depend on their number. after_block(first, last), when
  // given, runs on the worker that has just reordered particles [first, last) of every array (it
  // may read them through data(), and must not throw), so a copy of the new order needs no
  // pass, and no meeting of the workers, of its own.
  using BlockHook = std::function<void(size_t first, size_t last)>;
  void permute(const uint32_t* order, size_t n, const CpuParallel& parallel = {},
               const BlockHook& after_block = {});
  // Swaps the elements of two arrays of one size (the integration's double buffer).
  void swap_contents(CpuParticleArray& a, CpuParticleArray& b) { a.bytes.swap(b.bytes); }

  // Copies of the Carried arrays, to roll a failed frame back; restore() copies them back (the
  // arrays keep their capacity, so a restore does not allocate).
  HostVector<HostVector<unsigned char>> snapshot() const;
  void restore(const HostVector<HostVector<unsigned char>>& copy);

  const std::vector<std::unique_ptr<CpuParticleArray>>& arrays() const { return arrays_; }
  size_t particles() const { return particles_; }
  size_t bytes() const;

 private:
  static void check_element_size(const CpuParticleArray& a, size_t size);

  std::vector<std::unique_ptr<CpuParticleArray>> arrays_;
  HostVector<uint32_t> inverse_;  // new index of each old one, for the index rewrite
  size_t particles_ = 0;
};

}  // namespace sph
