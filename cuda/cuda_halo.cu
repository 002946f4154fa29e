// SPDX-License-Identifier: MIT
// The CUDA backend as one rank of a distributed world (include/sph_mpi.h, docs/distributed.md),
// host-staged: what crosses to another rank is downloaded, sent over the RankTransport (MPI in
// libsph_mpi; no CUDA-aware MPI) and uploaded where it arrives. The steps are the CPU rank's
// (src/cpu/cpu_halo.cpp), at the same points of the substep, with the same decisions
// (core/slab_rules.h, core/slab_rebalance.h) and the same agreements (core/rank_agreement.h).
// Who goes where is decided on the device, per particle (DeviceHalo's lists, in the order the
// CPU rank's loops list them); the host gets how many go to each rank and the bytes that leave:
//   the frame's start  the world's max speed and acceleration; new slabs when out of balance
//   before the sort    migrants leave with every carried array (the device compacts what stays),
//                      ghosts arrive after the owned particles; the sort takes all of them in
//                      the order of their keys (slot and place at the last sort), so each slot
//                      lists its particles as the undivided world's stable sort does
//   after the sort     the ghost mask, each particle's new key, and the lists of sorted places
//                      that send and take density records (and the owned ones, kept later)
//   after density      the ghosts take their owners' density, pressure, 1 / density and
//                      neighbour count (the force pass reads them), checked by id
//   forces             only owned particles are integrated and join the maxima (the mask)
//   the substep's end  max speed and acceleration, the first non-finite particle and a crowded
//                      slot reduced over the ranks before the device's end-of-substep kernel,
//                      which then picks the same step on every rank; ghosts dropped
// A distributed world runs on the stream driver (each step waits for the stream; the frame,
// the frame's start and the substep's reductions: cuda_halo_frame.cu). Symplectic Euler with the
// weakly compressible solver (with the normalised density and the density diffusion, whose
// republished densities the ghosts take again, surface tension, whose colour normals they take:
// substep_pipeline.cu, and collider loads, each rank's own particles' impulses added over the
// ranks at the frame's end: cuda_halo_frame.cu), RK4 (each of its four stages sorts, so each
// gathers its halo; between two stages the ranks agree on a failure, the ghosts go and the stage
// state, rk4_start and rk4_sum, travels with the migrants: halo_next_stage, as on the CPU rank)
// or DFSPH's Jacobi solves (the host drives each solve an iteration at a time,
// core/dfsph_jacobi_loop.h: the ghosts take their owners' densities and factors after the density
// pass, velocities and pressure steps within each iteration, and the mean error is an exact sum
// added over the ranks) and its density solve by conjugate gradients (the host drives it as the
// CPU rank's loop, dfsph_cg_rank_solver.cu's enqueue_dfsph_cg_rank_solve: the ghosts take their
// owners' search directions and velocity steps within each iteration, its sums are exact sums
// added over the ranks, halo_dfsph_cg_world); springs, whose lists name partners by id between
// substeps, with spring ghosts and the linking's candidates (cuda_halo_springs.cu, as
// src/cpu/cpu_halo_springs.cpp). The exchanges within a substep after the sort (the ghosts'
// records, the solves' sums, the probes' points) are cuda_halo_records.cu's.
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

void CudaBackend::attach_ranks(std::shared_ptr<const RankTransport> ranks,
                               const DistributedOptions& options) {
  if (!ranks) throw Error(Status::Internal, "attach_ranks: no transport");
  if (count_ != 0 || ranks_)
    throw Error(Status::Internal, "attach_ranks: the backend already holds particles");
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
        store->arrays().sorted_position, sizeof(Float4) * static_cast<size_t>(capacity), r_->stream,
        /*fit_to_extent=*/false);
    auto halo = std::make_unique<DeviceHalo>(capacity, ranks->size(), r_->stream);
    std::unique_ptr<DeviceHaloSprings> springs;
    if (options_.springs) springs = std::make_unique<DeviceHaloSprings>(capacity, r_->stream);
    store->enqueue_initial_world_words(r_->stream);
    cuda_check(cudaStreamSynchronize(r_->stream), "a distributed rank's arrays");
    r_->graph.reset();
    r_->grid.swap(grid);
    r_->store.swap(store);
    r_->halo.swap(halo);
    r_->halo_springs.swap(springs);
  });
  use_graphs_ = false;
  distributed_options_ = options;
  slabs_ = SlabDecomposition(ranks->size());
  ranks_ = std::move(ranks);
}

DistributedCounters CudaBackend::distributed_counters() const {
  DistributedCounters c = halo_counters_;
  slabs_.describe(ranks_ ? ranks_->rank() : 0, c);
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
  // RK4's stage state between two stages: it lives through a substep, and a particle may change
  // ranks between its stages (ghosts take it too, as on the CPU rank, and never read it).
  static_assert(sizeof(ParticleState) % 4 == 0 && sizeof(Rk4Accumulator) % 4 == 0, "RK4's state in words");
  if (halo_rk4_side_ != kNoRk4Side) {
    const int side = halo_rk4_side_;
    v.push_back(HaloArray{reinterpret_cast<unsigned char*>(a.rk4_start[side]), sizeof(ParticleState)});
    v.push_back(HaloArray{reinterpret_cast<unsigned char*>(a.rk4_sum[side]), sizeof(Rk4Accumulator)});
  }
  return v;
}

