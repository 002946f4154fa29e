// SPDX-License-Identifier: MIT
/* RGBA images to and from PNG files through libpng's simplified API. */
#ifndef SPH_SAMPLE_PNG_IMAGE_H
#define SPH_SAMPLE_PNG_IMAGE_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Writes width x height RGBA8 pixels whose rows run bottom to top (as glReadPixels gives them)
 * to path as a PNG, top row first. Returns 0, or 1 with the reason on stderr. */
int png_image_write_bottom_up(const char* path, int width, int height, const uint8_t* rgba);

/* Reads path and reports its size and how many pixels differ from its top-left pixel (the
 * background) in any channel by more than 8 of 255. Returns 0, or 1 with the reason on stderr. */
int png_image_inspect(const char* path, int* width, int* height, long* foreground_pixels);

#ifdef __cplusplus
}
#endif

#endif
