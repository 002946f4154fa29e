// SPDX-License-Identifier: MIT
// Internal error codes and the exception that carries them to the C layer. The values match
// sph_result one for one (checked in src/capi), but the core never sees sph_* types.
#pragma once

#include <stdexcept>
#include <string>

namespace sph {

enum class Status : int {
  Incomplete = 1,
  Ok = 0,
  InvalidArgument = -1,
  InvalidHandle = -2,
  VersionMismatch = -3,
  Unsupported = -4,
  FeatureDisabled = -5,
  Capacity = -6,
  OutOfHostMemory = -7,
  OutOfDeviceMemory = -8,
  WorldLocked = -9,
  Busy = -10,
  Device = -11,
  DeviceLost = -12,
  Internal = -13,
  BufferTooSmall = -14,
  NonFinite = -15,
  CorruptData = -16,
};

class Error : public std::runtime_error {
 public:
  Error(Status status, const std::string& message) : std::runtime_error(message), status_(status) {}
  Status status() const { return status_; }

 private:
  Status status_;
};

// Throws InvalidArgument with `message` unless `ok`: the input checks of the asset builders.
inline void require_argument(bool ok, const std::string& message) {
  if (!ok) throw Error(Status::InvalidArgument, message);
}

}  // namespace sph
