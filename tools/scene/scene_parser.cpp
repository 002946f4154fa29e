#include "scene_parser.h"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "json_node.h"
#include "parse_parts.h"
#include "scene_error.h"

namespace sph_tools {

namespace {

template <typename T, typename F>
void parse_list(const JsonNode& node, const char* what, std::vector<T>* out, F parse_one) {
  if (node.missing()) return;
  const size_t n = node.array_size(what);
  for (size_t i = 0; i < n; ++i) out->push_back(parse_one(node.index(i)));
}

}  // namespace

SceneDesc parse_scene(const std::string& text, const std::string& base_dir) {
  nlohmann::json root;
  try {
    root = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    // e.what() reads "[json.exception.parse_error.101] parse error at line 3, column 5: ..."
    std::string what = e.what();
    const size_t at = what.find("parse error");
    throw SceneError("", "not valid JSON: " + (at == std::string::npos ? what : what.substr(at)));
  }
  SceneDesc scene;
  scene.base_dir = base_dir;
  const JsonNode top(&root, "");
  top.expect_object("a scene", {"version", "name", "description", "world", "params", "time", "fluids",
                                "colliders", "sources", "sinks", "force_fields", "output"});
  if (!top["version"].missing()) top["version"].count(1, 1);
  scene.name = top["name"].opt_string("");
  scene.description = top["description"].opt_string("");
  parse_world(top["world"], &scene.world);
  parse_params(top["params"], &scene.params);
  parse_time(top["time"], &scene);
  parse_list(top["fluids"], "a list of fluid bodies", &scene.fluids, parse_fluid);
  parse_list(top["colliders"], "a list of colliders", &scene.colliders,
             [&](const JsonNode& n) { return parse_collider(n, base_dir); });
  parse_list(top["sources"], "a list of sources", &scene.sources,
             [&](const JsonNode& n) { return parse_source(n, base_dir); });
  parse_list(top["sinks"], "a list of sinks", &scene.sinks,
             [&](const JsonNode& n) { return parse_sink(n, base_dir); });
  parse_list(top["force_fields"], "a list of force fields", &scene.force_fields,
             [&](const JsonNode& n) { return parse_force_field(n, base_dir); });
  scene.output = parse_output(top["output"]);
  return scene;
}

SceneDesc load_scene_file(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw SceneError("", "cannot open " + file + ": " + std::strerror(errno));
  std::stringstream text;
  text << in.rdbuf();
  if (in.bad()) throw SceneError("", "cannot read " + file);
  const size_t slash = file.find_last_of('/');
  SceneDesc scene = parse_scene(text.str(), slash == std::string::npos ? "." : file.substr(0, slash));
  scene.file = file;
  return scene;
}

}  // namespace sph_tools
