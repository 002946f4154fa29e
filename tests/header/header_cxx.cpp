// SPDX-License-Identifier: MIT
// sph_c.h compiled as C++ with -Wall -Wextra -pedantic -Werror (and a few more warnings
// engines enable); the build fails if the header does not compile cleanly as C++. Run as a
// test, it checks that the extern "C" declarations link and agree with the library.
#include "sph_c.h"
#include "sph_c.h"  // the include guard holds

#include <cstdio>
#include <cstring>
#include <type_traits>

static_assert(std::is_standard_layout<sph_world_def>::value, "public structs are plain C structs");
static_assert(std::is_trivially_copyable<sph_stats>::value, "public structs are plain C structs");
static_assert(sizeof(sph_result) == 4 && sizeof(sph_backend) == 4 && sizeof(sph_integrator) == 4,
              "every enum is 32 bits (the _FORCE32 members)");

namespace {
void SPH_CALL on_log(void*, sph_log_level, sph_result, const char*) {}
}  // namespace

int main() {
  sph_context_def context_def{};
  sph_world_def world_def{};
  sph_world_params params{};
  sph_stats stats{};
  sph_log_fn log = on_log;
  int failures = 0;
  if (sph_context_def_init(&context_def) != SPH_OK || context_def.header_version != SPH_VERSION) ++failures;
  if (sph_world_def_init(&world_def) != SPH_OK || world_def.capacity == 0) ++failures;
  if (sph_world_params_init(&params) != SPH_OK) ++failures;
  if (sph_stats_init(&stats) != SPH_OK) ++failures;
  if (sph_get_version() != SPH_VERSION) ++failures;
  if (std::strlen(sph_result_string(SPH_OK)) == 0) ++failures;
  context_def.log_fn = log;
  sph_context* context = nullptr;
  context_def.backend = SPH_BACKEND_CPU;
  if (sph_context_create(&context_def, &context) != SPH_OK) ++failures;
  if (sph_context_destroy(context) != SPH_OK) ++failures;
  std::printf("sph_c.h as C++ (__cplusplus %ld): %d failure(s)\n", static_cast<long>(__cplusplus), failures);
  return failures == 0 ? 0 : 1;
}
