// SPDX-License-Identifier: MIT
// The CUDA backend as one rank of a distributed world (include/sph_mpi.h, docs/distributed.md),
// host-staged: what crosses to another rank is downloaded, sent over the RankTransport (MPI in
// libsph_mpi; no CUDA-aware MPI) and uploaded where it arrives. The steps are the CPU rank's
// (src/cpu/cpu_halo.cpp), at the same points of the substep, with the same decisions
// (core/slab_decomposition.h, core/slab_rebalance.h) and the same agreements (core/rank_agreement.h):
//   the frame's start  the world's max speed and acceleration; new slabs when out of balance
//   before the sort    migrants leave with every carried array (the device compacts what stays),
//                      ghosts arrive after the owned particles; the sort takes all of them in
//                      the order of their keys (slot and place at the last sort), so each slot
//                      lists its particles as the undivided world's stable sort does
//   after the sort     the ghost mask, each particle's new key, the order to the host
//   after density      the ghosts take their owners' density, pressure, 1 / density and
//                      neighbour count (the force pass reads them), checked by id
//   forces             only owned particles are integrated and join the maxima (the mask)
//   the substep's end  max speed and acceleration, the first non-finite particle and a crowded
//                      slot reduced over the ranks before the device's end-of-substep kernel,
//                      which then picks the same step on every rank; ghosts dropped
// A distributed world runs on the stream driver (each step waits for the stream; the frame,
// the frame's start and the substep's reductions: cuda_halo_frame.cu). Symplectic Euler with the
// weakly compressible solver only; attach_ranks refuses the rest by name.
#include <cstring>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "../src/core/crowded_cell.h"
#include "../src/core/grid_layout.h"
#include "../src/core/rank_agreement.h"
#include "../src/core/slab_rebalance.h"
#include "cuda_backend_impl.h"
#include "kernel_launch.h"

