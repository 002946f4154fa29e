// SPDX-License-Identifier: MIT
// Outputs read back equal the particle arrays (issue 7, items 3 and 6): the CSV, PLY and VDB
// points writers round-trip a frame exactly (VDB positions to float precision), sph-run's frame
// files hold what the world held after the same frames, and the surface encloses the fluid.
//   usage: cli_outputs SPH_RUN SCENES_DIR
#ifdef SPH_TOOLS_HAVE_OPENVDB
#include <openvdb/openvdb.h>
#include <openvdb/points/PointDataGrid.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/LevelSetSphere.h>
#endif

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_test_support.h"
#include "particle_frame.h"
#include "scene_parser.h"
#include "scene_runtime.h"
#include "writers.h"

// cmocka defines _skip, which OpenVDB uses as a name: it comes last.
extern "C" {
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
}

namespace {

std::string g_sph_run, g_scenes;

// A frame with awkward values: negative zero, tiny and large magnitudes, ids out of order.
sph_tools::ParticleFrame crafted_frame() {
  sph_tools::ParticleFrame f;
  f.frame = 7;
  f.time = 0.125;
  f.particle_spacing = 0.02f;
  f.count = 500;
  for (uint32_t i = 0; i < f.count; ++i) {
    const float a = static_cast<float>(i);
    f.position.insert(f.position.end(), {std::sin(a) * 0.7f, -0.0f + 1e-7f * a, 3.0f + std::cos(a * 1.3f)});
    f.velocity.insert(f.velocity.end(), {1e-30f * a, -12345.678f + a, 0.1f * a});
    f.density.push_back(900.0f + std::sqrt(a));
    f.pressure.push_back(std::fmod(a * 7.1f, 13.0f));
    f.id.push_back((i * 7919u) % 100003u + (i == 3 ? 4000000000u : 0u));
  }
  return f;
}

bool same_floats(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](float x, float y) {
           return std::memcmp(&x, &y, 4) == 0 || x == y;  // bit-equal (or both zeros)
         });
}

void expect_equal(const sph_tools::ParticleFrame& f, const cli_test::Particles& p, bool with_pressure) {
  assert_int_equal(p.count(), f.count);
  assert_true(std::equal(p.id.begin(), p.id.end(), f.id.begin()));
  assert_true(same_floats(p.position, f.position));
  assert_true(same_floats(p.velocity, f.velocity));
  assert_true(same_floats(p.density, f.density));
  if (with_pressure) assert_true(same_floats(p.pressure, f.pressure));
}

// The OBJ writer's vertex normals on a regular octahedron: by symmetry the area-weighted mean of
// the four faces around a corner points along that corner's axis, so each normal is the unit
// vector of its vertex (to float rounding), and the file names that normal at each corner.
void test_obj_vertex_normals(void** /*state*/) {
  sph_tools::SurfaceMesh mesh;
  mesh.vertices = {1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1};
  // Counter-clockwise seen from outside: (a, b, c) with (b - a) x (c - a) pointing out.
  const uint32_t px = 0, nx = 1, py = 2, ny = 3, pz = 4, nz = 5;
  mesh.triangles = {px, py, pz, py, nx, pz, nx, ny, pz, ny, px, pz,
                    py, px, nz, nx, py, nz, ny, nx, nz, px, ny, nz};
  std::vector<float> normals;
  sph_tools::vertex_normals(mesh, &normals);
  assert_int_equal(normals.size(), mesh.vertices.size());
  for (size_t i = 0; i < normals.size(); ++i) assert_true(std::fabs(normals[i] - mesh.vertices[i]) < 1e-6f);

  const std::string dir = cli_test::make_temp_dir("obj");
  const std::string path = dir + "/surface.obj";
  sph_tools::write_obj(mesh, 3, 0.25, path);
  std::FILE* in = std::fopen(path.c_str(), "r");
  assert_non_null(in);
  char line[256];
  int v = 0, vn = 0, f = 0;
  while (std::fgets(line, sizeof line, in)) {
    float x, y, z;
    unsigned a, a_n, b, b_n, c, c_n;
    if (std::sscanf(line, "vn %f %f %f", &x, &y, &z) == 3) {
      assert_true(std::fabs(x - mesh.vertices[3 * vn]) < 1e-6f &&
                  std::fabs(y - mesh.vertices[3 * vn + 1]) < 1e-6f &&
                  std::fabs(z - mesh.vertices[3 * vn + 2]) < 1e-6f);
      ++vn;
    } else if (std::sscanf(line, "v %f %f %f", &x, &y, &z) == 3) {
      ++v;
    } else if (std::sscanf(line, "f %u//%u %u//%u %u//%u", &a, &a_n, &b, &b_n, &c, &c_n) == 6) {
      assert_true(a == a_n && b == b_n && c == c_n);
      assert_int_equal(a, mesh.triangles[3 * static_cast<size_t>(f)] + 1);
      ++f;
    }
  }
  std::fclose(in);
  assert_int_equal(v, 6);
  assert_int_equal(vn, 6);
  assert_int_equal(f, 8);
}

