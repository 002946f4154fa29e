// SPDX-License-Identifier: MIT
// The scene a scene file describes, parsed and validated but not yet built: plain values that
// map one to one onto the public C API's descriptions (see docs/scenes.md for the file format).
#ifndef SPH_TOOLS_SCENE_DESC_H
#define SPH_TOOLS_SCENE_DESC_H

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "motion.h"
#include "sph_c.h"

namespace sph_tools {

// An SDF asset: an analytic shape of the library, a level set from a .vdb file, or a
// triangle mesh from an .obj or .stl file (read when the scene is parsed).
struct ShapeDesc {
  enum class Kind { kAnalytic, kVdb, kMesh };
  Kind kind = Kind::kAnalytic;
  sph_shape_desc analytic{};  // kAnalytic: filled by sph_shape_desc_init, then the file's fields
  std::string vdb_file;       // kVdb: absolute path
  std::string vdb_grid;       // kVdb: grid name, "" = the first float level set
  std::string path;           // where in the file, for errors ("colliders[1].shape")
  // kMesh: the file's triangles (scaled) and the sizes; mesh.vertices and mesh.indices are
  // pointed at mesh_vertices and mesh_indices when the asset is made.
  std::string mesh_file;
  std::vector<float> mesh_vertices;
  std::vector<uint32_t> mesh_indices;
  sph_mesh_desc mesh{};
  // kVdb: the box of the level set's active voxels in its local frame, when a tool that reads
  // OpenVDB files has filled it in (sph-run does, for the preview's camera and silhouettes).
  bool has_vdb_bounds = false;
  sph_vec3 vdb_bounds_min{}, vdb_bounds_max{};
};

// A fluid body added at `time` (s): a box or sphere filled on the FCC lattice, or explicit
// particles.
struct FluidDesc {
  enum class Kind { kBox, kSphere, kParticles };
  Kind kind = Kind::kBox;
  sph_vec3 min{}, max{};          // kBox
  sph_vec3 center{};              // kSphere
  float radius = 0.0f;            // kSphere
  sph_vec3 velocity{};            // kBox, kSphere
  std::vector<float> positions;   // kParticles: 3 floats each
  std::vector<float> velocities;  // kParticles: 3 floats each, or empty
  double time = 0.0;
  std::string path;
};

struct ColliderDesc {
  std::string name;
  ShapeDesc shape;
  sph_transform transform{};  // its pose at time 0 (the motion's, when it has one)
  Motion motion;
  bool inverted = false;
  float restitution = 0.0f, friction = 0.0f, stickiness = 0.0f;
  bool loads = false;           // "loads": its force and torque are written per frame (a CSV)
  sph_vec3 load_point{};        // the torque's point, in the collider's frame
  float load_threshold = 0.0f;  // N: a frame whose force reaches it is reported; 0 = never
  std::string path;
};

struct SourceDesc {
  std::string name;
  ShapeDesc shape;
  sph_transform transform{};
  Motion motion;
  sph_source_mode mode = SPH_SOURCE_FILL_ONCE;
  sph_vec3 velocity{};
  float spacing = 0.0f, min_distance = 0.0f, rate = 0.0f;
  uint32_t user_attribute = 0;      // its particles' user attribute
  bool has_user_attribute = false;  // given in the scene: the world gets SPH_FEATURE_USER_ATTRIBUTE
  double start = 0.0;               // s: created before the step at start
  double stop = std::numeric_limits<double>::infinity();  // s: removed from then on
  std::string path;
};

struct SinkDesc {
  std::string name;
  sph_sink_mode mode = SPH_SINK_REGION;
  ShapeDesc shape;  // kRegion
  sph_transform transform{};
  sph_vec3 bounds_min{}, bounds_max{};  // kOutsideBounds
  std::string path;
};

// A probe or gauge ("probes": [...]); sph-run writes its reading per frame to a CSV.
struct ProbeDesc {
  std::string name;
  sph_probe_kind kind = SPH_PROBE_POINT;
  sph_probe_sampling sampling = SPH_PROBE_EVERY_FRAME;
  sph_vec3 position{};
  sph_vec3 direction{};  // gauge; zero = up (against gravity)
  float length = 0.0f;   // gauge
  float sample_spacing = 0.0f;
  float pressure_threshold = 0.0f;  // Pa: a frame whose peak pressure reaches it is reported; 0 = never
  std::string path;
};

struct ForceFieldDesc {
  std::string name;
  sph_force_field_kind kind = SPH_FORCE_FIELD_UNIFORM;
  bool has_region = false;
  ShapeDesc region;
  sph_transform transform{};
  Motion motion;
  sph_vec3 vector{};  // uniform: acceleration; vortex: axis
  float strength = 0.0f, falloff_radius = 0.0f;
  double start = 0.0, stop = std::numeric_limits<double>::infinity();
  std::string path;
};

// The parameters of one physics method as the file sets them ("physics": {"tait": {...}}): a
// whole params struct of the library, the fields the file does not give at their defaults
// (from the library's description of the struct, sph_params_get_field_info).
struct PhysicsDesc {
  sph_params_kind kind = SPH_PARAMS_WORLD;
  std::vector<unsigned char> bytes;  // the struct, struct_size first
  std::string path;                  // "physics.tait"
};

enum class OutputFormat { kVdb, kPly, kCsv, kVtp };

struct CameraDesc {
  bool automatic = true;
  sph_vec3 position{}, target{}, up{0.0f, 1.0f, 0.0f};
  float fov_degrees = 40.0f;  // vertical
};

struct OutputDesc {
  std::string directory;              // absolute, or relative to the working directory; "" = not set
  std::vector<OutputFormat> formats;  // empty = not set (sph-run's default)
  bool surface = false;
  bool preview = false;
  bool preview_surface = false;  // the preview draws the surface mesh (needs surface) instead of particles
  CameraDesc camera;
  uint32_t width = 960, height = 540;
  float speed_max = 0.0f;       // speed drawn brightest, m/s; 0 = automatic
  float surface_radius = 0.0f;  // particle radius of the surface, m; 0 = the particle spacing
  float surface_voxel = 0.0f;   // voxel size of the surface, m; 0 = half the particle spacing
};

struct SceneDesc {
  std::string file;      // the scene file, as given
  std::string base_dir;  // its directory: relative paths in the file start here
  std::string name, description;
  sph_world_def world{};
  sph_world_params params{};
  std::vector<PhysicsDesc> physics;  // in the file's order
  uint32_t frames = 120;
  float fps = 60.0f;
  std::vector<FluidDesc> fluids;
  std::vector<ColliderDesc> colliders;
  std::vector<SourceDesc> sources;
  std::vector<SinkDesc> sinks;
  std::vector<ForceFieldDesc> force_fields;
  std::vector<ProbeDesc> probes;
  OutputDesc output;
};

}  // namespace sph_tools

#endif
