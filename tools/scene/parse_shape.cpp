// SPDX-License-Identifier: MIT
// Shapes of a scene file: the library's analytic shapes, a level set from a .vdb file, or a
// triangle mesh from an .obj or .stl file.
#include "mesh_file.h"
#include "parse_parts.h"
#include "scene_error.h"

namespace sph_tools {

namespace {

std::string resolve(const std::string& base_dir, const std::string& file) {
  if (file.empty() || file[0] == '/' || base_dir.empty()) return file;
  return base_dir + "/" + file;
}

}  // namespace

ShapeDesc parse_shape(const JsonNode& node, const std::string& base_dir) {
  ShapeDesc shape;
  shape.path = node.path();
  if (node.missing() || !node.json().is_object()) node.fail("a shape (an object with a \"type\")");
  const size_t type =
      node["type"].choice({"plane", "box", "sphere", "capsule", "cylinder", "cup", "vdb", "mesh"});
  if (type == 7) {
    node.expect_object("a mesh shape",
                       {"type", "file", "scale", "voxel_size", "band_width", "padding_voxels"});
    shape.kind = ShapeDesc::Kind::kMesh;
    const std::string file = node["file"].string();
    if (file.empty()) node["file"].fail("a file name (.obj or .stl)");
    shape.mesh_file = resolve(base_dir, file);
    const float scale = node["scale"].opt_positive(1.0f);
    try {
      MeshData data = read_mesh_file(shape.mesh_file, scale);
      shape.mesh_vertices = std::move(data.vertices);
      shape.mesh_indices = std::move(data.indices);
    } catch (const std::runtime_error& e) {
      throw SceneError(node["file"].path(), e.what());
    }
    sph_mesh_desc& m = shape.mesh;
    sph_mesh_desc_init(&m);
    m.voxel_size = node["voxel_size"].opt_positive(m.voxel_size);
    m.band_width = node["band_width"].opt_positive(m.band_width);
    m.padding_voxels = node["padding_voxels"].opt_count(m.padding_voxels, 1, 1024);
    return shape;
  }
  if (type == 6) {
    node.expect_object("a vdb shape", {"type", "file", "grid"});
    shape.kind = ShapeDesc::Kind::kVdb;
    const std::string file = node["file"].string();
    if (file.empty()) node["file"].fail("a file name");
    shape.vdb_file = resolve(base_dir, file);
    shape.vdb_grid = node["grid"].opt_string("");
    return shape;
  }
  sph_shape_desc& d = shape.analytic;
  sph_shape_desc_init(&d);
  switch (type) {
    case 0:
      node.expect_object("a plane", {"type", "half_extents", "voxel_size", "padding_voxels"});
      d.shape = SPH_SHAPE_PLANE;
      break;
    case 1:
      node.expect_object(
          "a box", {"type", "half_extents", "wall_thickness", "open_top", "voxel_size", "padding_voxels"});
      d.shape = SPH_SHAPE_BOX;
      break;
    case 2:
      node.expect_object("a sphere", {"type", "radius", "voxel_size", "padding_voxels"});
      d.shape = SPH_SHAPE_SPHERE;
      break;
    case 3:
      node.expect_object("a capsule", {"type", "radius", "half_height", "voxel_size", "padding_voxels"});
      d.shape = SPH_SHAPE_CAPSULE;
      break;
    case 4:
      node.expect_object("a cylinder", {"type", "radius", "half_height", "voxel_size", "padding_voxels"});
      d.shape = SPH_SHAPE_CYLINDER;
      break;
    default:
      node.expect_object("a cup",
                         {"type", "radius", "half_height", "wall_thickness", "voxel_size", "padding_voxels"});
      d.shape = SPH_SHAPE_CUP;
      break;
  }
  if (d.shape == SPH_SHAPE_PLANE || d.shape == SPH_SHAPE_BOX) {
    const JsonNode h = node["half_extents"];
    const sph_vec3 e = h.vec3();
    const float c[3] = {e.x, e.y, e.z};
    for (size_t i = 0; i < 3; ++i)
      if (!(c[i] > 0.0f)) h.index(i).fail("a positive number");
    d.half_extents = e;
  } else {
    d.radius = node["radius"].positive();
    if (d.shape != SPH_SHAPE_SPHERE) d.half_height = node["half_height"].positive();
  }
  if (d.shape == SPH_SHAPE_BOX) {
    d.wall_thickness = node["wall_thickness"].opt_non_negative(0.0f);
    if (node["open_top"].opt_boolean(false)) {
      if (d.wall_thickness <= 0.0f)
        node["open_top"].fail("false (an open top needs a hollow box: wall_thickness > 0)");
      d.flags |= SPH_SHAPE_FLAG_OPEN_TOP;
    }
  }
  if (d.shape == SPH_SHAPE_CUP) d.wall_thickness = node["wall_thickness"].positive();
  d.voxel_size = node["voxel_size"].opt_positive(d.voxel_size);
  d.padding_voxels = node["padding_voxels"].opt_count(d.padding_voxels == 0 ? 4 : d.padding_voxels, 1, 1024);
  return shape;
}

}  // namespace sph_tools
