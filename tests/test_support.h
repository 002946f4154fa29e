/* Shared by every test that creates contexts through the C API: the backend those contexts use
 * comes from the environment variable SPH_TEST_BACKEND (cpu | cuda | auto; default cpu), so
 * the GPU test script can rerun the same tests on the CUDA backend. */
#ifndef SPH_TEST_SUPPORT_H
#define SPH_TEST_SUPPORT_H

#include "sph_c.h"

#ifdef __cplusplus
extern "C" {
#endif

/** The backend named by SPH_TEST_BACKEND. An unknown name prints a message and exits with 2. */
sph_backend sph_test_backend(void);
/** "cpu", "cuda" or "auto": the value sph_test_backend() was read from. */
const char* sph_test_backend_name(void);
/** sph_context_def_init() with the test backend filled in. */
sph_result sph_test_context_def_init(sph_context_def* def);
/** Creates a context on the test backend with defaults otherwise. */
sph_result sph_test_context_create(sph_context** out);
/** A deterministic random number in [0, 1) (xorshift64*), so every run sees the same data. */
double sph_test_random(uint64_t* state);

#ifdef __cplusplus
}
#endif

#endif /* SPH_TEST_SUPPORT_H */
