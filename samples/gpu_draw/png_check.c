// SPDX-License-Identifier: MIT
/* png_check FILE WIDTH HEIGHT MIN_PIXELS: exits 0 when FILE is a WIDTH x HEIGHT PNG with at
 * least MIN_PIXELS pixels that differ from its top-left (background) pixel; prints what it
 * found either way. scripts/gpu-test and the gl_draw_host test check the samples' images
 * with it. */
#include <stdio.h>
#include <stdlib.h>

#include "png_image.h"

int main(int argc, char** argv) {
  int width = 0, height = 0;
  long foreground = 0, min_pixels;
  if (argc != 5) {
    fprintf(stderr, "usage: png_check FILE WIDTH HEIGHT MIN_PIXELS\n");
    return 2;
  }
  if (png_image_inspect(argv[1], &width, &height, &foreground)) return 1;
  min_pixels = atol(argv[4]);
  printf("%s: %dx%d, %ld of %ld pixels differ from the background\n", argv[1], width, height, foreground,
         (long)width * height);
  if (width != atoi(argv[2]) || height != atoi(argv[3])) {
    printf("FAIL: expected %sx%s\n", argv[2], argv[3]);
    return 1;
  }
  if (foreground < min_pixels) {
    printf("FAIL: fewer than %ld foreground pixels (a blank image?)\n", min_pixels);
    return 1;
  }
  return 0;
}
