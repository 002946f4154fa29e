// SPDX-License-Identifier: MIT
/* The renderer of particle_renderer.h on a headless EGL context (headless_egl.c): the GL
 * functions it uses loaded through eglGetProcAddress, a framebuffer object, the sprite shaders. */
#include "particle_renderer.h"

#include "headless_egl.h"

#include <GL/glcorearb.h> /* types, enums and PFN typedefs only: no prototypes are used */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Every GL function the renderer calls: X(type, name) becomes a member gl.name loaded from
 * "gl" #name. All are in OpenGL 3.3 core and OpenGL ES 3.0. */
#define RENDERER_GL_FUNCTIONS(X)                               \
  X(PFNGLGETERRORPROC, GetError)                               \
  X(PFNGLGETSTRINGPROC, GetString)                             \
  X(PFNGLVIEWPORTPROC, Viewport)                               \
  X(PFNGLCLEARCOLORPROC, ClearColor)                           \
  X(PFNGLCLEARPROC, Clear)                                     \
  X(PFNGLENABLEPROC, Enable)                                   \
  X(PFNGLREADPIXELSPROC, ReadPixels)                           \
  X(PFNGLPIXELSTOREIPROC, PixelStorei)                         \
  X(PFNGLDRAWARRAYSPROC, DrawArrays)                           \
  X(PFNGLGENBUFFERSPROC, GenBuffers)                           \
  X(PFNGLBINDBUFFERPROC, BindBuffer)                           \
  X(PFNGLBUFFERDATAPROC, BufferData)                           \
  X(PFNGLBUFFERSUBDATAPROC, BufferSubData)                     \
  X(PFNGLMAPBUFFERRANGEPROC, MapBufferRange)                   \
  X(PFNGLUNMAPBUFFERPROC, UnmapBuffer)                         \
  X(PFNGLDELETEBUFFERSPROC, DeleteBuffers)                     \
  X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays)                 \
  X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray)                 \
  X(PFNGLDELETEVERTEXARRAYSPROC, DeleteVertexArrays)           \
  X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer)         \
  X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray) \
  X(PFNGLCREATESHADERPROC, CreateShader)                       \
  X(PFNGLSHADERSOURCEPROC, ShaderSource)                       \
  X(PFNGLCOMPILESHADERPROC, CompileShader)                     \
  X(PFNGLGETSHADERIVPROC, GetShaderiv)                         \
  X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog)               \
  X(PFNGLDELETESHADERPROC, DeleteShader)                       \
  X(PFNGLCREATEPROGRAMPROC, CreateProgram)                     \
  X(PFNGLATTACHSHADERPROC, AttachShader)                       \
  X(PFNGLLINKPROGRAMPROC, LinkProgram)                         \
  X(PFNGLGETPROGRAMIVPROC, GetProgramiv)                       \
  X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog)             \
  X(PFNGLUSEPROGRAMPROC, UseProgram)                           \
  X(PFNGLDELETEPROGRAMPROC, DeleteProgram)                     \
  X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)           \
  X(PFNGLUNIFORMMATRIX4FVPROC, UniformMatrix4fv)               \
  X(PFNGLUNIFORM1FPROC, Uniform1f)                             \
  X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers)                 \
  X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer)                 \
  X(PFNGLFRAMEBUFFERRENDERBUFFERPROC, FramebufferRenderbuffer) \
  X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus)   \
  X(PFNGLDELETEFRAMEBUFFERSPROC, DeleteFramebuffers)           \
  X(PFNGLGENRENDERBUFFERSPROC, GenRenderbuffers)               \
  X(PFNGLBINDRENDERBUFFERPROC, BindRenderbuffer)               \
  X(PFNGLRENDERBUFFERSTORAGEPROC, RenderbufferStorage)         \
  X(PFNGLDELETERENDERBUFFERSPROC, DeleteRenderbuffers)

#define RENDERER_GL_MEMBER(type, name) type name;
typedef struct gl_functions {
  RENDERER_GL_FUNCTIONS(RENDERER_GL_MEMBER)
} gl_functions;

struct particle_renderer {
  particle_renderer_def def;
  headless_egl egl;
  int es; /* 1: an OpenGL ES 3.0 context (a copy of egl.es) */
  char device[128];
  gl_functions gl;
  GLuint framebuffer, colour_buffer, depth_buffer, vertex_array, vertex_buffer, program;
  GLint view_projection_location, point_scale_location;
};

