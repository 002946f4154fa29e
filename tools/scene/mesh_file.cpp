// SPDX-License-Identifier: MIT
#include "mesh_file.h"

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

namespace sph_tools {

namespace {

// More would not fit the library's uint32 vertex indices three to a triangle.
constexpr uint64_t kMaxTriangles = 1ull << 28;
constexpr uint64_t kMaxFileBytes = 1ull << 31;

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw std::runtime_error(path + ": " + what);
}

std::string lower_extension(const std::string& path) {
  const size_t dot = path.find_last_of('.');
  std::string ext = dot == std::string::npos ? "" : path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

std::string read_whole(const std::string& path) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) fail(path, std::string("cannot open: ") + std::strerror(errno));
  if (!S_ISREG(st.st_mode)) fail(path, "is not a regular file");
  if (static_cast<uint64_t>(st.st_size) > kMaxFileBytes) fail(path, "is larger than 2 GiB");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot open");
  std::string bytes(static_cast<size_t>(st.st_size), '\0');
  if (!bytes.empty() && !in.read(&bytes[0], static_cast<std::streamsize>(bytes.size())))
    fail(path, "cannot read");
  return bytes;
}

// Three numbers as text; false when a token is missing or not a number. Values beyond float's
// range come back infinite (add_vertex reports them), not as a parse failure.
bool read_xyz(std::istream& in, float xyz[3]) {
  for (int a = 0; a < 3; ++a) {
    std::string token;
    if (!(in >> token)) return false;
    char* end = nullptr;
    const double value = std::strtod(token.c_str(), &end);
    if (end == token.c_str() || *end != '\0') return false;
    xyz[a] = static_cast<float>(value);
  }
  return true;
}

void add_vertex(MeshData& m, const std::string& path, const std::string& where, const float xyz[3],
                float scale) {
  for (int a = 0; a < 3; ++a) {
    const float v = xyz[a] * scale;
    if (!std::isfinite(v)) fail(path, where + ": a coordinate is not a finite number");
    m.vertices.push_back(v);
  }
}

void add_triangle(MeshData& m, const std::string& path, uint32_t a, uint32_t b, uint32_t c) {
  if (m.indices.size() / 3 >= kMaxTriangles) fail(path, "has more than 2^28 triangles");
  m.indices.insert(m.indices.end(), {a, b, c});
}

MeshData read_obj(const std::string& path, const std::string& text, float scale) {
  MeshData m;
  std::istringstream lines(text);
  std::string line;
  uint64_t number = 0;
  std::vector<uint32_t> polygon;
  while (std::getline(lines, line)) {
    ++number;
    const std::string where = "line " + std::to_string(number);
    std::istringstream fields(line);
    std::string record;
    fields >> record;
    if (record == "v") {
      float xyz[3];
      if (!read_xyz(fields, xyz)) fail(path, where + ": a vertex needs x y z");
      add_vertex(m, path, where, xyz, scale);
    } else if (record == "f") {
      polygon.clear();
      const int64_t defined = static_cast<int64_t>(m.vertices.size() / 3);
      std::string corner;
      while (fields >> corner) {
        // "i", "i/t", "i//n" or "i/t/n": the vertex index is the first number; negative
        // indices count back from the last vertex defined.
        char* end = nullptr;
        errno = 0;
        const long long index = std::strtoll(corner.c_str(), &end, 10);
        if (end == corner.c_str() || (*end != '\0' && *end != '/'))
          fail(path, where + ": \"" + corner + "\" is not a vertex index");
        const int64_t resolved = index < 0 ? defined + index : index - 1;
        // Beyond long long, strtoll clamps: the message quotes the file's digits, not the clamp.
        const std::string shown = errno == ERANGE
                                      ? corner.substr(0, static_cast<size_t>(end - corner.c_str()))
                                      : std::to_string(index);
        if (index == 0 || resolved < 0 || resolved >= defined)
          fail(path, where + ": vertex " + shown + " is not defined before this line (" +
                         std::to_string(defined) + " are)");
        // A polygon of n corners makes n - 2 triangles: one past the limit fails before it grows.
        if (m.indices.size() / 3 + polygon.size() >= kMaxTriangles + 2)
          fail(path, "has more than 2^28 triangles");
        polygon.push_back(static_cast<uint32_t>(resolved));
      }
      if (polygon.size() < 3) fail(path, where + ": a face needs at least three vertices");
      for (size_t k = 1; k + 1 < polygon.size(); ++k)
        add_triangle(m, path, polygon[0], polygon[k], polygon[k + 1]);
    }
  }
  if (m.indices.empty()) fail(path, "has no faces (f records)");
  return m;
}

