// SPDX-License-Identifier: MIT
// The CPU rank's halo messages (cpu_rank_halo.h): which of a particle's arrays travel with it
// (the carried ones and RK4's stage state), and their layout, array after array, each array's rows
// in the order of the particles sent (the CUDA rank's layout, cuda/device_halo.cu's pack).
#include <cstring>

#include "cpu_backend_impl.h"

namespace sph {

bool CpuRankHalo::travels(const ParticleArraySpec& spec) {
  if (spec.elements_per_particle == 0) return false;
  // RK4's stage state lives through a substep, and a particle may change ranks between its stages.
  return spec.role == ParticleArrayRole::Carried || std::strcmp(spec.name, kArrayRk4Start) == 0 ||
         std::strcmp(spec.name, kArrayRk4Sum) == 0;
}

size_t CpuRankHalo::travelling_bytes() const {
  size_t record = 0;
  for (const auto& a : store_.arrays())
    if (travels(a->spec)) record += particle_bytes(a->spec);
  return record;
}

namespace {

// Rows `which` of a column of `bytes`-byte rows, one after the other into `to`; returns the end.
// (A fixed size per call for the common widths, so that each copy is a load and a store.)
template <size_t kBytes>
unsigned char* copy_rows(unsigned char* to, const unsigned char* column, const HostVector<uint32_t>& which) {
  for (const uint32_t i : which) {
    std::memcpy(to, column + static_cast<size_t>(i) * kBytes, kBytes);
    to += kBytes;
  }
  return to;
}

unsigned char* copy_rows(unsigned char* to, const unsigned char* column, size_t bytes,
                         const HostVector<uint32_t>& which) {
  switch (bytes) {
    case 4:
      return copy_rows<4>(to, column, which);
    case 8:
      return copy_rows<8>(to, column, which);
    case 12:
      return copy_rows<12>(to, column, which);
    case 16:
      return copy_rows<16>(to, column, which);
    default:
      for (const uint32_t i : which) {
        std::memcpy(to, column + static_cast<size_t>(i) * bytes, bytes);
        to += bytes;
      }
      return to;
  }
}

}  // namespace

// Array after array (the travelling ones' test and widths once a pack, not once a particle: the
// per-particle loop over every array, with travels()'s string compares, was the halo's largest
// cost outside the passes and the sort in a profile of 4 ranks, session 37).
void CpuRankHalo::pack(const HostVector<uint32_t>& which, RankBytes& out) const {
  out.clear();
  if (which.empty()) return;
  out.resize(travelling_bytes() * which.size());
  unsigned char* to = out.data();
  for (const auto& a : store_.arrays())
    if (travels(a->spec)) to = copy_rows(to, a->bytes.data(), particle_bytes(a->spec), which);
}

uint32_t CpuRankHalo::unpack(const RankBytes& in, uint32_t origin) {
  const size_t record = travelling_bytes();
  if (in.size() % record != 0) throw Error(Status::Internal, "halo: a rank sent a partial particle record");
  const uint32_t n = static_cast<uint32_t>(in.size() / record);
  if (n == 0) return 0;
  const uint32_t first = count_;
  store_.resize(static_cast<size_t>(first) + n);
  const unsigned char* from = in.data();
  for (const auto& a : store_.arrays()) {
    if (!travels(a->spec)) continue;
    const size_t bytes = particle_bytes(a->spec) * n;
    std::memcpy(a->bytes.data() + static_cast<size_t>(first) * particle_bytes(a->spec), from, bytes);
    from += bytes;
  }
  for (uint32_t k = 0; k < n; ++k) origin_[first + k] = origin;
  count_ = first + n;
  return n;
}

}  // namespace sph
