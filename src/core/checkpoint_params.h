// SPDX-License-Identifier: MIT
// The parameters section of a checkpoint (PARM), written and read generically from the methods'
// tables: one block per method (its name, its field count, its fields in table order), each
// checked on reading by the same validate() as the C layer's set calls (param_validation.h).
// Version 1 files (a fixed list of fields) still load: read_params_v1 maps them into the same
// Params and validates them the same way.
#pragma once

#include <stdint.h>

#include "byte_io.h"
#include "config.h"

namespace sph {

void write_params(ByteWriter& w, const RuntimeParams& p);
// Format version 2 and later.
RuntimeParams read_params(ByteReader& r, const WorldConfig& config);
// Format version 1.
RuntimeParams read_params_v1(ByteReader& r, const WorldConfig& config);

}  // namespace sph
