// SPDX-License-Identifier: MIT
// A number as an error message shows it: the shortest of fixed and exponent form, ten digits, so
// that a message names the bound the code checks ("1e+15", "0.5") rather than a copy of it.
#pragma once

#include <cstdio>
#include <string>

namespace sph {

inline std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

}  // namespace sph
