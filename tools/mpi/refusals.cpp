// SPDX-License-Identifier: MIT
#include "refusals.h"

namespace sph_tools {

namespace {

const char* const kWhere =
    " do not work on a distributed world yet (docs/distributed.md); run the scene with sph-run";

}  // namespace

std::string distributed_refusal(const SceneDesc& scene) {
  if (!scene.sources.empty()) return scene.sources[0].path + ": sources (emission across ranks)" + kWhere;
  if (!scene.probes.empty()) return scene.probes[0].path + ": probes (samples summed over ranks)" + kWhere;
  for (const ColliderDesc& c : scene.colliders)
    if (c.loads) return c.path + ".loads: collider loads (forces summed over ranks)" + kWhere;
  return "";
}

}  // namespace sph_tools
