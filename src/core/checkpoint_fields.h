// SPDX-License-Identifier: MIT
// Field readers of the checkpoint reader's files: each reads one value and refuses what the
// format does not allow as corrupt data, naming the field (checkpoint_reader.cpp,
// checkpoint_scene_reader.cpp, checkpoint_particles_reader.cpp).
#pragma once

#include <cmath>
#include <cstdio>
#include <string>

#include "../physics/methods.h"
#include "../physics/rigid_transform.h"
#include "byte_io.h"
#include "checkpoint_format.h"
#include "status.h"

namespace sph {
namespace checkpoint_read {

using namespace checkpoint;

[[noreturn]] inline void corrupt(const std::string& message) {
  throw Error(Status::CorruptData, "checkpoint: " + message);
}

inline std::string hex32(uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08x", v);
  return buf;
}

// Field readers that validate as they go; `name` is the field's path in messages.
inline float finite(ByteReader& r, const std::string& name) {
  const float v = r.f32();
  if (!std::isfinite(v)) corrupt(r.what() + ": " + name + " is not finite");
  return v;
}

inline float non_negative(ByteReader& r, const std::string& name) {
  const float v = finite(r, name);
  if (v < 0.0f) corrupt(r.what() + ": " + name + " is negative (" + std::to_string(v) + ")");
  return v;
}

// A maximum of |v| or |a| over finite vectors: non-negative, and +infinity when a squared
// length overflows float32 (a particle spawned at 2e19 m/s has finite components but an
// infinite |v|^2); never NaN. The writer saves what the world carries, so this accepts
// exactly that.
inline float magnitude_max(ByteReader& r, const std::string& name) {
  const float v = r.f32();
  if (std::isnan(v) || v < 0.0f) corrupt(r.what() + ": " + name + " is negative or not a number");
  return v;
}

inline float positive(ByteReader& r, const std::string& name) {
  const float v = finite(r, name);
  if (!(v > 0.0f)) corrupt(r.what() + ": " + name + " must be > 0, is " + std::to_string(v));
  return v;
}

inline uint32_t flag(ByteReader& r, const std::string& name) {
  const uint32_t v = r.u32();
  if (v > 1) corrupt(r.what() + ": " + name + " is " + std::to_string(v) + ", not 0 or 1");
  return v;
}

inline uint32_t below(ByteReader& r, uint32_t limit, const std::string& name) {
  const uint32_t v = r.u32();
  if (v >= limit)
    corrupt(r.what() + ": " + name + " is " + std::to_string(v) + ", not below " + std::to_string(limit));
  return v;
}

// A value of a world-def field that selects one method of the list (physics/methods.h).
inline uint32_t method(ByteReader& r, SwitchKind kind, const std::string& name) {
  const uint32_t v = r.u32();
  if (!selects_a_method(kind, v))
    corrupt(r.what() + ": " + name + " is " + std::to_string(v) + ", no method of this library");
  return v;
}

inline void zero(ByteReader& r, const std::string& name) {
  if (r.u32() != 0) corrupt(r.what() + ": " + name + " is reserved and must be 0");
}

// A pose as stored; the scene's rules (pose_rules.h) check it where the object is made.
inline RigidTransform raw_pose(ByteReader& r) {
  RigidTransform t;
  t.position.x = r.f32();
  t.position.y = r.f32();
  t.position.z = r.f32();
  t.rotation.x = r.f32();
  t.rotation.y = r.f32();
  t.rotation.z = r.f32();
  t.rotation.w = r.f32();
  return t;
}

inline Vec3 raw_vec3(ByteReader& r) {
  Vec3 v;
  v.x = r.f32();
  v.y = r.f32();
  v.z = r.f32();
  return v;
}

// Bulk floats: the message is built only on failure (a checkpoint may hold millions).
inline float bulk_finite(ByteReader& r, const char* what, uint32_t index) {
  const float v = r.f32();
  if (!std::isfinite(v)) corrupt(r.what() + ": " + what + " " + std::to_string(index) + " is not finite");
  return v;
}

inline Float4 float4(ByteReader& r, const char* what, uint32_t index) {
  Float4 v;
  v.x = bulk_finite(r, what, index);
  v.y = bulk_finite(r, what, index);
  v.z = bulk_finite(r, what, index);
  v.w = bulk_finite(r, what, index);
  return v;
}

inline Vec3 bulk_vec3(ByteReader& r, const char* what, uint32_t index) {
  Vec3 v;
  v.x = bulk_finite(r, what, index);
  v.y = bulk_finite(r, what, index);
  v.z = bulk_finite(r, what, index);
  return v;
}

}  // namespace checkpoint_read
}  // namespace sph
