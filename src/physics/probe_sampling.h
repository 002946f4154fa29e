// SPDX-License-Identifier: MIT
// Probes and gauges: the fluid's density, pressure and velocity at user points, and the water
// height along user lines, from the SPH interpolant over the particles of a substep's density
// pass (docs/physics.md "Probes and gauges"). Written once for both backends.
//
// At a point x, with V_j = m / rho_j:
//   kernel sum  S(x) = sum_j V_j W(|x - x_j|)        (the fluid fraction: ~1 inside, 0 in air)
//   field       A(x) = sum_j V_j A_j W(|x - x_j|) / S(x)   (Shepard-normalised, A = rho, p, v)
// The density needs no division by rho_j: sum_j V_j rho_j W = sum_j m W. A gauge is a line of
// points x_k = origin + (k + 1/2) step, k < count; its water height is the column integral of the
// mass interpolant over the rest density by the midpoint rule, H = sum_k sum_j m W(x_k) |step| /
// rho0: the mass per unit area the line passes through, as the height it stands at rest density.
// A line that starts below the floor (inside a wall, where no particle is) and ends above the
// surface reads the depth. m / rho0 rather than V_j = m / rho_j: the particles of a free surface
// read a density deficit (their kernels reach into air), so V_j overstates their volume; a block
// of 10 layers read +5.5 % with V_j and within the quadrature's error with m / rho0
// (tests/physics_options/test_probes.c). Its density, pressure and velocity are the Shepard means
// over the whole line: sum_k sum_j V_j A_j W / sum_k S(x_k).
//
// W is W_poly6 at the world's kernel radius, not the density's lattice-scaled W_spiky: the
// interpolant then is a plain normalised kernel (S -> 1 in the bulk), and poly6 is the smoothest
// kernel of the library. On the FCC lattice at h = 1.8 spacings, at random points, S has a
// standard deviation of 0.5 % about 1 with poly6 against 2.5 % with W_spiky (max 1.1 %, 10.7 %),
// and a column integral 0.13 % against 0.9 % (numpy, the lattice of fcc_lattice.h).
#pragma once

#include <stdint.h>

#include "float4_types.h"
#include "host_device.h"
#include "kernels.h"
#include "neighbor_walk.h"
#include "vec3.h"

