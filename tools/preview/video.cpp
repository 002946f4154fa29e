// SPDX-License-Identifier: MIT
#include "video.h"

#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

extern char** environ;

namespace sph_tools {

bool ffmpeg_on_path() {
  const char* path = std::getenv("PATH");
  if (!path) return false;
  std::string dirs = path;
  size_t start = 0;
  while (start <= dirs.size()) {
    const size_t end = dirs.find(':', start);
    const std::string dir = dirs.substr(start, end == std::string::npos ? std::string::npos : end - start);
    const std::string candidate = (dir.empty() ? "." : dir) + "/ffmpeg";
    struct stat st;
    if (stat(candidate.c_str(), &st) == 0 && S_ISREG(st.st_mode) && access(candidate.c_str(), X_OK) == 0)
      return true;
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return false;
}

std::string encode_mp4(const std::string& pattern, unsigned first_frame, float fps,
                       const std::string& mp4_path) {
  const size_t slash = mp4_path.find_last_of('/');
  const std::string temp = (slash == std::string::npos ? std::string() : mp4_path.substr(0, slash + 1)) +
                           "." + mp4_path.substr(slash == std::string::npos ? 0 : slash + 1) + ".tmp";
  char rate[32], start[32];
  std::snprintf(rate, sizeof rate, "%g", static_cast<double>(fps));
  std::snprintf(start, sizeof start, "%u", first_frame);
  // Even dimensions for yuv420p; a quiet, non-interactive run.
  std::vector<std::string> args = {"ffmpeg",
                                   "-nostdin",
                                   "-y",
                                   "-loglevel",
                                   "error",
                                   "-framerate",
                                   rate,
                                   "-start_number",
                                   start,
                                   "-i",
                                   pattern,
                                   "-vf",
                                   "pad=ceil(iw/2)*2:ceil(ih/2)*2",
                                   "-c:v",
                                   "libx264",
                                   "-pix_fmt",
                                   "yuv420p",
                                   "-crf",
                                   "20",
                                   "-movflags",
                                   "+faststart",
                                   "-f",
                                   "mp4",
                                   temp};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(&a[0]);
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, "ffmpeg", nullptr, nullptr, argv.data(), environ);
  if (spawned != 0) return std::string("cannot start ffmpeg: ") + std::strerror(spawned);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return std::string("waiting for ffmpeg: ") + std::strerror(errno);
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::remove(temp.c_str());
    return "ffmpeg failed (exit status " + std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ")";
  }
  if (std::rename(temp.c_str(), mp4_path.c_str()) != 0)
    return "cannot rename " + temp + ": " + std::strerror(errno);
  return "";
}

}  // namespace sph_tools
