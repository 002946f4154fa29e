// SPDX-License-Identifier: MIT
// The preview's caption: simulated time, frame number and particle count in the top-left
// corner and, when particles are drawn coloured by speed, the colour legend in the bottom-left,
// in a 5 x 7 bitmap font (no font library: the preview stays headless and self-contained).
#ifndef SPH_TOOLS_FRAME_CAPTION_H
#define SPH_TOOLS_FRAME_CAPTION_H

#include <cstdint>
#include <string>

#include "image.h"

namespace sph_tools {

struct FrameCaption {
  uint32_t frame = 0;
  double time = 0.0;  // s
  uint32_t particles = 0;
  bool speed_legend = false;  // the particles are coloured by speed_color(speed, speed_max)
  float speed_max = 1.0f;     // m/s
};

// "t = 0.250 s   frame 12   4096 particles"
std::string caption_text(const FrameCaption& caption);

// Draws the caption onto the image: white text with a dark shadow, scaled with the image
// height (2 pixels a font pixel at 540 rows).
void draw_caption(const FrameCaption& caption, Image* image);

// Draws `text` with its top-left corner at (x, y), each font pixel `scale` image pixels wide.
// Characters the font lacks are drawn as blanks. Returns the width drawn, in image pixels.
int draw_text(const std::string& text, int x, int y, int scale, Image* image);

}  // namespace sph_tools

#endif
