// SPDX-License-Identifier: MIT
// libFuzzer harness: the input is a .vdb file given to sph_vdb_load_sdf (libsph_vdb,
// src/io/vdb_sdf_loader.cpp). The loader must return SPH_OK with an asset or an error code with
// a message from sph_vdb_get_last_error(), and leave no object behind on failure. The first
// input byte picks the grid name (NULL, "", or a name); the rest is the file, written to a
// per-process temporary file because OpenVDB reads files by name.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "fuzz_check.h"
#include "sph_c.h"
#include "sph_vdb.h"

using sph_fuzz::create_cpu_context;
using sph_fuzz::violation;

namespace {

sph_context* shared_context() {
  static sph_context* context = create_cpu_context();
  return context;
}

const std::string& temp_path() {
  static const std::string path = [] {
    const char* dir = std::getenv("TMPDIR");
    return std::string(dir && dir[0] ? dir : "/tmp") + "/sph_fuzz_vdb_" + std::to_string(getpid()) + ".vdb";
  }();
  return path;
}

uint32_t live_objects() {
  uint32_t n = 0;
  sph_get_live_object_count(&n);
  return n;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const char* names[] = {nullptr, "", "ls", "sphere", "density", "surface"};
  const char* grid_name = names[data[0] % 6];
  std::FILE* f = std::fopen(temp_path().c_str(), "wb");
  if (!f) violation("cannot write %s", temp_path().c_str());
  if (size > 1 && std::fwrite(data + 1, 1, size - 1, f) != size - 1) violation("short write");
  std::fclose(f);

  sph_context* context = shared_context();
  const uint32_t before = live_objects();
  sph_sdf* sdf = nullptr;
  const sph_result r = sph_vdb_load_sdf(context, temp_path().c_str(), grid_name, &sdf);
  if (!sph_fuzz::is_known_result(r)) violation("sph_vdb_load_sdf returned %d", static_cast<int>(r));
  const char* message = sph_vdb_get_last_error();
  if (r == SPH_OK) {
    if (!sdf) violation("sph_vdb_load_sdf succeeded without an asset");
    if (message[0] != '\0') violation("sph_vdb_load_sdf succeeded with message \"%s\"", message);
    uint32_t dims[3];
    FUZZ_CALL(sph_sdf_get_dims(sdf, dims));
    float d = 0.0f;
    FUZZ_CALL(sph_sdf_sample(sdf, sph_vec3{0.0f, 0.0f, 0.0f}, &d));
    if (FUZZ_CALL(sph_sdf_destroy(sdf)) != SPH_OK) violation("cannot destroy the loaded asset");
  } else {
    if (message[0] == '\0') violation("sph_vdb_load_sdf failed with %d and no message", static_cast<int>(r));
    if (sdf) violation("sph_vdb_load_sdf wrote *out on failure");
  }
  if (live_objects() != before) violation("sph_vdb_load_sdf leaked an object");
  std::remove(temp_path().c_str());
  return 0;
}