namespace sph {
namespace {

void refuse(const std::string& what) {
  throw Error(Status::Unsupported, "world: " + what +
                                       " does not work in a distributed world on the CUDA backend yet "
                                       "(docs/distributed.md lists what does)");
}

}  // namespace

void CudaBackend::attach_ranks(std::shared_ptr<const RankTransport> ranks,
                               const DistributedOptions& options) {
  if (!ranks) throw Error(Status::Internal, "attach_ranks: no transport");
  if (count_ != 0 || ranks_)
    throw Error(Status::Internal, "attach_ranks: the backend already holds particles");
  const struct {
    uint32_t bit;
    const char* name;
  } features[] = {{kFeatureSprings, "SPH_FEATURE_SPRINGS (springs across ranks)"},
                  {kFeatureSurfaceTension, "SPH_FEATURE_SURFACE_TENSION"},
                  {kFeatureNormalizedDensity, "SPH_FEATURE_NORMALIZED_DENSITY"},
                  {kFeatureDensityDiffusion, "SPH_FEATURE_DENSITY_DIFFUSION"},
                  {kFeatureColliderLoads, "SPH_FEATURE_COLLIDER_LOADS"}};
  for (const auto& f : features)
    if (config_.features & f.bit) refuse(f.name);
  if (config_.solver == Solver::Dfsph) refuse("the DFSPH solver");
  if (config_.integrator == Integrator::Rk4) refuse("the RK4 integrator");
  require_alive();
  DeviceGuard guard(device_);
  guarded([&] {
    // The store again with the rank's arrays: the sort keys (carried: they travel, roll back and
    // grow with the particles) and the ghost mask; the grid's sort scratch lives in the store.
    std::vector<ParticleArraySpec> specs;
    for (const auto& m : r_->store->method_arrays()) specs.push_back(m->spec);
    specs.push_back(ParticleArraySpec{kArrayDistributedSortKey, sizeof(uint64_t), ParticleArrayRole::Carried,
                                      1, nullptr, nullptr});
    specs.push_back(ParticleArraySpec{kArrayHaloGhost, sizeof(uint32_t), ParticleArrayRole::Scratch, 1,
                                      nullptr, nullptr});
    const uint32_t capacity = config_.capacity;
    auto store = std::make_unique<DeviceParticleStore>(capacity, specs);
    auto grid = std::make_unique<DeviceNeighborGrid>(
        make_grid_shape(config_.kernel_radius, capacity), capacity,
        max_particles_per_cell(config_.particle_spacing, config_.kernel_radius), store->sort_scratch(),
        store->arrays().sorted_position, sizeof(Float4) * static_cast<size_t>(capacity),
        /*fit_to_extent=*/false);
    auto halo = std::make_unique<DeviceHalo>(capacity);
    store->enqueue_initial_world_words(r_->stream);
    cuda_check(cudaStreamSynchronize(r_->stream), "a distributed rank's arrays");
    r_->graph.reset();
    r_->grid.swap(grid);
    r_->store.swap(store);
    r_->halo.swap(halo);
  });
  use_graphs_ = false;
  distributed_options_ = options;
  slabs_ = SlabDecomposition(ranks->size());
  ranks_ = std::move(ranks);
}

DistributedCounters CudaBackend::distributed_counters() const {
  DistributedCounters c = halo_counters_;
  c.axis = slabs_.axis();
  const int me = ranks_ ? ranks_->rank() : 0;
  const std::vector<int32_t>& cuts = slabs_.cuts();
  c.slab_first = me == 0 ? INT32_MIN : cuts[static_cast<size_t>(me - 1)];
  c.slab_last = me == static_cast<int>(cuts.size()) ? INT32_MAX : cuts[static_cast<size_t>(me)] - 1;
  return c;
}

DistributedState CudaBackend::distributed_state() const {
  DistributedState s;
  if (!ranks_) return s;
  s.axis = slabs_.axis();
  s.cuts = slabs_.cuts();
  s.cut = slabs_cut_;
  s.counters = halo_counters_;
  s.rebalance_threshold = distributed_options_.rebalance_threshold;
  return s;
}

void CudaBackend::restore_distributed_state(const DistributedState& state) {
  if (!ranks_) throw Error(Status::Internal, "restore_distributed_state: not a distributed world");
  slabs_.restore(state.axis, state.cuts);
  slabs_cut_ = state.cut;
  halo_counters_ = state.counters;
}

void CudaBackend::rethrow_step_failure() const {
  if (ranks_) rethrow_agreed(*ranks_);
  throw;
}

bool CudaBackend::halo_any(bool flag) const {
  int64_t lowered = flag ? 0 : 1;  // (an agreement reduces by min)
  agree(*ranks_, &lowered);
  return lowered == 0;
}

void CudaBackend::halo_agree() const { agree(*ranks_); }

HostVector<HaloArray> CudaBackend::halo_arrays() const {
  const ParticleArrays& a = r_->store->arrays();
  HostVector<HaloArray> v;
  // The position first: the receiver reads the migrants' layers from it (halo_gather).
  v.push_back(HaloArray{reinterpret_cast<unsigned char*>(a.position), sizeof(Float4)});
  v.push_back(HaloArray{reinterpret_cast<unsigned char*>(a.velocity), sizeof(Float4)});
  v.push_back(HaloArray{reinterpret_cast<unsigned char*>(a.id), sizeof(uint32_t)});
  v.push_back(HaloArray{reinterpret_cast<unsigned char*>(a.density), sizeof(float)});
  for (const auto& m : r_->store->method_arrays()) {
    if (m->spec.role != ParticleArrayRole::Carried || m->spec.elements_per_particle == 0) continue;
    const uint64_t bytes = static_cast<uint64_t>(m->spec.element_size) * m->spec.elements_per_particle;
    if (bytes % 4 != 0)
      throw Error(Status::Internal, std::string("halo: array ") + m->spec.name + " is not in words");
    v.push_back(HaloArray{m->side[0].get(), static_cast<uint32_t>(bytes)});
  }
  return v;
}

// to[d]: the indices of the particles for rank d. Each rank's bytes hold its particles' arrays
// one after the other (DeviceHalo::pack's layout, for that rank's particles alone).
std::vector<RankBytes> CudaBackend::halo_send(const std::vector<HostVector<uint32_t>>& to) {
  std::vector<RankBytes> out(to.size());
  HostVector<uint32_t> all;
  for (const auto& list : to) all.insert(all.end(), list.begin(), list.end());
  const uint32_t m = static_cast<uint32_t>(all.size());
  if (m == 0) return out;
  const HostVector<HaloArray> arrays = halo_arrays();
  DeviceHalo& h = *r_->halo;
  h.upload_index(all.data(), m, r_->stream);
  const unsigned char* host = h.pack(arrays.data(), static_cast<int>(arrays.size()), m, r_->stream);
  size_t start = 0;
  for (size_t d = 0; d < to.size(); ++d) {
    const size_t count = to[d].size();
    size_t offset = 0;
    for (const HaloArray& x : arrays) {
      const unsigned char* from = host + offset + x.bytes * start;
      out[d].insert(out[d].end(), from, from + x.bytes * count);
      offset += static_cast<size_t>(x.bytes) * m;
    }
    start += count;
  }
  return out;
}

uint32_t CudaBackend::halo_receive(const RankBytes& in, uint32_t first) {
  if (in.empty()) return 0;
  const HostVector<HaloArray> arrays = halo_arrays();
  size_t record = 0;
  for (const HaloArray& x : arrays) record += x.bytes;
  if (in.size() % record != 0) throw Error(Status::Internal, "halo: a rank sent a partial particle record");
  const size_t m = in.size() / record;
  if (first + m > config_.capacity)
    throw Error(Status::Capacity, "halo: this rank's particles and ghosts (" + std::to_string(first + m) +
                                      ") exceed the world's capacity " + std::to_string(config_.capacity) +
                                      " (a rank holds its slab and the layers beside it)");
  r_->halo->unpack(arrays.data(), static_cast<int>(arrays.size()), in.data(), static_cast<uint32_t>(m), first,
                   r_->stream);
  return static_cast<uint32_t>(m);
}

void CudaBackend::halo_gather() {
  const RankTransport& t = *ranks_;
  const int me = t.rank();
  const size_t size = static_cast<size_t>(t.size());
  const int axis = slabs_.axis();
  const float inv = 1.0f / config_.kernel_radius;
  cudaStream_t s = r_->stream;
  DeviceHalo& h = *r_->halo;
  uint32_t owned = halo_owned_;
  // Migration: what another rank's slab holds goes there with every carried array.
  h.download_layers(r_->store->arrays().position, owned, axis, inv, s);
  const int32_t* layer = h.host_layers();
  std::vector<HostVector<uint32_t>> to(size);
  halo_keep_.clear();
  halo_layer_.clear();
  for (uint32_t i = 0; i < owned; ++i) {
    const int owner = slabs_.owner(layer[i]);
    if (owner == me) {
      halo_keep_.push_back(i);
      halo_layer_.push_back(layer[i]);
    } else {
      to[static_cast<size_t>(owner)].push_back(i);
    }
  }
  std::vector<RankBytes> in = t.exchange(halo_send(to));  // (an agreement: the substep so far, the packing)
  const uint32_t kept = static_cast<uint32_t>(halo_keep_.size());
  halo_counters_.migrated_out += owned - kept;
  const HostVector<HaloArray> arrays = halo_arrays();
  if (kept < owned) {
    h.upload_index(halo_keep_.data(), kept, s);
    h.keep(arrays.data(), static_cast<int>(arrays.size()), kept, s);
  }
  owned = kept;
  for (const RankBytes& bytes : in) {
    const uint32_t m = halo_receive(bytes, owned);
    for (uint32_t k = 0; k < m; ++k) {  // (the positions come first, DeviceHalo::pack)
      Float4 p;
      std::memcpy(&p, bytes.data() + sizeof(Float4) * k, sizeof p);
      halo_layer_.push_back(slab_layer(p.x, p.y, p.z, axis, inv));
    }
    owned += m;
    halo_counters_.migrated_in += m;
  }
  // Ghosts: each owned particle of a layer beside another rank's slab goes to that rank.
  for (auto& list : to) list.clear();
  for (uint32_t i = 0; i < owned; ++i) {
    int dst[2];
    const int n = slabs_.ghost_destinations(halo_layer_[i], me, dst);
    for (int k = 0; k < n; ++k) to[static_cast<size_t>(dst[k])].push_back(i);
  }
  in = t.exchange(halo_send(to));  // (an agreement: the migrants' arrival, the ghosts' packing)
  halo_origin_.assign(owned, 0u);
  uint32_t n = owned;
  for (size_t r = 0; r < size; ++r) {
    const uint32_t m = halo_receive(in[r], n);
    halo_origin_.insert(halo_origin_.end(), m, static_cast<uint32_t>(r) + 1u);
    n += m;
  }
  halo_owned_ = owned;
  halo_ghosts_ = n - owned;
  halo_counters_.ghosts = halo_ghosts_;
  int64_t total = owned;
  halo_agree();  // (the ghosts' arrival)
  t.all_sum(&total, 1);
  halo_world_count_ = total;
  h.enqueue_visit(static_cast<const uint64_t*>(r_->store->find(kArrayDistributedSortKey)), n, s);
}

void CudaBackend::halo_after_sort(cudaStream_t stream) {
  r_->halo->enqueue_mark(*r_->grid, halo_owned_ + halo_ghosts_, halo_owned_, r_->store->arrays().halo_ghost,
                         static_cast<uint64_t*>(r_->store->find(kArrayDistributedSortKey)), stream);
}

void CudaBackend::halo_after_density(cudaStream_t stream) {
  const RankTransport& t = *ranks_;
  const int me = t.rank();
  const size_t size = static_cast<size_t>(t.size());
  const uint32_t n = halo_owned_ + halo_ghosts_;
  DeviceHalo& h = *r_->halo;
  cuda_check(cudaStreamSynchronize(stream), "the sort's order");
  // Both sides list the particles they share in the sorted order, which is the same on every rank
  // (the keys): the receiver reads its ghosts' records in its own order, checked by id.
  const uint32_t* order = h.host_order();
  std::vector<HostVector<uint32_t>> send(size), receive(size);
  halo_keep_.clear();
  for (uint32_t i = 0; i < n; ++i) {
    const uint32_t k = order[i];
    if (k >= n) throw Error(Status::Internal, "halo: the sort's order names no particle");
    if (k < halo_owned_) {
      halo_keep_.push_back(i);
      int dst[2];
      const int c = slabs_.ghost_destinations(halo_layer_[k], me, dst);
      for (int e = 0; e < c; ++e) send[static_cast<size_t>(dst[e])].push_back(i);
    } else {
      receive[halo_origin_[k] - 1u].push_back(i);
    }
  }
  HostVector<uint32_t> all;
  for (const auto& list : send) all.insert(all.end(), list.begin(), list.end());
  const ParticleArrays& a = r_->store->arrays();
  std::vector<RankBytes> out(size);
  if (!all.empty()) {
    h.upload_index(all.data(), static_cast<uint32_t>(all.size()), stream);
    const HaloDensityRecord* records = h.pack_density(a, static_cast<uint32_t>(all.size()), stream);
    size_t start = 0;
    for (size_t d = 0; d < size; ++d) {
      const unsigned char* from = reinterpret_cast<const unsigned char*>(records + start);
      out[d].assign(from, from + sizeof(HaloDensityRecord) * send[d].size());
      start += send[d].size();
    }
  }
  const std::vector<RankBytes> in = t.exchange(out);
  HostVector<HaloDensityRecord> got;
  HostVector<uint32_t> ghosts;
  for (size_t r = 0; r < size; ++r) {
    if (in[r].size() != sizeof(HaloDensityRecord) * receive[r].size())
      throw Error(Status::Internal, "halo: rank " + std::to_string(r) + " sent " +
                                        std::to_string(in[r].size() / sizeof(HaloDensityRecord)) +
                                        " density records for " + std::to_string(receive[r].size()) +
                                        " ghosts");
    const size_t first = got.size();
    got.resize(first + receive[r].size());
    if (!receive[r].empty()) std::memcpy(got.data() + first, in[r].data(), in[r].size());
    ghosts.insert(ghosts.end(), receive[r].begin(), receive[r].end());
  }
  if (ghosts.empty()) return;
  h.upload_index(ghosts.data(), static_cast<uint32_t>(ghosts.size()), stream);
  h.enqueue_apply_density(a, got.data(), static_cast<uint32_t>(got.size()), stream);
}

void CudaBackend::halo_drop_ghosts() {
  if (halo_ghosts_ == 0) return;
  const HostVector<HaloArray> arrays = halo_arrays();
  const uint32_t kept = static_cast<uint32_t>(halo_keep_.size());
  if (kept != halo_owned_) throw Error(Status::Internal, "halo: the sorted order lost an owned particle");
  r_->halo->upload_index(halo_keep_.data(), kept, r_->stream);
  r_->halo->keep(arrays.data(), static_cast<int>(arrays.size()), kept, r_->stream);
  halo_ghosts_ = 0;
}

}  // namespace sph
