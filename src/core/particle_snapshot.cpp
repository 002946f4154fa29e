// SPDX-License-Identifier: MIT
#include "particle_snapshot.h"

#include "status.h"

namespace sph {
namespace {

uint64_t elements_of(const ParticleArraySpec& spec, uint32_t n) {
  return spec.elements_per_particle == 0 ? 1u : static_cast<uint64_t>(n) * spec.elements_per_particle;
}

}  // namespace

void check_carried_arrays(const ParticleSnapshot& s, const std::vector<ParticleArraySpec>& specs,
                          uint32_t n) {
  for (const CarriedArray& a : s.carried) {
    const ParticleArraySpec* spec = find_array_spec(specs, a.name.c_str());
    if (!spec || spec->role != ParticleArrayRole::Carried)
      throw Error(Status::Internal, "import_particles: the snapshot carries '" + a.name +
                                        "', which this world's methods do not carry");
    if (a.element_size != spec->element_size || a.bytes.size() != elements_of(*spec, n) * spec->element_size)
      throw Error(Status::Internal, "import_particles: '" + a.name + "' does not match the particles");
  }
}

HostVector<unsigned char> carried_bytes(const ParticleSnapshot& s, const ParticleArraySpec& spec,
                                        uint32_t n) {
  if (const CarriedArray* a = s.find(spec.name)) return a->bytes;
  const uint64_t elements = elements_of(spec, n);
  HostVector<unsigned char> bytes(elements * spec.element_size, 0);
  if (spec.initial)
    for (uint64_t e = 0; e < elements; ++e)
      std::memcpy(bytes.data() + e * spec.element_size, spec.initial, spec.element_size);
  return bytes;
}

}  // namespace sph
