// SPDX-License-Identifier: MIT
#include "probe_csv.h"

#include <cctype>
#include <cerrno>
#include <cstring>

namespace sph_tools {

std::string ProbeCsv::open(const std::string& directory, const SceneRuntime& runtime) {
  const std::vector<ProbeDesc>& probes = runtime.scene().probes;
  for (size_t k = 0; k < probes.size(); ++k) {
    const std::string& name = probes[k].name;
    std::string path = directory + "/probe_" + std::to_string(k);
    if (!name.empty()) path += "_";
    for (char ch : name) path += (std::isalnum(static_cast<unsigned char>(ch)) || ch == '-') ? ch : '_';
    path += ".csv";
    std::FILE* f = std::fopen(path.c_str(), "w");
    if (!f) return path + ": " + std::strerror(errno);
    files_.push_back(File{k, path, f});
    std::fprintf(f,
                 "frame,time_s,density_kg_m3,pressure_Pa,velocity_x_m_s,velocity_y_m_s,velocity_z_m_s,"
                 "pressure_max_Pa,kernel_sum,water_height_m,samples,span_s\n");
  }
  return "";
}

std::string ProbeCsv::write(const SceneRuntime& runtime, uint32_t frame, double time) {
  for (const File& f : files_) {
    sph_probe_reading r;
    sph_probe_reading_init(&r);
    if (sph_probe_get_reading(runtime.world(), runtime.probes()[f.probe], &r) != SPH_OK)
      return f.path + ": " + sph_get_last_error();
    if (std::fprintf(f.file, "%u,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%u,%.9g\n", frame, time,
                     static_cast<double>(r.density), static_cast<double>(r.pressure),
                     static_cast<double>(r.velocity.x), static_cast<double>(r.velocity.y),
                     static_cast<double>(r.velocity.z), static_cast<double>(r.pressure_max),
                     static_cast<double>(r.kernel_sum), static_cast<double>(r.water_height), r.samples,
                     r.time) < 0)
      return f.path + ": " + std::strerror(errno);
  }
  return "";
}

std::string ProbeCsv::close() {
  std::string problem;
  for (File& f : files_)
    if (f.file && std::fclose(f.file) != 0 && problem.empty()) problem = f.path + ": " + std::strerror(errno);
  files_.clear();
  return problem;
}

}  // namespace sph_tools