static int load_functions(particle_renderer* r) {
#define RENDERER_GL_LOAD(type, name)                                                         \
  r->gl.name = (type)eglGetProcAddress("gl" #name);                                          \
  if (!r->gl.name) {                                                                         \
    fprintf(stderr, "particle_renderer: eglGetProcAddress(\"gl%s\") gave nothing\n", #name); \
    return 1;                                                                                \
  }
  RENDERER_GL_FUNCTIONS(RENDERER_GL_LOAD)
#undef RENDERER_GL_LOAD
  return 0;
}

/* Sprites of the particle radius in pixels (point_scale / clip w), shaded as spheres lit from
 * the upper right front; the depth stays the sprite plane's (enough for a picture). */
static const char* const vertex_body =
    "layout(location = 0) in vec3 position;\n"
    "layout(location = 1) in vec4 colour;\n"
    "uniform mat4 view_projection;\n"
    "uniform float point_scale;\n"
    "out vec4 v_colour;\n"
    "void main() {\n"
    "  gl_Position = view_projection * vec4(position, 1.0);\n"
    "  gl_PointSize = max(point_scale / gl_Position.w, 1.0);\n"
    "  v_colour = colour;\n"
    "}\n";
static const char* const fragment_body =
    "in vec4 v_colour;\n"
    "out vec4 fragment;\n"
    "void main() {\n"
    "  vec2 p = gl_PointCoord * 2.0 - 1.0;\n"
    "  float r2 = dot(p, p);\n"
    "  if (r2 > 1.0) discard;\n"
    "  vec3 normal = vec3(p.x, -p.y, sqrt(1.0 - r2));\n"
    "  float diffuse = max(dot(normal, normalize(vec3(0.4, 0.6, 0.7))), 0.0);\n"
    "  fragment = vec4(v_colour.rgb * (0.3 + 0.7 * diffuse), 1.0);\n"
    "}\n";

static GLuint compile(particle_renderer* r, GLenum kind, const char* body) {
  const char* sources[2] = {r->es ? "#version 300 es\nprecision highp float;\n" : "#version 330 core\n",
                            body};
  GLuint shader = r->gl.CreateShader(kind);
  GLint ok = 0;
  r->gl.ShaderSource(shader, 2, sources, NULL);
  r->gl.CompileShader(shader);
  r->gl.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048];
    r->gl.GetShaderInfoLog(shader, (GLsizei)sizeof log, NULL, log);
    fprintf(stderr, "particle_renderer: shader compilation failed: %s\n", log);
    r->gl.DeleteShader(shader);
    return 0;
  }
  return shader;
}

static int build_program(particle_renderer* r) {
  GLuint vertex = compile(r, GL_VERTEX_SHADER, vertex_body), fragment = 0;
  GLint ok = 0;
  if (vertex) fragment = compile(r, GL_FRAGMENT_SHADER, fragment_body);
  if (!fragment) {
    if (vertex) r->gl.DeleteShader(vertex);
    return 1;
  }
  r->program = r->gl.CreateProgram();
  r->gl.AttachShader(r->program, vertex);
  r->gl.AttachShader(r->program, fragment);
  r->gl.LinkProgram(r->program);
  r->gl.DeleteShader(vertex); /* flagged; freed with the program */
  r->gl.DeleteShader(fragment);
  r->gl.GetProgramiv(r->program, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[2048];
    r->gl.GetProgramInfoLog(r->program, (GLsizei)sizeof log, NULL, log);
    fprintf(stderr, "particle_renderer: program link failed: %s\n", log);
    return 1;
  }
  r->view_projection_location = r->gl.GetUniformLocation(r->program, "view_projection");
  r->point_scale_location = r->gl.GetUniformLocation(r->program, "point_scale");
  return 0;
}

