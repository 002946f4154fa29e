// SPDX-License-Identifier: MIT
// A CPU rank's own table (rank_grid_shape, src/core/grid_layout.h): the undivided world's table cut
// to the band of cells the rank holds along the slabs' axis. The ranks' sums equal the undivided
// world's bit for bit only if each owned particle's neighbour walk visits the same cells in the
// same runs (the CPU's SIMD lanes restart at each run: a row of three cells is one run, or two
// where the table wraps inside it). Checked here by walking both tables with the real walk
// (for_each_neighbor_range) over a table whose every slot holds one particle, its own index: for
// every owned cell and many worlds, bands and axes, the runs name the same cells in the same
// order, split in the same places; the band's cells are distinct slots; and a rank that owns
// nothing, a folded world or a band as wide as the world keeps the world's table.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

#include <map>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "core/grid_layout.h"
#include "physics/neighbor_walk.h"

namespace {

using sph::CellCoord;
using sph::GridShape;

constexpr float kH = 1.0f;  // cell size 1: a cell's centre is its coordinate + 0.5

int32_t axis_of(const CellCoord& c, int axis) { return axis == 0 ? c.x : (axis == 1 ? c.y : c.z); }

// The walk's runs around cell c, each as the cells it visits in order: a run [begin, end) of a
// table where slot k holds particle k names the slots begin..end-1, and each slot is the one cell
// of c's 3x3x3 block that hashes there (the tables do not fold).
std::vector<std::vector<CellCoord>> runs_around(const GridShape& g, CellCoord c) {
  std::map<uint32_t, CellCoord> cell_of_slot;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const CellCoord n{c.x + dx, c.y + dy, c.z + dz};
        const uint32_t slot = sph::cell_hash(g, n);
        // Two cells of one block in one slot: the table folds there.
        assert_true(cell_of_slot.emplace(slot, n).second);
      }
  std::vector<uint32_t> starts(static_cast<size_t>(g.cell_count) + 1);
  for (uint32_t k = 0; k <= g.cell_count; ++k) starts[k] = k;
  const sph::GridView view{g, starts.data()};
  std::vector<std::vector<CellCoord>> runs;
  const sph::Vec3 p{c.x + 0.5f, c.y + 0.5f, c.z + 0.5f};
  sph::for_each_neighbor_range(view, p, [&](uint32_t begin, uint32_t end) {
    std::vector<CellCoord> run;
    for (uint32_t k = begin; k < end; ++k) {
      const auto found = cell_of_slot.find(k);
      assert_true(found != cell_of_slot.end());  // a run covers only the block's cells
      run.push_back(found->second);
    }
    runs.push_back(run);
  });
  return runs;
}

bool same_runs(const std::vector<std::vector<CellCoord>>& a, const std::vector<std::vector<CellCoord>>& b) {
  if (a.size() != b.size()) return false;
  for (size_t r = 0; r < a.size(); ++r) {
    if (a[r].size() != b[r].size()) return false;
    for (size_t k = 0; k < a[r].size(); ++k)
      if (a[r][k].x != b[r][k].x || a[r][k].y != b[r][k].y || a[r][k].z != b[r][k].z) return false;
  }
  return true;
}

struct Case {
  CellCoord lo, hi;
  int axis;
  int32_t first, last, held_first, held_last;
};

// Checks one case; returns whether the rank got a table of its own (narrower than the world's).
bool check_case(const Case& k) {
  const uint32_t count = 1000000;  // enough slots that the world's table does not fold
  const GridShape world = sph::make_grid_shape_for_extent(kH, k.lo, k.hi, count);
  const GridShape rank =
      sph::rank_grid_shape(world, k.lo, k.hi, k.axis, k.first, k.last, k.held_first, k.held_last);
  if (rank.cell_count == world.cell_count) return false;
  assert_true(rank.cell_count < world.cell_count);
  // The band's cells (at a fixed row and column of the other axes) are distinct slots.
  std::set<uint32_t> slots;
  const int32_t band_first = std::min(k.held_first, k.first - 1),
                band_last = std::max(k.held_last, k.last + 1);
  for (int32_t a = band_first; a <= band_last; ++a) {
    CellCoord c = k.lo;
    if (k.axis == 0) c.x = a;
    if (k.axis == 1) c.y = a;
    if (k.axis == 2) c.z = a;
    assert_true(slots.insert(sph::cell_hash(rank, c)).second);
  }
  // A walk from outside the band (a probe point beyond the rank's particles) meets band cells only
  // three or more cells away (particles 2 h or more away, far from the r < h test's rounding).
  for (int32_t a = band_first - 3; a <= band_last + 3; ++a) {
    if (a >= band_first && a <= band_last) continue;
    for (int32_t d = -1; d <= 1; ++d)
      for (int32_t q = band_first; q <= band_last; ++q) {
        CellCoord probe = k.lo, cell = k.lo;
        if (k.axis == 0) probe.x = a + d, cell.x = q;
        if (k.axis == 1) probe.y = a + d, cell.y = q;
        if (k.axis == 2) probe.z = a + d, cell.z = q;
        if (sph::cell_hash(rank, probe) == sph::cell_hash(rank, cell) && q != a + d)
          assert_true(q - a >= 3 || a - q >= 3);
      }
  }
  // Every owned cell's walk: the same runs of the same cells (the other axes at their span's ends,
  // where the world's table may wrap too).
  for (int32_t a = k.first; a <= k.last; ++a)
    for (int u = 0; u < 2; ++u) {
      CellCoord c = u == 0 ? CellCoord{k.lo.x, k.hi.y, k.lo.z} : CellCoord{k.hi.x, k.lo.y, k.hi.z};
      if (k.axis == 0) c.x = a;
      if (k.axis == 1) c.y = a;
      if (k.axis == 2) c.z = a;
      assert_int_equal(axis_of(c, k.axis), a);
      assert_true(same_runs(runs_around(world, c), runs_around(rank, c)));
    }
  return true;
}