#ifdef SPH_TOOLS_HAVE_OPENVDB
// Reads a VDB points frame into arrays ordered by id.
std::map<uint32_t, std::array<float, 7>> read_vdb_points(const std::string& path, int32_t* frame_meta) {
  openvdb::initialize();
  openvdb::io::File file(path);
  file.open();
  openvdb::GridBase::Ptr base = file.readGrid("points");
  file.close();
  auto grid = openvdb::gridPtrCast<openvdb::points::PointDataGrid>(base);
  assert_non_null(grid.get());
  *frame_meta = grid->metaValue<int32_t>("frame");
  std::map<uint32_t, std::array<float, 7>> out;
  for (auto leaf = grid->tree().cbeginLeaf(); leaf; ++leaf) {
    openvdb::points::AttributeHandle<openvdb::Vec3f> p(leaf->constAttributeArray("P"));
    openvdb::points::AttributeHandle<openvdb::Vec3f> v(leaf->constAttributeArray("v"));
    openvdb::points::AttributeHandle<float> rho(leaf->constAttributeArray("density"));
    openvdb::points::AttributeHandle<int64_t> id(leaf->constAttributeArray("id"));
    for (auto index = leaf->beginIndexOn(); index; ++index) {
      const openvdb::Vec3d world = grid->transform().indexToWorld(index.getCoord().asVec3d() + p.get(*index));
      const openvdb::Vec3f vel = v.get(*index);
      out[static_cast<uint32_t>(id.get(*index))] = {static_cast<float>(world.x()),
                                                    static_cast<float>(world.y()),
                                                    static_cast<float>(world.z()),
                                                    vel.x(),
                                                    vel.y(),
                                                    vel.z(),
                                                    rho.get(*index)};
    }
  }
  return out;
}

void expect_vdb_equal(const sph_tools::ParticleFrame& f, const std::string& path) {
  int32_t frame = -1;
  const auto points = read_vdb_points(path, &frame);
  assert_int_equal(frame, static_cast<int32_t>(f.frame));
  assert_int_equal(points.size(), f.count);
  for (uint32_t i = 0; i < f.count; ++i) {
    const auto it = points.find(f.id[i]);
    assert_true(it != points.end());
    // Positions are stored relative to their voxel: exact to float rounding of that offset.
    for (int a = 0; a < 3; ++a) assert_true(std::fabs(it->second[a] - f.position[3 * i + a]) <= 1e-6f);
    for (int a = 0; a < 3; ++a) assert_true(it->second[3 + a] == f.velocity[3 * i + a]);
    assert_true(it->second[6] == f.density[i]);
  }
}
#endif

void test_writers_round_trip(void**) {
  const sph_tools::ParticleFrame f = crafted_frame();
  const std::string dir = cli_test::make_temp_dir("writers");
  std::string error;
  cli_test::Particles p;
  sph_tools::write_ply(f, dir + "/f.ply");
  if (!cli_test::read_ply(dir + "/f.ply", &p, &error)) std::printf("%s\n", error.c_str());
  expect_equal(f, p, false);
  sph_tools::write_csv(f, dir + "/f.csv");
  assert_true(cli_test::read_csv(dir + "/f.csv", &p, &error));
  expect_equal(f, p, true);
#ifdef SPH_TOOLS_HAVE_OPENVDB
  sph_tools::write_vdb_points(f, dir + "/f.vdb");
  expect_vdb_equal(f, dir + "/f.vdb");
#endif
  // An empty frame is a valid file of each kind.
  sph_tools::ParticleFrame empty;
  sph_tools::write_ply(empty, dir + "/e.ply");
  assert_true(cli_test::read_ply(dir + "/e.ply", &p, &error) && p.count() == 0);
  sph_tools::write_csv(empty, dir + "/e.csv");
  assert_true(cli_test::read_csv(dir + "/e.csv", &p, &error) && p.count() == 0);
#ifdef SPH_TOOLS_HAVE_OPENVDB
  sph_tools::write_vdb_points(empty, dir + "/e.vdb");
  int32_t frame = -1;
  assert_int_equal(read_vdb_points(dir + "/e.vdb", &frame).size(), 0);
#endif
}

