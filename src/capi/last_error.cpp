// SPDX-License-Identifier: MIT
#include "last_error.h"

#include <cstring>

namespace sph {
namespace {
thread_local char g_message[1024] = "";
}

void set_last_error(const char* message) {
  std::strncpy(g_message, message ? message : "", sizeof g_message - 1);
  g_message[sizeof g_message - 1] = '\0';
}

void clear_last_error() { g_message[0] = '\0'; }

const char* last_error() { return g_message; }

}  // namespace sph
