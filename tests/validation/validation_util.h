// SPDX-License-Identifier: MIT
/* Helpers of the validation cases (tests/validation): the resolution switch between CI and the
 * full run and where results go. Their scenes (lattices, the tank, the rest sphere, the
 * Martin & Moyce dam break) are tests/support's. They drive the library through the C API only. */
#ifndef SPH_VALIDATION_UTIL_H
#define SPH_VALIDATION_UTIL_H

#include <stdint.h>
#include <stdio.h>

#include "capi_test.h"

/* 1 when SPH_VALIDATION_FULL=1 asks for the full resolution (scripts/validate --full), else 0:
 * the reduced resolution CI runs. */
int validation_full(void);

/* Where a case writes its results for scripts/validate (SPH_VALIDATION_OUT, a folder), or NULL
 * when unset. validation_open_output opens `name` there for writing, or returns NULL. */
const char* validation_output_dir(void);
FILE* validation_open_output(const char* name);

#endif
