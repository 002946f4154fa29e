// SPDX-License-Identifier: MIT
// CSV frames: a header line and one particle per line.
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>

#include "new_file.h"
#include "writers.h"

namespace sph_tools {

void write_csv(const ParticleFrame& f, const std::string& path) {
  NewFile file(path);
  std::FILE* out = file.get();
  std::fputs(
      f.has_user ? "id,x,y,z,vx,vy,vz,density,pressure,user\n" : "id,x,y,z,vx,vy,vz,density,pressure\n", out);
  for (uint32_t i = 0; i < f.count; ++i) {
    const float* x = &f.position[3 * static_cast<size_t>(i)];
    const float* v = &f.velocity[3 * static_cast<size_t>(i)];
    std::fprintf(out, "%u,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g", f.id[i], x[0], x[1], x[2], v[0], v[1],
                 v[2], f.density[i], f.pressure[i]);
    if (f.has_user) std::fprintf(out, ",%u", f.user[i]);
    std::fputc('\n', out);
  }
  file.close();
}

}  // namespace sph_tools
