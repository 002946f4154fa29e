// SPDX-License-Identifier: MIT
// VTK XML PolyData frames (.vtp) and their ParaView time series (.pvd). The arrays go in one
// raw appended block (each array a UInt64 byte count and its little-endian bytes), which VTK
// reads without base64 decoding and sph-run writes straight from the frame's arrays.
#include <cstdint>
#include <cstdio>
#include <vector>

#include "new_file.h"
#include "writers.h"

#if !defined(__BYTE_ORDER__) || __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "write_vtp.cpp writes its arrays in host byte order and declares them LittleEndian"
#endif

namespace sph_tools {

namespace {

struct Array {
  const char* name;  // nullptr: the Points array, which is unnamed by convention
  const char* type;
  int components;
  uint64_t bytes;
};

void write_block(std::FILE* out, const void* data, uint64_t bytes) {
  std::fwrite(&bytes, sizeof bytes, 1, out);
  if (bytes) std::fwrite(data, 1, bytes, out);
}

// connectivity 0..n-1 or offsets 1..n, as Int64, written in batches.
void write_index_block(std::FILE* out, uint32_t n, int64_t first_value) {
  const uint64_t bytes = 8ull * n;
  std::fwrite(&bytes, sizeof bytes, 1, out);
  std::vector<int64_t> batch(4096);
  for (uint32_t first = 0; first < n; first += 4096) {
    const uint32_t k = n - first < 4096 ? n - first : 4096;
    for (uint32_t i = 0; i < k; ++i) batch[i] = first_value + first + i;
    if (std::fwrite(batch.data(), 8, k, out) != k) return;
  }
}

void declare(std::FILE* out, const Array& a, uint64_t* offset) {
  std::fprintf(out, "        <DataArray type=\"%s\"", a.type);
  if (a.name) std::fprintf(out, " Name=\"%s\"", a.name);
  if (a.components > 1) std::fprintf(out, " NumberOfComponents=\"%d\"", a.components);
  std::fprintf(out, " format=\"appended\" offset=\"%llu\"/>\n", static_cast<unsigned long long>(*offset));
  *offset += 8 + a.bytes;
}

}  // namespace

void write_vtp(const ParticleFrame& f, const std::string& path) {
  NewFile file(path);
  std::FILE* out = file.get();
  const uint64_t n = f.count;
  const Array velocity{"velocity", "Float32", 3, 12 * n}, density{"density", "Float32", 1, 4 * n},
      pressure{"pressure", "Float32", 1, 4 * n}, id{"id", "UInt32", 1, 4 * n},
      user{"user", "UInt32", 1, 4 * n}, points{nullptr, "Float32", 3, 12 * n},
      connectivity{"connectivity", "Int64", 1, 8 * n}, offsets{"offsets", "Int64", 1, 8 * n};
  std::fprintf(
      out,
      "<?xml version=\"1.0\"?>\n"
      "<!-- sph-run frame %u time %.9g s -->\n"
      "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
      "  <PolyData>\n"
      "    <FieldData>\n"
      "      <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" format=\"ascii\">%.17g"
      "</DataArray>\n"
      "      <DataArray type=\"UInt32\" Name=\"frame\" NumberOfTuples=\"1\" format=\"ascii\">%u</DataArray>\n"
      "    </FieldData>\n"
      "    <Piece NumberOfPoints=\"%u\" NumberOfVerts=\"%u\" NumberOfLines=\"0\" NumberOfStrips=\"0\" "
      "NumberOfPolys=\"0\">\n"
      "      <PointData Scalars=\"density\" Vectors=\"velocity\">\n",
      f.frame, f.time, f.time, f.frame, f.count, f.count);
  uint64_t offset = 0;
  for (const Array* a : {&velocity, &density, &pressure, &id}) declare(out, *a, &offset);
  if (f.has_user) declare(out, user, &offset);  // SPH_FEATURE_USER_ATTRIBUTE
  std::fputs("      </PointData>\n      <Points>\n", out);
  declare(out, points, &offset);
  // One vertex cell per particle, so ParaView draws the points without a Glyph filter.
  std::fputs("      </Points>\n      <Verts>\n", out);
  declare(out, connectivity, &offset);
  declare(out, offsets, &offset);
  std::fputs("      </Verts>\n    </Piece>\n  </PolyData>\n  <AppendedData encoding=\"raw\">\n   _", out);
  write_block(out, f.velocity.data(), velocity.bytes);
  write_block(out, f.density.data(), density.bytes);
  write_block(out, f.pressure.data(), pressure.bytes);
  write_block(out, f.id.data(), id.bytes);
  if (f.has_user) write_block(out, f.user.data(), user.bytes);
  write_block(out, f.position.data(), points.bytes);
  write_index_block(out, f.count, 0);
  write_index_block(out, f.count, 1);
  std::fputs("\n  </AppendedData>\n</VTKFile>\n", out);
  file.close();
}

void write_pvd(const std::vector<SeriesEntry>& series, const std::string& path) {
  NewFile file(path);
  std::FILE* out = file.get();
  std::fputs(
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      "  <Collection>\n",
      out);
  for (const SeriesEntry& e : series)
    std::fprintf(out, "    <DataSet timestep=\"%.17g\" group=\"\" part=\"0\" file=\"%s\"/>\n", e.time,
                 e.file.c_str());
  std::fputs("  </Collection>\n</VTKFile>\n", out);
  file.close();
}

}  // namespace sph_tools
