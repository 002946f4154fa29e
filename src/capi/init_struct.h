// SPDX-License-Identifier: MIT
// The body of every *_init_sized function: check the caller's size, start from a struct with
// every byte zero and struct_size set, let `fill` write the defaults, and copy it out.
#pragma once

#include <cstring>

#include "guard.h"
#include "struct_io.h"

namespace sph {

template <class T>
T zeroed_struct() {
  T d;
  std::memset(&d, 0, sizeof d);
  d.struct_size = sizeof d;
  return d;
}

template <class T, class Fill>
sph_result init_user_struct(const char* function, const char* name, T* user, uint32_t size, Fill&& fill) {
  return guarded(function, nullptr, [&] {
    require_init_size(user, size, name);
    T d = zeroed_struct<T>();
    fill(d);
    write_user_struct(user, size, d);
    return SPH_OK;
  });
}

template <class T>
sph_result init_user_struct(const char* function, const char* name, T* user, uint32_t size) {
  return init_user_struct(function, name, user, size, [](T&) {});
}

}  // namespace sph
