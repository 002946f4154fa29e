// SPDX-License-Identifier: MIT
// compare_vdb_frames A.vdb B.vdb: whether two of sph-run's VDB frames hold the same grids, for
// tests/mpi/check_sph_run_mpi.py (sph-run against sph-run-mpi's merged frames).
//   points   (fluid_NNNN.vdb)   the same particles by id: each one's voxel, position in it, v and
//                               density bit for bit (the two files list a voxel's particles in
//                               another order: sph-run in its storage order, sph-run-mpi by id)
//   surface  (surface_NNNN.vdb) the same level set: transform, background, topology, and every
//                               active voxel's value bit for bit
// and the same frame and time metadata. Prints what it compared; exit 0 when equal, 1 with the
// first difference, 2 on a file it cannot read.
#include <openvdb/openvdb.h>
#include <openvdb/points/PointDataGrid.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>

namespace {

struct Point {
  openvdb::Coord voxel;
  uint32_t bits[7];  // offset xyz, v xyz, density
};

uint32_t bits(float f) {
  uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

openvdb::GridPtrVecPtr read_grids(const std::string& path) {
  openvdb::io::File file(path);
  file.open();
  openvdb::GridPtrVecPtr grids = file.getGrids();
  file.close();
  return grids;
}

std::map<int64_t, Point> points_of(const openvdb::points::PointDataGrid& grid) {
  std::map<int64_t, Point> out;
  for (auto leaf = grid.tree().cbeginLeaf(); leaf; ++leaf) {
    openvdb::points::AttributeHandle<openvdb::Vec3f> p(leaf->constAttributeArray("P"));
    openvdb::points::AttributeHandle<openvdb::Vec3f> v(leaf->constAttributeArray("v"));
    openvdb::points::AttributeHandle<float> density(leaf->constAttributeArray("density"));
    openvdb::points::AttributeHandle<int64_t> id(leaf->constAttributeArray("id"));
    for (auto voxel = leaf->cbeginValueOn(); voxel; ++voxel)
      for (auto i = leaf->beginIndexVoxel(voxel.getCoord()); i; ++i) {
        Point q;
        q.voxel = voxel.getCoord();
        const openvdb::Vec3f x = p.get(*i), u = v.get(*i);
        for (int a = 0; a < 3; ++a) {
          q.bits[a] = bits(x[a]);
          q.bits[3 + a] = bits(u[a]);
        }
        q.bits[6] = bits(density.get(*i));
        if (!out.emplace(id.get(*i), q).second)
          throw std::runtime_error("id " + std::to_string(id.get(*i)) + " twice in one grid");
      }
  }
  return out;
}

std::string compare_points(const openvdb::points::PointDataGrid& a, const openvdb::points::PointDataGrid& b) {
  if (a.transform() != b.transform()) return "the points' transforms differ";
  const std::map<int64_t, Point> pa = points_of(a), pb = points_of(b);
  if (pa.size() != pb.size())
    return std::to_string(pa.size()) + " points against " + std::to_string(pb.size());
  size_t differ = 0;
  std::string first;
  for (const auto& [id, p] : pa) {
    const auto q = pb.find(id);
    if (q == pb.end()) return "id " + std::to_string(id) + " is in the first file only";
    if (p.voxel != q->second.voxel || std::memcmp(p.bits, q->second.bits, sizeof p.bits) != 0) {
      if (differ++ == 0) first = "id " + std::to_string(id);
    }
  }
  if (differ)
    return std::to_string(differ) + " of " + std::to_string(pa.size()) + " points differ (first: " + first +
           ")";
  std::printf("%zu points equal by id", pa.size());
  return "";
}

std::string compare_level_sets(const openvdb::FloatGrid& a, const openvdb::FloatGrid& b) {
  if (a.transform() != b.transform()) return "the level sets' transforms differ";
  if (bits(a.background()) != bits(b.background())) return "the backgrounds differ";
  if (!a.tree().hasSameTopology(b.tree())) return "the level sets' topologies differ";
  size_t active = 0, differ = 0;
  for (auto v = a.cbeginValueAll(); v; ++v) {
    const float other = b.tree().getValue(v.getCoord());
    if (bits(*v) != bits(other)) ++differ;
    active += v.isValueOn() ? 1 : 0;
  }
  if (differ) return std::to_string(differ) + " values differ";
  std::printf("%zu active voxels equal", active);
  return "";
}

std::string compare_meta(const openvdb::GridBase& a, const openvdb::GridBase& b) {
  for (const char* key : {"frame", "time"}) {
    const openvdb::Metadata::ConstPtr x = a[key], y = b[key];
    if (!x || !y || x->str() != y->str()) return std::string("the grids' ") + key + " differ";
  }
  return "";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: compare_vdb_frames A.vdb B.vdb\n");
    return 2;
  }
  openvdb::initialize();
  openvdb::GridPtrVecPtr a, b;
  try {
    a = read_grids(argv[1]);
    b = read_grids(argv[2]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "compare_vdb_frames: %s\n", e.what());
    return 2;
  }
  if (a->size() != 1 || b->size() != 1) {
    std::fprintf(stderr, "compare_vdb_frames: %zu and %zu grids, expected one each\n", a->size(), b->size());
    return 1;
  }
  const openvdb::GridBase& ga = *a->front();
  const openvdb::GridBase& gb = *b->front();
  std::string problem;
  try {
    if (ga.getName() != gb.getName() || ga.type() != gb.type()) {
      problem = "the grids' names or types differ";
    } else if (ga.isType<openvdb::points::PointDataGrid>()) {
      problem = compare_points(static_cast<const openvdb::points::PointDataGrid&>(ga),
                               static_cast<const openvdb::points::PointDataGrid&>(gb));
    } else if (ga.isType<openvdb::FloatGrid>()) {
      problem = compare_level_sets(static_cast<const openvdb::FloatGrid&>(ga),
                                   static_cast<const openvdb::FloatGrid&>(gb));
    } else {
      problem = "a grid of type " + ga.type() + ", neither points nor a level set";
    }
    if (problem.empty()) problem = compare_meta(ga, gb);
  } catch (const std::exception& e) {
    problem = e.what();
  }
  if (!problem.empty()) {
    std::printf("\n%s vs %s: %s\n", argv[1], argv[2], problem.c_str());
    return 1;
  }
  std::printf(" (%s)\n", ga.getName().c_str());
  return 0;
}
