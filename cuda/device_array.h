// SPDX-License-Identifier: MIT
// Owning handles of device and pinned host memory. Allocation failures throw
// Error(OutOfDeviceMemory / OutOfHostMemory) and leave nothing allocated; release never throws.
#pragma once

#include <stddef.h>

#include <string>
#include <utility>

#include "cuda_status.h"
#include "device_allocation_faults.h"

namespace sph {

template <class T>
class DeviceArray {
 public:
  DeviceArray() = default;
  DeviceArray(size_t count, const char* name) { allocate(count, name); }
  ~DeviceArray() { release(); }
  DeviceArray(DeviceArray&& other) noexcept
      : data_(std::exchange(other.data_, nullptr)), count_(std::exchange(other.count_, 0)) {}
  DeviceArray& operator=(DeviceArray&& other) noexcept {
    if (this != &other) {
      release();
      data_ = std::exchange(other.data_, nullptr);
      count_ = std::exchange(other.count_, 0);
    }
    return *this;
  }
  DeviceArray(const DeviceArray&) = delete;
  DeviceArray& operator=(const DeviceArray&) = delete;

  void allocate(size_t count, const char* name) {
    release();
    if (count == 0) return;
    void* p = nullptr;
    const cudaError_t e = testing::device_allocation_fault_due() ? cudaErrorMemoryAllocation
                                                                 : cudaMalloc(&p, count * sizeof(T));
    if (e != cudaSuccess) {
      (void)cudaGetLastError();
      if (e == cudaErrorMemoryAllocation)
        throw Error(Status::OutOfDeviceMemory, std::string("cudaMalloc of ") + name + " (" +
                                                   std::to_string(count * sizeof(T)) + " bytes) failed");
      cuda_check(e, name);
    }
    data_ = static_cast<T*>(p);
    count_ = count;
  }

  void release() noexcept {
    if (data_ && cudaFree(data_) != cudaSuccess) (void)cudaGetLastError();
    data_ = nullptr;
    count_ = 0;
  }

  T* get() const { return data_; }
  size_t size() const { return count_; }
  size_t bytes() const { return count_ * sizeof(T); }

 private:
  T* data_ = nullptr;
  size_t count_ = 0;
};

// Page-locked host memory: the only host memory a captured graph may copy to or from.
template <class T>
class PinnedArray {
 public:
  PinnedArray() = default;
  ~PinnedArray() { release(); }
  PinnedArray(const PinnedArray&) = delete;
  PinnedArray& operator=(const PinnedArray&) = delete;

  void allocate(size_t count, const char* name) {
    release();
    void* p = nullptr;
    const cudaError_t e = testing::device_allocation_fault_due() ? cudaErrorMemoryAllocation
                                                                 : cudaMallocHost(&p, count * sizeof(T));
    if (e != cudaSuccess) {
      (void)cudaGetLastError();
      if (e == cudaErrorMemoryAllocation)
        throw Error(Status::OutOfHostMemory, std::string("cudaMallocHost of ") + name + " failed");
      cuda_check(e, name);
    }
    data_ = static_cast<T*>(p);
  }

  void release() noexcept {
    if (data_ && cudaFreeHost(data_) != cudaSuccess) (void)cudaGetLastError();
    data_ = nullptr;
  }

  T* get() const { return data_; }

 private:
  T* data_ = nullptr;
};

}  // namespace sph
