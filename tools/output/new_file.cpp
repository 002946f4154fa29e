// SPDX-License-Identifier: MIT
#include "new_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace sph_tools {

namespace {

int open_new(const std::string& path) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
  if (fd < 0) throw std::runtime_error("cannot create " + path + ": " + std::strerror(errno));
  return fd;
}

}  // namespace

NewFile::NewFile(const std::string& path) : path_(path) {
  const int fd = open_new(path);
  file_ = ::fdopen(fd, "wb");
  if (!file_) {
    const int error = errno;
    ::close(fd);
    throw std::runtime_error("cannot write " + path + ": " + std::strerror(error));
  }
}

NewFile::~NewFile() {
  if (file_) std::fclose(file_);
}

void NewFile::close() {
  std::FILE* file = file_;
  file_ = nullptr;
  const bool failed = std::ferror(file) != 0;
  const int error = errno;
  if (std::fclose(file) != 0 || failed)
    throw std::runtime_error("cannot write " + path_ + ": " + std::strerror(failed ? error : errno));
}

void create_new_file(const std::string& path) { ::close(open_new(path)); }

}  // namespace sph_tools
