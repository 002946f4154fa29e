// SPDX-License-Identifier: MIT
// The thread-local message behind sph_get_last_error(). A plain char array, so the library
// can be unloaded without thread-exit destructors.
#pragma once

namespace sph {

void set_last_error(const char* message);
void clear_last_error();
const char* last_error();

}  // namespace sph
