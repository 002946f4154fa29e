// SPDX-License-Identifier: MIT
// The replaced operator new of allocation_injector.h.
#include "allocation_injector.h"

#include <stdlib.h>

#include <atomic>
#include <cstddef>
#include <cstdlib>
#include <new>

// The replacements below pair malloc with free themselves; GCC cannot see that through
// inlining and warns that free() meets a pointer from operator new.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif
namespace {

std::atomic<long> g_countdown{-1};  // allocations to let through before one fails; -1 = off
std::atomic<long> g_injected{0};    // failures injected since the last arm()
// Each thread's own byte: its address names the thread (no allocation, unlike std::thread::id's
// uses, and nothing to construct on threads the injector never saw).
thread_local char t_thread_tag;
std::atomic<const char*> g_armed_by{nullptr};  // the thread that called arm()
std::atomic<bool> g_injected_elsewhere{false};

bool allocation_fault_due() {
  long left = g_countdown.load(std::memory_order_relaxed);
  while (left >= 0) {
    if (g_countdown.compare_exchange_weak(left, left - 1, std::memory_order_relaxed)) {
      if (left == 0) {
        g_injected.fetch_add(1, std::memory_order_relaxed);
        if (&t_thread_tag != g_armed_by.load(std::memory_order_relaxed)) g_injected_elsewhere.store(true);
        return true;
      }
      return false;
    }
  }
  return false;
}

}  // namespace

namespace alloc_fault {

void arm(long n) {
  g_injected.store(0);
  g_injected_elsewhere.store(false);
  g_armed_by.store(&t_thread_tag);
  g_countdown.store(n);
}

bool disarm() {
  g_countdown.store(-1);
  return g_injected.load() != 0;
}

bool injected_on_another_thread() { return g_injected_elsewhere.load(); }

}  // namespace alloc_fault

namespace {

void* checked_malloc(std::size_t size) { return std::malloc(size ? size : 1); }

void* checked_aligned(std::size_t size, std::align_val_t alignment) {
  const std::size_t a = static_cast<std::size_t>(alignment);
  void* p = nullptr;
  if (posix_memalign(&p, a < sizeof(void*) ? sizeof(void*) : a, size ? size : 1) != 0) return nullptr;
  return p;
}

}  // namespace

void* operator new(std::size_t size) {
  if (allocation_fault_due()) throw std::bad_alloc();
  void* p = checked_malloc(size);
  if (!p) throw std::bad_alloc();
  return p;
}
void* operator new[](std::size_t size) { return operator new(size); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  return allocation_fault_due() ? nullptr : checked_malloc(size);
}
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
  return allocation_fault_due() ? nullptr : checked_malloc(size);
}
void* operator new(std::size_t size, std::align_val_t alignment) {
  if (allocation_fault_due()) throw std::bad_alloc();
  void* p = checked_aligned(size, alignment);
  if (!p) throw std::bad_alloc();
  return p;
}
void* operator new[](std::size_t size, std::align_val_t alignment) { return operator new(size, alignment); }
void* operator new(std::size_t size, std::align_val_t alignment, const std::nothrow_t&) noexcept {
  return allocation_fault_due() ? nullptr : checked_aligned(size, alignment);
}
void* operator new[](std::size_t size, std::align_val_t alignment, const std::nothrow_t&) noexcept {
  return allocation_fault_due() ? nullptr : checked_aligned(size, alignment);
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
