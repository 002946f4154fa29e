// SPDX-License-Identifier: MIT
#include "particle_arrays.h"

#include <cstring>
#include <iterator>

#include "../physics/integrate.h"
#include "../physics/methods.h"

namespace sph {
namespace {

// A method's kArrays, or none for a method that has no arrays of its own.
template <class Method>
auto arrays_of(int) -> decltype(std::begin(Method::kArrays), std::vector<ParticleArraySpec>()) {
  return std::vector<ParticleArraySpec>(std::begin(Method::kArrays), std::end(Method::kArrays));
}
template <class Method>
std::vector<ParticleArraySpec> arrays_of(long) {
  return {};
}

}  // namespace

std::vector<ParticleArraySpec> method_particle_arrays(const WorldConfig& config) {
  std::vector<ParticleArraySpec> arrays;
  const MethodSelection selection = config.selection();
  for_each_method([&](auto tag) {
    using Method = typename decltype(tag)::type;
    if (!runs(selection, tag)) return;
    for (const ParticleArraySpec& spec : arrays_of<Method>(0)) arrays.push_back(spec);
  });
  // RK4: the start state and the slope sums of the four stages, which follow the stages' sorts.
  if (config.integrator == Integrator::Rk4) {
    arrays.push_back(ParticleArraySpec{kArrayRk4Start, sizeof(ParticleState), ParticleArrayRole::Sorted, 1,
                                       nullptr, nullptr});
    arrays.push_back(ParticleArraySpec{kArrayRk4Sum, sizeof(Rk4Accumulator), ParticleArrayRole::Sorted, 1,
                                       nullptr, nullptr});
  }
  // DFSPH's loads: the impulses of its contact clamp, per particle and substep (collider_loads.h).
  if (config.solver == Solver::Dfsph && (config.features & kFeatureColliderLoads))
    arrays.push_back(ParticleArraySpec{kArrayDfsphContactImpulse, sizeof(Float4), ParticleArrayRole::Scratch,
                                       1, nullptr, nullptr});
  // DFSPH's conjugate gradients (dfsph_cg.h): a runtime choice (sph_dfsph_params.linear_solver), so
  // its arrays are there wherever it may be chosen, and only there (capi/dfsph_solver_check.h
  // refuses it with the walls in the density or the loads). 25 bytes per particle.
  if (config.solver == Solver::Dfsph &&
      !(config.features & (kFeatureBoundaryDensity | kFeatureColliderLoads)))
    for (const ParticleArraySpec& spec : {ParticleArraySpec{kArrayDfsphCgValue, sizeof(float),
                                                            ParticleArrayRole::Scratch, 1, nullptr, nullptr},
                                          ParticleArraySpec{kArrayDfsphCgChange, sizeof(float),
                                                            ParticleArrayRole::Scratch, 1, nullptr, nullptr},
                                          ParticleArraySpec{kArrayDfsphCgVelocityStep, sizeof(Float4),
                                                            ParticleArrayRole::Scratch, 1, nullptr, nullptr},
                                          ParticleArraySpec{kArrayDfsphCgState, sizeof(uint8_t),
                                                            ParticleArrayRole::Scratch, 1, nullptr, nullptr}})
      arrays.push_back(spec);
  if (config.features & kFeatureUserAttribute)
    arrays.push_back(ParticleArraySpec{kArrayUserAttribute, sizeof(uint32_t), ParticleArrayRole::Carried, 1,
                                       nullptr, nullptr});
  return arrays;
}

const ParticleArraySpec* find_array_spec(const std::vector<ParticleArraySpec>& specs, const char* name) {
  for (const ParticleArraySpec& s : specs)
    if (std::strcmp(s.name, name) == 0) return &s;
  return nullptr;
}

}  // namespace sph
