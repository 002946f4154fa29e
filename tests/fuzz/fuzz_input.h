// SPDX-License-Identifier: MIT
// FuzzInput: the fuzzer's bytes read as a stream of small decisions. Once the bytes run out every
// read returns zero, so a harness never reads past its input and short inputs stay meaningful.
#ifndef SPH_FUZZ_INPUT_H
#define SPH_FUZZ_INPUT_H

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>

namespace sph_fuzz {

class FuzzInput {
 public:
  FuzzInput(const uint8_t* data, size_t size) : data_(data), size_(size) {}

  bool empty() const { return at_ >= size_; }
  size_t remaining() const { return at_ < size_ ? size_ - at_ : 0; }

  uint8_t u8() { return at_ < size_ ? data_[at_++] : 0; }
  uint16_t u16() { return static_cast<uint16_t>(u8() | (u8() << 8)); }
  uint32_t u32() { return static_cast<uint32_t>(u16()) | (static_cast<uint32_t>(u16()) << 16); }
  uint64_t u64() { return static_cast<uint64_t>(u32()) | (static_cast<uint64_t>(u32()) << 32); }
  bool chance(uint8_t in_256) { return u8() < in_256; }

  // A value in [lo, hi] (inclusive), lo <= hi.
  uint32_t range(uint32_t lo, uint32_t hi) {
    const uint64_t span = static_cast<uint64_t>(hi) - lo + 1;
    return lo + static_cast<uint32_t>(u32() % span);
  }

  // A float in [lo, hi] in 1/65535 steps: the well-behaved values most calls get.
  float unit(float lo, float hi) { return lo + (hi - lo) * (static_cast<float>(u16()) / 65535.0f); }

  // A hostile float: NaN, infinities, zeros, huge, tiny, denormal, negative, or raw bits.
  float hostile() {
    switch (u8() % 12) {
      case 0:
        return std::numeric_limits<float>::quiet_NaN();
      case 1:
        return std::numeric_limits<float>::infinity();
      case 2:
        return -std::numeric_limits<float>::infinity();
      case 3:
        return 0.0f;
      case 4:
        return -0.0f;
      case 5:
        return 3.0e38f;
      case 6:
        return -3.0e38f;
      case 7:
        return std::numeric_limits<float>::denorm_min();
      case 8:
        return 1.0e-30f;
      case 9:
        return -1.0f;
      case 10:
        return 1.0e7f;
      default: {
        const uint32_t bits = u32();
        float f;
        std::memcpy(&f, &bits, sizeof f);
        return f;
      }
    }
  }

  // Mostly a value in [lo, hi]; one time in eight a hostile one.
  float maybe_hostile(float lo, float hi) { return chance(32) ? hostile() : unit(lo, hi); }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t at_ = 0;
};

}  // namespace sph_fuzz

#endif
