// SPDX-License-Identifier: MIT
// The CPU backend's one way to run a loop in parallel: items in blocks of a fixed size, handed
// to OpenMP's workers on demand, or to the engine's task system when the context has one
// (core/task_system.h; then the library starts no thread). Every block's work depends on its
// items alone and reductions are kept per block and combined in block order, so results are
// the same bits on any number of workers and on either path. Blocks on demand, not a static
// split: on a machine where something else holds a core, the worker it keeps waiting holds up
// only its block (docs/performance.md).
#pragma once

#include <stddef.h>
#include <stdint.h>

#include "../core/host_memory.h"
#include "../core/task_system.h"

namespace sph {

// Below this many particles the CPU backend's loops run on the calling thread alone, where
// waking a team (or a task system) would cost more than the work.
constexpr uint32_t kParallelMinimum = 4096;

// The particles of one block of the per-particle loops: 1024 are about 0.1-0.3 ms of a
// gather, large against the cost of handing out a block. Results do not depend on it.
constexpr uint32_t kParticleChunk = 1024;

class CpuParallel {
 public:
  // `workers` 0 or 1: every loop on the calling thread.
  CpuParallel(unsigned workers = 1, const TaskSystem& tasks = {}) : workers_(workers), tasks_(tasks) {}

  unsigned workers() const { return workers_; }
  // The same, on the calling thread alone unless `items` reach kParallelMinimum.
  CpuParallel for_items(size_t items) const {
    return items >= kParallelMinimum ? *this : CpuParallel(1, tasks_);
  }

  // body(first, last) for the blocks [first, last) of `block` items that tile [0, items) (the
  // last one shorter). Blocks run concurrently: body must not throw and may write only what its
  // items own.
  template <class Body>
  void for_blocks(size_t items, size_t block, Body&& body) const {
    const size_t blocks = (items + block - 1) / block;
    if (blocks == 0) return;
    struct Loop {
      Body* body;
      size_t items, block;
    } loop{&body, items, block};
    const BlockFn run = [](size_t first_block, size_t last_block, void* context) {
      const Loop& l = *static_cast<const Loop*>(context);
      for (size_t b = first_block; b < last_block; ++b) {
        const size_t first = b * l.block;
        const size_t last = first + l.block < l.items ? first + l.block : l.items;
        (*l.body)(first, last);
      }
    };
    if (workers_ <= 1 || blocks == 1) return run(0, blocks, &loop);
    run_blocks(blocks, run, &loop);
  }

  // body(i) for every i in [0, n), in blocks of kParticleChunk.
  template <class Body>
  void for_each(uint32_t n, Body&& body) const {
    for_blocks(n, kParticleChunk, [&body](size_t first, size_t last) {
      for (size_t i = first; i < last; ++i) body(static_cast<uint32_t>(i));
    });
  }

  // body(i, acc) for every i in [0, n) into one T per block (from `identity`), then the blocks'
  // values combined in block order: the same result on any split.
  template <class T, class Body, class Combine>
  T reduce(uint32_t n, const T& identity, Body&& body, Combine&& combine) const {
    HostVector<T> partial((static_cast<size_t>(n) + kParticleChunk - 1) / kParticleChunk, identity);
    for_blocks(n, kParticleChunk, [&](size_t first, size_t last) {
      T acc = identity;
      for (size_t i = first; i < last; ++i) body(static_cast<uint32_t>(i), acc);
      partial[first / kParticleChunk] = acc;
    });
    T total = identity;
    for (const T& p : partial) total = combine(total, p);
    return total;
  }

 private:
  using BlockFn = void (*)(size_t first_block, size_t last_block, void* context);
  // The one parallel region of the CPU backend (cpu_parallel.cpp).
  void run_blocks(size_t blocks, BlockFn run, void* context) const;

  unsigned workers_;
  TaskSystem tasks_;
};

}  // namespace sph
