// SPDX-License-Identifier: MIT
#include "host_memory.h"

namespace sph {
namespace {
thread_local const MemoryHooks* t_current = nullptr;
}  // namespace

const MemoryHooks* current_memory_hooks() noexcept { return t_current; }

MemoryScope::MemoryScope(const MemoryHooks* hooks) noexcept : previous_(t_current) { t_current = hooks; }
MemoryScope::~MemoryScope() { t_current = previous_; }

void* host_allocate(const MemoryHooks* hooks, size_t bytes, size_t alignment) {
  if (hooks && hooks->host.alloc) {
    void* p = hooks->host.alloc(bytes, alignment, hooks->host.user_context);
    if (!p) throw std::bad_alloc();
    return p;
  }
  return ::operator new(bytes, std::align_val_t(alignment));
}

void host_free(const MemoryHooks* hooks, void* memory, size_t bytes, size_t alignment) noexcept {
  if (!memory) return;
  if (hooks && hooks->host.free) {
    hooks->host.free(memory, bytes, hooks->host.user_context);
    return;
  }
  ::operator delete(memory, std::align_val_t(alignment));
}

}  // namespace sph
