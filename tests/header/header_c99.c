// SPDX-License-Identifier: MIT
/* sph_c.h compiled as strict C99 with -Wall -Wextra -pedantic -Werror (and a few more
 * warnings engines enable); the build fails if the header is not real C. Run as a test, it
 * also checks that the declarations it uses link and agree with the library. */
#include "sph_c.h"
#include "sph_c.h" /* the include guard holds */

#include <stdio.h>
#include <string.h>

static void SPH_CALL on_log(void* user_data, sph_log_level level, sph_result code, const char* message) {
  (void)user_data;
  (void)level;
  (void)code;
  (void)message;
}

int main(void) {
  sph_context_def context_def;
  sph_world_def world_def;
  sph_world_params params;
  sph_spawn_desc spawn;
  sph_fill_box_desc box;
  sph_fill_sphere_desc sphere;
  sph_stats stats;
  sph_log_fn log = on_log;
  sph_vec3 v = {1.0f, 2.0f, 3.0f};
  sph_bool32 yes = 1u;
  sph_feature_flags features = SPH_FEATURE_NONE;
  const sph_attribute attribute = SPH_ATTRIBUTE_POSITION;
  const sph_stage stage = SPH_STAGE_DENSITY;
  int failures = 0;

  if (sph_context_def_init(&context_def) != SPH_OK || context_def.header_version != SPH_VERSION) ++failures;
  if (sph_world_def_init(&world_def) != SPH_OK || world_def.struct_size != sizeof world_def) ++failures;
  if (sph_world_params_init(&params) != SPH_OK) ++failures;
  if (sph_spawn_desc_init(&spawn) != SPH_OK) ++failures;
  if (sph_fill_box_desc_init(&box) != SPH_OK) ++failures;
  if (sph_fill_sphere_desc_init(&sphere) != SPH_OK) ++failures;
  if (sph_stats_init(&stats) != SPH_OK) ++failures;
  if (sph_get_version() != SPH_VERSION) ++failures;
  if (sph_get_abi_version() != SPH_ABI_VERSION) ++failures;
  if (SPH_MAKE_VERSION(SPH_VERSION_MAJOR, SPH_VERSION_MINOR, SPH_VERSION_PATCH) != SPH_VERSION) ++failures;
  if (strlen(sph_result_string(SPH_ERROR_CAPACITY)) == 0) ++failures;
  if (sizeof(sph_result) != 4 || sizeof(sph_backend) != 4 || sizeof(sph_attribute) != 4) ++failures;
  context_def.log_fn = log;
  (void)v;
  (void)yes;
  (void)features;
  (void)attribute;
  (void)stage;
  printf("sph_c.h as C99: %s, %d failure(s)\n", sph_get_build_info(), failures);
  return failures == 0 ? 0 : 1;
}
