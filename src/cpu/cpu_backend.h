// SPDX-License-Identifier: MIT
// Entry point of the CPU backend, seen by the backend factory (src/factory) only.
#pragma once

#include <memory>

#include "../core/backend.h"

namespace sph {

// A CPU backend running its loops on worker_count threads (0 means 1).
std::unique_ptr<Backend> make_cpu_backend(const WorldConfig& config, unsigned worker_count);

}  // namespace sph
