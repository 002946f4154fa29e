// SPDX-License-Identifier: MIT
// A test hook for device and pinned-host allocation failures (issue 9, item 6). Armed with n,
// the n-th DeviceArray/PinnedArray allocation from then on fails once, exactly as a real
// cudaErrorMemoryAllocation would. Off unless a test arms it; the check costs one relaxed
// atomic load per allocation (allocations happen at world creation and on growth, never per
// substep). Reachable only from code linked against sph_internal: libsph exports sph_* alone.
#pragma once

namespace sph {
namespace testing {

void arm_device_allocation_fault(long n);
// Turns the hook off; returns whether a failure was injected since it was armed.
bool disarm_device_allocation_fault();
// Called by every allocation: true when this one must fail.
bool device_allocation_fault_due();

}  // namespace testing
}  // namespace sph
