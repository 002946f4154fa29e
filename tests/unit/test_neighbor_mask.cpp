// SPDX-License-Identifier: MIT
// The candidate masks of CUDA DFSPH's solves (src/physics/neighbor_walk.h, issue 18) against
// brute force on the host: for every particle of a scene, the mask that the density pass
// (gather_density_and_factor with a NeighborMaskWriter; with a null one it stores nothing and
// gives the same sample) records has bit k set exactly for the
// k-th candidate of the plain 27-cell walk that is within the mask's bound (neighbor_mask_bound)
// and not the particle itself, and is marked overflowing exactly when the walk has more than 383
// candidates; for_each_masked_neighbor visits exactly those candidates, in the plain walk's order
// (every candidate where the mask overflowed or is null); and the two solve passes (density_rate,
// pressure_velocity_change) give the same bits through the masked walk as through the plain one.
// The neighbour lists: write_neighbor_list's from each finished mask against the lists the density
// pass writes in the same walk as the mask (NeighborMaskWriter with lists, CUDA's way), slot by slot,
// and the listed walk against the masked one.
// The scenes: a table folded over a larger cloud (rows that wrap around the table, far
// particles in folded slots) dense enough that some particles overflow and others do not; a
// lattice at h / 2 whose pairs at exactly r = h sit on the passes' test's edge (inside the mask's
// bound, outside r < h); a sparse cloud.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <random>
#include <vector>

#include "core/config.h"
#include "physics/dfsph_passes.h"
#include "physics/neighbor_walk.h"

namespace {

using sph::Float4;
using sph::Vec3;

constexpr float kH = 1.0f;  // the cell size; positions in units of h keep the lattice exact

// A dense cell-start table over an nx * ny * nz table, built here (not by a backend's grid) so
// that the table can be much smaller than the cloud: the positions sorted by slot (stable).
struct Table {
  sph::GridShape shape;
  std::vector<uint32_t> cell_start;
  std::vector<Float4> positions;
  std::vector<Float4> velocities;
  std::vector<float> k;

  Table(const std::vector<Vec3>& points, int32_t n_axis, uint32_t seed) {
    shape =
        sph::GridShape{1.0f / kH, n_axis, n_axis, n_axis, static_cast<uint32_t>(n_axis * n_axis * n_axis)};
    const uint32_t n = static_cast<uint32_t>(points.size());
    std::vector<uint32_t> order(n);
    for (uint32_t i = 0; i < n; ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
      return sph::cell_hash_of_position(shape, points[a]) < sph::cell_hash_of_position(shape, points[b]);
    });
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> speed(-0.2f, 0.2f), pressure(0.0f, 1e-3f);
    for (uint32_t i = 0; i < n; ++i) {
      positions.push_back(sph::make_float4_record(points[order[i]], 0.0f));
      velocities.push_back(Float4{speed(rng), speed(rng), speed(rng), 0.0f});
      k.push_back(pressure(rng));
    }
    cell_start.assign(shape.cell_count + 1u, n);
    for (uint32_t c = 0, i = 0; c <= shape.cell_count; ++c) {
      while (i < n && sph::cell_hash_of_position(shape, xyz(positions[i])) < c) ++i;
      cell_start[c] = i;
    }
  }
  sph::GridView view() const { return sph::GridView{shape, cell_start.data()}; }
  uint32_t size() const { return static_cast<uint32_t>(positions.size()); }
};

sph::FluidConstants fluid() {
  sph::WorldConfig config;
  config.kernel_radius = kH;
  config.particle_spacing = kH / 1.8f;
  config.rest_density = 1000.0f;
  config.particle_mass =
      1000.0f * config.particle_spacing * config.particle_spacing * config.particle_spacing;
  config.density_self_weight = 1.0f;
  config.solver = sph::Solver::Dfsph;
  return sph::make_fluid_constants(config, sph::RuntimeParams{});
}

template <class T>
bool same_bits(const T& a, const T& b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}

struct Tally {
  uint32_t particles = 0, overflowed = 0, wrapped_rows = 0, edge_pairs = 0, mismatches = 0;
  uint32_t listed = 0;        // particles whose neighbour list holds every visit (the rest walk their masks)
  uint32_t long_lists = 0;    // particles with a mask of their own (not overflowed) and more than 63 visits
  uint32_t walked_slots = 0;  // list slots the density pass's lists were compared on
};

