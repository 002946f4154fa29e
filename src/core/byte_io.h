// SPDX-License-Identifier: MIT
// Little-endian byte streams for checkpoints: a growing writer, and a reader that checks every
// read against the bytes that remain, so hostile input can never make it read out of bounds
// or allocate more than the input could possibly describe.
#pragma once

#include <stddef.h>
#include <stdint.h>

#include <cstring>
#include <string>
#include <vector>

#include "host_memory.h"
#include "status.h"

namespace sph {

static_assert(sizeof(float) == 4 && sizeof(double) == 8, "IEEE 754 binary32/binary64 expected");

// FNV-1a, 64 bits: a few lines, no table, and every single-byte change of the input changes
// the result (each step is a bijection of the state), which is what corruption tests rely on.
class Fnv1a64 {
 public:
  void add(const void* data, size_t n) {
    const unsigned char* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) {
      hash_ ^= p[i];
      hash_ *= 0x100000001b3ull;
    }
  }
  uint64_t value() const { return hash_; }

 private:
  uint64_t hash_ = 0xcbf29ce484222325ull;
};

class ByteWriter {
 public:
  void u8(uint8_t v) { bytes_.push_back(v); }
  void u32(uint32_t v) {
    for (int k = 0; k < 4; ++k) bytes_.push_back(static_cast<uint8_t>(v >> (8 * k)));
  }
  void u64(uint64_t v) {
    for (int k = 0; k < 8; ++k) bytes_.push_back(static_cast<uint8_t>(v >> (8 * k)));
  }
  void f32(float v) {
    uint32_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    u32(bits);
  }
  void f64(double v) {
    uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    u64(bits);
  }
  void bytes(const void* data, size_t n) {
    const unsigned char* p = static_cast<const unsigned char*>(data);
    bytes_.insert(bytes_.end(), p, p + n);
  }
  // Overwrites 8 bytes at `at` (a length or a checksum filled in after the fact).
  void patch_u64(size_t at, uint64_t v) {
    for (int k = 0; k < 8; ++k) bytes_[at + k] = static_cast<uint8_t>(v >> (8 * k));
  }
  size_t size() const { return bytes_.size(); }
  HostVector<uint8_t>& buffer() { return bytes_; }

 private:
  HostVector<uint8_t> bytes_;
};

class ByteReader {
 public:
  // `what` names the region being read in error messages ("section 'particles'").
  ByteReader(const uint8_t* data, size_t size, std::string what)
      : p_(data), left_(size), what_(std::move(what)) {}

  size_t remaining() const { return left_; }
  const std::string& what() const { return what_; }

  // Throws unless n more bytes are there.
  void need(uint64_t n) const {
    if (n > left_)
      throw Error(Status::CorruptData, "checkpoint: truncated in " + what_ + " (needs " + std::to_string(n) +
                                           " bytes, " + std::to_string(left_) + " left)");
  }
  // Throws unless count elements of elem_size bytes each are there; checked before any
  // allocation and safe against overflow of count * elem_size.
  void need_elements(uint64_t count, uint64_t elem_size, const char* name) const {
    if (elem_size != 0 && count > left_ / elem_size)
      throw Error(Status::CorruptData, "checkpoint: truncated in " + what_ + ": " + std::to_string(count) +
                                           " " + name + " need " + std::to_string(count) + " x " +
                                           std::to_string(elem_size) + " bytes, " + std::to_string(left_) +
                                           " left");
  }

  uint8_t u8() {
    need(1);
    const uint8_t v = p_[0];
    advance(1);
    return v;
  }
  uint32_t u32() {
    need(4);
    uint32_t v = 0;
    for (int k = 0; k < 4; ++k) v |= static_cast<uint32_t>(p_[k]) << (8 * k);
    advance(4);
    return v;
  }
  uint64_t u64() {
    need(8);
    uint64_t v = 0;
    for (int k = 0; k < 8; ++k) v |= static_cast<uint64_t>(p_[k]) << (8 * k);
    advance(8);
    return v;
  }
  float f32() {
    const uint32_t bits = u32();
    float v;
    std::memcpy(&v, &bits, sizeof v);
    return v;
  }
  double f64() {
    const uint64_t bits = u64();
    double v;
    std::memcpy(&v, &bits, sizeof v);
    return v;
  }
  // A sub-reader over the next n bytes (a section body), which this reader skips.
  ByteReader sub(uint64_t n, std::string what) {
    need(n);
    ByteReader r(p_, static_cast<size_t>(n), std::move(what));
    advance(static_cast<size_t>(n));
    return r;
  }
  // Throws unless everything was read (a section longer than its contents is corrupt).
  void expect_end() const {
    if (left_ != 0)
      throw Error(Status::CorruptData,
                  "checkpoint: " + what_ + " has " + std::to_string(left_) + " unexpected trailing bytes");
  }

 private:
  void advance(size_t n) {
    p_ += n;
    left_ -= n;
  }
  const uint8_t* p_;
  size_t left_;
  std::string what_;
};

}  // namespace sph
