// Checkpoints: saving a world to memory or a file (atomically), loading one into a new world,
// restoring one into an existing world. The format itself lives in src/core/checkpoint*.
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#if defined(_WIN32)
#include <windows.h>
#else
#include <fcntl.h>
#include <unistd.h>
#endif

#include "../core/checkpoint.h"
#include "guard.h"
#include "handles.h"

using sph::Error;
using sph::Status;

namespace {

std::vector<uint8_t> save_world(const sph_world* world) {
  sph::CheckpointOrigin origin;
  origin.backend = static_cast<uint32_t>(world->context->backend);
  origin.library_version = SPH_VERSION;
  try {
    return sph::write_checkpoint(*world->world, origin);
  } catch (const Error& e) {
    if (e.status() == Status::DeviceLost) const_cast<sph_world*>(world)->device_lost = true;
    throw;
  }
}

std::unique_ptr<sph::World> load_world(sph_context* context, const void* data, uint64_t size) {
  if (!data) throw Error(Status::InvalidArgument, "data: is NULL");
  if (size > SIZE_MAX) throw Error(Status::InvalidArgument, "size: does not fit in memory");
  return sph::read_checkpoint(static_cast<const uint8_t*>(data), static_cast<size_t>(size),
                              [context](const sph::WorldConfig& config) {
                                return sph::make_backend(context->backend, config, context->device_ordinal,
                                                         context->cpu_workers, context->cuda_tuning);
                              });
}

// `hold` keeps the context alive from the start of the call to the new world's registration.
sph_result publish(const sph::ContextHold& hold, std::unique_ptr<sph::World> loaded, sph_world** out) {
  auto world = std::make_unique<sph_world>();
  world->context = hold.get();
  world->world = std::move(loaded);
  *out = sph::publish_world(std::move(world));
  return SPH_OK;
}

std::string system_error() { return std::strerror(errno); }

// A name next to `path` that no other writer (thread or process) uses at the same time.
std::string temporary_name(const std::string& path) {
  static std::atomic<uint64_t> counter{0};
  const uint64_t now = static_cast<uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
#if defined(_WIN32)
  const unsigned long pid = GetCurrentProcessId();
#else
  const unsigned long pid = static_cast<unsigned long>(getpid());
#endif
  return path + ".tmp-" + std::to_string(pid) + "-" + std::to_string(counter.fetch_add(1)) + "-" +
         std::to_string(now % 1000000007u);
}

#if defined(_WIN32)
void write_file_atomically(const std::string& path, const std::vector<uint8_t>& bytes) {
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
void write_file_atomically(const std::string& path, const std::vector<uint8_t>& bytes) {
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
  const size_t slash = path.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "." : (slash == 0 ? "/" : path.substr(0, slash));
  const int dir_fd = ::open(dir.c_str(), O_RDONLY | O_CLOEXEC);
  if (dir_fd >= 0) {
    (void)::fsync(dir_fd);
    ::close(dir_fd);
  }
}
#endif

std::vector<uint8_t> read_file(const char* path) {
  // Closed on every path out, exceptions (a failed allocation) included.
  struct Closer {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  std::unique_ptr<std::FILE, Closer> file(std::fopen(path, "rb"));
  if (!file)
    throw Error(Status::InvalidArgument,
                std::string("path: cannot open '") + path + "' (" + system_error() + ")");
  std::vector<uint8_t> bytes;
  uint8_t chunk[1 << 16];
  for (;;) {
    const size_t n = std::fread(chunk, 1, sizeof chunk, file.get());
    bytes.insert(bytes.end(), chunk, chunk + n);
    if (n < sizeof chunk) break;
  }
  if (std::ferror(file.get()) != 0) {
    const int error = errno;
    throw Error(Status::InvalidArgument,
                std::string("path: cannot read '") + path + "' (" + std::strerror(error) + ")");
  }
  return bytes;
}

void require_path(const char* path) {
  if (!path) throw Error(Status::InvalidArgument, "path: is NULL");
  if (!*path) throw Error(Status::InvalidArgument, "path: is empty");
}

}  // namespace

extern "C" {

SPH_API sph_result SPH_CALL sph_world_save(const sph_world* world, void* buffer, uint64_t buffer_size,
                                           uint64_t* out_size) {
  return sph::guarded("sph_world_save", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    if (!out_size) throw Error(Status::InvalidArgument, "out_size: is NULL");
    if (!buffer && buffer_size != 0)
      throw Error(Status::InvalidArgument, "buffer: is NULL but buffer_size is " +
                                               std::to_string(buffer_size) + " (pass 0 to ask the size)");
    const std::vector<uint8_t> bytes = save_world(world);
    *out_size = bytes.size();
    if (!buffer) return SPH_OK;
    if (buffer_size < bytes.size())
      throw Error(Status::BufferTooSmall, "buffer_size: " + std::to_string(buffer_size) +
                                              " bytes; the checkpoint needs " + std::to_string(bytes.size()) +
                                              " (in *out_size)");
    std::memcpy(buffer, bytes.data(), bytes.size());
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_world_save_file(const sph_world* world, const char* path) {
  return sph::guarded("sph_world_save_file", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    require_path(path);
    write_file_atomically(path, save_world(world));
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_world_load(sph_context* context, const void* data, uint64_t size,
                                           sph_world** out) {
  return sph::guarded("sph_world_load", context, [&] {
    const sph::ContextHold hold(context);
    if (!out) throw Error(Status::InvalidArgument, "out: is NULL");
    return publish(hold, load_world(hold.get(), data, size), out);
  });
}

SPH_API sph_result SPH_CALL sph_world_load_file(sph_context* context, const char* path, sph_world** out) {
  return sph::guarded("sph_world_load_file", context, [&] {
    const sph::ContextHold hold(context);
    require_path(path);
    if (!out) throw Error(Status::InvalidArgument, "out: is NULL");
    const std::vector<uint8_t> bytes = read_file(path);
    try {
      static const uint8_t nothing = 0;  // an empty file is a truncated checkpoint, not NULL data
      return publish(hold, load_world(hold.get(), bytes.empty() ? &nothing : bytes.data(), bytes.size()),
                     out);
    } catch (const Error& e) {
      throw Error(e.status(), std::string(e.what()) + " (file '" + path + "')");
    }
  });
}

SPH_API sph_result SPH_CALL sph_world_restore(sph_world* world, const void* data, uint64_t size) {
  return sph::guarded("sph_world_restore", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world);
    // The new state is built whole beside the old one, then swapped in.
    std::unique_ptr<sph::World> loaded = load_world(world->context, data, size);
    world->world.swap(loaded);
    return SPH_OK;
  });
}

}  // extern "C"
