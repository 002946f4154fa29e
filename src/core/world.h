// A simulation world: its fixed configuration, runtime parameters, particle ids and time,
// and the backend that holds and steps the particles.
#pragma once

#include <stdint.h>

#include <memory>
#include <vector>

#include "backend.h"
#include "config.h"
#include "frame_report.h"

namespace sph {

class World {
 public:
  World(const WorldConfig& config, std::unique_ptr<Backend> backend);

  const WorldConfig& config() const { return config_; }
  const RuntimeParams& params() const { return params_; }
  void set_params(const RuntimeParams& params) { params_ = params; }

  uint32_t particle_count() const { return backend_->particle_count(); }
  uint32_t free_capacity() const { return config_.capacity - particle_count(); }

  // Adds particles; throws Error(Capacity) if they do not fit. Returns the first new id.
  uint32_t spawn(const std::vector<Vec3>& positions, const std::vector<Vec3>* velocities);

  // Runs one frame; returns false when max_substeps ran out before frame_dt.
  bool step(double frame_dt);

  const FrameReport& last_report() const { return report_; }
  double simulated_time() const { return simulated_time_; }
  float last_step_ms() const { return last_step_ms_; }

  const Backend& backend() const { return *backend_; }

 private:
  WorldConfig config_;
  RuntimeParams params_;
  std::unique_ptr<Backend> backend_;
  uint32_t next_id_ = 0;
  double simulated_time_ = 0.0;
  FrameReport report_;
  float last_step_ms_ = 0.0f;
};

}  // namespace sph
