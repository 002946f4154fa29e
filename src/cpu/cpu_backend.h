// SPDX-License-Identifier: MIT
// Entry point of the CPU backend, seen by the backend factory (src/factory) only.
#pragma once

#include <memory>

#include "../core/backend.h"
#include "../core/task_system.h"

namespace sph {

// A CPU backend running its loops on worker_count OpenMP threads (0 means 1), or through the
// engine's task system when `tasks` has one (then it starts no thread).
std::unique_ptr<Backend> make_cpu_backend(const WorldConfig& config, unsigned worker_count,
                                          const TaskSystem& tasks = {});

}  // namespace sph