namespace sph {

struct ProbeSampling {
  static constexpr const char* kName = "probes";
};

// Samples along a gauge at most (the C layer refuses more).
constexpr uint32_t kMaxGaugeSamples = 65536;
// Sample points of all a world's probes together at most (a point probe has one, a gauge its
// samples): 2^22, 96 MiB of a frame's gathers. Without it 65536 gauges of 65536 samples (each
// within its own bound) counted 2^32 points, which wrapped the frame's 32-bit point indices.
constexpr uint32_t kMaxProbePoints = 1u << 22;

// One probe in a frame, as both backends see it.
struct ProbeView {
  Vec3 origin;           // POINT: the point; GAUGE: the line's start
  Vec3 step;             // GAUGE: from one sample to the next (zero for a point)
  uint32_t first_point;  // index of its first sample point in the frame's list of points
  uint32_t point_count;  // 1 for a point
  uint32_t gauge;        // 1: a gauge (the water height is computed)
  uint32_t every_substep;
};

// The constants of a frame's sampling.
struct ProbeConstants {
  KernelCoefficients kernel;  // make_kernel_coefficients(h): unscaled poly6
  float particle_mass;
  float rest_density;
};

// The sums of one sample point (or of a gauge's points).
struct ProbeGather {
  float kernel_sum;    // sum_j V_j W
  float mass_sum;      // sum_j m W  (= sum_j V_j rho_j W)
  float pressure_sum;  // sum_j V_j p_j W
  Vec3 velocity_sum;   // sum_j V_j v_j W
};

SPH_HD ProbeGather zero_probe_gather() { return ProbeGather{0.0f, 0.0f, 0.0f, Vec3{0.0f, 0.0f, 0.0f}}; }

SPH_HD ProbeGather operator+(const ProbeGather& a, const ProbeGather& b) {
  return ProbeGather{a.kernel_sum + b.kernel_sum, a.mass_sum + b.mass_sum, a.pressure_sum + b.pressure_sum,
                     a.velocity_sum + b.velocity_sum};
}

// Sample point k of a probe.
SPH_HD Vec3 probe_point(const ProbeView& p, uint32_t k) {
  return p.origin + p.step * (static_cast<float>(k) + (p.gauge ? 0.5f : 0.0f));
}

// The interpolant's sums at x over the sorted particles of a density pass: positions (w: the
// pressure) and velocities (w: 1 / rho), as both backends keep them after it.
SPH_HD ProbeGather gather_probe_point(const ProbeConstants& c, const GridView& grid, const Float4* positions,
                                      const Float4* velocities, Vec3 x) {
  ProbeGather g = zero_probe_gather();
  for_each_neighbor_candidate(grid, x, [&](uint32_t j) {
    const Float4 p = positions[j];
    const float r2 = length_squared(x - xyz(p));
    if (r2 < c.kernel.h2) {
      const float w = poly6(c.kernel, r2);
      const Float4 v = velocities[j];
      const float vw = c.particle_mass * v.w * w;  // V_j W
      g.kernel_sum += vw;
      g.mass_sum += c.particle_mass * w;
      g.pressure_sum += vw * p.w;
      g.velocity_sum += xyz(v) * vw;
    }
  });
  return g;
}

// What one sample of a probe reads.
struct ProbeSample {
  float kernel_sum;  // the fluid fraction (a gauge's: the mean over its points)
  float density;
  float pressure;
  Vec3 velocity;
  float water_height;  // gauges
};

// The sample from the sums of a probe's points (in point order); zero where no particle is near.
SPH_HD ProbeSample probe_sample(const ProbeConstants& c, const ProbeView& p, const ProbeGather& g) {
  ProbeSample s{0.0f, 0.0f, 0.0f, Vec3{0.0f, 0.0f, 0.0f}, 0.0f};
  const float count = static_cast<float>(p.point_count);
  s.kernel_sum = g.kernel_sum / count;
  if (p.gauge) s.water_height = g.mass_sum * length(p.step) / c.rest_density;
  if (g.kernel_sum > 0.0f) {
    const float inv = 1.0f / g.kernel_sum;
    s.density = g.mass_sum * inv;
    s.pressure = g.pressure_sum * inv;
    s.velocity = g.velocity_sum * inv;
  }
  return s;
}

// A probe's samples over a frame, in double: EVERY_SUBSTEP adds each substep's sample times its
// length, EVERY_FRAME keeps the last one. The reading is each sum over `time`.
struct ProbeSums {
  double time;  // s
  double kernel_sum;
  double density;
  double pressure;
  double velocity[3];
  double water_height;
  float pressure_max;
  uint32_t samples;
};

SPH_HD void add_probe_sample(ProbeSums& sums, const ProbeView& p, const ProbeSample& s, float dt) {
  const double w = static_cast<double>(dt);
  if (!p.every_substep || sums.samples == 0) {
    sums.time = 0.0;
    sums.kernel_sum = sums.density = sums.pressure = sums.water_height = 0.0;
    sums.velocity[0] = sums.velocity[1] = sums.velocity[2] = 0.0;
    sums.pressure_max = s.pressure;
    sums.samples = 0;
  }
  sums.time += w;
  sums.kernel_sum += w * s.kernel_sum;
  sums.density += w * s.density;
  sums.pressure += w * s.pressure;
  sums.velocity[0] += w * s.velocity.x;
  sums.velocity[1] += w * s.velocity.y;
  sums.velocity[2] += w * s.velocity.z;
  sums.water_height += w * s.water_height;
  sums.pressure_max = s.pressure > sums.pressure_max ? s.pressure : sums.pressure_max;
  sums.samples += 1;
}

}  // namespace sph
