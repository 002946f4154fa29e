// The interface the core drives a backend through. A backend owns the particle state (host
// arrays on the CPU, device arrays on CUDA) and runs whole frames; the core validates input,
// assigns ids and keeps parameters.
#pragma once

#include <stddef.h>
#include <stdint.h>

#include <memory>

#include "../physics/vec3.h"
#include "config.h"
#include "frame_report.h"

namespace sph {

enum class AttributeKind : uint32_t { Position = 0, Velocity = 1, Density = 2, Pressure = 3, Id = 4 };

class Backend {
 public:
  virtual ~Backend() = default;

  virtual uint32_t particle_count() const = 0;

  // Appends n particles (velocities may be null = zero) with ids first_id, first_id + 1, ...
  // The caller has checked capacity and finiteness. All-or-nothing: throws on failure and
  // leaves the particles as they were.
  virtual void append(const Vec3* positions, const Vec3* velocities, uint32_t n, uint32_t first_id) = 0;

  // Runs adaptive substeps until frame_dt is reached or params.max_substeps is spent. On a
  // non-finite state it restores the particles as they were before the call and throws
  // Error(Status::NonFinite).
  virtual FrameReport step_frame(double frame_dt, const RuntimeParams& params) = 0;

  // Writes particles [first, first + count) of one attribute to dst with a byte stride, as
  // float32 x3 (position, velocity), float32 (density, pressure) or uint32 (id).
  virtual void copy_attribute(AttributeKind kind, uint32_t first, uint32_t count, void* dst,
                              size_t stride) const = 0;

  // Bytes held for particles and grids (device bytes on a GPU backend).
  virtual uint64_t memory_bytes() const = 0;
};

std::unique_ptr<Backend> make_cpu_backend(const WorldConfig& config, unsigned worker_count);

}  // namespace sph
