// SPDX-License-Identifier: MIT
// Output settings: where frames go, in which formats, the surface and the preview images.
#include "parse_parts.h"
#include "scene_error.h"

namespace sph_tools {

namespace {

OutputFormat parse_format(const JsonNode& node) {
  switch (node.choice({"vdb", "ply", "csv", "vtp"})) {
    case 0:
      return OutputFormat::kVdb;
    case 1:
      return OutputFormat::kPly;
    case 3:
      return OutputFormat::kVtp;
    default:
      return OutputFormat::kCsv;
  }
}

void parse_camera(const JsonNode& node, CameraDesc* camera) {
  if (node.missing()) return;
  if (node.json().is_string()) {
    node.choice({"auto"});
    camera->automatic = true;
    return;
  }
  node.expect_object("a camera (or \"auto\")", {"position", "target", "up", "fov_degrees"});
  camera->automatic = false;
  camera->position = node["position"].vec3();
  camera->target = node["target"].vec3();
  const sph_vec3 d{camera->target.x - camera->position.x, camera->target.y - camera->position.y,
                   camera->target.z - camera->position.z};
  if (d.x == 0.0f && d.y == 0.0f && d.z == 0.0f) node["target"].fail("a point other than the position");
  camera->up = node["up"].missing() ? camera->up : node["up"].direction();
  camera->fov_degrees = node["fov_degrees"].opt_in_range(camera->fov_degrees, 1.0f, 170.0f);
}

}  // namespace

OutputDesc parse_output(const JsonNode& node) {
  OutputDesc out;
  if (node.missing()) return out;
  node.expect_object("output", {"directory", "format", "surface", "preview"});
  out.directory = node["directory"].opt_string("");
  const JsonNode format = node["format"];
  if (!format.missing()) {
    if (format.json().is_array()) {
      const size_t n = format.array_size("a list of formats", 1);
      for (size_t i = 0; i < n; ++i) {
        const OutputFormat f = parse_format(format.index(i));
        // Each format writes one file a frame under one name: twice would be the same file.
        for (OutputFormat earlier : out.formats)
          if (earlier == f) format.index(i).fail("a format not listed before it");
        out.formats.push_back(f);
      }
    } else {
      out.formats.push_back(parse_format(format));
    }
  }
  const JsonNode surface = node["surface"];
  if (!surface.missing()) {
    if (surface.json().is_boolean()) {
      out.surface = surface.boolean();
    } else {
      surface.expect_object("surface settings (or true/false)", {"enabled", "particle_radius", "voxel_size"});
      out.surface = surface["enabled"].opt_boolean(true);
      out.surface_radius = surface["particle_radius"].opt_positive(0.0f);
      out.surface_voxel = surface["voxel_size"].opt_positive(0.0f);
    }
  }
  const JsonNode preview = node["preview"];
  if (!preview.missing()) {
    if (preview.json().is_boolean()) {
      out.preview = preview.boolean();
    } else {
      preview.expect_object("preview settings (or true/false)",
                            {"enabled", "style", "camera", "width", "height", "speed_max"});
      out.preview = preview["enabled"].opt_boolean(true);
      out.preview_surface = preview["style"].opt_choice(0, {"particles", "surface"}) == 1;
      parse_camera(preview["camera"], &out.camera);
      out.width = preview["width"].opt_count(out.width, 16, 8192);
      out.height = preview["height"].opt_count(out.height, 16, 8192);
      out.speed_max = preview["speed_max"].opt_positive(0.0f);
    }
  }
  return out;
}

}  // namespace sph_tools
