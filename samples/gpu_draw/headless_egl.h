// SPDX-License-Identifier: MIT
/* An EGL context with no window system, current on the calling thread: the display of the EGL
 * device that is a given CUDA device (EGL_EXT_device_enumeration, EGL_EXT_platform_device and
 * EGL_NV_device_cuda; CUDA-GL interop needs the GL context on the CUDA device's GPU), or with no
 * CUDA device asked for, the first EGL device or Mesa's surfaceless platform; then an OpenGL 3.3
 * core context, or an OpenGL ES 3.0 one where desktop GL is refused, made current without a
 * surface (EGL_KHR_surfaceless_context: the caller draws into a framebuffer object). */
#ifndef SPH_SAMPLE_HEADLESS_EGL_H
#define SPH_SAMPLE_HEADLESS_EGL_H

#include <EGL/egl.h>

typedef struct headless_egl {
  EGLDisplay display;
  EGLContext context;
  int es; /* 1: OpenGL ES 3.0, 0: OpenGL 3.3 core */
} headless_egl;

/* cuda_device: the CUDA ordinal whose EGL device to use, or -1 for any. Returns 0; 77 when no
 * display can be opened (no EGL driver, or none for that CUDA device); 1 when a display opened
 * but no context could be made current. Prints why on stderr. On failure *egl holds nothing. */
int headless_egl_open(int cuda_device, headless_egl* egl);

/* Releases the context and the display (a zeroed or failed headless_egl is allowed). */
void headless_egl_close(headless_egl* egl);

#endif
