// SPDX-License-Identifier: MIT
#include "vdb_file.h"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "new_file.h"

namespace sph_tools {

namespace {

// io::File::write() is Archive::write(stream, grids, seekable = true) on an ofstream it opens
// and never checks; Archive's stream overload is protected, hence this subclass.
class CheckedArchive : public openvdb::io::Archive {
 public:
  void write_to(std::ostream& out, const openvdb::GridCPtrVec& grids) const {
    openvdb::io::Archive::write(out, grids, /*seekable=*/true);
  }
};

}  // namespace

void write_vdb_file(const std::string& path, const openvdb::GridCPtrVec& grids) {
  create_new_file(path);
  std::ofstream out(path, std::ios_base::out | std::ios_base::binary | std::ios_base::trunc);
  if (!out) throw std::runtime_error("cannot write " + path + ": " + std::strerror(errno));
  try {
    CheckedArchive().write_to(out, grids);
  } catch (const openvdb::Exception& e) {
    throw std::runtime_error("cannot write " + path + ": " + e.what());
  }
  out.flush();
  const bool failed = out.fail();
  const int error = errno;
  out.close();
  if (failed || out.fail())
    throw std::runtime_error("cannot write " + path + ": " + std::strerror(error != 0 ? error : EIO));
}

}  // namespace sph_tools
