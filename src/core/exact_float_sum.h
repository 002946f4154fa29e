// SPDX-License-Identifier: MIT
// A sum of floats whose value does not depend on the order of the terms: each term's integer
// significand is added exactly into the bin of its binary exponent (int64 additions, which are
// associative), and the value is read from the bins in one fixed order (the only roundings:
// the bins' conversion to one double, the same for the same bins). Partial sums (one per
// thread, or per rank of a distributed world) combine by adding their bins, so DFSPH's mean
// error is the same bits in an undivided world and on any number of ranks (docs/distributed.md).
// A bin holds at most 2^24 per term, so 2^39 terms fit before it could overflow.
#pragma once

#include <stdint.h>
#include <string.h>

#include <cmath>
#include <limits>

#include "../physics/host_device.h"

namespace sph {

// Where a float (its bits) goes in an exact sum: the bin and the integer added there. Host and
// device (a distributed CUDA rank adds its DFSPH errors into the same bins on the device).
struct ExactFloatTerm {
  int bin;
  int64_t term;
};

SPH_HD ExactFloatTerm exact_float_term(uint32_t bits) {
  const uint32_t exponent = (bits >> 23) & 0xffu;
  const bool negative = (bits >> 31) != 0;
  if (exponent == 0xffu)  // as IEEE sums them: NaN beats inf, +inf and -inf make NaN
    return ExactFloatTerm{(bits & 0x7fffffu) != 0 ? 255 : (negative ? 257 : 256), 1};
  int64_t significand = bits & 0x7fffffu;
  if (exponent != 0) significand |= 0x800000;  // the implicit bit of a normal float
  return ExactFloatTerm{static_cast<int>(exponent), negative ? -significand : significand};
}

class ExactFloatSum {
 public:
  // The bins and the counts of NaN, +inf and -inf terms, for a reduction that adds them (all_sum).
  static constexpr int kTerms = 258;

  void add(float x) {
    uint32_t bits;
    memcpy(&bits, &x, sizeof bits);
    const ExactFloatTerm t = exact_float_term(bits);
    terms_[t.bin] += t.term;
  }
  int64_t* terms() { return terms_; }

  // The sum, from the smallest exponent's bin up (each bin a double times its power of two).
  double value() const {
    const bool plus = terms_[kPlusInf] != 0, minus = terms_[kMinusInf] != 0;
    if (terms_[kNan] != 0 || (plus && minus)) return std::numeric_limits<double>::quiet_NaN();
    if (plus || minus) return plus ? HUGE_VAL : -HUGE_VAL;
    double sum = 0.0;
    for (int e = 0; e < kNan; ++e)
      if (terms_[e] != 0) sum += std::ldexp(static_cast<double>(terms_[e]), (e == 0 ? 1 : e) - 150);
    return sum;
  }

 private:
  // After the 255 exponents' bins (exact_float_term's).
  static constexpr int kNan = 255, kPlusInf = 256, kMinusInf = 257;
  int64_t terms_[kTerms] = {};
};

}  // namespace sph