void test_random_bands(void**) {
  std::mt19937 rng(20261206);
  int own = 0, split_in_band = 0;
  for (int t = 0; t < 3000; ++t) {
    std::uniform_int_distribution<int32_t> origin(-40, 40), span(0, 30), axis_pick(0, 2);
    Case k;
    k.lo = CellCoord{origin(rng), origin(rng), origin(rng)};
    k.hi = CellCoord{k.lo.x + span(rng), k.lo.y + span(rng), k.lo.z + span(rng)};
    k.axis = axis_pick(rng);
    const int32_t lo = axis_of(k.lo, k.axis), hi = axis_of(k.hi, k.axis);
    std::uniform_int_distribution<int32_t> in(lo, hi);
    k.first = in(rng);
    k.last = std::uniform_int_distribution<int32_t>(k.first, hi)(rng);
    // Ghosts one layer out, or further where the rank's slab reaches past its owned cells.
    k.held_first = std::uniform_int_distribution<int32_t>(lo - 1, k.first)(rng);
    k.held_last = std::uniform_int_distribution<int32_t>(k.last, hi + 1)(rng);
    if (check_case(k)) {
      ++own;
      // Does the world wrap inside a row the rank walks (the band then wraps there too)?
      const GridShape world = sph::make_grid_shape_for_extent(kH, k.lo, k.hi, 1000000);
      const int32_t n = k.axis == 0 ? world.nx : (k.axis == 1 ? world.ny : world.nz);
      for (int32_t a = k.first; a <= k.last + 1; ++a)
        if (sph::wrap_index(a, n) == 0) ++split_in_band;
    }
  }
  // The draw covers both kinds of band (counts printed for the record; each is far from zero).
  printf("rank tables of their own: %d of 3000; with the world's wrap point inside: %d\n", own,
         split_in_band);
  assert_true(own > 1000);
  assert_true(split_in_band > 100);
}

void test_world_table_kept(void**) {
  const CellCoord lo{0, 0, 0}, hi{20, 10, 10};
  const GridShape world = sph::make_grid_shape_for_extent(kH, lo, hi, 1000000);
  // Owning nothing (last < first), or a band as wide as the world's axis: the world's table.
  GridShape g = sph::rank_grid_shape(world, lo, hi, 0, 5, 4, 5, 4);
  assert_int_equal(g.cell_count, world.cell_count);
  g = sph::rank_grid_shape(world, lo, hi, 0, 0, 20, -1, 21);
  assert_int_equal(g.cell_count, world.cell_count);
  // A world whose table folds (2 slots a particle for 100 particles over 21 x 11 x 11 cells).
  const GridShape folded = sph::make_grid_shape_for_extent(kH, lo, hi, 100);
  assert_true(folded.nx < hi.x - lo.x + 3 || folded.ny < hi.y - lo.y + 3 || folded.nz < hi.z - lo.z + 3);
  g = sph::rank_grid_shape(folded, lo, hi, 0, 5, 8, 4, 9);
  assert_int_equal(g.cell_count, folded.cell_count);
  assert_int_equal(g.nx, folded.nx);
  // A narrow band of the unfolded world: 6 cells (4..9) along x instead of 23.
  g = sph::rank_grid_shape(world, lo, hi, 0, 5, 8, 4, 9);
  assert_int_equal(g.nx, 6);
  // One owned layer and no ghosts: 3 cells read, 4 slots (the least).
  g = sph::rank_grid_shape(world, lo, hi, 0, 7, 7, 7, 7);
  assert_int_equal(g.nx, 4);
  assert_int_equal(g.ny, world.ny);
  assert_int_equal(g.nz, world.nz);
}

}  // namespace

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_random_bands),
      cmocka_unit_test(test_world_table_kept),
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
