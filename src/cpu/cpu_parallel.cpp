// SPDX-License-Identifier: MIT
#include "cpu_parallel.h"

namespace sph {

// The blocks go to the engine's task system as its items (at least one a range), or to OpenMP's
// workers one at a time. Either way each block runs with the calling thread's memory hooks
// current, so what a block allocates comes from the world's allocator too.
void CpuParallel::run_blocks(size_t blocks, BlockFn run, void* context) const {
  struct Task {
    BlockFn run;
    void* context;
    const MemoryHooks* memory;
  } task{run, context, current_memory_hooks()};
  if (tasks_) {
    const TaskFn entry = [](uint32_t first, uint32_t last, uint32_t, void* task_context) {
      const Task& t = *static_cast<const Task*>(task_context);
      const MemoryScope scope(t.memory);
      t.run(first, last, t.context);
    };
    void* handle = tasks_.enqueue(entry, static_cast<uint32_t>(blocks), 1, &task, tasks_.user_context);
    if (handle) tasks_.finish(handle, tasks_.user_context);
    return;
  }
  const long count = static_cast<long>(blocks);
#pragma omp parallel for num_threads(workers_) schedule(dynamic, 1)
  for (long b = 0; b < count; ++b) {
    const MemoryScope scope(task.memory);
    task.run(static_cast<size_t>(b), static_cast<size_t>(b) + 1, task.context);
  }
}

}  // namespace sph
