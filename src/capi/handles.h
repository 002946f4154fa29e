// The opaque objects of the C ABI and the registry that tells a live handle from a dangling
// or foreign pointer in every build.
#pragma once

#include <atomic>
#include <memory>

#include "../core/sdf_asset.h"
#include "../core/world.h"
#include "../factory/backend_factory.h"
#include "sph_c.h"

struct sph_context {
  sph::BackendKind backend;
  int device_ordinal;
  unsigned cpu_workers;
  sph::CudaTuning cuda_tuning;
  sph_log_fn log_fn;
  void* log_user_data;
  std::atomic<uint32_t> world_count{0};
  std::atomic<uint32_t> sdf_count{0};
};

struct sph_sdf {
  sph_context* context;
  std::shared_ptr<sph::SdfAsset> asset;
};

struct sph_world {
  sph_context* context;
  std::unique_ptr<sph::World> world;
  std::atomic<bool> busy{false};
  bool device_lost = false;
};

namespace sph {

enum class HandleKind { Context, World, Sdf };

void register_handle(const void* handle, HandleKind kind);
void unregister_handle(const void* handle);
bool is_live_handle(const void* handle, HandleKind kind);
uint32_t live_handle_count();

}  // namespace sph