MeshData read_binary_stl(const std::string& path, const std::string& bytes, uint32_t triangles, float scale) {
  MeshData m;
  m.vertices.reserve(9 * static_cast<size_t>(triangles));
  for (uint32_t t = 0; t < triangles; ++t) {
    // 12 floats (normal, three corners, little-endian) and a 2-byte attribute per triangle.
    const char* record = bytes.data() + 84 + 50 * static_cast<size_t>(t);
    for (int corner = 0; corner < 3; ++corner) {
      float xyz[3];
      std::memcpy(xyz, record + 12 + 12 * corner, sizeof xyz);
      add_vertex(m, path, "triangle " + std::to_string(t), xyz, scale);
    }
    const uint32_t first = 3 * t;
    add_triangle(m, path, first, first + 1, first + 2);
  }
  if (m.indices.empty()) fail(path, "has no triangles");
  return m;
}

MeshData read_ascii_stl(const std::string& path, const std::string& text, float scale) {
  MeshData m;
  std::istringstream words(text);
  std::string word;
  uint32_t corners = 0;
  uint64_t facet = 0;
  while (words >> word) {
    if (word == "facet") {
      ++facet;
      corners = 0;
    } else if (word == "vertex") {
      float xyz[3];
      const std::string where = "facet " + std::to_string(facet);
      if (!read_xyz(words, xyz)) fail(path, where + ": a vertex needs x y z");
      add_vertex(m, path, where, xyz, scale);
      ++corners;
    } else if (word == "endfacet") {
      if (corners != 3)
        fail(path,
             "facet " + std::to_string(facet) + ": has " + std::to_string(corners) + " vertices, not 3");
      const uint32_t first = static_cast<uint32_t>(m.vertices.size() / 3 - 3);
      add_triangle(m, path, first, first + 1, first + 2);
      // A second "endfacet" has no vertices of its own (it added the same triangle again).
      corners = 0;
    }
  }
  if (m.indices.empty()) fail(path, "has no facets (neither binary STL of 84 + 50 n bytes nor ASCII STL)");
  return m;
}

MeshData read_stl(const std::string& path, const std::string& bytes, float scale) {
  // Binary STL: an 80-byte header, a uint32 count n, then 50 bytes per triangle; some binary
  // files also begin with "solid", so the size decides first.
  if (bytes.size() >= 84) {
    uint32_t n = 0;
    std::memcpy(&n, bytes.data() + 80, sizeof n);
    if (bytes.size() == 84 + 50 * static_cast<uint64_t>(n)) return read_binary_stl(path, bytes, n, scale);
  }
  if (bytes.compare(0, 5, "solid") == 0) return read_ascii_stl(path, bytes, scale);
  fail(path, "is neither binary STL (84 + 50 n bytes) nor ASCII STL (starting with \"solid\")");
}

}  // namespace

MeshData parse_mesh(const std::string& bytes, MeshFormat format, float scale,
                    const std::string& name_for_errors) {
  if (bytes.size() > kMaxFileBytes) fail(name_for_errors, "is larger than 2 GiB");
  return format == MeshFormat::kObj ? read_obj(name_for_errors, bytes, scale)
                                    : read_stl(name_for_errors, bytes, scale);
}

MeshData read_mesh_file(const std::string& path, float scale) {
  const std::string ext = lower_extension(path);
  if (ext != "obj" && ext != "stl") fail(path, "is not a .obj or .stl file");
  return parse_mesh(read_whole(path), ext == "obj" ? MeshFormat::kObj : MeshFormat::kStl, scale, path);
}

}  // namespace sph_tools