// The particles the device index list names at [starts[0], starts[size]) leave: rank d's are
// [starts[d], starts[d + 1]). Each rank's bytes hold its particles' arrays one after the other
// (DeviceHalo::pack's layout, for that rank's particles alone).
std::vector<RankBytes> CudaBackend::halo_send(const uint32_t* starts) {
  const size_t size = static_cast<size_t>(ranks_->size());
  std::vector<RankBytes> out(size);
  const uint32_t m = starts[size] - starts[0];
  if (m == 0) return out;
  const HostVector<HaloArray> arrays = halo_arrays();
  DeviceHalo& h = *r_->halo;
  const unsigned char* host =
      h.pack(arrays.data(), static_cast<int>(arrays.size()), h.list() + starts[0], m, r_->stream);
  for (size_t d = 0; d < size; ++d) {
    const size_t start = starts[d] - starts[0], count = starts[d + 1] - starts[d];
    size_t offset = 0;
    for (const HaloArray& x : arrays) {
      const unsigned char* from = host + offset + x.bytes * start;
      out[d].insert(out[d].end(), from, from + x.bytes * count);
      offset += static_cast<size_t>(x.bytes) * m;
    }
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
  const Float4* position = r_->store->arrays().position;
  uint32_t owned = halo_owned_;
  halo_kept_ = kNoKeptList;
  // Migration: what another rank's slab holds goes there with every carried array (the lists and
  // their order: DeviceHalo::list_migrants; what stays is listed last).
  h.set_cuts(slabs_.cuts(), s);
  const uint32_t* starts = h.list_migrants(position, owned, axis, inv, me, s);
  std::vector<RankBytes> in =
      t.exchange(halo_send(starts));  // (an agreement: the substep so far, the packing)
  const uint32_t leaving = starts[size];
  const uint32_t kept = owned - leaving;
  halo_counters_.migrated_out += leaving;
  const HostVector<HaloArray> arrays = halo_arrays();
  if (kept < owned) h.keep(arrays.data(), static_cast<int>(arrays.size()), h.list() + leaving, kept, s);
  owned = kept;
  for (const RankBytes& bytes : in) {
    const uint32_t m = halo_receive(bytes, owned);
    owned += m;
    halo_counters_.migrated_in += m;
  }
  // Ghosts: each owned particle goes to the other ranks whose slabs meet its layer or those beside.
  in = t.exchange(halo_send(h.list_ghosts(position, owned, axis, inv, me, s)));
  // (an agreement: the migrants' arrival, the ghosts' packing)
  uint32_t n = owned;
  for (size_t r = 0; r < size; ++r) {
    const uint32_t m = halo_receive(in[r], n);
    h.enqueue_origin(n, m, static_cast<uint32_t>(r), s);
    n += m;
  }
  // Springs: the owned lists' partner ids to indices, the partners held nowhere here as spring
  // ghosts (cuda_halo_springs.cu).
  if (r_->halo_springs) n = halo_gather_spring_partners(owned, n);
  halo_owned_ = owned;
  halo_ghosts_ = n - owned;
  halo_counters_.ghosts = halo_ghosts_;
  int64_t total = owned;
  halo_agree();  // (the ghosts' arrival)
  t.all_sum(&total, 1);
  halo_world_count_ = total;
  if (r_->halo_springs) halo_agree_link_from();
  h.enqueue_visit(static_cast<const uint64_t*>(r_->store->find(kArrayDistributedSortKey)), n, s);
}

void CudaBackend::halo_after_sort(cudaStream_t stream) {
  r_->halo->enqueue_mark(*r_->grid, halo_owned_ + halo_ghosts_, halo_owned_, ranks_->rank(),
                         r_->store->arrays().halo_ghost,
                         static_cast<uint64_t*>(r_->store->find(kArrayDistributedSortKey)), stream);
}

void CudaBackend::halo_drop_ghosts(uint32_t* counts) {
  if (r_->halo_springs) halo_springs_to_ids();  // before the ghosts go, whose indices the lists hold
  if (halo_ghosts_ == 0) return;
  HostVector<HaloArray> arrays = halo_arrays();
  if (counts) arrays.push_back(HaloArray{reinterpret_cast<unsigned char*>(counts), sizeof(uint32_t)});
  if (halo_kept_ != halo_owned_)
    throw Error(Status::Internal, "halo: the sorted order lost an owned particle");
  r_->halo->keep(arrays.data(), static_cast<int>(arrays.size()), r_->halo->kept_list(), halo_kept_,
                 r_->stream);
  halo_ghosts_ = 0;
}

}  // namespace sph