static int build_buffers(particle_renderer* r) {
  const particle_renderer_def* d = &r->def;
  r->gl.GenRenderbuffers(1, &r->colour_buffer);
  r->gl.BindRenderbuffer(GL_RENDERBUFFER, r->colour_buffer);
  r->gl.RenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, d->width, d->height);
  r->gl.GenRenderbuffers(1, &r->depth_buffer);
  r->gl.BindRenderbuffer(GL_RENDERBUFFER, r->depth_buffer);
  r->gl.RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, d->width, d->height);
  r->gl.GenFramebuffers(1, &r->framebuffer);
  r->gl.BindFramebuffer(GL_FRAMEBUFFER, r->framebuffer);
  r->gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, r->colour_buffer);
  r->gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, r->depth_buffer);
  if (r->gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    fprintf(stderr, "particle_renderer: the %dx%d framebuffer is incomplete\n", d->width, d->height);
    return 1;
  }
  r->gl.GenVertexArrays(1, &r->vertex_array);
  r->gl.BindVertexArray(r->vertex_array);
  r->gl.GenBuffers(1, &r->vertex_buffer);
  r->gl.BindBuffer(GL_ARRAY_BUFFER, r->vertex_buffer);
  r->gl.BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)d->capacity * (GLsizeiptr)sizeof(particle_vertex), NULL,
                   GL_DYNAMIC_DRAW);
  r->gl.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(particle_vertex), (const void*)0);
  r->gl.VertexAttribPointer(1, 4, GL_UNSIGNED_BYTE, GL_TRUE, sizeof(particle_vertex),
                            (const void*)offsetof(particle_vertex, rgba));
  r->gl.EnableVertexAttribArray(0);
  r->gl.EnableVertexAttribArray(1);
  return r->gl.GetError() == GL_NO_ERROR ? 0 : 1;
}

/* Column-major projection * view for the def's camera. */
static void view_projection(const particle_renderer_def* d, float m[16]) {
  const float pi = 3.14159265f, near_plane = 0.05f, far_plane = 20.0f;
  const float aspect = (float)d->width / (float)d->height,
              f = 1.0f / tanf(0.5f * d->fov_y_degrees * pi / 180.0f);
  float z[3], x[3], y[3], n;
  int i;
  for (i = 0; i < 3; ++i) z[i] = d->eye[i] - d->target[i]; /* the camera looks down -z */
  n = sqrtf(z[0] * z[0] + z[1] * z[1] + z[2] * z[2]);
  for (i = 0; i < 3; ++i) z[i] /= n;
  x[0] = z[2]; /* (0, 1, 0) x z */
  x[1] = 0.0f;
  x[2] = -z[0];
  n = sqrtf(x[0] * x[0] + x[2] * x[2]);
  x[0] /= n;
  x[2] /= n;
  y[0] = z[1] * x[2] - z[2] * x[1];
  y[1] = z[2] * x[0] - z[0] * x[2];
  y[2] = z[0] * x[1] - z[1] * x[0];
  for (i = 0; i < 3; ++i) {
    const float a = f / aspect * x[i], b = f * y[i], c = z[i];
    m[4 * i + 0] = a;
    m[4 * i + 1] = b;
    m[4 * i + 2] = c * (far_plane + near_plane) / (near_plane - far_plane);
    m[4 * i + 3] = -c;
  }
  {
    const float tx = -(x[0] * d->eye[0] + x[1] * d->eye[1] + x[2] * d->eye[2]);
    const float ty = -(y[0] * d->eye[0] + y[1] * d->eye[1] + y[2] * d->eye[2]);
    const float tz = -(z[0] * d->eye[0] + z[1] * d->eye[1] + z[2] * d->eye[2]);
    m[12] = f / aspect * tx;
    m[13] = f * ty;
    m[14] = tz * (far_plane + near_plane) / (near_plane - far_plane) +
            2.0f * far_plane * near_plane / (near_plane - far_plane);
    m[15] = -tz;
  }
}

int particle_renderer_create(const particle_renderer_def* def, particle_renderer** out) {
  particle_renderer* r;
  const char* renderer_name;
  int status;
  *out = NULL;
  if (def->width <= 0 || def->height <= 0 || def->capacity == 0) {
    fprintf(stderr, "particle_renderer: width, height and capacity must be positive\n");
    return 1;
  }
  r = (particle_renderer*)calloc(1, sizeof *r);
  if (!r) return 1;
  r->def = *def;
  status = headless_egl_open(def->cuda_device, &r->egl);
  if (status != 0) {
    free(r);
    return status;
  }
  r->es = r->egl.es;
  if (load_functions(r) || build_program(r) || build_buffers(r)) {
    particle_renderer_destroy(r);
    return 1;
  }
  renderer_name = (const char*)r->gl.GetString(GL_RENDERER);
  snprintf(r->device, sizeof r->device, "%s", renderer_name ? renderer_name : "unknown");
  *out = r;
  return 0;
}

