// SPDX-License-Identifier: MIT
// Reads every grid of a .vdb file so that a file cut short is an error, never a runaway read.
// Shared by libsph_vdb (sph_vdb_load_sdf) and sph-run (the preview's level-set bounds): both
// read files that users hand them.
#pragma once

#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>

#include <exception>
#include <fstream>
#include <new>
#include <string>

namespace sph_io {

// The grids of the regular file `path` (the caller checks that it is one: OpenVDB would read a
// FIFO without end), or null with *error saying why. OpenVDB checks few of its reads: io::File
// went on past the end of a file cut short with the offsets and string lengths it had failed to
// read (91 bytes of a sphere, the end of the grid's type name, made it allocate gigabytes without
// end). Here OpenVDB reads through a stream that throws at the first short read. io::Stream
// reads every grid in order and, with delayLoad false, loads none lazily, so nothing is
// memory-mapped either: OpenVDB's delayed loading trusts a file's "file_delayed_load" metadata,
// indexing its mask table with the leaf count without a bounds check, and a file truncated by
// someone else later would raise SIGBUS on a read of the mapping. std::bad_alloc propagates.
inline openvdb::GridPtrVecPtr read_vdb_grids(const std::string& path, std::string* error) {
  std::ifstream stream(path, std::ios::in | std::ios::binary);
  if (!stream) {
    *error = "cannot open '" + path + "'";
    return nullptr;
  }
  try {
    stream.exceptions(std::ios::failbit | std::ios::badbit);
    return openvdb::io::Stream(stream, /*delayLoad=*/false).getGrids();
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& e) {
    // libstdc++'s own ios_base::failure may not match a catch of it (GCC bug 66145), so the
    // stream's state tells a short read from OpenVDB's errors.
    *error =
        stream.fail() || stream.bad()
            ? "cannot read '" + path + "' as a VDB file: it ends early (a truncated file, or not a VDB file)"
            : "cannot read '" + path + "' as a VDB file (" + e.what() + ")";
    return nullptr;
  }
}

}  // namespace sph_io
