// SPDX-License-Identifier: MIT
// Reading a scene file: JSON text to a validated SceneDesc (docs/scenes.md is the schema).
#ifndef SPH_TOOLS_SCENE_PARSER_H
#define SPH_TOOLS_SCENE_PARSER_H

#include <string>

#include "scene_desc.h"

namespace sph_tools {

// Parses scene JSON text. base_dir is where relative file names in it start. Throws
// SceneError (path + what was expected) for any problem.
SceneDesc parse_scene(const std::string& text, const std::string& base_dir);

// Reads and parses a scene file. Throws SceneError; a file that cannot be read has path "".
SceneDesc load_scene_file(const std::string& file);

}  // namespace sph_tools

#endif
