// SPDX-License-Identifier: MIT
#include "world_stats.h"

#include <algorithm>
#include <limits>

namespace sph_tools {

namespace {

enum Sum { kCount, kDensitySum, kNeighborSum, kMemory, kSums };
// Minima enter negated, so that one MPI_MAX reduces them all.
enum Max {
  kSubsteps,
  kNeighborsMax,
  kDtMax,
  kDtMinNegated,
  kSpeed,
  kDensityMax,
  kDensityMinNegated,
  kStepMs,
  kSignal,
  kStages,
  kMaxes = kStages + SPH_STAGE_COUNT
};

}  // namespace

sph_stats world_stats(const sph_stats& own, int signal, MPI_Comm comm, int* agreed) {
  const double n = own.particle_count;
  double sums[kSums] = {n, n * own.density_mean, n * own.neighbors_mean,
                        static_cast<double>(own.memory_bytes)};
  // A rank without particles has no density or speed to report, and its time step limits
  // nothing: it must not lower a minimum (or raise a maximum) with a value of no particle.
  const double none = -std::numeric_limits<double>::infinity();
  const bool holds = own.particle_count > 0;
  double maxes[kMaxes] = {};
  maxes[kSubsteps] = own.substeps;
  maxes[kNeighborsMax] = own.neighbors_max;
  maxes[kDtMax] = holds ? own.dt_max : none;
  maxes[kDtMinNegated] = holds ? -static_cast<double>(own.dt_min) : none;
  maxes[kSpeed] = own.max_speed;
  maxes[kDensityMax] = holds ? own.density_max : none;
  maxes[kDensityMinNegated] = holds ? -static_cast<double>(own.density_min) : none;
  maxes[kStepMs] = own.step_ms;
  maxes[kSignal] = signal;
  for (int i = 0; i < SPH_STAGE_COUNT; ++i) maxes[kStages + i] = own.stage_ms[i];
  MPI_Allreduce(MPI_IN_PLACE, sums, kSums, MPI_DOUBLE, MPI_SUM, comm);
  MPI_Allreduce(MPI_IN_PLACE, maxes, kMaxes, MPI_DOUBLE, MPI_MAX, comm);

  sph_stats w = own;
  const double total = sums[kCount];
  w.particle_count = static_cast<uint32_t>(total);
  w.memory_bytes = static_cast<uint64_t>(sums[kMemory]);
  w.density_mean = total > 0.0 ? static_cast<float>(sums[kDensitySum] / total) : 0.0f;
  w.neighbors_mean = total > 0.0 ? static_cast<float>(sums[kNeighborSum] / total) : 0.0f;
  w.substeps = static_cast<uint32_t>(maxes[kSubsteps]);
  w.neighbors_max = static_cast<uint32_t>(maxes[kNeighborsMax]);
  w.max_speed = static_cast<float>(maxes[kSpeed]);
  if (total > 0.0) {  // else every rank is empty: keep this rank's (empty) figures
    w.dt_max = static_cast<float>(maxes[kDtMax]);
    w.dt_min = static_cast<float>(-maxes[kDtMinNegated]);
    w.density_max = static_cast<float>(maxes[kDensityMax]);
    w.density_min = static_cast<float>(-maxes[kDensityMinNegated]);
  }
  w.step_ms = static_cast<float>(maxes[kStepMs]);
  for (int i = 0; i < SPH_STAGE_COUNT; ++i) w.stage_ms[i] = static_cast<float>(maxes[kStages + i]);
  *agreed = static_cast<int>(maxes[kSignal]);
  return w;
}

int agreed_signal(int signal, MPI_Comm comm) {
  MPI_Allreduce(MPI_IN_PLACE, &signal, 1, MPI_INT, MPI_MAX, comm);
  return signal;
}

}  // namespace sph_tools
