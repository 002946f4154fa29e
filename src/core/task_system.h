// SPDX-License-Identifier: MIT
// The engine's task system, when it gives one (sph_context_def's enqueue_task / finish_task, the
// shape of Box2D v3's b2EnqueueTaskCallback / b2FinishTaskCallback): the CPU backend hands its
// parallel loops to it instead of starting threads of its own, and the C layer runs each
// asynchronous step as one task of it (capi/async_stepper.h), whose loops are then tasks
// enqueued from inside a task. The C layer checks the pair and passes it down unchanged; the
// types are the public ones (the C layer asserts they match).
#pragma once

#include <stdint.h>

namespace sph {

// Runs items [first, last) of a task; `worker` is the task system's worker index (unused here).
using TaskFn = void (*)(uint32_t first, uint32_t last, uint32_t worker, void* task_context);
// Schedules task over items [0, item_count) in ranges of at least min_range items, and returns a
// handle for finish, or null when it has already run every item on the calling thread.
using EnqueueTaskFn = void* (*)(TaskFn task, uint32_t item_count, uint32_t min_range, void* task_context,
                                void* user_context);
// Returns once every item of the task behind `user_task` has run.
using FinishTaskFn = void (*)(void* user_task, void* user_context);

struct TaskSystem {
  EnqueueTaskFn enqueue = nullptr;  // null: the CPU backend uses its OpenMP workers
  FinishTaskFn finish = nullptr;
  void* user_context = nullptr;

  explicit operator bool() const { return enqueue != nullptr; }
};

}  // namespace sph
