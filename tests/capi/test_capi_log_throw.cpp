// SPDX-License-Identifier: MIT
/* A C++ log callback that throws (sph_log_fn says it must return normally; the library catches
 * and drops what one throws anyway, src/capi/guard.h): the calls that told it return their own
 * results, no exception crosses the C boundary, the process does not terminate, and the
 * "inside the callback" flag is reset, so later reports on the thread still reach the callback. */
#include <stdio.h>
#include <string.h>

#include <stdexcept>

extern "C" {
#include "capi_test.h"
}

namespace {

struct ThrowingLog {
  int calls = 0;
  sph_log_level last_level = SPH_LOG_ERROR;
};

void SPH_CALL throw_from_log(void* user_data, sph_log_level level, sph_result, const char*) {
  auto* log = static_cast<ThrowingLog*>(user_data);
  ++log->calls;
  log->last_level = level;
  throw std::runtime_error("a callback that throws");
}

void test_throwing_callback(void** state) {
  ThrowingLog log;
  sph_context_def def;
  sph_context* context = nullptr;
  sph_world* world = nullptr;
  sph_sdf* sdf = nullptr;
  (void)state;
  sph_test_context_def_init(&def);
  def.log_fn = throw_from_log;
  def.log_user_data = &log;
  EXPECT_OK(sph_context_create(&def, &context));
  capi_coarse_collider_case(context, &world, &sdf);

  /* A warning's callback throws: the call succeeded and says so. */
  EXPECT_OK(capi_add_collider(world, sdf));
  assert_int_equal(log.calls, 1);
  assert_int_equal(log.last_level, SPH_LOG_WARNING);
  assert_string_equal(sph_get_last_error(), "");

  /* A failure's callback throws: the call returns its error, with its message. */
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "frame_dt", sph_world_step(world, -1.0f));
  assert_int_equal(log.calls, 2); /* the flag was reset after the first throw */
  assert_int_equal(log.last_level, SPH_LOG_ERROR);
  EXPECT_ERROR(SPH_ERROR_INVALID_ARGUMENT, "frame_dt", sph_world_step(world, -2.0f));
  assert_int_equal(log.calls, 3);

  /* The world was released by every call: it steps. */
  EXPECT_OK(sph_world_step(world, 0.001f));
  EXPECT_OK(sph_world_destroy(world));
  EXPECT_OK(sph_sdf_destroy(sdf));
  EXPECT_OK(sph_context_destroy(context));
}

}  // namespace

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_throwing_callback),
  };
  return cmocka_run_group_tests_name("capi_log_throw", tests, nullptr, nullptr);
}
