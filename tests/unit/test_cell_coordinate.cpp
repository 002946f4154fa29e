// SPDX-License-Identifier: MIT
// The grid's cell along one axis (src/physics/grid_hash.h, cell_coordinate): floor(x / h), clamped
// to +-2^30, with denormal inputs and products flushed to zero by hand, so that a CUDA file compiled
// with -ftz=true (the density pass, which writes DFSPH's neighbour masks over its cells' runs) and
// one compiled with IEEE arithmetic (the conjugate gradients' solves, which walk those masks) put a
// particle in the same cell. The expected cells are worked by hand from the flush rule: a denormal
// is zero, so its cell is 0 whatever its sign; the smallest normal numbers keep IEEE's floor.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

#include <cfloat>
#include <cmath>
#include <limits>

#include "physics/grid_hash.h"

namespace {

using sph::cell_coordinate;

// Kept out of constant folding, so the arithmetic is the library's at run time.
volatile float g_inv_cell_size = 50.0f;  // h = 2 cm

void test_normal_values_are_floor(void**) {
  const float inv = g_inv_cell_size;
  assert_int_equal(cell_coordinate(0.0f, inv), 0);
  assert_int_equal(cell_coordinate(-0.0f, inv), 0);
  assert_int_equal(cell_coordinate(0.019f, inv), 0);
  assert_int_equal(cell_coordinate(0.021f, inv), 1);
  assert_int_equal(cell_coordinate(-0.001f, inv), -1);
  assert_int_equal(cell_coordinate(-0.041f, inv), -3);
  // The smallest normal numbers are not flushed: -FLT_MIN times 50 is a normal negative number.
  assert_int_equal(cell_coordinate(-FLT_MIN, inv), -1);
  assert_int_equal(cell_coordinate(-1e-30f, inv), -1);
  assert_int_equal(cell_coordinate(FLT_MIN, inv), 0);
}

void test_denormal_inputs_are_cell_zero(void**) {
  const float inv = g_inv_cell_size;
  const float tiny = std::numeric_limits<float>::denorm_min();
  // IEEE alone: floor(-1e-40 * 50) = floor(-5e-39) = -1; -ftz: -0, cell 0. The flush gives 0.
  assert_true(std::fpclassify(-1e-40f) == FP_SUBNORMAL);
  assert_int_equal(cell_coordinate(-1e-40f, inv), 0);
  assert_int_equal(cell_coordinate(1e-40f, inv), 0);
  assert_int_equal(cell_coordinate(-tiny, inv), 0);
  assert_int_equal(cell_coordinate(-FLT_MIN * 0.5f, inv), 0);
}

void test_denormal_products_are_cell_zero(void**) {
  // A normal input whose product with 1 / h is denormal: -1e-30 * 1e-10 = -1e-40 (IEEE: cell -1).
  volatile float small_inv = 1e-10f;
  const float inv = small_inv;
  assert_true(std::fpclassify(-1e-30f * inv) == FP_SUBNORMAL);
  assert_int_equal(cell_coordinate(-1e-30f, inv), 0);
  // A product that stays normal keeps its floor.
  assert_int_equal(cell_coordinate(-1e-20f, inv), -1);
}

void test_large_values_are_clamped(void**) {
  const float inv = g_inv_cell_size;
  assert_int_equal(cell_coordinate(1e30f, inv), 1073741824);
  assert_int_equal(cell_coordinate(-1e30f, inv), -1073741824);
  assert_int_equal(cell_coordinate(std::numeric_limits<float>::infinity(), inv), 1073741824);
}

}  // namespace

int main() {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_normal_values_are_floor),
      cmocka_unit_test(test_denormal_inputs_are_cell_zero),
      cmocka_unit_test(test_denormal_products_are_cell_zero),
      cmocka_unit_test(test_large_values_are_clamped),
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
