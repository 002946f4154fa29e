// SPDX-License-Identifier: MIT
#include "device_allocation_faults.h"

#include <atomic>

namespace sph {
namespace testing {
namespace {
std::atomic<long> countdown{-1};  // allocations to let through before one fails; -1 = off
std::atomic<bool> injected{false};
}  // namespace

void arm_device_allocation_fault(long n) {
  injected.store(false);
  countdown.store(n);
}

bool disarm_device_allocation_fault() {
  countdown.store(-1);
  return injected.load();
}

bool device_allocation_fault_due() {
  long left = countdown.load(std::memory_order_relaxed);
  while (left >= 0) {
    if (countdown.compare_exchange_weak(left, left - 1, std::memory_order_relaxed)) {
      if (left != 0) return false;
      injected.store(true);
      return true;
    }
  }
  return false;
}

}  // namespace testing
}  // namespace sph