// sph-run's frame files against the same scene stepped here through the scene loader: the CPU
// backend is deterministic, so the arrays are equal bit for bit.
void test_run_outputs_equal_world(void**) {
  const std::string scene_file = g_scenes + "/tiny.json";
  const std::string dir = cli_test::make_temp_dir("run_outputs");
  std::string formats = "ply,csv";
#ifdef SPH_TOOLS_HAVE_OPENVDB
  formats += ",vdb";
#endif
  std::string log;
  const std::string stats_file = dir + "/stats.json";
  const int status =
      cli_test::run({g_sph_run, scene_file, "--frames", "3", "--backend", "cpu", "--threads", "2", "--format",
                     formats, "--out", dir, "--quiet", "--stats-json", stats_file},
                    &log);
  std::printf("%s", log.c_str());
  assert_int_equal(status, 0);
  // --stats-json: the run's figures, consistent with the frames it wrote.
  const nlohmann::json stats = nlohmann::json::parse(cli_test::read_text(stats_file));
  assert_int_equal(stats.at("frames").get<int>(), 3);
  assert_true(stats.at("substeps").get<long>() >= 3);
  assert_true(stats.at("s_per_frame").get<double>() > 0.0);
  assert_true(stats.at("stage_ms").at("density").get<double>() > 0.0);
  const uint32_t particles_end = stats.at("particles_end").get<uint32_t>();

  sph_context_def def;
  sph_context_def_init(&def);
  def.backend = SPH_BACKEND_CPU;
  def.cpu_worker_count = 2;
  sph_context* context = nullptr;
  assert_int_equal(sph_context_create(&def, &context), SPH_OK);
  {
    const sph_tools::SceneDesc scene = sph_tools::load_scene_file(scene_file);
    sph_tools::SceneRuntime runtime(scene, context);
    sph_tools::ParticleFrame f;
    for (uint32_t frame = 0; frame <= 3; ++frame) {
      if (frame > 0) runtime.step_frame();
      sph_tools::read_particles(runtime.world(), frame, runtime.time(), &f);
      assert_true(f.count > 100);
      char name[64];
      std::snprintf(name, sizeof name, "%s/fluid_%04u", dir.c_str(), frame);
      cli_test::Particles p;
      std::string error;
      assert_true(cli_test::read_ply(std::string(name) + ".ply", &p, &error));
      expect_equal(f, p, false);
      if (frame == 3) assert_int_equal(p.count(), particles_end);
      assert_true(cli_test::read_csv(std::string(name) + ".csv", &p, &error));
      expect_equal(f, p, true);
#ifdef SPH_TOOLS_HAVE_OPENVDB
      expect_vdb_equal(f, std::string(name) + ".vdb");
#endif
    }
  }
  assert_int_equal(sph_context_destroy(context), SPH_OK);
}

