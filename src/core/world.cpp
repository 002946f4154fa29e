#include "world.h"

#include <chrono>
#include <string>

#include "status.h"

namespace sph {

World::World(const WorldConfig& config, std::unique_ptr<Backend> backend)
    : config_(config), backend_(std::move(backend)) {}

uint32_t World::spawn(const std::vector<Vec3>& positions, const std::vector<Vec3>* velocities) {
  const uint64_t n = positions.size();
  if (n > free_capacity())
    throw Error(Status::Capacity, "spawn: " + std::to_string(n) + " particles do not fit; the world holds " +
                                      std::to_string(particle_count()) + " of its capacity " +
                                      std::to_string(config_.capacity));
  if (static_cast<uint64_t>(next_id_) + n > UINT32_MAX)
    throw Error(Status::Capacity, "spawn: the world has used up its 2^32 particle ids");
  const uint32_t first = next_id_;
  if (n == 0) return first;
  backend_->append(positions.data(), velocities ? velocities->data() : nullptr, static_cast<uint32_t>(n),
                   first);
  next_id_ += static_cast<uint32_t>(n);
  return first;
}

bool World::step(double frame_dt) {
  const auto start = std::chrono::steady_clock::now();
  FrameReport report = backend_->step_frame(frame_dt, params_);
  report_ = report;
  simulated_time_ += report.time_advanced;
  last_step_ms_ = static_cast<float>(
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  return report.completed;
}

}  // namespace sph
