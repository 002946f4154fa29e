// SPDX-License-Identifier: MIT
// Reading caller structs by their struct_size (the kernel's copy_struct_from_user rule):
// smaller than the struct's first released size is a version mismatch; between that and ours
// (a caller built against an older header) the fields it does not have read as zero, which
// keeps the old behaviour since fields are only appended and zero means the old behaviour;
// larger than ours is accepted only if the extra bytes are zero.
#pragma once

#include <cstring>
#include <string>

#include "../core/status.h"
#include "sph_c.h"

namespace sph {

// The size of a public struct in the first release that had it. A struct that grows gets a
// specialisation with its old size (docs/versioning.md), so callers built against the older
// header keep working:
//   template <> inline constexpr uint32_t kFirstStructSize<sph_context_def> = 40;
// (inline: an explicit specialisation of a variable template is not inline by itself, and
// clang then defines it in every object that includes this header: a duplicate at link time.)
template <class T>
inline constexpr uint32_t kFirstStructSize = static_cast<uint32_t>(sizeof(T));

// Structs that grew after their first release, with the size they had then.
template <>
inline constexpr uint32_t kFirstStructSize<sph_context_def> =
    24 + 2 * sizeof(void*);  // 0.1.0; 0.2.0 adds the CUDA tuning
template <>
inline constexpr uint32_t kFirstStructSize<sph_world_def> =
    40;  // 0.1.0; 0.2.0 adds the solver, then max_capacity (44 and 48)
template <>
inline constexpr uint32_t kFirstStructSize<sph_world_params> = 48;  // 0.1.0; 0.2.0 adds tension_ratio (52)
template <>
inline constexpr uint32_t kFirstStructSize<sph_stats> =
    104;  // 0.1.0; 0.2.0 adds DFSPH's solves, then the capacity (144 and 160)

// No public struct comes near this size. A larger struct_size is garbage, not a newer header:
// it is refused rather than read (its bytes past ours are checked to be zero one by one, and
// _init_sized clears `size` bytes).
constexpr uint32_t kMaxStructSize = 64u * 1024u;

inline void require_plausible_struct_size(uint32_t size, const char* name, const char* field) {
  if (size > kMaxStructSize)
    throw Error(Status::InvalidArgument, std::string(name) + field + std::to_string(size) +
                                             " is larger than any sph struct (64 KiB); fill the struct "
                                             "with its _init() function");
}

template <class T>
T read_user_struct(const T* user, const char* name) {
  if (!user) throw Error(Status::InvalidArgument, std::string(name) + ": is NULL");
  const uint32_t size = user->struct_size;
  require_plausible_struct_size(size, name, "->struct_size: ");
  if (size < kFirstStructSize<T>)
    throw Error(Status::VersionMismatch, std::string(name) + "->struct_size: " + std::to_string(size) +
                                             " is smaller than " + std::to_string(kFirstStructSize<T>) +
                                             "; fill the struct with its _init() function");
  if (size < sizeof(T)) {
    T copy;
    std::memset(&copy, 0, sizeof copy);
    std::memcpy(&copy, user, size);
    copy.struct_size = sizeof(T);
    return copy;
  }
  const unsigned char* bytes = reinterpret_cast<const unsigned char*>(user);
  for (uint32_t i = sizeof(T); i < size; ++i)
    if (bytes[i] != 0)
      throw Error(Status::Unsupported,
                  std::string(name) + "->struct_size: " + std::to_string(size) +
                      " has fields this library version does not know, and they are not zero");
  T copy;
  std::memcpy(&copy, user, sizeof(T));
  return copy;
}

// For _init_sized(): zero the caller's whole struct, then fill the prefix both know (an older
// caller's struct is shorter than ours).
template <class T>
void write_user_struct(T* user, uint32_t size, const T& value) {
  std::memset(user, 0, size);
  std::memcpy(user, &value, size < sizeof(T) ? size : sizeof(T));
  user->struct_size = size;
}

template <class T>
void require_init_size(const T* user, uint32_t size, const char* name) {
  if (!user) throw Error(Status::InvalidArgument, std::string(name) + ": is NULL");
  require_plausible_struct_size(size, name, ": size ");
  if (size < kFirstStructSize<T>)
    throw Error(Status::VersionMismatch, std::string(name) + ": size " + std::to_string(size) +
                                             " is smaller than " + std::to_string(kFirstStructSize<T>));
}

// Output structs: the caller sets struct_size; we write min(that, ours) bytes.
template <class T>
void write_output_struct(T* user, const T& value, const char* name) {
  if (!user) throw Error(Status::InvalidArgument, std::string(name) + ": is NULL");
  const uint32_t size = user->struct_size;
  if (size < sizeof(uint32_t) * 2)
    throw Error(Status::VersionMismatch, std::string(name) + "->struct_size: " + std::to_string(size) +
                                             " is too small; fill the struct with its _init() function");
  const size_t n = size < sizeof(T) ? size : sizeof(T);
  std::memcpy(user, &value, n);
  user->struct_size = size;
}

}  // namespace sph
