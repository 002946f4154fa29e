// SPDX-License-Identifier: MIT
#include "cli_test_support.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <thread>

namespace cli_test {

pid_t start(const std::vector<std::string>& argv, const std::string& log) {
  const pid_t pid = fork();
  if (pid == 0) {
    const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      dup2(fd, 1);
      dup2(fd, 2);
      close(fd);
    }
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    execv(args[0], args.data());
    std::perror("execv");
    _exit(127);
  }
  return pid;
}

int wait_for(pid_t pid, int timeout_s) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(timeout_s);
  int status = 0;
  while (true) {
    const pid_t done = waitpid(pid, &status, WNOHANG);
    if (done == pid) break;
    if (std::chrono::steady_clock::now() > deadline) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      return -1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return -1;
}

int run(const std::vector<std::string>& argv, std::string* output, int timeout_s) {
  const std::string dir = make_temp_dir("run");
  const std::string log = dir + "/output.txt";
  const int status = wait_for(start(argv, log), timeout_s);
  if (output) *output = read_text(log);
  std::remove(log.c_str());
  rmdir(dir.c_str());
  return status;
}

std::string make_temp_dir(const char* name) {
  const char* base = std::getenv("TMPDIR");
  std::string pattern = std::string(base && base[0] ? base : "/tmp") + "/sph_cli_" + name + "_XXXXXX";
  std::vector<char> buffer(pattern.begin(), pattern.end());
  buffer.push_back('\0');
  if (!mkdtemp(buffer.data())) {
    std::perror("mkdtemp");
    std::abort();
  }
  return buffer.data();
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

bool file_exists(const std::string& path) {
  struct stat st;
  return stat(path.c_str(), &st) == 0;
}

std::vector<std::string> list_dir(const std::string& dir) {
  std::vector<std::string> names;
  if (DIR* d = opendir(dir.c_str())) {
    while (const dirent* e = readdir(d))
      if (std::strcmp(e->d_name, ".") != 0 && std::strcmp(e->d_name, "..") != 0) names.push_back(e->d_name);
    closedir(d);
  }
  return names;
}

bool read_ply(const std::string& path, Particles* out, std::string* error) {
  const std::string data = read_text(path);
  const size_t end = data.find("end_header\n");
  if (data.compare(0, 4, "ply\n") != 0 || end == std::string::npos) {
    *error = path + ": no PLY header";
    return false;
  }
  std::istringstream header(data.substr(0, end));
  std::string line;
  std::vector<std::string> properties;
  size_t count = 0;
  bool little_endian = false;
  while (std::getline(header, line)) {
    if (line == "format binary_little_endian 1.0") little_endian = true;
    if (line.rfind("element vertex ", 0) == 0) count = std::strtoul(line.c_str() + 15, nullptr, 10);
    if (line.rfind("property ", 0) == 0) properties.push_back(line.substr(9));
  }
  const std::vector<std::string> expected = {"float x",  "float y",  "float z",       "float vx",
                                             "float vy", "float vz", "float density", "uint id"};
  if (!little_endian || properties != expected) {
    *error = path + ": unexpected format or properties";
    return false;
  }
  const size_t body = end + 11;
  if (data.size() != body + 32 * count) {
    *error = path + ": " + std::to_string(data.size() - body) + " bytes of data for " +
             std::to_string(count) + " vertices";
    return false;
  }
  *out = Particles{};
  for (size_t i = 0; i < count; ++i) {
    const char* r = data.data() + body + 32 * i;
    float f[7];
    uint32_t id;
    std::memcpy(f, r, 28);
    std::memcpy(&id, r + 28, 4);
    out->position.insert(out->position.end(), {f[0], f[1], f[2]});
    out->velocity.insert(out->velocity.end(), {f[3], f[4], f[5]});
    out->density.push_back(f[6]);
    out->id.push_back(id);
  }
  return true;
}

bool read_csv(const std::string& path, Particles* out, std::string* error) {
  std::ifstream in(path);
  std::string line;
  if (!std::getline(in, line) || line != "id,x,y,z,vx,vy,vz,density,pressure") {
    *error = path + ": unexpected header \"" + line + "\"";
    return false;
  }
  *out = Particles{};
  while (std::getline(in, line)) {
    unsigned id;
    float v[8];
    if (std::sscanf(line.c_str(), "%u,%g,%g,%g,%g,%g,%g,%g,%g", &id, &v[0], &v[1], &v[2], &v[3], &v[4], &v[5],
                    &v[6], &v[7]) != 9) {
      *error = path + ": bad line \"" + line + "\"";
      return false;
    }
    out->id.push_back(id);
    out->position.insert(out->position.end(), {v[0], v[1], v[2]});
    out->velocity.insert(out->velocity.end(), {v[3], v[4], v[5]});
    out->density.push_back(v[6]);
    out->pressure.push_back(v[7]);
  }
  return true;
}

}  // namespace cli_test
