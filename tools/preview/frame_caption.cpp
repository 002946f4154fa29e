// SPDX-License-Identifier: MIT
#include "frame_caption.h"

#include <algorithm>
#include <cstdio>

#include "shading.h"

namespace sph_tools {

namespace {

struct Glyph {
  char c;
  uint8_t rows[7];  // bit 4 is the leftmost of 5 columns
};

// The characters the caption and the legend use.
constexpr Glyph kFont[] = {
    {'0', {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}}, {'1', {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E}},
    {'2', {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}}, {'3', {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E}},
    {'4', {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}}, {'5', {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E}},
    {'6', {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}}, {'7', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
    {'8', {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}}, {'9', {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}},
    {'.', {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C}}, {'-', {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00}},
    {'=', {0x00, 0x00, 0x1F, 0x00, 0x1F, 0x00, 0x00}}, {'/', {0x01, 0x02, 0x02, 0x04, 0x08, 0x08, 0x10}},
    {'(', {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02}}, {')', {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08}},
    {'a', {0x00, 0x00, 0x0E, 0x01, 0x0F, 0x11, 0x0F}}, {'c', {0x00, 0x00, 0x0E, 0x10, 0x10, 0x11, 0x0E}},
    {'d', {0x01, 0x01, 0x0D, 0x13, 0x11, 0x11, 0x0F}}, {'e', {0x00, 0x00, 0x0E, 0x11, 0x1F, 0x10, 0x0E}},
    {'f', {0x06, 0x09, 0x08, 0x1C, 0x08, 0x08, 0x08}}, {'i', {0x04, 0x00, 0x0C, 0x04, 0x04, 0x04, 0x0E}},
    {'l', {0x0C, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E}}, {'m', {0x00, 0x00, 0x1A, 0x15, 0x15, 0x11, 0x11}},
    {'n', {0x00, 0x00, 0x16, 0x19, 0x11, 0x11, 0x11}}, {'o', {0x00, 0x00, 0x0E, 0x11, 0x11, 0x11, 0x0E}},
    {'p', {0x00, 0x00, 0x1E, 0x11, 0x1E, 0x10, 0x10}}, {'r', {0x00, 0x00, 0x16, 0x19, 0x10, 0x10, 0x10}},
    {'s', {0x00, 0x00, 0x0E, 0x10, 0x0E, 0x01, 0x1E}}, {'t', {0x08, 0x08, 0x1C, 0x08, 0x08, 0x09, 0x06}},
    {'u', {0x00, 0x00, 0x11, 0x11, 0x11, 0x13, 0x0D}},
};

const Glyph* find_glyph(char c) {
  for (const Glyph& g : kFont)
    if (g.c == c) return &g;
  return nullptr;
}

void put(Image* image, int x, int y, float r, float g, float b) {
  if (x < 0 || y < 0 || x >= static_cast<int>(image->width) || y >= static_cast<int>(image->height)) return;
  float* c = &image->rgb[3 * (static_cast<size_t>(y) * image->width + static_cast<size_t>(x))];
  c[0] = r;
  c[1] = g;
  c[2] = b;
}

void fill_box(Image* image, int x, int y, int w, int h, float r, float g, float b) {
  for (int py = y; py < y + h; ++py)
    for (int px = x; px < x + w; ++px) put(image, px, py, r, g, b);
}

// One pass of the text in one colour, offset by (dx, dy): a shadow pass then the text.
int text_pass(const std::string& text, int x, int y, int scale, float level, Image* image) {
  const int advance = 6 * scale;
  int pen = x;
  for (char ch : text) {
    if (const Glyph* g = find_glyph(ch)) {
      for (int row = 0; row < 7; ++row)
        for (int col = 0; col < 5; ++col)
          if (g->rows[row] & (0x10 >> col))
            fill_box(image, pen + col * scale, y + row * scale, scale, scale, level, level, level);
    }
    pen += advance;
  }
  return pen - x;
}

}  // namespace

std::string caption_text(const FrameCaption& caption) {
  char text[128];
  std::snprintf(text, sizeof text, "t = %.3f s   frame %u   %u particles", caption.time, caption.frame,
                caption.particles);
  return text;
}

int draw_text(const std::string& text, int x, int y, int scale, Image* image) {
  const int shadow = std::max(1, scale / 2);
  text_pass(text, x + shadow, y + shadow, scale, 0.0f, image);
  return text_pass(text, x, y, scale, 0.92f, image);
}

void draw_caption(const FrameCaption& caption, Image* image) {
  const int scale = std::max(1, static_cast<int>(image->height) / 270);
  const int margin = 6 * scale;
  draw_text(caption_text(caption), margin, margin, scale, image);
  if (!caption.speed_legend) return;

  // The legend: "speed (m/s)" above a ramp from 0 to speed_max, its ends labelled.
  const int bar_w = std::min(static_cast<int>(image->width) - 2 * margin, 80 * scale);
  const int bar_h = 5 * scale;
  const int bar_y = static_cast<int>(image->height) - margin - 7 * scale - 2 * scale - bar_h;
  draw_text("speed (m/s)", margin, bar_y - 9 * scale, scale, image);
  fill_box(image, margin - 1, bar_y - 1, bar_w + 2, bar_h + 2, 0.0f, 0.0f, 0.0f);
  for (int i = 0; i < bar_w; ++i) {
    const float speed =
        caption.speed_max * static_cast<float>(i) / static_cast<float>(std::max(1, bar_w - 1));
    const Rgb c = speed_color(speed, caption.speed_max);
    fill_box(image, margin + i, bar_y, 1, bar_h, c.r, c.g, c.b);
  }
  char top[32];
  std::snprintf(top, sizeof top, "%.2g", static_cast<double>(caption.speed_max));
  const int label_y = bar_y + bar_h + 2 * scale;
  draw_text("0", margin, label_y, scale, image);
  const int top_w = 6 * scale * static_cast<int>(std::string(top).size());
  draw_text(top, margin + bar_w - top_w, label_y, scale, image);
}

}  // namespace sph_tools
