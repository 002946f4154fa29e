// SPDX-License-Identifier: MIT
#include "checkpoint_files.h"

#include <atomic>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>

#if defined(_WIN32)
#include <windows.h>
#else
#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>
#endif

#include "../core/status.h"

namespace sph {
namespace {

// The largest checkpoint file sph_world_load_file reads: 256 GiB, more than any world one
// device holds (an H200 has 141 GB). A larger file is refused before anything is read.
constexpr uint64_t kMaxCheckpointFileBytes = 1ull << 38;

std::string system_error() { return std::strerror(errno); }

#if !defined(_WIN32)
// This host's name as it appears in temporary names: letters, digits, '.' and '_' kept, any
// other byte as '_' (the name must not hold '/' or the '-' that separates the fields); at most 64.
std::string host_tag() {
  char name[256] = "";
  if (gethostname(name, sizeof name - 1) != 0 || name[0] == '\0') return "unknown_host";
  std::string tag;
  for (const char* c = name; *c && tag.size() < 64; ++c)
    tag += (std::isalnum(static_cast<unsigned char>(*c)) || *c == '.' || *c == '_') ? *c : '_';
  return tag;
}
#endif

// A name next to `path` that no other writer (thread or process) uses at the same time:
// path + ".tmp-" + pid + "-" + counter + "-" + nonce + "-" + host. The pid and host let a later
// save recognise the temporary file of a save that was killed (remove_stale_temporaries).
std::string temporary_name(const std::string& path) {
  static std::atomic<uint64_t> counter{0};
  const uint64_t now = static_cast<uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
#if defined(_WIN32)
  const unsigned long pid = GetCurrentProcessId();
  const std::string host = "windows";
#else
  const unsigned long pid = static_cast<unsigned long>(getpid());
  const std::string host = host_tag();
#endif
  return path + ".tmp-" + std::to_string(pid) + "-" + std::to_string(counter.fetch_add(1)) + "-" +
         std::to_string(now % 1000000007u) + "-" + host;
}

#if defined(_WIN32)
void write_atomically(const std::string& path, const HostVector<uint8_t>& bytes) {
  for (int attempt = 0;; ++attempt) {
    const std::string temp = temporary_name(path);
    HANDLE file =
        CreateFileA(temp.c_str(), GENERIC_WRITE, 0, nullptr, CREATE_NEW, FILE_ATTRIBUTE_NORMAL, nullptr);
    if (file == INVALID_HANDLE_VALUE) {
      if (GetLastError() == ERROR_FILE_EXISTS && attempt < 8) continue;
      throw Error(Status::InvalidArgument, "path: cannot create '" + temp + "'");
    }
    size_t done = 0;
    bool ok = true;
    while (ok && done < bytes.size()) {
      const DWORD chunk = static_cast<DWORD>(std::min<size_t>(bytes.size() - done, 1u << 30));
      DWORD written = 0;
      ok = WriteFile(file, bytes.data() + done, chunk, &written, nullptr) && written > 0;
      done += written;
    }
    ok = ok && FlushFileBuffers(file);
    ok = CloseHandle(file) && ok;
    if (ok) ok = MoveFileExA(temp.c_str(), path.c_str(), MOVEFILE_REPLACE_EXISTING | MOVEFILE_WRITE_THROUGH);
    if (!ok) {
      DeleteFileA(temp.c_str());
      throw Error(Status::InvalidArgument, "path: cannot write '" + path + "'");
    }
    return;
  }
}
#else
// The pid of a temporary name made by temporary_name() for `name` on this host, or 0 if the
// entry is not one (another program's file, another host's, or an older library's).
unsigned long temporary_owner(const std::string& entry, const std::string& name, const std::string& host) {
  const std::string prefix = name + ".tmp-";
  if (entry.compare(0, prefix.size(), prefix) != 0) return 0;
  // pid "-" counter "-" nonce "-" host, the three numbers in decimal.
  size_t at = prefix.size();
  unsigned long fields[3] = {0, 0, 0};
  for (unsigned long& field : fields) {
    const size_t start = at;
    while (at < entry.size() && entry[at] >= '0' && entry[at] <= '9' && at - start < 19)
      field = field * 10 + static_cast<unsigned long>(entry[at++] - '0');
    if (at == start || at >= entry.size() || entry[at] != '-') return 0;
    ++at;
  }
  return entry.compare(at, std::string::npos, host) == 0 ? fields[0] : 0;
}

// Removes the temporary files that saves to `path` on this host left when they were killed
// (their process is gone), so they do not pile up. A file is removed only when its whole name
// is one temporary_name() makes for `path` with this host's name, its pid names no running
// process, and it is a regular file: another program's files, another host's (a shared file
// system) and a live save's are left alone. Best effort: a failure here never fails the save.
void remove_stale_temporaries(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "." : (slash == 0 ? "/" : path.substr(0, slash));
  const std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  const std::string host = host_tag();
  DIR* listing = ::opendir(dir.c_str());
  if (!listing) return;
  // Closed however the loop ends: the names below are strings, whose allocations may throw.
  struct Closer {
    DIR* listing;
    ~Closer() { ::closedir(listing); }
  } closer{listing};
  while (const dirent* entry = ::readdir(listing)) {
    const unsigned long pid = temporary_owner(entry->d_name, name, host);
    if (pid == 0 || pid > static_cast<unsigned long>(INT32_MAX)) continue;
    if (::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;  // alive, or not ours to judge
    const std::string stale = dir + "/" + entry->d_name;
    struct stat st;
    if (::lstat(stale.c_str(), &st) == 0 && S_ISREG(st.st_mode)) (void)::unlink(stale.c_str());
  }
}

void write_atomically(const std::string& path, const HostVector<uint8_t>& bytes) {
  remove_stale_temporaries(path);
  // The folder, whose entry the rename changes: named before the temporary file exists, since
  // nothing may throw once the rename has put the new file in place (the call would report an
  // error with the file replaced).
  const size_t slash = path.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "." : (slash == 0 ? "/" : path.substr(0, slash));
  std::string temp;
  int fd = -1;
  for (int attempt = 0; fd < 0; ++attempt) {
    temp = temporary_name(path);
    fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0 && !(errno == EEXIST && attempt < 8))
      throw Error(Status::InvalidArgument,
                  "path: cannot create the temporary file '" + temp + "' (" + system_error() + ")");
  }
  // On any failure from here on: close, remove the temporary file, report.
  // The clean-up comes before anything that allocates (building the message may throw).
  auto fail = [&](const char* step) {
    const int error = errno;
    if (fd >= 0) ::close(fd);
    ::unlink(temp.c_str());
    throw Error(Status::InvalidArgument, "path: " + std::string(step) + " '" + path + "' failed (" +
                                             std::strerror(error) + "); the file there is unchanged");
  };
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) fail("writing the checkpoint for");
    done += static_cast<size_t>(n);
  }
  if (::fsync(fd) != 0) fail("flushing the checkpoint for");
  const int closed = ::close(fd);
  fd = -1;
  if (closed != 0) fail("closing the checkpoint for");
  if (::rename(temp.c_str(), path.c_str()) != 0) fail("renaming the checkpoint to");
  // Make the rename itself durable (best effort: the new file is in place either way).
  const int dir_fd = ::open(dir.c_str(), O_RDONLY | O_CLOEXEC);
  if (dir_fd >= 0) {
    (void)::fsync(dir_fd);
    ::close(dir_fd);
  }
}
#endif

