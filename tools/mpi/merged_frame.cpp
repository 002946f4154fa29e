// SPDX-License-Identifier: MIT
#include "merged_frame.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "library_error.h"

namespace sph_tools {

namespace {

// One particle's attributes that sph_mpi_world_gather leaves out, as four words.
constexpr int kWords = 4;

uint32_t bits(float f) {
  uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

float from_bits(uint32_t u) {
  float f;
  std::memcpy(&f, &u, sizeof f);
  return f;
}

void check_mpi(int code, const char* what) {
  if (code != MPI_SUCCESS)
    throw std::runtime_error(std::string("merging the ranks' particles: ") + what + " failed");
}

}  // namespace

void gather_frame(const sph_world* world, MPI_Comm comm, const ParticleFrame& own, ParticleFrame* out) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  sph_mpi_counts counts;
  sph_mpi_counts_init(&counts);
  sph_result r = sph_mpi_world_get_counts(world, &counts);
  if (r < 0) throw LibraryError(r, "reading the distributed world's counts");
  const uint64_t n = rank == 0 ? counts.global_count : 0;
  if (rank == 0) {
    out->frame = own.frame;
    out->time = own.time;
    out->particle_spacing = own.particle_spacing;
    out->count = static_cast<uint32_t>(n);
    out->position.resize(3 * n);
    out->velocity.resize(3 * n);
    out->id.resize(n);
    out->density.resize(n);
    out->pressure.resize(n);
    out->has_user = own.has_user;
    out->user.resize(own.has_user ? n : 0);
  }
  uint64_t gathered = 0;
  r = sph_mpi_world_gather(world, 0, rank == 0 ? out->position.data() : nullptr,
                           rank == 0 ? out->velocity.data() : nullptr, rank == 0 ? out->id.data() : nullptr,
                           n, &gathered);
  if (r < 0) throw LibraryError(r, "gathering the ranks' particles");

  std::vector<uint32_t> mine(static_cast<size_t>(kWords) * own.count);
  for (uint32_t i = 0; i < own.count; ++i) {
    uint32_t* w = &mine[static_cast<size_t>(kWords) * i];
    w[0] = own.id[i];
    w[1] = bits(own.density[i]);
    w[2] = bits(own.pressure[i]);
    w[3] = own.has_user ? own.user[i] : 0u;
  }
  const int my_words = static_cast<int>(mine.size());
  std::vector<int> words(rank == 0 ? ranks : 0), offsets(rank == 0 ? ranks : 0);
  check_mpi(MPI_Gather(&my_words, 1, MPI_INT, words.data(), 1, MPI_INT, 0, comm), "MPI_Gather");
  std::vector<uint32_t> all;
  if (rank == 0) {
    size_t total = 0;
    for (int k = 0; k < ranks; ++k) {
      offsets[k] = static_cast<int>(total);
      total += static_cast<size_t>(words[k]);
    }
    all.resize(total);
  }
  check_mpi(MPI_Gatherv(mine.data(), my_words, MPI_UINT32_T, all.data(), words.data(), offsets.data(),
                        MPI_UINT32_T, 0, comm),
            "MPI_Gatherv");
  if (rank != 0) return;
  if (gathered != n || all.size() != static_cast<size_t>(kWords) * n)
    throw std::runtime_error("merging the ranks' particles: the gather returned " + std::to_string(gathered) +
                             " particles, the ranks hold " + std::to_string(all.size() / kWords) + " of " +
                             std::to_string(n));
  // out->id is sorted (sph_mpi_world_gather orders by id): place each record by its id.
  for (size_t k = 0; k < all.size(); k += kWords) {
    const uint32_t* w = &all[k];
    const auto at = std::lower_bound(out->id.begin(), out->id.end(), w[0]);
    if (at == out->id.end() || *at != w[0])
      throw std::runtime_error("merging the ranks' particles: id " + std::to_string(w[0]) +
                               " is not in the gather");
    const size_t i = static_cast<size_t>(at - out->id.begin());
    out->density[i] = from_bits(w[1]);
    out->pressure[i] = from_bits(w[2]);
    if (out->has_user) out->user[i] = w[3];
  }
}

}  // namespace sph_tools