unsigned particle_renderer_vertex_buffer(const particle_renderer* renderer) {
  return renderer->vertex_buffer;
}
const char* particle_renderer_api(const particle_renderer* renderer) {
  return renderer->es ? "OpenGL ES 3.0" : "OpenGL 3.3 core";
}
const char* particle_renderer_device(const particle_renderer* renderer) { return renderer->device; }

int particle_renderer_upload(particle_renderer* r, const particle_vertex* vertices, uint32_t count) {
  if (count > r->def.capacity) {
    fprintf(stderr, "particle_renderer: %u vertices, the buffer holds %u\n", count, r->def.capacity);
    return 1;
  }
  r->gl.BindBuffer(GL_ARRAY_BUFFER, r->vertex_buffer);
  r->gl.BufferSubData(GL_ARRAY_BUFFER, 0, (GLsizeiptr)count * (GLsizeiptr)sizeof(particle_vertex), vertices);
  return r->gl.GetError() == GL_NO_ERROR ? 0 : 1;
}

int particle_renderer_read_vertices(particle_renderer* r, uint32_t count, particle_vertex* out) {
  const void* mapped;
  GLboolean intact;
  if (count > r->def.capacity) {
    fprintf(stderr, "particle_renderer: %u vertices asked back, the buffer holds %u\n", count,
            r->def.capacity);
    return 1;
  }
  if (count == 0) return 0;
  r->gl.BindBuffer(GL_ARRAY_BUFFER, r->vertex_buffer);
  mapped = r->gl.MapBufferRange(GL_ARRAY_BUFFER, 0, (GLsizeiptr)count * (GLsizeiptr)sizeof(particle_vertex),
                                GL_MAP_READ_BIT);
  if (!mapped) {
    fprintf(stderr, "particle_renderer: glMapBufferRange failed (GL error 0x%x)\n",
            (unsigned)r->gl.GetError());
    return 1;
  }
  memcpy(out, mapped, (size_t)count * sizeof(particle_vertex));
  intact = r->gl.UnmapBuffer(GL_ARRAY_BUFFER); /* GL_FALSE: the store was lost while mapped */
  return intact == GL_TRUE && r->gl.GetError() == GL_NO_ERROR ? 0 : 1;
}

int particle_renderer_draw(particle_renderer* r, uint32_t count, uint8_t* rgba) {
  const particle_renderer_def* d = &r->def;
  const float pi = 3.14159265f;
  float m[16];
  GLenum error;
  if (count > d->capacity) count = d->capacity;
  view_projection(d, m);
  r->gl.BindFramebuffer(GL_FRAMEBUFFER, r->framebuffer);
  r->gl.Viewport(0, 0, d->width, d->height);
  r->gl.ClearColor(0.1f, 0.1f, 0.12f, 1.0f);
  r->gl.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  r->gl.Enable(GL_DEPTH_TEST);
  if (!r->es) r->gl.Enable(GL_PROGRAM_POINT_SIZE); /* ES always takes gl_PointSize */
  r->gl.UseProgram(r->program);
  r->gl.UniformMatrix4fv(r->view_projection_location, 1, GL_FALSE, m);
  /* A sphere of radius R at distance w spans 2 R (h / 2) / (w tan(fov / 2)) pixels. */
  r->gl.Uniform1f(r->point_scale_location,
                  d->particle_radius * (float)d->height / tanf(0.5f * d->fov_y_degrees * pi / 180.0f));
  r->gl.BindVertexArray(r->vertex_array);
  r->gl.DrawArrays(GL_POINTS, 0, (GLsizei)count);
  r->gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
  r->gl.ReadPixels(0, 0, d->width, d->height, GL_RGBA, GL_UNSIGNED_BYTE, rgba);
  error = r->gl.GetError();
  if (error != GL_NO_ERROR) {
    fprintf(stderr, "particle_renderer: GL error 0x%x while drawing\n", (unsigned)error);
    return 1;
  }
  return 0;
}

void particle_renderer_destroy(particle_renderer* r) {
  if (!r) return;
  if (r->gl.DeleteBuffers) { /* the functions are loaded: the context is current */
    r->gl.DeleteBuffers(1, &r->vertex_buffer);
    r->gl.DeleteVertexArrays(1, &r->vertex_array);
    r->gl.DeleteFramebuffers(1, &r->framebuffer);
    r->gl.DeleteRenderbuffers(1, &r->colour_buffer);
    r->gl.DeleteRenderbuffers(1, &r->depth_buffer);
    r->gl.DeleteProgram(r->program);
  }
  headless_egl_close(&r->egl);
  free(r);
}
