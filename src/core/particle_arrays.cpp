#include "particle_arrays.h"

#include <cstring>

#include "../physics/density_normalization.h"
#include "../physics/float4_types.h"
#include "../physics/integrate.h"
#include "../physics/springs.h"

namespace sph {
namespace {

void rewrite_spring_partners(void* element, const uint32_t* new_index_of_old) {
  SpringList* list = static_cast<SpringList*>(element);
  *list = remap_spring_list(*list, new_index_of_old);
}

const SpringList kEmptySprings = empty_spring_list();
const float kFreshDensityFactor = fresh_density_factor();
const uint32_t kNoLinksPending = kNoPendingLinks;

ParticleArraySpec spec(const char* name, uint32_t element_size, ParticleArrayRole role,
                       uint32_t elements_per_particle = 1, const void* initial = nullptr,
                       void (*rewrite_indices)(void*, const uint32_t*) = nullptr) {
  return ParticleArraySpec{name, element_size, role, elements_per_particle, initial, rewrite_indices};
}

}  // namespace

std::vector<ParticleArraySpec> method_particle_arrays(const WorldConfig& config) {
  using Role = ParticleArrayRole;
  std::vector<ParticleArraySpec> arrays;
  // Clavet viscosity: the density pass's neighbour counts, which the force pass reads.
  if (config.viscosity_method == ViscosityMethod::Clavet)
    arrays.push_back(spec(kArrayNeighborCount, sizeof(uint32_t), Role::Scratch));
  // Normalised density: each particle's carried factor (NaN until its first density pass,
  // density_normalization.h), and the kernel sum, then the filtered density (eq. 31).
  if (config.features & kFeatureNormalizedDensity) {
    arrays.push_back(spec(kArrayDensityFactor, sizeof(float), Role::Carried, 1, &kFreshDensityFactor));
    arrays.push_back(spec(kArrayNormalizedDensity, sizeof(float), Role::Scratch));
  }
  // Surface tension: the colour-field normals (n, |n|) the force gather reads for neighbours.
  if (config.features & kFeatureSurfaceTension)
    arrays.push_back(spec(kArrayColourNormal, sizeof(Float4), Role::Scratch));
  // Springs: each particle's list (partners as storage indices), the lowest id that waits for
  // its springs, and per evaluation the link candidates and the spring accelerations.
  if (config.features & kFeatureSprings) {
    arrays.push_back(
        spec(kArraySprings, sizeof(SpringList), Role::Carried, 1, &kEmptySprings, &rewrite_spring_partners));
    arrays.push_back(spec(kArraySpringLinkFrom, sizeof(uint32_t), Role::Carried, 0, &kNoLinksPending));
    arrays.push_back(spec(kArraySpringCandidates, sizeof(uint32_t), Role::Scratch, kSpringSlots));
    arrays.push_back(spec(kArraySpringAcceleration, sizeof(Float4), Role::Scratch));
  }
  // RK4: the start state and the slope sums of the four stages, which follow the stages' sorts.
  if (config.integrator == Integrator::Rk4) {
    arrays.push_back(spec(kArrayRk4Start, sizeof(ParticleState), Role::Sorted));
    arrays.push_back(spec(kArrayRk4Sum, sizeof(Rk4Accumulator), Role::Sorted));
  }
  return arrays;
}

const ParticleArraySpec* find_array_spec(const std::vector<ParticleArraySpec>& specs, const char* name) {
  for (const ParticleArraySpec& s : specs)
    if (std::strcmp(s.name, name) == 0) return &s;
  return nullptr;
}

}  // namespace sph
