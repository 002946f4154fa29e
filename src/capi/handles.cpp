#include "handles.h"

#include <mutex>
#include <unordered_map>

namespace sph {
namespace {

std::mutex& registry_mutex() {
  static std::mutex m;
  return m;
}

std::unordered_map<const void*, HandleKind>& registry() {
  static std::unordered_map<const void*, HandleKind> r;
  return r;
}

}  // namespace

void register_handle(const void* handle, HandleKind kind) {
  std::lock_guard<std::mutex> lock(registry_mutex());
  registry()[handle] = kind;
}

void unregister_handle(const void* handle) {
  std::lock_guard<std::mutex> lock(registry_mutex());
  registry().erase(handle);
}

bool is_live_handle(const void* handle, HandleKind kind) {
  std::lock_guard<std::mutex> lock(registry_mutex());
  const auto it = registry().find(handle);
  return it != registry().end() && it->second == kind;
}

uint32_t live_handle_count() {
  std::lock_guard<std::mutex> lock(registry_mutex());
  return static_cast<uint32_t>(registry().size());
}

}  // namespace sph
