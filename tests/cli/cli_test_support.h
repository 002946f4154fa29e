// SPDX-License-Identifier: MIT
// Helpers of the sph-run tests: running a program, temporary directories, and readers for the
// PLY and CSV frames written independently of the writers under test.
#ifndef SPH_CLI_TEST_SUPPORT_H
#define SPH_CLI_TEST_SUPPORT_H

#include <sys/types.h>

#include <cstdint>
#include <string>
#include <vector>

namespace cli_test {

// Runs argv (argv[0] a path) with stdout and stderr captured into *output; returns its exit
// status, or 128 + the signal that ended it. The child is killed after timeout_s seconds.
int run(const std::vector<std::string>& argv, std::string* output, int timeout_s = 120);
// Starts argv in the background with output to `log`; returns the pid.
pid_t start(const std::vector<std::string>& argv, const std::string& log);
// Waits for pid; as run().
int wait_for(pid_t pid, int timeout_s);

// A fresh empty directory under $TMPDIR (or /tmp).
std::string make_temp_dir(const char* name);
void write_text(const std::string& path, const std::string& text);
std::string read_text(const std::string& path);
bool file_exists(const std::string& path);
std::vector<std::string> list_dir(const std::string& dir);

struct Particles {
  std::vector<float> position, velocity, density, pressure;  // 3, 3, 1, 1 per particle
  std::vector<uint32_t> id;
  size_t count() const { return id.size(); }
};

// Reads a binary little-endian PLY frame of sph-run; false (with *error) if it is not whole.
bool read_ply(const std::string& path, Particles* out, std::string* error);
// Reads a CSV frame of sph-run.
bool read_csv(const std::string& path, Particles* out, std::string* error);

}  // namespace cli_test

#endif
