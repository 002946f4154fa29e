// SPDX-License-Identifier: MIT
// The preview's frame buffer: linear RGB in [0, 1] and a depth per pixel.
#ifndef SPH_TOOLS_IMAGE_H
#define SPH_TOOLS_IMAGE_H

#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

namespace sph_tools {

struct Image {
  uint32_t width = 0, height = 0;
  std::vector<float> rgb;    // 3 x width x height, row-major from the top
  std::vector<float> depth;  // distance along the view axis; +inf where nothing was drawn

  void resize(uint32_t w, uint32_t h) {
    width = w;
    height = h;
    rgb.assign(3 * static_cast<size_t>(w) * h, 0.0f);
    depth.assign(static_cast<size_t>(w) * h, std::numeric_limits<float>::infinity());
  }
};

// Writes an 8-bit RGB PNG (sRGB-encoded) with libpng to `out` (the caller opened it and closes
// it; `name` is for messages). Throws std::runtime_error.
void write_png(const Image& image, std::FILE* out, const std::string& name);
// Whether this build has libpng (write_png throws without it).
bool png_available();

}  // namespace sph_tools

#endif
