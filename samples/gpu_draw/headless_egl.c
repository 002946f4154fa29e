// SPDX-License-Identifier: MIT
#include "headless_egl.h"

#include <EGL/eglext.h>
#include <stdio.h>
#include <string.h>

#ifndef EGL_PLATFORM_SURFACELESS_MESA
#define EGL_PLATFORM_SURFACELESS_MESA 0x31DD
#endif

static int has_extension(const char* list, const char* name) {
  const size_t n = strlen(name);
  const char* p = list;
  while (p && (p = strstr(p, name)) != NULL) {
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return 1;
    p += n;
  }
  return 0;
}

/* The EGL device whose CUDA ordinal is cuda_device (or the first that initialises when
 * cuda_device < 0), through EGL_EXT_device_enumeration and EGL_EXT_platform_device; with
 * cuda_device < 0 and no device, Mesa's surfaceless platform. */
static EGLDisplay open_display(int cuda_device) {
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  /* EGL_EXT_device_base is EGL_EXT_device_enumeration and _query together; libglvnd's loader
   * lists only it. */
  if (client &&
      (has_extension(client, "EGL_EXT_device_enumeration") || has_extension(client, "EGL_EXT_device_base")) &&
      has_extension(client, "EGL_EXT_platform_device")) {
    PFNEGLQUERYDEVICESEXTPROC query_devices =
        (PFNEGLQUERYDEVICESEXTPROC)eglGetProcAddress("eglQueryDevicesEXT");
    PFNEGLQUERYDEVICEATTRIBEXTPROC query_attribute =
        (PFNEGLQUERYDEVICEATTRIBEXTPROC)eglGetProcAddress("eglQueryDeviceAttribEXT");
    PFNEGLQUERYDEVICESTRINGEXTPROC query_string =
        (PFNEGLQUERYDEVICESTRINGEXTPROC)eglGetProcAddress("eglQueryDeviceStringEXT");
    EGLDeviceEXT devices[32];
    EGLint count = 0, i;
    if (query_devices && query_devices(32, devices, &count)) {
      for (i = 0; i < count; ++i) {
        EGLDisplay display;
        if (cuda_device >= 0) {
          EGLAttrib ordinal = -1;
          const char* extensions = query_string ? query_string(devices[i], EGL_EXTENSIONS) : NULL;
          if (!extensions || !has_extension(extensions, "EGL_NV_device_cuda") || !query_attribute ||
              !query_attribute(devices[i], EGL_CUDA_DEVICE_NV, &ordinal) || ordinal != cuda_device)
            continue;
        }
        display = eglGetPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[i], NULL);
        if (display != EGL_NO_DISPLAY && eglInitialize(display, NULL, NULL)) return display;
      }
    }
    if (cuda_device >= 0) {
      fprintf(stderr, "headless_egl: none of the %d EGL devices is CUDA device %d (EGL_NV_device_cuda)\n",
              (int)count, cuda_device);
      return EGL_NO_DISPLAY;
    }
  } else if (cuda_device >= 0) {
    /* The client extensions say which vendor libraries EGL loaded: none at all (a null list,
     * or only the loader's own) means the driver's EGL library was not found or failed. */
    fprintf(stderr,
            "headless_egl: EGL has no device enumeration (EGL_EXT_device_enumeration, "
            "EGL_EXT_platform_device): cannot find the GL device of CUDA device %d; client extensions: "
            "%s (eglGetError 0x%x)\n",
            cuda_device, client ? client : "(none)", (unsigned)eglGetError());
    return EGL_NO_DISPLAY;
  }
  if (client && has_extension(client, "EGL_MESA_platform_surfaceless")) {
    EGLDisplay display = eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
    if (display != EGL_NO_DISPLAY && eglInitialize(display, NULL, NULL)) return display;
  }
  fprintf(stderr, "headless_egl: no EGL display (no device platform, no surfaceless platform)\n");
  return EGL_NO_DISPLAY;
}

/* Desktop OpenGL 3.3 core first, then OpenGL ES 3.0; surfaceless (EGL_KHR_surfaceless_context:
 * everything is drawn into the framebuffer object). */
static int create_context(headless_egl* r) { /* r: display set, context made here */
  /* EGL_SURFACE_TYPE defaults to EGL_WINDOW_BIT, which no headless config has. */
  static const EGLint gl_config[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                                     EGL_NONE};
  static const EGLint es_config[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE,
                                     EGL_OPENGL_ES3_BIT, EGL_NONE};
  static const EGLint gl_attributes[] = {EGL_CONTEXT_MAJOR_VERSION,
                                         3,
                                         EGL_CONTEXT_MINOR_VERSION,
                                         3,
                                         EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                         EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                         EGL_NONE};
  static const EGLint es_attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 0,
                                         EGL_NONE};
  int es;
  if (!has_extension(eglQueryString(r->display, EGL_EXTENSIONS), "EGL_KHR_surfaceless_context")) {
    fprintf(stderr, "headless_egl: the EGL display has no EGL_KHR_surfaceless_context\n");
    return 1;
  }
  for (es = 0; es < 2; ++es) {
    EGLConfig config;
    EGLint configs = 0;
    if (!eglBindAPI(es ? EGL_OPENGL_ES_API : EGL_OPENGL_API)) continue;
    if (!eglChooseConfig(r->display, es ? es_config : gl_config, &config, 1, &configs) || configs < 1)
      continue;
    r->context = eglCreateContext(r->display, config, EGL_NO_CONTEXT, es ? es_attributes : gl_attributes);
    if (r->context == EGL_NO_CONTEXT) continue;
    if (!eglMakeCurrent(r->display, EGL_NO_SURFACE, EGL_NO_SURFACE, r->context)) {
      eglDestroyContext(r->display, r->context);
      r->context = EGL_NO_CONTEXT;
      continue;
    }
    r->es = es;
    return 0;
  }
  fprintf(stderr, "headless_egl: neither an OpenGL 3.3 core nor an OpenGL ES 3.0 context (EGL error 0x%x)\n",
          (unsigned)eglGetError());
  return 1;
}

int headless_egl_open(int cuda_device, headless_egl* egl) {
  egl->display = open_display(cuda_device);
  egl->context = EGL_NO_CONTEXT;
  egl->es = 0;
  if (egl->display == EGL_NO_DISPLAY) return 77;
  if (create_context(egl)) {
    eglTerminate(egl->display);
    egl->display = EGL_NO_DISPLAY;
    return 1;
  }
  return 0;
}

void headless_egl_close(headless_egl* egl) {
  if (egl->display == EGL_NO_DISPLAY) return;
  eglMakeCurrent(egl->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  if (egl->context != EGL_NO_CONTEXT) eglDestroyContext(egl->display, egl->context);
  eglTerminate(egl->display);
  egl->display = EGL_NO_DISPLAY;
  egl->context = EGL_NO_CONTEXT;
}
