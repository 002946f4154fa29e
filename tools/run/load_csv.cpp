// SPDX-License-Identifier: MIT
#include "load_csv.h"

#include <cerrno>
#include <cstring>

namespace sph_tools {

std::string LoadCsv::open(const std::string& directory, const SceneRuntime& runtime) {
  const std::vector<SceneRuntime::Collider>& colliders = runtime.colliders();
  for (size_t k = 0; k < colliders.size(); ++k) {
    if (!colliders[k].desc->loads) continue;
    const std::string problem =
        files_.open(directory, "loads", k, colliders[k].desc->name,
                    "frame,time_s,force_x_N,force_y_N,force_z_N,torque_x_Nm,torque_y_Nm,torque_z_Nm,"
                    "point_x_m,point_y_m,point_z_m,frame_time_s\n");
    if (!problem.empty()) return problem;
  }
  return "";
}

std::string LoadCsv::write(const SceneRuntime& runtime, uint32_t frame, double time) {
  for (const ObjectCsvFiles::File& f : files_.files()) {
    sph_collider_loads l;
    sph_collider_loads_init(&l);
    if (sph_collider_get_loads(runtime.world(), runtime.colliders()[f.object].id, &l) != SPH_OK)
      return f.path + ": " + sph_get_last_error();
    if (std::fprintf(f.file, "%u,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", frame, time,
                     static_cast<double>(l.force.x), static_cast<double>(l.force.y),
                     static_cast<double>(l.force.z), static_cast<double>(l.torque.x),
                     static_cast<double>(l.torque.y), static_cast<double>(l.torque.z),
                     static_cast<double>(l.point.x), static_cast<double>(l.point.y),
                     static_cast<double>(l.point.z), l.frame_time) < 0)
      return f.path + ": " + std::strerror(errno);
  }
  return "";
}

}  // namespace sph_tools
