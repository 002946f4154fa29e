// SPDX-License-Identifier: MIT
// The exact float sum behind DFSPH's mean error (src/core/exact_float_sum.h): exact where a
// running double sum rounds, the same bits in any order and from any split into partial sums
// (as the ranks of a distributed world split it), denormals exact, non-finite terms as a float sum has them.
// The references are integers and powers of two whose sums are known exactly.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "core/exact_float_sum.h"

namespace {

using sph::ExactFloatSum;

double sum_of(const std::vector<float>& terms) {
  ExactFloatSum s;
  for (float x : terms) s.add(x);
  return s.value();
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// 2^60 + 1 - 2^60: a running double sum loses the 1 (2^60 + 1 rounds to 2^60); the exact sum
// keeps it.
void test_exact_where_double_rounds(void**) {
  const float big = std::ldexp(1.0f, 60);
  double running = 0.0;
  for (float x : {big, 1.0f, -big}) running += x;
  assert_true(running == 0.0);
  assert_true(sum_of({big, 1.0f, -big}) == 1.0);
}

// Integers below 2^20 (exact as floats): the sum is their integer sum, exactly.
void test_integers(void**) {
  std::mt19937 random(7);
  std::vector<float> terms;
  int64_t want = 0;
  for (int i = 0; i < 100000; ++i) {
    const int32_t k = static_cast<int32_t>(random() % (1u << 20)) - (1 << 19);
    terms.push_back(static_cast<float>(k));
    want += k;
  }
  assert_true(sum_of(terms) == static_cast<double>(want));
}

// The smallest denormal three times, and a denormal plus the smallest normal.
void test_denormals(void**) {
  const float tiny = std::ldexp(1.0f, -149);
  assert_true(sum_of({tiny, tiny, tiny}) == std::ldexp(3.0, -149));
  assert_true(sum_of({tiny, std::ldexp(1.0f, -126)}) == std::ldexp(1.0, -126) + std::ldexp(1.0, -149));
}

// Terms over 40 decades: forward, backward, shuffled, and split into three partial sums whose
// bins are added (as all_sum adds the ranks'), all the same bits.
void test_order_and_split(void**) {
  std::mt19937 random(11);
  std::uniform_real_distribution<float> exponent(-30.0f, 10.0f);
  std::vector<float> terms;
  for (int i = 0; i < 20000; ++i) terms.push_back(std::pow(10.0f, exponent(random)));
  const double forward = sum_of(terms);
  std::vector<float> backward(terms.rbegin(), terms.rend());
  assert_true(same_bits(sum_of(backward), forward));
  std::shuffle(terms.begin(), terms.end(), random);
  assert_true(same_bits(sum_of(terms), forward));
  ExactFloatSum part[3];
  for (size_t i = 0; i < terms.size(); ++i) part[i % 3].add(terms[i]);
  for (int k = 0; k < ExactFloatSum::kTerms; ++k)
    part[0].terms()[k] += part[1].terms()[k] + part[2].terms()[k];
  assert_true(same_bits(part[0].value(), forward));
  // Within a double's rounding of the running sum (both near the exact value).
  double running = 0.0;
  for (float x : terms) running += x;
  assert_true(std::fabs(running - forward) <= 1e-12 * forward);
}

// Non-finite terms as a float sum treats them: NaN, or an infinity of one sign.
void test_non_finite(void**) {
  assert_true(std::isnan(sum_of({1.0f, NAN, 2.0f})));
  assert_true(sum_of({1.0f, INFINITY}) == HUGE_VAL);
  assert_true(sum_of({-INFINITY, 1.0f}) == -HUGE_VAL);
  assert_true(std::isnan(sum_of({INFINITY, -INFINITY})));
  assert_true(std::isnan(sum_of({INFINITY, NAN})));
  assert_true(sum_of({}) == 0.0);
}

}  // namespace

int main() {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_exact_where_double_rounds),
      cmocka_unit_test(test_integers),
      cmocka_unit_test(test_denormals),
      cmocka_unit_test(test_order_and_split),
      cmocka_unit_test(test_non_finite),
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