#ifdef SPH_TOOLS_HAVE_OPENVDB
// The surface level set is negative at every particle (it encloses the fluid) and its mesh is
// closed, wound outward, and holds about the fluid's volume.
void test_surface_encloses_fluid(void**) {
  const std::string dir = cli_test::make_temp_dir("surface");
  std::string log;
  assert_int_equal(cli_test::run({g_sph_run, g_scenes + "/tiny.json", "--frames", "1", "--backend", "cpu",
                                  "--format", "ply", "--surface", "--out", dir, "--quiet"},
                                 &log),
                   0);
  cli_test::Particles p;
  std::string error;
  assert_true(cli_test::read_ply(dir + "/fluid_0001.ply", &p, &error));
  openvdb::initialize();
  openvdb::io::File file(dir + "/surface_0001.vdb");
  file.open();
  auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid("surface"));
  file.close();
  assert_true(grid && grid->getGridClass() == openvdb::GRID_LEVEL_SET);
  openvdb::tools::GridSampler<openvdb::FloatGrid, openvdb::tools::BoxSampler> sampler(*grid);
  size_t inside = 0;
  for (size_t i = 0; i < p.count(); ++i)
    inside += sampler.wsSample(
                  openvdb::Vec3d(p.position[3 * i], p.position[3 * i + 1], p.position[3 * i + 2])) < 0.0f;
  assert_true(inside >= p.count() * 99 / 100);  // a lone particle may thin out below a voxel

  std::vector<std::array<double, 3>> v;
  double volume = 0.0;
  size_t faces = 0;
  std::FILE* obj = std::fopen((dir + "/surface_0001.obj").c_str(), "r");
  assert_non_null(obj);
  char line[256];
  while (std::fgets(line, sizeof line, obj)) {
    double x, y, z;
    unsigned a, b, c, na, nb, nc;
    if (std::sscanf(line, "v %lf %lf %lf", &x, &y, &z) == 3) v.push_back({x, y, z});
    // Faces name their vertex normals ("f a//na b//nb c//nc", write_obj.cpp).
    if (std::sscanf(line, "f %u//%u %u//%u %u//%u", &a, &na, &b, &nb, &c, &nc) == 6) {
      assert_true(na == a && nb == b && nc == c);  // one normal per vertex
      const auto &p0 = v.at(a - 1), &p1 = v.at(b - 1), &p2 = v.at(c - 1);
      volume += (p0[0] * (p1[1] * p2[2] - p1[2] * p2[1]) + p0[1] * (p1[2] * p2[0] - p1[0] * p2[2]) +
                 p0[2] * (p1[0] * p2[1] - p1[1] * p2[0])) /
                6.0;
      ++faces;
    }
  }
  std::fclose(obj);
  const double fluid = p.count() * std::pow(0.02, 3) / std::sqrt(2.0);  // FCC: sqrt(2) / s^3 per m^3
  std::printf("surface: %zu faces, volume %.5f m^3, fluid %.5f m^3\n", faces, volume, fluid);
  assert_true(faces > 100);
  assert_true(volume > 0.7 * fluid && volume < 1.5 * fluid);
}

// A collider from a .vdb level set (sph_vdb_load_sdf through the scene file, the file name
// relative to the scene): fluid dropped onto a sphere read from a file stays out of it.
void test_vdb_level_set_collider(void**) {
  const std::string dir = cli_test::make_temp_dir("vdb_collider");
  openvdb::initialize();
  openvdb::FloatGrid::Ptr ball = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(
      0.1f, openvdb::Vec3f(0.0f, 0.1f, 0.0f), 0.005f, 3.0f);
  ball->setName("ball");
  openvdb::io::File file(dir + "/ball.vdb");
  file.write(openvdb::GridPtrVec{ball});
  file.close();
  cli_test::write_text(dir + "/scene.json", R"({
    "world": {"capacity": 4000, "particle_spacing": 0.02},
    "time": {"fps": 50, "frames": 12},
    "fluids": [{"type": "box", "min": [-0.06, 0.25, -0.06], "max": [0.06, 0.35, 0.06]}],
    "colliders": [{"shape": {"type": "vdb", "file": "ball.vdb", "grid": "ball"}}],
    "output": {"format": "ply"}})");
  std::string log;
  const int status = cli_test::run(
      {g_sph_run, dir + "/scene.json", "--backend", "cpu", "--out", dir + "/out", "--preview", "--quiet"},
      &log);
  std::printf("%s", log.c_str());
  assert_int_equal(status, 0);
  cli_test::Particles p;
  std::string error;
  assert_true(cli_test::read_ply(dir + "/out/fluid_0012.ply", &p, &error));
  float lowest = 1e9f;
  for (size_t i = 0; i < p.count(); ++i) {
    const float x = p.position[3 * i], y = p.position[3 * i + 1] - 0.1f, z = p.position[3 * i + 2];
    assert_true(std::sqrt(x * x + y * y + z * z) > 0.1f - 0.01f);  // outside the ball (half a spacing)
    lowest = std::min(lowest, p.position[3 * i + 1]);
  }
  assert_true(lowest < 0.25f);  // the fluid did fall onto the ball
  // A missing grid name is a scene error at the shape's file.
  cli_test::write_text(dir + "/bad.json",
                       R"({"colliders": [{"shape": {"type": "vdb", "file": "ball.vdb", "grid": "cube"}}]})");
  assert_int_equal(cli_test::run({g_sph_run, dir + "/bad.json", "--out", dir + "/bad"}, &log), 3);
  assert_true(log.find("colliders[0].shape.file: cannot load a level set from " + dir + "/ball.vdb") !=
              std::string::npos);
}
#endif