// Reads a whole checkpoint file. Only a regular file is read, and only as many bytes as it had
// when it was opened (at most kMaxCheckpointFileBytes): /dev/zero, a FIFO or a device would
// otherwise be read until memory runs out, or block forever.
#if defined(_WIN32)
HostVector<uint8_t> read_file(const char* path) {
  struct Closer {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  std::unique_ptr<std::FILE, Closer> file(std::fopen(path, "rb"));
  if (!file)
    throw Error(Status::InvalidArgument,
                std::string("path: cannot open '") + path + "' (" + system_error() + ")");
  HostVector<uint8_t> bytes;
  uint8_t chunk[1 << 16];
  for (;;) {
    const size_t n = std::fread(chunk, 1, sizeof chunk, file.get());
    if (bytes.size() + n > kMaxCheckpointFileBytes)
      throw Error(Status::InvalidArgument, std::string("path: '") + path + "' is larger than 256 GiB");
    bytes.insert(bytes.end(), chunk, chunk + n);
    if (n < sizeof chunk) break;
  }
  if (std::ferror(file.get()) != 0)
    throw Error(Status::InvalidArgument, std::string("path: cannot read '") + path + "'");
  return bytes;
}
#else
HostVector<uint8_t> read_file(const char* path) {
  // O_NONBLOCK: opening a FIFO for reading would otherwise wait for a writer.
  const int fd = ::open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0)
    throw Error(Status::InvalidArgument,
                std::string("path: cannot open '") + path + "' (" + system_error() + ")");
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st;
  if (::fstat(fd, &st) != 0)
    throw Error(Status::InvalidArgument,
                std::string("path: cannot read '") + path + "' (" + system_error() + ")");
  if (!S_ISREG(st.st_mode))
    throw Error(Status::InvalidArgument, std::string("path: '") + path +
                                             "' is not a regular file (a directory, device, FIFO or "
                                             "socket); checkpoints are read from regular files only");
  const uint64_t size = static_cast<uint64_t>(st.st_size);
  if (size > kMaxCheckpointFileBytes || size > SIZE_MAX)
    throw Error(Status::InvalidArgument, std::string("path: '") + path + "' is " + std::to_string(size) +
                                             " bytes, more than the 256 GiB a checkpoint may have");
  HostVector<uint8_t> bytes(static_cast<size_t>(size));
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::read(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
    if (n < 0)
      throw Error(Status::InvalidArgument,
                  std::string("path: cannot read '") + path + "' (" + system_error() + ")");
    if (n == 0) break;  // the file shrank meanwhile: the loader reports a truncated checkpoint
    done += static_cast<size_t>(n);
  }
  bytes.resize(done);
  return bytes;
}
#endif

}  // namespace

void write_file_atomically(const std::string& path, const HostVector<uint8_t>& bytes) {
  write_atomically(path, bytes);
}

HostVector<uint8_t> read_checkpoint_file(const char* path) { return read_file(path); }

void move_file(const std::string& from, const std::string& to) {
#if defined(_WIN32)
  const bool ok =
      MoveFileExA(from.c_str(), to.c_str(), MOVEFILE_REPLACE_EXISTING | MOVEFILE_WRITE_THROUGH) != 0;
#else
  const bool ok = ::rename(from.c_str(), to.c_str()) == 0;
#endif
  if (!ok)
    throw Error(Status::InvalidArgument,
                "path: cannot rename '" + from + "' to '" + to + "' (" + system_error() + ")");
}

}  // namespace sph
