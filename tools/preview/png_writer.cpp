// SPDX-License-Identifier: MIT
// PNG files through libpng (in builds that found it).
#ifdef SPH_TOOLS_HAVE_PNG
#include <png.h>
#endif

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "image.h"

namespace sph_tools {

#ifdef SPH_TOOLS_HAVE_PNG
bool png_available() { return true; }

namespace {

// Linear [0, 1] to 8-bit sRGB through a table of 4096 steps (finer than 8 bits everywhere
// except the darkest shades, which the table's linear segment covers exactly).
unsigned char encode_srgb(float linear) {
  static const std::vector<unsigned char> table = [] {
    std::vector<unsigned char> t(4097);
    for (size_t i = 0; i < t.size(); ++i) {
      const double c = static_cast<double>(i) / 4096.0;
      const double s = c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
      t[i] = static_cast<unsigned char>(std::lround(255.0 * s));
    }
    return t;
  }();
  const float c = std::clamp(linear, 0.0f, 1.0f);
  return table[static_cast<size_t>(c * 4096.0f + 0.5f)];
}

// libpng reports errors by longjmp, so this function holds no object with a destructor.
bool encode(std::FILE* file, const unsigned char* pixels, uint32_t width, uint32_t height) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  if (!png) return false;
  png_infop info = png_create_info_struct(png);
  if (!info || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_init_io(png, file);
  png_set_IHDR(png, info, width, height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_compression_level(png, 1);  // fast: a preview is written every frame
  png_set_filter(png, 0, PNG_FILTER_SUB);
  png_set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
  png_write_info(png, info);
  for (uint32_t y = 0; y < height; ++y) png_write_row(png, pixels + 3 * static_cast<size_t>(width) * y);
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  return true;
}

}  // namespace

void write_png(const Image& image, std::FILE* out, const std::string& name) {
  std::vector<unsigned char> pixels(image.rgb.size());
  for (size_t i = 0; i < pixels.size(); ++i) pixels[i] = encode_srgb(image.rgb[i]);
  if (!encode(out, pixels.data(), image.width, image.height) || std::fflush(out) != 0 || std::ferror(out))
    throw std::runtime_error("cannot write " + name + ": libpng or the file failed (" + std::strerror(errno) +
                             ")");
}

#else
bool png_available() { return false; }

void write_png(const Image&, std::FILE*, const std::string& name) {
  throw std::runtime_error("cannot write " + name + ": this build has no libpng");
}
#endif

}  // namespace sph_tools
