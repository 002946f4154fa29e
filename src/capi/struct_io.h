// Reading caller structs by their struct_size (the kernel's copy_struct_from_user rule):
// smaller than the first version is a version mismatch; larger than ours is accepted only if
// the extra bytes are zero.
#pragma once

#include <cstring>
#include <string>

#include "../core/status.h"

namespace sph {

template <class T>
T read_user_struct(const T* user, const char* name) {
  if (!user) throw Error(Status::InvalidArgument, std::string(name) + ": is NULL");
  const uint32_t size = user->struct_size;
  if (size < sizeof(T))
    throw Error(Status::VersionMismatch, std::string(name) + "->struct_size: " + std::to_string(size) +
                                             " is smaller than " + std::to_string(sizeof(T)) +
                                             "; fill the struct with its _init() function");
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

// For _init_sized(): zero the caller's whole struct, then fill our known prefix.
template <class T>
void write_user_struct(T* user, uint32_t size, const T& value) {
  std::memset(user, 0, size);
  std::memcpy(user, &value, sizeof(T));
  user->struct_size = size;
}

template <class T>
void require_init_size(const T* user, uint32_t size, const char* name) {
  if (!user) throw Error(Status::InvalidArgument, std::string(name) + ": is NULL");
  if (size < sizeof(T))
    throw Error(Status::VersionMismatch, std::string(name) + ": size " + std::to_string(size) +
                                             " is smaller than " + std::to_string(sizeof(T)));
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
