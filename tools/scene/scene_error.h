// SPDX-License-Identifier: MIT
// SceneError: a scene file that cannot be used, with the path of the offending field
// ("colliders[2].shape.radius") and what was expected there.
#ifndef SPH_TOOLS_SCENE_ERROR_H
#define SPH_TOOLS_SCENE_ERROR_H

#include <stdexcept>
#include <string>

namespace sph_tools {

class SceneError : public std::runtime_error {
 public:
  // path: the field's path in the file ("" for the file as a whole); message: what is wrong.
  SceneError(const std::string& path, const std::string& message)
      : std::runtime_error(path.empty() ? message : path + ": " + message), path_(path), message_(message) {}
  const std::string& path() const { return path_; }
  const std::string& message() const { return message_; }

 private:
  std::string path_;
  std::string message_;
};

}  // namespace sph_tools

#endif
