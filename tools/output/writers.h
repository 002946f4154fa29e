// SPDX-License-Identifier: MIT
// The per-frame file writers. Each writes one file at `path` (the caller's temporary name)
// and throws std::runtime_error when it cannot.
#ifndef SPH_TOOLS_WRITERS_H
#define SPH_TOOLS_WRITERS_H

#include <string>
#include <vector>

#include "particle_frame.h"
#include "surface_mesh.h"

namespace sph_tools {

// CSV with a header line: id,x,y,z,vx,vy,vz,density,pressure; floats with 9 significant
// digits, so every value reads back to the same float.
void write_csv(const ParticleFrame& frame, const std::string& path);

// Binary little-endian PLY: one vertex element with float x y z vx vy vz density, uint id.
void write_ply(const ParticleFrame& frame, const std::string& path);

// VTK XML PolyData (.vtp, ParaView, VTK, meshio): every attribute as point data (velocity,
// density, pressure, id), one vertex cell per particle, the frame's time as field data
// TimeValue; binary arrays in a raw appended block.
void write_vtp(const ParticleFrame& frame, const std::string& path);

// One frame of a ParaView time series: its file name (relative to the .pvd) and time in s.
struct SeriesEntry {
  std::string file;
  double time = 0.0;
};
// A ParaView Data collection (.pvd) listing the frames of a series with their times.
void write_pvd(const std::vector<SeriesEntry>& series, const std::string& path);

// OpenVDB points (grid "points"): P, v (velocity), density (float) and id (int64), with the
// frame number and time as grid metadata. Only in builds with OpenVDB.
void write_vdb_points(const ParticleFrame& frame, const std::string& path);

// Per-vertex unit normals of a mesh (3 floats a vertex): the area-weighted mean of the normals
// of the faces around each vertex, pointing out for counter-clockwise faces; 0 for a vertex no
// face uses.
void vertex_normals(const SurfaceMesh& mesh, std::vector<float>* normals);

// A surface mesh as Wavefront OBJ: v, vn (vertex_normals) and f a//a b//b c//c.
void write_obj(const SurfaceMesh& mesh, uint32_t frame, double time, const std::string& path);

// The fluid surface (builds with OpenVDB): particles to a level set (grid "surface") written
// as .vdb, and that level set's zero isosurface written as a Wavefront OBJ mesh (also
// returned in `mesh`, for the preview). radius and voxel in metres.
void write_surface(const ParticleFrame& frame, float radius, float voxel, const std::string& vdb_path,
                   const std::string& obj_path, SurfaceMesh* mesh);

}  // namespace sph_tools

#endif