// Every particle of the table against brute force (the file's header).
Tally check_table(const Table& t) {
  const sph::FluidConstants f = fluid();
  const sph::GridView view = t.view();
  const float bound = sph::neighbor_mask_bound(f.kernel.h2);
  const float dt = 1e-3f;
  const sph::DfsphWalls no_walls{nullptr};
  std::vector<uint32_t> masks(static_cast<size_t>(t.size()) * sph::kNeighborMaskWords, 0xdeadbeefu);
  // The lists, slot-major with a stride above the particle count (a world's capacity).
  const uint32_t stride = t.size() + 7u;
  std::vector<uint32_t> lists(static_cast<size_t>(stride) * sph::kNeighborListRows, 0xdeadbeefu);
  // The lists the density pass writes as it records the masks (CUDA with lists), to hold equal to
  // write_neighbor_list's from the finished masks.
  std::vector<uint32_t> walked(static_cast<size_t>(stride) * sph::kNeighborListRows, 0xdeadbeefu);
  Tally tally;
  for (uint32_t i = 0; i < t.size(); ++i) {
    ++tally.particles;
    const Vec3 xi = sph::xyz(t.positions[i]);
    uint32_t* mask = masks.data() + static_cast<size_t>(i) * sph::kNeighborMaskWords;
    // The density pass with and without recording: the same sample.
    const sph::DfsphDensitySample plain =
        sph::gather_density_and_factor(f, view, t.positions.data(), sph::no_boundary_share(), i);
    const sph::DfsphDensitySample recorded = sph::gather_density_and_factor(
        f, view, t.positions.data(), sph::no_boundary_share(), i, sph::NeighborMaskWriter{mask});
    // A world without masks runs the recording pass with a null writer (cuda/dfsph_solver.cu):
    // the same sample, nothing stored.
    const sph::DfsphDensitySample unrecorded = sph::gather_density_and_factor(
        f, view, t.positions.data(), sph::no_boundary_share(), i, sph::NeighborMaskWriter{nullptr});
    // With lists: the mask again (the same words) and the list, in the same walk.
    std::vector<uint32_t> mask_again(sph::kNeighborMaskWords, 0xdeadbeefu);
    const sph::DfsphDensitySample listing =
        sph::gather_density_and_factor(f, view, t.positions.data(), sph::no_boundary_share(), i,
                                       sph::NeighborMaskWriter{mask_again.data(), walked.data(), stride, i});
    bool ok = same_bits(plain, recorded) && same_bits(plain, unrecorded) && same_bits(plain, listing);
    ok = ok && std::equal(mask_again.begin(), mask_again.end(), mask);
    // Brute force: the candidates in the walk's order, and those within the bound.
    std::vector<uint32_t> candidates, kept;
    sph::for_each_neighbor_range(view, xi, [&](uint32_t begin, uint32_t end) {
      for (uint32_t j = begin; j < end; ++j) candidates.push_back(j);
    });
    sph::GridShape g = view.shape;
    const sph::CellCoord c = sph::cell_of(g, xi);
    if (sph::wrap_index(c.x, g.nx) == 0 || sph::wrap_index(c.x, g.nx) == g.nx - 1) ++tally.wrapped_rows;
    for (uint32_t j : candidates) {
      const float r2 = sph::length_squared(xi - sph::xyz(t.positions[j]));
      if (r2 < bound && j != i) kept.push_back(j);
      if (r2 == f.kernel.h2) ++tally.edge_pairs;
    }
    const bool overflow = candidates.size() > sph::kNeighborMaskCandidates;
    tally.overflowed += overflow;
    ok = ok && ((mask[sph::kNeighborMaskWords - 1] & sph::kNeighborMaskOverflow) != 0) == overflow;
    if (!overflow) {
      for (uint32_t k = 0; k < 32u * sph::kNeighborMaskWords; ++k) {
        const bool bit = (mask[k >> 5] >> (k & 31u)) & 1u;
        const bool expected =
            k < candidates.size() && std::find(kept.begin(), kept.end(), candidates[k]) != kept.end();
        ok = ok && bit == expected;
      }
    }
    // The masked walk's visits.
    std::vector<uint32_t> visited;
    sph::for_each_masked_neighbor(view, xi, mask, [&](uint32_t j) { visited.push_back(j); });
    ok = ok && visited == (overflow ? candidates : kept);
    std::vector<uint32_t> without;  // no mask: every candidate
    sph::for_each_masked_neighbor(view, xi, nullptr, [&](uint32_t j) { without.push_back(j); });
    ok = ok && without == candidates;
    // The list written from the mask: its count is the masked walk's, and the listed walk visits
    // what the masked walk does, in its order, from the list or (past 63) from the mask.
    sph::write_neighbor_list(view, xi, mask, lists.data(), stride, i);
    ok = ok && lists[i] == (overflow ? sph::kNeighborListSlots + 1u : visited.size());
    // The density pass's list: the same count and, where the list holds its visits, the same slots.
    // (Past the slots neither list is read: ListedCandidates walks the mask.)
    ok = ok && walked[i] == lists[i];
    if (lists[i] <= sph::kNeighborListSlots) {
      for (uint32_t slot = 1; slot <= lists[i]; ++slot)
        ok = ok &&
             walked[static_cast<size_t>(slot) * stride + i] == lists[static_cast<size_t>(slot) * stride + i];
      tally.walked_slots += lists[i];
    }
    tally.listed += visited.size() <= sph::kNeighborListSlots;
    tally.long_lists += !overflow && visited.size() > sph::kNeighborListSlots;
    const sph::ListedCandidates listed{masks.data(), lists.data(), stride};
    std::vector<uint32_t> listed_visits;
    listed(view, xi, i, [&](uint32_t j) { listed_visits.push_back(j); });
    ok = ok && listed_visits == visited;
    std::vector<uint32_t> unlisted;  // a world without lists: the masked walk
    sph::ListedCandidates{masks.data(), nullptr, 0}(view, xi, i, [&](uint32_t j) { unlisted.push_back(j); });
    ok = ok && unlisted == visited;
    // The solves' passes through both walks.
    const sph::MaskedCandidates masked{masks.data()};
    const float rate = sph::density_rate(f, view, t.positions.data(), t.velocities.data(), no_walls, i);
    const float rate_masked =
        sph::density_rate(f, view, t.positions.data(), t.velocities.data(), no_walls, i, masked);
    const Vec3 dv =
        sph::pressure_velocity_change<false>(f, view, t.positions.data(), t.k.data(), no_walls, i, dt);
    const Vec3 dv_masked = sph::pressure_velocity_change<false>(f, view, t.positions.data(), t.k.data(),
                                                                no_walls, i, dt, masked);
    // The corrected gradient's pass (SPH_DFSPH_CORRECTED_GRADIENT) through both walks.
    const Vec3 dvc =
        sph::pressure_velocity_change<true>(f, view, t.positions.data(), t.k.data(), no_walls, i, dt);
    const Vec3 dvc_masked =
        sph::pressure_velocity_change<true>(f, view, t.positions.data(), t.k.data(), no_walls, i, dt, masked);
    ok = ok && same_bits(rate, rate_masked) && same_bits(dv, dv_masked) && same_bits(dvc, dvc_masked);
    const float rate_listed =
        sph::density_rate(f, view, t.positions.data(), t.velocities.data(), no_walls, i, listed);
    const Vec3 dv_listed = sph::pressure_velocity_change<false>(f, view, t.positions.data(), t.k.data(),
                                                                no_walls, i, dt, listed);
    const Vec3 dvc_listed =
        sph::pressure_velocity_change<true>(f, view, t.positions.data(), t.k.data(), no_walls, i, dt, listed);
    ok = ok && same_bits(rate, rate_listed) && same_bits(dv, dv_listed) && same_bits(dvc, dvc_listed);
    ok = ok && (rate != 0.0f || plain.neighbor_count == 0);  // the passes saw neighbours
    if (!ok && tally.mismatches++ < 5)
      std::printf("  particle %u: %zu candidates, %zu kept, %zu visited\n", i, candidates.size(), kept.size(),
                  visited.size());
  }
  return tally;
}

