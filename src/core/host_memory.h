// SPDX-License-Identifier: MIT
// Where a context's worlds take their memory: the engine's allocator hooks when it gave them
// (sph_context_def.alloc_fn/free_fn for the host, sph_cuda.h's device allocator for the GPU),
// the system heap otherwise. The hooks live in the context, which outlives its worlds and SDF
// assets. The C layer makes them current on the calling thread for the length of each call on
// a world or context (MemoryScope); a container or device array takes the current hooks when it
// is made and keeps them, so it frees through them on whatever thread it dies.
#pragma once

#include <stddef.h>
#include <stdint.h>

#include <limits>
#include <new>
#include <type_traits>
#include <vector>

namespace sph {

struct HostMemoryHooks {
  void* (*alloc)(size_t size, size_t alignment, void* user_context) = nullptr;  // null: the heap
  void (*free)(void* memory, size_t size, void* user_context) = nullptr;
  void* user_context = nullptr;
};

struct DeviceMemoryHooks {
  void* (*alloc)(size_t size, int32_t device_ordinal, void* user_context) = nullptr;  // null: cudaMalloc
  void (*free)(void* memory, size_t size, int32_t device_ordinal, void* user_context) = nullptr;
  void* user_context = nullptr;
};

struct MemoryHooks {
  HostMemoryHooks host;
  DeviceMemoryHooks device;
};

// The hooks of the call this thread is in (null: none, the system heap and cudaMalloc).
const MemoryHooks* current_memory_hooks() noexcept;

// Makes `hooks` current on this thread until the scope ends (scopes nest).
class MemoryScope {
 public:
  explicit MemoryScope(const MemoryHooks* hooks) noexcept;
  ~MemoryScope();
  MemoryScope(const MemoryScope&) = delete;
  MemoryScope& operator=(const MemoryScope&) = delete;

 private:
  const MemoryHooks* previous_;
};

// Host memory from `hooks` (the heap when null or without a host allocator), aligned to
// `alignment` (a power of two). Throws std::bad_alloc when the allocator gives nothing.
void* host_allocate(const MemoryHooks* hooks, size_t bytes, size_t alignment);
void host_free(const MemoryHooks* hooks, void* memory, size_t bytes, size_t alignment) noexcept;

// A standard allocator over host_allocate, bound to the hooks current when it was made.
// Containers of a world's data use it (HostVector), so their memory comes from the engine's
// allocator when it gave one.
template <class T>
class HostAllocator {
 public:
  using value_type = T;
  using propagate_on_container_move_assignment = std::true_type;
  using propagate_on_container_swap = std::true_type;

  HostAllocator() noexcept : hooks_(current_memory_hooks()) {}
  explicit HostAllocator(const MemoryHooks* hooks) noexcept : hooks_(hooks) {}
  template <class U>
  HostAllocator(const HostAllocator<U>& other) noexcept : hooks_(other.hooks()) {}

  T* allocate(size_t n) {
    if (n > std::numeric_limits<size_t>::max() / sizeof(T)) throw std::bad_alloc();
    return static_cast<T*>(host_allocate(hooks_, n * sizeof(T), kAlignment));
  }
  void deallocate(T* p, size_t n) noexcept { host_free(hooks_, p, n * sizeof(T), kAlignment); }

  const MemoryHooks* hooks() const noexcept { return hooks_; }
  template <class U>
  bool operator==(const HostAllocator<U>& other) const noexcept {
    return hooks_ == other.hooks();
  }
  template <class U>
  bool operator!=(const HostAllocator<U>& other) const noexcept {
    return hooks_ != other.hooks();
  }

 private:
  // 16 bytes at least: the particle arrays hold float4 records (what the heap gives too).
  static constexpr size_t kAlignment = alignof(T) > 16 ? alignof(T) : 16;
  const MemoryHooks* hooks_;
};

// The container of a world's data.
template <class T>
using HostVector = std::vector<T, HostAllocator<T>>;

}  // namespace sph