// Loads per collider (issue 17): a collider with "loads" gets loads_<index>_<name>.csv, a row per
// frame; water resting in a tank presses its floor with about its weight, and each row covers
// one frame's time. On either solver (world.solver: "wcsph" or "dfsph").
void loads_csv(const std::string& solver) {
  const std::string dir = cli_test::make_temp_dir(("loads_csv_" + solver).c_str());
  const std::string scene_file = dir + "/loads.json";
  cli_test::write_text(scene_file, R"({
    "world": { "capacity": 4000, "particle_spacing": 0.02, "solver": ")" +
                                       solver + R"(" },
    "time": { "fps": 50, "frames": 3 },
    "fluids": [ { "type": "box", "min": [-0.1, 0.0, -0.1], "max": [0.1, 0.06, 0.1] } ],
    "colliders": [ { "name": "the tank", "inverted": true, "loads": { "point": [0.1, 0, 0] },
                     "shape": { "type": "box", "half_extents": [0.1, 0.1, 0.1], "voxel_size": 0.02 },
                     "transform": { "position": [0, 0.1, 0] } } ],
    "output": { "format": "csv" } })");
  std::string log;
  const int status = cli_test::run(
      {g_sph_run, scene_file, "--backend", "cpu", "--threads", "2", "--out", dir + "/out", "--quiet"}, &log);
  std::printf("%s", log.c_str());
  assert_int_equal(status, 0);
  const std::string text = cli_test::read_text(dir + "/out/loads_0_the_tank.csv");
  std::vector<std::string> lines;
  for (size_t start = 0, end; start < text.size(); start = end + 1) {
    end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    lines.push_back(text.substr(start, end - start));
  }
  assert_int_equal(lines.size(), 4);
  assert_true(lines[0].rfind("frame,time_s,force_x_N,force_y_N,force_z_N,torque_x_Nm", 0) == 0);
  int frame = 0;
  double time = 0, f[3], t[3], p[3], frame_time = 0;
  assert_int_equal(
      std::sscanf(lines[3].c_str(), "%d,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &frame, &time, &f[0],
                  &f[1], &f[2], &t[0], &t[1], &t[2], &p[0], &p[1], &p[2], &frame_time),
      12);
  assert_int_equal(frame, 3);
  assert_true(std::fabs(frame_time - 0.02) < 1e-6 && std::fabs(time - 0.06) < 1e-6);
  assert_true(std::fabs(p[0] - 0.1) < 1e-6 && std::fabs(p[1] - 0.1) < 1e-6);  // the point, posed
  assert_true(f[1] < 0.0);                                                    // pressed down
}

void test_loads_csv(void**) {
  loads_csv("wcsph");
  loads_csv("dfsph");
}

// Threshold events (issue 17): a collider's "loads.threshold" below the water's weight and a
// probe's "pressure_threshold" below its pressure make sph-run print a line for each frame that
// reaches them ("sph-run: frame N: colliders[0]: ..."), the first three in full and the rest folded
// into one line at the end; thresholds no reading reaches print nothing.
void test_threshold_notices(void**) {
  const std::string dir = cli_test::make_temp_dir("threshold_notices");
  const std::string scene_file = dir + "/thresholds.json";
  // 0.2 x 0.06 x 0.2 m of water weighs about 24 N and stands 6 cm: 1 N and 1 Pa are reached
  // once it rests; 1e6 N and 1e6 Pa never.
  const char* scene = R"({
    "world": { "capacity": 4000, "particle_spacing": 0.02 },
    "time": { "fps": 50, "frames": 8 },
    "fluids": [ { "type": "box", "min": [-0.1, 0.0, -0.1], "max": [0.1, 0.06, 0.1] } ],
    "colliders": [ { "name": "tank", "inverted": true, "loads": { "threshold": THRESHOLD },
                     "shape": { "type": "box", "half_extents": [0.1, 0.1, 0.1], "voxel_size": 0.02 },
                     "transform": { "position": [0, 0.1, 0] } } ],
    "probes": [ { "type": "point", "name": "floor", "position": [0, 0.01, 0], "pressure_threshold": THRESHOLD } ],
    "output": { "format": "csv" } })";
  for (const char* threshold : {"1", "1e6"}) {
    std::string text = scene;
    for (size_t at; (at = text.find("THRESHOLD")) != std::string::npos;) text.replace(at, 9, threshold);
    cli_test::write_text(scene_file, text);
    std::string log;
    const int status = cli_test::run(
        {g_sph_run, scene_file, "--backend", "cpu", "--threads", "2", "--out", dir + "/out", "--quiet"},
        &log);
    std::printf("%s", log.c_str());
    assert_int_equal(status, 0);
    const bool low = std::string(threshold) == "1";
    assert_true((log.find(": colliders[0]: the fluid's force ") != std::string::npos) == low);
    assert_true((log.find(" N reached its loads.threshold") != std::string::npos) == low);
    assert_true((log.find(": probes[0]: the peak pressure ") != std::string::npos) == low);
    assert_true((log.find(" Pa reached its pressure_threshold") != std::string::npos) == low);
    // A notice prints in full for the first three frames that reach it, the third saying so, and
    // one line after the progress counts the rest (no total: a force, a pressure). The water
    // rests on the floor from frame 3 or so on (its weight, 24 N, far above 1 N): the collider's
    // notice folds; the probe's peak pressure, near 1 Pa at first, may miss a frame.
    for (const std::string what : {"colliders[0]: the fluid's force", "probes[0]: the peak pressure"}) {
      int printed = 0;
      bool noted = false;  // the third printed frame's note
      for (size_t at = log.find("sph-run: frame "); at != std::string::npos;
           at = log.find("sph-run: frame ", at + 1)) {
        const std::string line = log.substr(at, log.find('\n', at) - at);
        if (line.find(": " + what + " ") == std::string::npos) continue;
        ++printed;
        noted = line.find("(from here on, frames with this message are counted") != std::string::npos;
        assert_true(noted == (printed == 3));
      }
      const size_t closing = log.find("sph-run: " + what + " reached its " +
                                      (what[0] == 'c' ? "loads.threshold" : "pressure_threshold") + " in ");
      if (!low) assert_int_equal(printed, 0);
      if (low) assert_true(printed >= 1 && printed <= 3);
      if (closing != std::string::npos) {
        assert_true(noted);
        assert_true(log.compare(log.find('\n', closing) - 14, 14, ", not printed)") == 0);
      }
      if (low && what[0] == 'c') assert_true(closing != std::string::npos);
    }
  }
}