std::vector<Vec3> uniform_cloud(uint32_t count, float extent, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, extent);
  std::vector<Vec3> points(count);
  for (Vec3& p : points) p = Vec3{u(rng), u(rng), u(rng)};
  return points;
}

// 7 h of cloud folded onto a 5-slot table: slots 0-1 hold two cells' particles, and the rows of
// the edge slots wrap. 6 particles a cell: 162 candidates where no axis folds, 384 where all three do.
void test_folded_table(void**) {
  const Table t(uniform_cloud(2058, 7.0f * kH, 1), 5, 2);
  const Tally r = check_table(t);
  std::printf("folded table: %u particles, %u overflowing, %u listed, %u in wrapping rows, %u mismatches\n",
              r.particles, r.overflowed, r.listed, r.wrapped_rows, r.mismatches);
  assert_int_equal(r.mismatches, 0);
  assert_true(r.overflowed > 0 && r.overflowed < r.particles);  // both kinds of particle exercised
  assert_true(r.listed > 0 && r.listed < r.particles);          // lists used, and walks past them
  assert_true(r.walked_slots > 0);
  assert_true(r.wrapped_rows > 0);
}

// A cubic lattice at h / 2 (exact in float): pairs two steps apart along an axis are at r^2 = h^2
// exactly, which the mask keeps and the passes' test drops. 8 particles a cell: 216 candidates.
void test_lattice_edges(void**) {
  std::vector<Vec3> points;
  for (int z = 0; z < 14; ++z)
    for (int y = 0; y < 14; ++y)
      for (int x = 0; x < 14; ++x)
        points.push_back(Vec3{0.5f * x + 0.25f, 0.5f * y + 0.25f, 0.5f * z + 0.25f});
  const Table t(points, 8, 3);
  const Tally r = check_table(t);
  std::printf(
      "lattice: %u particles, %u overflowing, %u listed, %u list slots compared, %u pairs at r = h, %u "
      "mismatches\n",
      r.particles, r.overflowed, r.listed, r.walked_slots, r.edge_pairs, r.mismatches);
  assert_int_equal(r.mismatches, 0);
  assert_int_equal(r.listed, r.particles);  // 33 to 44 visits a particle: every list holds them
  assert_true(r.walked_slots > 20u * r.particles);
  assert_true(r.edge_pairs > 0);
}

