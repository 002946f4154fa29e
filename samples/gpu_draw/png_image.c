// SPDX-License-Identifier: MIT
#include "png_image.h"

#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int png_image_write_bottom_up(const char* path, int width, int height, const uint8_t* rgba) {
  png_image image;
  memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  image.width = (png_uint_32)width;
  image.height = (png_uint_32)height;
  image.format = PNG_FORMAT_RGBA;
  /* A negative row stride: the first row in memory is the bottom of the image. */
  if (!png_image_write_to_file(&image, path, 0, rgba, -(png_int_32)(4 * width), NULL)) {
    fprintf(stderr, "png: cannot write %s: %s\n", path, image.message);
    return 1;
  }
  return 0;
}

int png_image_inspect(const char* path, int* width, int* height, long* foreground_pixels) {
  png_image image;
  uint8_t* pixels;
  size_t i, n;
  long count = 0;
  memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&image, path)) {
    fprintf(stderr, "png: cannot read %s: %s\n", path, image.message);
    return 1;
  }
  image.format = PNG_FORMAT_RGBA;
  n = (size_t)image.width * image.height;
  pixels = (uint8_t*)malloc(4 * n);
  if (!pixels || !png_image_finish_read(&image, NULL, pixels, 0, NULL)) {
    fprintf(stderr, "png: cannot decode %s: %s\n", path, pixels ? image.message : "out of memory");
    free(pixels);
    png_image_free(&image);
    return 1;
  }
  for (i = 0; i < n; ++i) {
    int c, differs = 0;
    for (c = 0; c < 4; ++c) differs |= abs((int)pixels[4 * i + c] - (int)pixels[c]) > 8;
    count += differs;
  }
  free(pixels);
  *width = (int)image.width;
  *height = (int)image.height;
  *foreground_pixels = count;
  return 0;
}
