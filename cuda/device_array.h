// SPDX-License-Identifier: MIT
// Owning handles of device and pinned host memory (every device allocation of the CUDA backend
// is a DeviceArray). Allocation failures throw
// Error(OutOfDeviceMemory / OutOfHostMemory) and leave nothing allocated; release never throws.
#pragma once

#include <stddef.h>
#include <stdint.h>

#include <atomic>
#include <string>
#include <utility>

#include "../src/core/host_memory.h"
#include "cuda_status.h"
#include "device_allocation_faults.h"

namespace sph {

// A number no earlier call returned, for a set of buffers that a captured frame graph copies to or
// from. The graph's memset and copy nodes hold the allocations they were captured with: replaying
// it after one of them was freed crashes in cudaGraphLaunch even when the new allocation has the
// old address (seen on an H100, session 45). A buffer set takes a new number before it frees any
// buffer, and the frame graph is rebuilt when the number differs (frame_loop.cu, same_setup).
inline uint64_t next_buffer_generation() {
  static std::atomic<uint64_t> last{0};
  return ++last;
}

// Device memory comes from the engine's device allocator when its context has one
// (sph_cuda_context_set_allocator; core/host_memory.h), cudaMalloc otherwise: the hooks current
// when the array is allocated, kept with it so it frees there.
template <class T>
class DeviceArray {
 public:
  DeviceArray() = default;
  DeviceArray(size_t count, const char* name) { allocate(count, name); }
  ~DeviceArray() { release(); }
  DeviceArray(DeviceArray&& other) noexcept
      : data_(std::exchange(other.data_, nullptr)),
        count_(std::exchange(other.count_, 0)),
        hooks_(std::exchange(other.hooks_, nullptr)),
        device_(other.device_) {}
  DeviceArray& operator=(DeviceArray&& other) noexcept {
    if (this != &other) {
      release();
      data_ = std::exchange(other.data_, nullptr);
      count_ = std::exchange(other.count_, 0);
      hooks_ = std::exchange(other.hooks_, nullptr);
      device_ = other.device_;
    }
    return *this;
  }
  DeviceArray(const DeviceArray&) = delete;
  DeviceArray& operator=(const DeviceArray&) = delete;

  void allocate(size_t count, const char* name) {
    release();
    if (count == 0) return;
    const size_t bytes = count * sizeof(T);
    const MemoryHooks* current = current_memory_hooks();
    const DeviceMemoryHooks* engine = current && current->device.alloc ? &current->device : nullptr;
    void* p = nullptr;
    cudaError_t e = cudaSuccess;
    int device = 0;
    if (testing::device_allocation_fault_due()) {
      e = cudaErrorMemoryAllocation;
    } else if (engine) {
      cuda_check(cudaGetDevice(&device), name);
      p = engine->alloc(bytes, device, engine->user_context);
      if (!p) e = cudaErrorMemoryAllocation;
      if (p && reinterpret_cast<uintptr_t>(p) % 256 != 0) {
        engine->free(p, bytes, device, engine->user_context);
        throw Error(Status::OutOfDeviceMemory, std::string("the engine's device allocator gave ") + name +
                                                   " memory that is not 256-byte aligned");
      }
    } else {
      e = cudaMalloc(&p, bytes);
    }
    if (e != cudaSuccess) {
      (void)cudaGetLastError();
      if (e == cudaErrorMemoryAllocation)
        throw Error(Status::OutOfDeviceMemory,
                    std::string(engine ? "the engine's device allocator" : "cudaMalloc") + " of " + name +
                        " (" + std::to_string(bytes) + " bytes) failed");
      cuda_check(e, name);
    }
    data_ = static_cast<T*>(p);
    count_ = count;
    hooks_ = engine ? current : nullptr;
    device_ = device;
  }

  void release() noexcept {
    if (data_) {
      if (hooks_)
        hooks_->device.free(data_, count_ * sizeof(T), device_, hooks_->device.user_context);
      else if (cudaFree(data_) != cudaSuccess)
        (void)cudaGetLastError();
    }
    data_ = nullptr;
    count_ = 0;
    hooks_ = nullptr;
  }

  T* get() const { return data_; }
  size_t size() const { return count_; }
  size_t bytes() const { return count_ * sizeof(T); }

 private:
  T* data_ = nullptr;
  size_t count_ = 0;
  const MemoryHooks* hooks_ = nullptr;  // the engine's allocator that gave data_ (null: cudaMalloc)
  int device_ = 0;
};

// Page-locked host memory: the only host memory a captured graph may copy to or from.
template <class T>
class PinnedArray {
 public:
  PinnedArray() = default;
  ~PinnedArray() { release(); }
  PinnedArray(const PinnedArray&) = delete;
  PinnedArray& operator=(const PinnedArray&) = delete;
  PinnedArray(PinnedArray&& other) noexcept : data_(other.data_) { other.data_ = nullptr; }
  PinnedArray& operator=(PinnedArray&& other) noexcept {
    if (this != &other) {
      release();
      data_ = other.data_;
      other.data_ = nullptr;
    }
    return *this;
  }

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