// 13 particles a cell (about 351 candidates and 54 neighbours): masks that hold (below 384
// candidates) with more than 63 visits, whose lists overflow and whose passes walk the masks,
// beside listed particles. Then masks made by hand with exactly 63 and 64 bits set: the first
// list is full and used, the second one past the slots.
void test_long_lists(void**) {
  const Table t(uniform_cloud(2808, 6.0f * kH, 6), 6, 7);
  const Tally r = check_table(t);
  std::printf(
      "long lists: %u particles, %u overflowing, %u listed, %u with more than 63 visits, %u mismatches\n",
      r.particles, r.overflowed, r.listed, r.long_lists, r.mismatches);
  assert_int_equal(r.mismatches, 0);
  assert_true(r.long_lists > 0 && r.listed > 0);
  const sph::GridView view = t.view();
  const uint32_t stride = t.size();
  std::vector<uint32_t> lists(static_cast<size_t>(stride) * sph::kNeighborListRows, 0xdeadbeefu);
  for (uint32_t bits : {sph::kNeighborListSlots, sph::kNeighborListSlots + 1u}) {
    uint32_t checked = 0;
    for (uint32_t i = 0; i < t.size(); i += 97) {
      const Vec3 xi = sph::xyz(t.positions[i]);
      uint32_t candidates = 0;
      sph::for_each_neighbor_range(view, xi, [&](uint32_t b, uint32_t e) { candidates += e - b; });
      if (candidates < bits || candidates > sph::kNeighborMaskCandidates) continue;
      uint32_t mask[sph::kNeighborMaskWords] = {};
      for (uint32_t k = 0; k < bits; ++k) mask[k >> 5] |= 1u << (k & 31u);  // the first `bits` candidates
      std::vector<uint32_t> masked, listed;
      sph::for_each_masked_neighbor(view, xi, mask, [&](uint32_t j) { masked.push_back(j); });
      sph::write_neighbor_list(view, xi, mask, lists.data(), stride, i);
      // A world of this one particle's mask: the listed walk reads masks + i * words.
      std::vector<uint32_t> masks(static_cast<size_t>(t.size()) * sph::kNeighborMaskWords, 0u);
      std::copy(mask, mask + sph::kNeighborMaskWords,
                masks.begin() + static_cast<std::ptrdiff_t>(i) * sph::kNeighborMaskWords);
      sph::ListedCandidates{masks.data(), lists.data(), stride}(view, xi, i,
                                                                [&](uint32_t j) { listed.push_back(j); });
      assert_int_equal(masked.size(), bits);
      assert_int_equal(lists[i], bits);
      assert_true(listed == masked);
      ++checked;
    }
    assert_true(checked > 10);  // of 29 particles tried
  }
}

// Few particles a cell, and a table larger than the cloud: short masks, most words zero.
void test_sparse(void**) {
  const Table t(uniform_cloud(300, 6.0f * kH, 4), 8, 5);
  const Tally r = check_table(t);
  std::printf("sparse: %u particles, %u overflowing, %u mismatches\n", r.particles, r.overflowed,
              r.mismatches);
  assert_int_equal(r.mismatches, 0);
  assert_int_equal(r.overflowed, 0);
}

}  // namespace

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_folded_table),
      cmocka_unit_test(test_lattice_edges),
      cmocka_unit_test(test_long_lists),
      cmocka_unit_test(test_sparse),
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