// DFSPH's solves in sph-run's progress lines, summary and --stats-json, and a capped solve never
// silent (issue 16 item 1): water resting in a tank, 6 frames. At the defaults: the summary's solve lines, no
// cap reached, no warning. With max_iterations 2 under a 1e-6 bound: a warning for each frame whose solves
// stopped at the cap, the counts in the warnings adding up to the summary's and the JSON's
// pressure_solves_capped (> 0). A weakly compressible world prints and writes no solve figures.
void test_dfsph_solve_report(void**) {
  const std::string dir = cli_test::make_temp_dir("dfsph_solve_report");
  const std::string scene_file = dir + "/tank.json", stats_file = dir + "/stats.json";
  const char* scene = R"({
    "world": { "capacity": 4000, "particle_spacing": 0.02, "solver": "SOLVER" },
    PHYSICS "time": { "fps": 50, "frames": 6 },
    "fluids": [ { "type": "box", "min": [-0.1, 0.0, -0.1], "max": [0.1, 0.08, 0.1] } ],
    "colliders": [ { "inverted": true,
                     "shape": { "type": "box", "half_extents": [0.1, 0.1, 0.1], "voxel_size": 0.02 },
                     "transform": { "position": [0, 0.1, 0] } } ],
    "output": { "format": "csv" } })";
  struct Case {
    const char* solver;
    const char* physics;  // (a weakly compressible world refuses a physics.dfsph section)
    int density_cap;      // the density solve's cap a warning must name; 0: no density solve capped
    int divergence_cap;   // likewise for the divergence solve
  };
  const Case cases[] = {
      {"dfsph", R"("physics": { "dfsph": { "max_iterations": 100, "density_error": 0.001 } },)", 0, 0},
      {"dfsph", R"("physics": { "dfsph": { "max_iterations": 2, "density_error": 1e-6 } },)", 2, 0},
      {"dfsph",
       R"("physics": { "dfsph": { "max_divergence_iterations": 1, "divergence_error": 1e-6,
                                  "divergence_error_per_step": 1e-9 } },)",
       0, 1},
      {"dfsph", R"("physics": { "dfsph": { "flags": 1 } },)", 0, 0},  // SPH_DFSPH_SKIP_DIVERGENCE_SOLVE
      {"wcsph", "", 0, 0}};
  int folded_runs = 0;  // runs whose warnings were folded: at least one case must fold
  for (const Case& c : cases) {
    std::string text = scene;
    text.replace(text.find("SOLVER"), 6, c.solver);
    text.replace(text.find("PHYSICS"), 7, c.physics);
    cli_test::write_text(scene_file, text);
    std::string log;
    const int status = cli_test::run({g_sph_run, scene_file, "--backend", "cpu", "--threads", "2", "--out",
                                      dir + "/out", "--stats-json", stats_file},
                                     &log);
    std::printf("%s", log.c_str());
    assert_int_equal(status, 0);
    const nlohmann::json stats = nlohmann::json::parse(cli_test::read_text(stats_file));
    const bool dfsph = std::string(c.solver) == "dfsph";
    // The progress lines (not a terminal: a line a frame) show the frame's iterations a substep.
    assert_true((log.find("frame 6/6: ") != std::string::npos));
    assert_true((log.find(" density iterations a substep), step ") != std::string::npos) == dfsph);
    assert_true((log.find("  DFSPH density solve: ") != std::string::npos) == dfsph);
    assert_true(stats.contains("dfsph") == dfsph);
    // The warnings ("frame N: the DFSPH <solve> solve stopped at its cap of C iteration(s) above its
    // bound(s) in K of the frame's substeps"): each names the case's cap; their K summed. A solve
    // capped in every frame prints in full for the first three frames only (MessageFold), the third
    // saying so, and the run's end adds the rest in one line ("... in 3 more frames (4 to 6, not
    // printed): K substeps"): its K summed too.
    const auto warned = [&](const std::string& solve, int cap) {
      const std::string head = "sph-run: warning: frame ",
                        what = ": the DFSPH " + solve + " solve stopped at its cap of ";
      long sum = 0;
      int frames = 0;
      bool folding = false;  // the third frame printed said that the rest are counted
      for (size_t at = log.find(head); at != std::string::npos; at = log.find(head, at + 1)) {
        const size_t line_end = log.find('\n', at), here = log.find(what, at);
        if (here == std::string::npos || here > line_end) continue;  // another warning
        assert_false(folding);  // nothing printed in full after the fold's note
        ++frames;
        assert_true(log.compare(here + what.size(), std::to_string(cap).size() + 10,
                                std::to_string(cap) + " iteration") == 0);
        const size_t in = log.find(" in ", here + what.size());
        assert_true(in != std::string::npos && in < line_end);
        sum += std::strtol(log.c_str() + in + 4, nullptr, 10);
        folding = log.substr(at, line_end - at).find("(from here on, frames with this message are counted") !=
                  std::string::npos;
        assert_true(folding == (frames == 3));
      }
      const std::string rest =
          "sph-run: warning: the DFSPH " + solve + " solve stopped at its cap above its bound";
      const size_t at = log.find(rest);
      if (at != std::string::npos) {
        assert_true(folding);  // only after the third frame's note
        ++folded_runs;
        const size_t line_end = log.find('\n', at), more = log.find(" more frame", at),
                     total = log.find(", not printed): ", at);
        assert_true(more < line_end && total < line_end);
        assert_true(std::strtol(log.c_str() + log.find(" in ", at + rest.size()) + 4, nullptr, 10) >= 1);
        sum += std::strtol(log.c_str() + total + 16, nullptr, 10);
        assert_true(log.compare(log.find(" substeps", total), 10, " substeps\n") == 0);
      }
      return sum;
    };
    const long density_warned = warned("density", c.density_cap),
               divergence_warned = warned("divergence", c.divergence_cap);
    if (!dfsph) {
      assert_int_equal(density_warned + divergence_warned, 0);
      continue;
    }
    const nlohmann::json& d = stats.at("dfsph");
    const long substeps = d.at("substeps").get<long>(), capped = d.at("pressure_solves_capped").get<long>(),
               divergence_capped = d.at("divergence_solves_capped").get<long>();
    assert_int_equal(substeps, stats.at("substeps").get<long>());
    assert_true(d.at("pressure_iterations").get<long>() >= 2 * substeps);  // at least two a substep
    assert_int_equal(density_warned, capped);
    assert_int_equal(divergence_warned, divergence_capped);
    assert_true(log.find("caps above their bounds: " + std::to_string(capped) + " density, " +
                         std::to_string(divergence_capped) + " divergence") != std::string::npos);
    assert_true((capped > 0) == (c.density_cap > 0));
    assert_true((divergence_capped > 0) == (c.divergence_cap > 0));
    if (c.density_cap > 0) assert_int_equal(d.at("pressure_iterations_max").get<long>(), c.density_cap);
    if (c.divergence_cap > 0)
      assert_int_equal(d.at("divergence_iterations_max").get<long>(), c.divergence_cap);
    if (c.density_cap == 0) {
      // The density bound holds in every substep: the worst substep's mean error within it.
      assert_true(d.at("density_error_max").get<double>() <= 0.001);
    }
    // The divergence solve switched off: no iterations, and the summary says so.
    const bool skipped = std::strstr(c.physics, "\"flags\": 1") != nullptr;
    assert_true((d.at("divergence_iterations").get<long>() == 0) == skipped);
    assert_true((log.find("  DFSPH divergence solve: off\n") != std::string::npos) == skipped);
  }
  assert_true(folded_runs >= 1);  // the divergence cap's case warns in every frame: its last three fold
}

