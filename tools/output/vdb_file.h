// SPDX-License-Identifier: MIT
// Writing a .vdb file whose every byte is checked. openvdb::io::File::write() does not look at
// its stream after writing: a full disk or a file size limit (EFBIG) left a truncated file
// that it reported as written. This writes the same file (OpenVDB's seekable archive format,
// grid offsets included) through a stream of ours, and fails when any write did.
#ifndef SPH_TOOLS_VDB_FILE_H
#define SPH_TOOLS_VDB_FILE_H

#include <openvdb/openvdb.h>

#include <string>

namespace sph_tools {

// Claims `path` as a new file (new_file.h: O_CREAT | O_EXCL | O_NOFOLLOW) and writes `grids`
// to it; throws std::runtime_error naming the path and the reason.
void write_vdb_file(const std::string& path, const openvdb::GridCPtrVec& grids);

}  // namespace sph_tools

#endif
