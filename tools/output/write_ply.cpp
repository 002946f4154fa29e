// SPDX-License-Identifier: MIT
// PLY frames: binary little-endian, one vertex element per particle.
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <vector>

#include "new_file.h"
#include "writers.h"

#if !defined(__BYTE_ORDER__) || __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "write_ply.cpp writes its records in host byte order, which must be little-endian"
#endif

namespace sph_tools {

void write_ply(const ParticleFrame& f, const std::string& path) {
  NewFile file(path);
  std::FILE* out = file.get();
  std::fprintf(out,
               "ply\nformat binary_little_endian 1.0\ncomment sph-run frame %u time %.9g\n"
               "element vertex %u\nproperty float x\nproperty float y\nproperty float z\n"
               "property float vx\nproperty float vy\nproperty float vz\nproperty float density\n"
               "property uint id\n%send_header\n",
               f.frame, f.time, f.count, f.has_user ? "property uint user\n" : "");
  constexpr size_t kBatch = 4096;
  const size_t kRecord = f.has_user ? 36 : 32;
  std::vector<unsigned char> buffer(kRecord * kBatch);
  for (uint32_t first = 0; first < f.count; first += kBatch) {
    const uint32_t n = f.count - first < kBatch ? f.count - first : static_cast<uint32_t>(kBatch);
    for (uint32_t k = 0; k < n; ++k) {
      const size_t i = first + k;
      unsigned char* r = &buffer[kRecord * k];
      std::memcpy(r, &f.position[3 * i], 12);
      std::memcpy(r + 12, &f.velocity[3 * i], 12);
      std::memcpy(r + 24, &f.density[i], 4);
      std::memcpy(r + 28, &f.id[i], 4);
      if (f.has_user) std::memcpy(r + 32, &f.user[i], 4);
    }
    if (std::fwrite(buffer.data(), kRecord, n, out) != n) break;
  }
  file.close();
}

}  // namespace sph_tools
