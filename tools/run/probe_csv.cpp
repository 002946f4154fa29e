// SPDX-License-Identifier: MIT
#include "probe_csv.h"

#include <cerrno>
#include <cstring>

namespace sph_tools {

std::string ProbeCsv::open(const std::string& directory, const SceneRuntime& runtime) {
  const std::vector<ProbeDesc>& probes = runtime.scene().probes;
  for (size_t k = 0; k < probes.size(); ++k) {
    const std::string problem =
        files_.open(directory, "probe", k, probes[k].name,
                    "frame,time_s,density_kg_m3,pressure_Pa,velocity_x_m_s,velocity_y_m_s,velocity_z_m_s,"
                    "pressure_max_Pa,kernel_sum,water_height_m,samples,span_s\n");
    if (!problem.empty()) return problem;
  }
  return "";
}

std::string ProbeCsv::write(const SceneRuntime& runtime, uint32_t frame, double time) {
  for (const ObjectCsvFiles::File& f : files_.files()) {
    sph_probe_reading r;
    sph_probe_reading_init(&r);
    if (sph_probe_get_reading(runtime.world(), runtime.probes()[f.object], &r) != SPH_OK)
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

}  // namespace sph_tools
