// SPDX-License-Identifier: MIT
#include "frame_manifest.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <nlohmann/json.hpp>
#include <stdexcept>

namespace sph_tools {

namespace {

// An earlier manifest longer than this is not read (nothing of it is removed then): a run of
// ten million frames writes about 1 GiB of it, far past any real run.
constexpr off_t kMaxManifestBytes = 1 << 30;

// The output names an earlier manifest recorded ("files" and "tables" of any line; only sph-run's own names
// are taken, so a doctored manifest cannot name anything else to remove).
std::vector<std::string> recorded_outputs(const std::string& path) {
  std::vector<std::string> names;
  const int fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return names;
  struct stat st;
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || st.st_size > kMaxManifestBytes) {
    ::close(fd);
    return names;
  }
  std::string text(static_cast<size_t>(st.st_size), '\0');
  size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::read(fd, &text[done], text.size() - done);
    if (n <= 0) break;
    done += static_cast<size_t>(n);
  }
  ::close(fd);
  text.resize(done);
  size_t start = 0;
  while (start < text.size()) {
    const size_t end = text.find('\n', start);
    if (end == std::string::npos) break;  // a last line cut short
    const nlohmann::json line = nlohmann::json::parse(text.begin() + static_cast<std::ptrdiff_t>(start),
                                                      text.begin() + static_cast<std::ptrdiff_t>(end),
                                                      nullptr, /*allow_exceptions=*/false);
    start = end + 1;
    if (!line.is_object()) continue;
    for (const char* key : {"files", "tables"}) {
      if (!line.contains(key) || !line[key].is_array()) continue;
      for (const nlohmann::json& file : line[key])
        if (file.is_string() && is_output_name(file.get<std::string>()))
          names.push_back(file.get<std::string>());
    }
  }
  return names;
}

nlohmann::ordered_json file_list(const std::vector<std::string>& files) {
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (const std::string& f : files) list.push_back(f);
  return list;
}

}  // namespace

FrameManifest::FrameManifest(const std::string& directory, const StagingDirectory& staging,
                             const ManifestHeader& header)
    : path_(directory + "/" + kManifestName) {
  const std::vector<std::string> earlier = recorded_outputs(path_);
  const std::string staged = staging.file(kManifestName);
  fd_ = ::open(staged.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_APPEND | O_CLOEXEC, 0666);
  if (fd_ < 0) throw std::runtime_error("cannot create " + staged + ": " + std::strerror(errno));
  nlohmann::ordered_json head;
  head["sph_run_manifest"] = 1;
  head["scene"] = header.scene;
  head["fps"] = header.fps;
  head["frames"] = header.frames;
  append(head.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace));
  // From here the earlier run's frames are no longer trusted; then they go.
  if (std::rename(staged.c_str(), path_.c_str()) != 0)
    throw std::runtime_error("cannot move " + staged + " to " + path_ + ": " + std::strerror(errno));
  for (const std::string& name : earlier)
    if (::unlink((directory + "/" + name).c_str()) == 0) ++removed_earlier_;
}

FrameManifest::~FrameManifest() {
  if (fd_ >= 0) ::close(fd_);
}

void FrameManifest::append(const std::string& line) {
  // One write() per line: a kill leaves whole lines, or a last line without its newline.
  const std::string text = line + "\n";
  size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd_, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw std::runtime_error("cannot write " + path_ + ": " + std::strerror(errno));
    done += static_cast<size_t>(n);
  }
}

void FrameManifest::writing(uint32_t frame, double time, const std::vector<std::string>& files) {
  append(nlohmann::ordered_json{
      {"frame", frame}, {"time", time}, {"state", "writing"}, {"files", file_list(files)}}
             .dump());
}

void FrameManifest::complete(uint32_t frame, double time, const std::vector<std::string>& files) {
  append(nlohmann::ordered_json{
      {"frame", frame}, {"time", time}, {"state", "complete"}, {"files", file_list(files)}}
             .dump());
}

void FrameManifest::tables(const std::vector<std::string>& names) {
  if (names.empty()) return;
  append(nlohmann::ordered_json{{"tables", file_list(names)}}.dump());
}

void FrameManifest::writing_video(const std::string& name) {
  append(nlohmann::ordered_json{{"video", name}, {"state", "writing"}, {"files", file_list({name})}}.dump());
}

void FrameManifest::complete_video(const std::string& name) {
  append(nlohmann::ordered_json{{"video", name}, {"state", "complete"}, {"files", file_list({name})}}.dump());
}

void FrameManifest::end(const char* how, uint32_t last_frame) {
  append(nlohmann::ordered_json{{"end", how}, {"last_frame", last_frame}}.dump());
}

}  // namespace sph_tools
