// SPDX-License-Identifier: MIT
/* What the scene samples share and a user would write once: reporting a failed call, the
 * command line (OUTPUT_DIR --frames N --backend auto|cpu|cuda), and writing each frame's
 * particles as CSV (id, x, y, z, vx, vy, vz, density) through a temporary name, so an
 * interrupted run leaves only complete frames, with a progress line now and then. */
#ifndef SPH_SAMPLE_IO_H
#define SPH_SAMPLE_IO_H

#include "sph_c.h"

/* Prints "NAME: WHAT failed: ..." with the library's message when r is an error; returns 1
 * then, else 0. */
int sample_failed(sph_result r, const char* what);

/* Parses [OUTPUT_DIR] [--frames N] [--backend auto|cpu|cuda] over the defaults in *out_dir and
 * *frames, and creates the output directory. name labels every message. Returns 0, 2 for a
 * usage error, 1 when the directory cannot be made. */
int sample_parse_args(int argc, char** argv, const char* name, const char** out_dir, int* frames,
                      sph_backend* backend);

/* Writes DIR/frame_NNNN.csv with every particle of the world. Returns 0 or 1 (reported). */
int sample_write_frame(const sph_world* world, const char* dir, int frame);

/* Steps the world one frame of 1/60 s, writes it as frame `frame` of `frames` and prints a
 * progress line every 30 frames and at the last. Returns 0 or 1 (reported). */
int sample_step_and_write(sph_world* world, const char* dir, int frame, int frames);

#endif
