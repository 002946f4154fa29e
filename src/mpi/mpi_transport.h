// SPDX-License-Identifier: MIT
// RankTransport (core/rank_transport.h) over MPI: the one file set of the library that sees
// mpi.h, built into libsph_mpi only.
#pragma once

#include <mpi.h>

#include "../core/rank_transport.h"

namespace sph {

class MpiTransport final : public RankTransport {
 public:
  // Duplicates `comm`, so the world's messages never meet the caller's. Throws Error.
  explicit MpiTransport(MPI_Comm comm);
  ~MpiTransport() override;
  MpiTransport(const MpiTransport&) = delete;
  MpiTransport& operator=(const MpiTransport&) = delete;

  int rank() const override { return rank_; }
  int size() const override { return size_; }
  void all_min(int64_t* values, int n) const override;
  void all_max(int64_t* values, int n) const override;
  void all_sum(int64_t* values, int n) const override;
  void all_max(float* values, int n) const override;
  int64_t exclusive_sum(int64_t value) const override;
  std::vector<RankBytes> exchange(const std::vector<RankBytes>& send) const override;
  std::vector<RankBytes> gather(const RankBytes& mine, int root) const override;
  RankBytes broadcast(const RankBytes& bytes, int root) const override;

 private:
  MPI_Comm comm_ = MPI_COMM_NULL;
  int rank_ = 0;
  int size_ = 1;
};

}  // namespace sph
