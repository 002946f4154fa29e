// SPDX-License-Identifier: MIT
// A main() for builds without libFuzzer (gcc, the ordinary Release build): runs the harness's
// LLVMFuzzerTestOneInput over every file named on the command line, or every file in a named
// folder (options that start with '-' are libFuzzer's and skipped), so the saved crash inputs
// (tests/fuzz/regressions/<target>/) stay regression tests in every ctest run. Exits non-zero when no input
// was found; a crash aborts the process.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace {

bool replay(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    std::fprintf(stderr, "replay: cannot read %s\n", file.c_str());
    return false;
  }
  const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::printf("replay: %s (%zu bytes)\n", file.c_str(), bytes.size());
  std::fflush(stdout);
  LLVMFuzzerTestOneInput(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::filesystem::path> files;
  for (int i = 1; i < argc; ++i) {
    if (argv[i][0] == '-') continue;  // a libFuzzer option (-runs=0)
    const std::filesystem::path arg(argv[i]);
    std::error_code ec;
    if (std::filesystem::is_directory(arg, ec)) {
      for (const auto& entry : std::filesystem::directory_iterator(arg))
        if (entry.is_regular_file()) files.push_back(entry.path());
    } else {
      files.push_back(arg);
    }
  }
  std::sort(files.begin(), files.end());
  size_t replayed = 0;
  for (const auto& f : files) replayed += replay(f) ? 1 : 0;
  std::printf("replay: %zu input(s) ran without a crash\n", replayed);
  return replayed == files.size() && replayed > 0 ? 0 : 1;
}
