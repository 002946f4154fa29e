// The CPU backend's per-particle spring lists (SPH_FEATURE_SPRINGS), registered in the
// particle store like any attribute: when the store permutes the particles (the neighbour
// sort, a sink's removal) the lists move with them and their partner indices are rewritten
// through the inverse permutation, so a spring to a removed particle is dropped.
#pragma once

#include <stddef.h>
#include <stdint.h>

#include <memory>
#include <vector>

#include "../physics/springs.h"
#include "host_particle_store.h"

namespace sph {

class HostSpringArray final : public HostArrayBase {
 public:
  std::vector<SpringList> data;

  void resize(size_t n) override { data.resize(n, empty_spring_list()); }
  void gather(const uint32_t* order, size_t n) override {
    inverse_.assign(data.size(), kNoSpring);
    for (size_t i = 0; i < n; ++i) inverse_[order[i]] = static_cast<uint32_t>(i);
    scratch_.resize(data.size());
    for (size_t i = 0; i < n; ++i) scratch_[i] = remap_spring_list(data[order[i]], inverse_.data());
    data.swap(scratch_);
  }
  size_t bytes() const override {
    return (data.capacity() + scratch_.capacity()) * sizeof(SpringList) +
           inverse_.capacity() * sizeof(uint32_t);
  }
  std::unique_ptr<HostArrayBase> clone() const override {
    auto copy = std::make_unique<HostSpringArray>();
    copy->data = data;
    return copy;
  }
  void assign_from(const HostArrayBase& other) override {
    data = static_cast<const HostSpringArray&>(other).data;
  }

 private:
  std::vector<SpringList> scratch_;
  std::vector<uint32_t> inverse_;
};

}  // namespace sph
