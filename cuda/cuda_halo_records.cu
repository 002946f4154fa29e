// SPDX-License-Identifier: MIT
// A distributed CUDA rank's exchanges within a substep, after the sort (cuda_halo.cu has the rank,
// its migration and ghosts; the CPU rank's twins are cpu_halo.cpp's halo_share_* and
// cpu_halo_solvers.cpp): the ghosts take their owners' records (halo_refresh: the density
// records, the colour normals, DFSPH's densities and factors, a solve's velocities and pressure
// steps), the DFSPH solves' exact sums and maxima are added over the ranks, and each probe point's
// gather becomes its owner rank's.
#include <cstring>
#include <string>
#include <vector>

#include "../src/core/exact_float_sum.h"
#include "../src/core/rank_agreement.h"
#include "../src/core/rank_probe_points.h"
#include "cuda_backend_impl.h"
#include "kernel_launch.h"

namespace sph {

template <class Record>
void CudaBackend::halo_refresh(cudaStream_t stream, const char* what, const ParticleArrays& a) {
  const RankTransport& t = *ranks_;
  const size_t size = static_cast<size_t>(t.size());
  DeviceHalo& h = *r_->halo;
  cuda_check(cudaStreamSynchronize(stream), "the halo's lists");
  // Both sides list the particles they share in the sorted order, which is the same on every rank
  // (the keys): the receiver reads its ghosts' records in its own order, checked by id. The lists
  // (DeviceHalo::enqueue_mark): the records to send, rank by rank, then the ghosts that take
  // them, rank by rank.
  if (h.order_names_no_particle()) throw Error(Status::Internal, "halo: the sort's order names no particle");
  const uint32_t* starts = h.starts();
  const uint32_t sent = starts[size];
  std::vector<RankBytes> out(size);
  if (sent > 0) {
    const Record* records = h.pack_records<Record>(a, h.list(), sent, stream);
    for (size_t d = 0; d < size; ++d) {
      const unsigned char* from = reinterpret_cast<const unsigned char*>(records + starts[d]);
      out[d].assign(from, from + sizeof(Record) * (starts[d + 1] - starts[d]));
    }
  }
  // (starts is pinned memory the exchange leaves alone; the next lists come with the next substep)
  halo_kept_ = h.kept_count();
  const std::vector<RankBytes> in = t.exchange(out);
  HostVector<Record> got;
  for (size_t r = 0; r < size; ++r) {
    const size_t ghosts = starts[size + r + 1] - starts[size + r];
    if (in[r].size() != sizeof(Record) * ghosts)
      throw Error(Status::Internal, "halo: rank " + std::to_string(r) + " sent " +
                                        std::to_string(in[r].size() / sizeof(Record)) + " " + what + " for " +
                                        std::to_string(ghosts) + " ghosts");
    const size_t first = got.size();
    got.resize(first + ghosts);
    if (ghosts > 0) std::memcpy(got.data() + first, in[r].data(), in[r].size());
  }
  if (got.empty()) return;
  h.enqueue_apply_records(a, h.list() + sent, got.data(), static_cast<uint32_t>(got.size()), stream);
}

// (cuda_halo_springs.cu's linking refreshes the ghosts' candidates.)
template void CudaBackend::halo_refresh<HaloSpringCandidateRecord>(cudaStream_t, const char*,
                                                                   const ParticleArrays&);

void CudaBackend::halo_after_density(cudaStream_t stream) {
  halo_refresh<HaloDensityRecord>(stream, "density records", r_->store->arrays());
}

void CudaBackend::halo_after_normals(cudaStream_t stream) {
  halo_refresh<HaloNormalRecord>(stream, "colour normals", r_->store->arrays());
}

void CudaBackend::halo_after_dfsph_density(cudaStream_t stream) {
  halo_refresh<HaloDfsphDensityRecord>(stream, "DFSPH density records", r_->store->arrays());
}

void CudaBackend::halo_share_velocities(Float4* v, cudaStream_t stream) {
  // The velocity record carries the arrays' sorted_velocity: here the solve's (the divergence
  // solve's are the sorted velocities, the density solve's v* the state array).
  ParticleArrays view = r_->store->arrays();
  view.sorted_velocity = v;
  halo_refresh<HaloVelocityRecord>(stream, "DFSPH velocities", view);
}

void CudaBackend::halo_share_dfsph_steps(cudaStream_t stream) {
  halo_refresh<HaloDfsphStepRecord>(stream, "DFSPH pressure steps", r_->store->arrays());
}

// As the CPU rank's (CpuBackend::dfsph_errors): the rank's exact bins, added over the ranks, over
// the world's count, and the ranks' largest error, for the density solve only, which bounds it
// (the divergence solve's rate kernel leaves it 0: no all_max per divergence iteration); the same
// bits on every rank, whichever particles each holds.
DfsphErrors CudaBackend::halo_dfsph_errors(bool divergence, cudaStream_t stream) {
  ExactFloatSum sum;
  const int64_t* words = r_->halo->download_error_bins(stream, kDfsphRankErrorWords);
  std::memcpy(sum.terms(), words, sizeof(int64_t) * ExactFloatSum::kTerms);
  const uint32_t largest_bits = static_cast<uint32_t>(static_cast<uint64_t>(words[ExactFloatSum::kTerms]));
  float largest = 0.0f;
  std::memcpy(&largest, &largest_bits, sizeof largest);
  halo_agree();  // (the refreshes' buffers: a rank that failed there meets the others here)
  ranks_->all_sum(sum.terms(), ExactFloatSum::kTerms);
  if (!divergence) ranks_->all_max(&largest, 1);
  const int64_t particles = halo_world_count_;
  return {particles > 0 ? static_cast<float>(sum.value() / static_cast<double>(particles)) : 0.0f, largest};
}

// As the CPU rank's (CpuBackend::dfsph_cg_world): the rank's exact bins of each sum added over the
// ranks, its maxima the ranks' largest, after an agreement; the same bits on every rank.
int64_t CudaBackend::halo_dfsph_cg_world(int sums, double* values, int maxima, float* largest,
                                         cudaStream_t stream) {
  constexpr int kTerms = ExactFloatSum::kTerms;
  if (sums > 3 || maxima > 2) throw Error(Status::Internal, "halo: more DFSPH sums than the bins hold");
  const int64_t* words = r_->halo->download_error_bins(stream, kDfsphRankCgWords);
  ExactFloatSum sum[3];
  for (int s = 0; s < sums; ++s) std::memcpy(sum[s].terms(), words + s * kTerms, sizeof(int64_t) * kTerms);
  for (int m = 0; m < maxima; ++m) {
    const uint32_t bits = static_cast<uint32_t>(static_cast<uint64_t>(words[kDfsphRankCgMaxima + m]));
    std::memcpy(&largest[m], &bits, sizeof bits);
  }
  int64_t bins[3 * kTerms];  // (on the stack: no allocation between the agreement and the sum)
  for (int s = 0; s < sums; ++s) std::memcpy(bins + s * kTerms, sum[s].terms(), sizeof(int64_t) * kTerms);
  halo_agree();  // (the refreshes' buffers: a rank that failed there meets the others here)
  ranks_->all_sum(bins, sums * kTerms);
  if (maxima > 0) ranks_->all_max(largest, maxima);
  for (int s = 0; s < sums; ++s) {
    std::memcpy(sum[s].terms(), bins + s * kTerms, sizeof(int64_t) * kTerms);
    values[s] = sum[s].value();
  }
  return halo_world_count_;
}

// The points' gathers through the host: down, the owners' picked (the CPU rank's rule), up.
void CudaBackend::halo_pick_probe_points(const DeviceProbes& probes, cudaStream_t stream) {
  HostVector<ProbeGather> points(probes.point_count);
  if (probes.point_count > 0)
    cuda_check(cudaMemcpyAsync(points.data(), probes.points, sizeof(ProbeGather) * points.size(),
                               cudaMemcpyDeviceToHost, stream),
               "copy of the probes' points");
  cuda_check(cudaStreamSynchronize(stream), "the probes' points");
  const HostVector<ProbeView>& views = r_->probes.host_views();
  pick_rank_probe_points(*ranks_, slabs_, config_.kernel_radius, views.data(), views.size(), points.data(),
                         points.size());
  if (probes.point_count > 0)
    cuda_check(cudaMemcpyAsync(probes.points, points.data(), sizeof(ProbeGather) * points.size(),
                               cudaMemcpyHostToDevice, stream),
               "copy of the probes' picked points");
  cuda_check(cudaStreamSynchronize(stream), "the probes' picked points");  // (points is freed on return)
}

}  // namespace sph
