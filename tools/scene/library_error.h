// SPDX-License-Identifier: MIT
// LibraryError: a call of the sph C API that failed outside any one scene object (creating the
// context or world, stepping), with its result code and the library's message.
#ifndef SPH_TOOLS_LIBRARY_ERROR_H
#define SPH_TOOLS_LIBRARY_ERROR_H

#include <stdexcept>
#include <string>

#include "sph_c.h"

namespace sph_tools {

class LibraryError : public std::runtime_error {
 public:
  LibraryError(sph_result code, const std::string& what_failed)
      : std::runtime_error(what_failed + ": " + sph_result_string(code) + describe_last()), code_(code) {}
  sph_result code() const { return code_; }

 private:
  static std::string describe_last() {
    const char* last = sph_get_last_error();
    return last && last[0] ? std::string("\n  ") + last : std::string();
  }
  sph_result code_;
};

}  // namespace sph_tools

#endif
