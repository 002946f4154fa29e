// SPDX-License-Identifier: MIT
#include "scene_parser.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <set>

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

// Rejects a key given twice in one object (JSON parsers keep one of them silently), with the
// path of the second.
class DuplicateKeyCheck {
 public:
  bool operator()(int, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
    using Event = nlohmann::json::parse_event_t;
    switch (event) {
      case Event::object_start:
      case Event::array_start:
        if (!frames_.empty() && frames_.back().is_array) ++frames_.back().index;
        frames_.push_back(Frame{event == Event::array_start, -1, {}, {}});
        break;
      case Event::object_end:
      case Event::array_end:
        if (!frames_.empty()) frames_.pop_back();
        break;
      case Event::key: {
        Frame& top = frames_.back();
        top.key = parsed.get<std::string>();
        if (!top.seen.insert(top.key).second) throw SceneError(path(), "given twice in one object");
        break;
      }
      case Event::value:
        if (!frames_.empty() && frames_.back().is_array) ++frames_.back().index;
        break;
    }
    return true;
  }

 private:
  struct Frame {
    bool is_array;
    long index;
    std::string key;
    std::set<std::string> seen;
  };
  std::string path() const {
    std::string p;
    for (const Frame& f : frames_) {
      if (f.is_array)
        p += "[" + std::to_string(f.index) + "]";
      else
        p += (p.empty() ? "" : ".") + f.key;
    }
    return p;
  }
  std::vector<Frame> frames_;
};

}  // namespace

SceneDesc parse_scene(const std::string& text, const std::string& base_dir) {
  nlohmann::json root;
  try {
    root = nlohmann::json::parse(text, DuplicateKeyCheck());
  } catch (const nlohmann::json::parse_error& e) {
    // e.what() reads "[json.exception.parse_error.101] parse error at line 3, column 5: ..."
    std::string what = e.what();
    const size_t at = what.find("parse error");
    throw SceneError("", "not valid JSON: " + (at == std::string::npos ? what : what.substr(at)));
  } catch (const nlohmann::json::exception& e) {
    // Other errors of the parser: a number beyond double's range (3e9619) is out_of_range.406,
    // "[json.exception.out_of_range.406] number overflow parsing '3e9619'".
    std::string what = e.what();
    const size_t at = what.find("] ");
    throw SceneError("", "not valid JSON: " + (at == std::string::npos ? what : what.substr(at + 2)));
  }
  SceneDesc scene;
  scene.base_dir = base_dir;
  const JsonNode top(&root, "");
  top.expect_object("a scene",
                    {"version", "name", "description", "world", "params", "physics", "time", "fluids",
                     "colliders", "sources", "sinks", "force_fields", "probes", "output"});
  if (!top["version"].missing()) top["version"].count(1, 1);
  scene.name = top["name"].opt_string("");
  scene.description = top["description"].opt_string("");
  parse_world(top["world"], &scene.world);
  parse_params(top["params"], &scene.params);
  scene.physics = parse_physics(top["physics"], scene.world);
  parse_time(top["time"], &scene);
  parse_list(top["fluids"], "a list of fluid bodies", &scene.fluids, parse_fluid);
  parse_list(top["colliders"], "a list of colliders", &scene.colliders,
             [&](const JsonNode& n) { return parse_collider(n, base_dir); });
  for (const ColliderDesc& c : scene.colliders)
    if (c.loads) scene.world.features |= SPH_FEATURE_COLLIDER_LOADS;
  parse_list(top["sources"], "a list of sources", &scene.sources,
             [&](const JsonNode& n) { return parse_source(n, base_dir); });
  for (const SourceDesc& s : scene.sources)
    if (s.has_user_attribute) scene.world.features |= SPH_FEATURE_USER_ATTRIBUTE;
  parse_list(top["sinks"], "a list of sinks", &scene.sinks,
             [&](const JsonNode& n) { return parse_sink(n, base_dir); });
  parse_list(top["force_fields"], "a list of force fields", &scene.force_fields,
             [&](const JsonNode& n) { return parse_force_field(n, base_dir); });
  parse_list(top["probes"], "a list of probes", &scene.probes, parse_probe);
  scene.output = parse_output(top["output"]);
  return scene;
}

namespace {

// A scene file is JSON of a few kilobytes; its large data (level sets) lives in other files.
constexpr off_t kMaxSceneFileBytes = 64 << 20;

// Reads a scene file: a regular file of at most 64 MiB, never beyond the size it had when
// opened (/dev/zero or a FIFO would otherwise be read until memory runs out, or block).
std::string read_scene_text(const std::string& file) {
  const int fd = ::open(file.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw SceneError("", "cannot open " + file + ": " + std::strerror(errno));
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st;
  if (::fstat(fd, &st) != 0) throw SceneError("", "cannot read " + file + ": " + std::strerror(errno));
  if (S_ISDIR(st.st_mode)) throw SceneError("", "cannot open " + file + ": a directory, not a scene file");
  if (!S_ISREG(st.st_mode))
    throw SceneError("", "cannot open " + file + ": not a regular file (a device, FIFO or socket)");
  if (st.st_size > kMaxSceneFileBytes)
    throw SceneError("", "cannot open " + file + ": " + std::to_string(st.st_size) +
                             " bytes, more than a scene file may have (64 MiB)");
  std::string text(static_cast<size_t>(st.st_size), '\0');
  size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::read(fd, &text[done], text.size() - done);
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
    if (n < 0) throw SceneError("", "cannot read " + file + ": " + std::strerror(errno));
    if (n == 0) break;
    done += static_cast<size_t>(n);
  }
  text.resize(done);
  return text;
}

}  // namespace

SceneDesc load_scene_file(const std::string& file) {
  const std::string text = read_scene_text(file);
  const size_t slash = file.find_last_of('/');
  SceneDesc scene = parse_scene(text, slash == std::string::npos ? "." : file.substr(0, slash));
  scene.file = file;
  return scene;
}

}  // namespace sph_tools