// Probes (issue 17 item 2): each probe of "probes" gets probe_<index>[_<name>].csv, a row per
// frame; a point in water resting in a tank reads a density near rho0, a gauge through it the few
// centimetres of water (the 6 cm fluid box holds three lattice layers, 4.2 cm, before it spreads
// over the tank's floor; test_probes.c holds the gauge to the fill height). On either solver.
void probe_csv(const std::string& solver) {
  const std::string dir = cli_test::make_temp_dir(("probe_csv_" + solver).c_str());
  const std::string scene_file = dir + "/probes.json";
  cli_test::write_text(scene_file, R"({
    "world": { "capacity": 4000, "particle_spacing": 0.02, "solver": ")" +
                                       solver + R"(" },
    "time": { "fps": 50, "frames": 3 },
    "fluids": [ { "type": "box", "min": [-0.1, 0.0, -0.1], "max": [0.1, 0.06, 0.1] } ],
    "colliders": [ { "inverted": true,
                     "shape": { "type": "box", "half_extents": [0.1, 0.1, 0.1], "voxel_size": 0.02 },
                     "transform": { "position": [0, 0.1, 0] } } ],
    "probes": [ { "type": "point", "position": [0, 0.02, 0], "sampling": "substep" },
                { "type": "gauge", "name": "mid", "position": [0, -0.05, 0], "length": 0.2 } ],
    "output": { "format": "csv" } })");
  std::string log;
  const int status = cli_test::run(
      {g_sph_run, scene_file, "--backend", "cpu", "--threads", "2", "--out", dir + "/out", "--quiet"}, &log);
  std::printf("%s", log.c_str());
  assert_int_equal(status, 0);
  for (int k = 0; k < 2; ++k) {
    const std::string text =
        cli_test::read_text(dir + (k == 0 ? "/out/probe_0.csv" : "/out/probe_1_mid.csv"));
    std::vector<std::string> lines;
    for (size_t start = 0, end; start < text.size(); start = end + 1) {
      end = text.find('\n', start);
      if (end == std::string::npos) end = text.size();
      lines.push_back(text.substr(start, end - start));
    }
    assert_int_equal(lines.size(), 4);
    assert_true(lines[0].rfind("frame,time_s,density_kg_m3,pressure_Pa,velocity_x_m_s", 0) == 0);
    int frame = 0;
    unsigned samples = 0;
    double time = 0, rho = 0, p = 0, v[3], p_max = 0, kernel_sum = 0, height = 0, span = 0;
    assert_int_equal(
        std::sscanf(lines[3].c_str(), "%d,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%u,%lf", &frame, &time, &rho,
                    &p, &v[0], &v[1], &v[2], &p_max, &kernel_sum, &height, &samples, &span),
        12);
    assert_int_equal(frame, 3);
    assert_true(std::fabs(time - 0.06) < 1e-6);
    // All of this 6 cm layer at 2 cm spacing lies within h of the floor or the surface, where the
    // summed densities the interpolant averages read a deficit (measured 844 and 807).
    assert_true(rho > 700.0 && rho < 1100.0);
    if (k == 0) {
      assert_true(samples > 1 && std::fabs(span - 0.02) < 1e-6 && height == 0.0);
    } else {
      assert_true(samples == 1 && height > 0.03 && height < 0.065);
    }
  }
}

void test_probe_csv(void**) {
  probe_csv("wcsph");
  probe_csv("dfsph");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s SPH_RUN SCENES_DIR\n", argv[0]);
    return 2;
  }
  g_sph_run = argv[1];
  g_scenes = argv[2];
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_writers_round_trip),
      cmocka_unit_test(test_run_outputs_equal_world),
      cmocka_unit_test(test_loads_csv),
      cmocka_unit_test(test_threshold_notices),
      cmocka_unit_test(test_dfsph_solve_report),
      cmocka_unit_test(test_probe_csv),
      cmocka_unit_test(test_obj_vertex_normals),
#ifdef SPH_TOOLS_HAVE_OPENVDB
      cmocka_unit_test(test_surface_encloses_fluid),
      cmocka_unit_test(test_vdb_level_set_collider),
#endif
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
