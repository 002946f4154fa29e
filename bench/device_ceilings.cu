// SPDX-License-Identifier: MIT
// device_ceilings - the physical limits of the GPU the benchmarks run on (BENCHMARK.md, issue
// 10 item 3), measured, not taken from a data sheet:
//   - copy bandwidth: cudaMemcpyAsync device-to-device of a 1 GiB buffer (bytes read + written)
//   - streaming bandwidth: a float4 copy kernel (the access pattern of the particle passes)
//   - FP32 rate: a kernel of independent FMA chains (2 FLOP per FMA), enough warps to fill
//     every SM
// Each is timed with CUDA events after a warm-up, repeated, and the median is reported.
//
//   device_ceilings [--json FILE]
#include <cuda_runtime.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace {

void check(cudaError_t e, const char* what) {
  if (e != cudaSuccess) {
    std::fprintf(stderr, "device_ceilings: %s: %s\n", what, cudaGetErrorString(e));
    std::exit(e == cudaErrorNoDevice || e == cudaErrorInsufficientDriver ? 77 : 1);
  }
}

template <class Launch>
double median_ms(Launch&& launch, int repeats) {
  cudaEvent_t start, stop;
  check(cudaEventCreate(&start), "cudaEventCreate");
  check(cudaEventCreate(&stop), "cudaEventCreate");
  for (int i = 0; i < 3; ++i) launch();  // warm-up
  check(cudaDeviceSynchronize(), "warm-up");
  std::vector<double> ms;
  for (int i = 0; i < repeats; ++i) {
    check(cudaEventRecord(start), "cudaEventRecord");
    launch();
    check(cudaEventRecord(stop), "cudaEventRecord");
    check(cudaEventSynchronize(stop), "cudaEventSynchronize");
    float t = 0.0f;
    check(cudaEventElapsedTime(&t, start, stop), "cudaEventElapsedTime");
    ms.push_back(t);
  }
  cudaEventDestroy(start);
  cudaEventDestroy(stop);
  std::sort(ms.begin(), ms.end());
  return ms[ms.size() / 2];
}

__global__ void copy_float4(const float4* __restrict__ in, float4* __restrict__ out, size_t n) {
  for (size_t i = blockIdx.x * size_t{blockDim.x} + threadIdx.x; i < n; i += size_t{gridDim.x} * blockDim.x)
    out[i] = in[i];
}

// Eight independent FMA chains per thread hide the FMA latency; the result is stored so that
// the compiler cannot drop the work.
constexpr int kFmaIterations = 4096;
constexpr int kChains = 8;
__global__ void fma_chains(float* out, float a, float b) {
  float x[kChains];
#pragma unroll
  for (int c = 0; c < kChains; ++c) x[c] = static_cast<float>(threadIdx.x + c);
  for (int i = 0; i < kFmaIterations; ++i) {
#pragma unroll
    for (int c = 0; c < kChains; ++c) x[c] = fmaf(x[c], a, b);
  }
  float sum = 0.0f;
#pragma unroll
  for (int c = 0; c < kChains; ++c) sum += x[c];
  out[blockIdx.x * blockDim.x + threadIdx.x] = sum;
}

}  // namespace

int main(int argc, char** argv) {
  const char* json = nullptr;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--json") == 0 && i + 1 < argc) {
      json = argv[++i];
    } else {
      std::fprintf(stderr, "usage: device_ceilings [--json FILE]\n");
      return 2;
    }
  }
  int device = 0;
  check(cudaGetDevice(&device), "cudaGetDevice");
  cudaDeviceProp prop;
  check(cudaGetDeviceProperties(&prop, device), "cudaGetDeviceProperties");

  const size_t bytes = size_t{1} << 30;
  void *a = nullptr, *b = nullptr;
  check(cudaMalloc(&a, bytes), "cudaMalloc");
  check(cudaMalloc(&b, bytes), "cudaMalloc");
  check(cudaMemset(a, 1, bytes), "cudaMemset");
  const double memcpy_ms =
      median_ms([&] { check(cudaMemcpyAsync(b, a, bytes, cudaMemcpyDeviceToDevice), "copy"); }, 20);
  const size_t n4 = bytes / sizeof(float4);
  const int blocks = prop.multiProcessorCount * 8;
  const double kernel_ms = median_ms(
      [&] { copy_float4<<<blocks, 256>>>(static_cast<const float4*>(a), static_cast<float4*>(b), n4); }, 20);
  check(cudaGetLastError(), "copy_float4");

  const int fma_blocks = prop.multiProcessorCount * 16;
  const int fma_threads = 256;
  float* out = nullptr;
  check(cudaMalloc(&out, sizeof(float) * fma_blocks * fma_threads), "cudaMalloc");
  const double fma_ms = median_ms([&] { fma_chains<<<fma_blocks, fma_threads>>>(out, 0.999f, 0.001f); }, 10);
  check(cudaGetLastError(), "fma_chains");
  cudaFree(a);
  cudaFree(b);
  cudaFree(out);

  const double copy_gbs = 2.0 * bytes / (memcpy_ms * 1e-3) / 1e9;  // read + write
  const double stream_gbs = 2.0 * bytes / (kernel_ms * 1e-3) / 1e9;
  const double flops = 2.0 * kFmaIterations * kChains * double(fma_blocks) * fma_threads;
  const double tflops = flops / (fma_ms * 1e-3) / 1e12;

  std::printf("device: %s (%d SMs, %.1f GiB)\n", prop.name, prop.multiProcessorCount,
              prop.totalGlobalMem / 1073741824.0);
  std::printf("  %-40s %10.1f GB/s\n", "cudaMemcpy device-to-device (r+w)", copy_gbs);
  std::printf("  %-40s %10.1f GB/s\n", "float4 copy kernel (r+w)", stream_gbs);
  std::printf("  %-40s %10.2f TFLOP/s\n", "FP32 FMA chains", tflops);
  if (json) {
    FILE* f = std::fopen(json, "w");
    if (!f) {
      std::fprintf(stderr, "device_ceilings: cannot write %s\n", json);
      return 1;
    }
    std::fprintf(
        f,
        "{\"benchmark\": \"device_ceilings\", \"device\": \"%s\", \"sms\": %d, \"memcpy_gb_s\": %.2f, "
        "\"stream_gb_s\": %.2f, \"fp32_tflop_s\": %.3f}\n",
        prop.name, prop.multiProcessorCount, copy_gbs, stream_gbs, tflops);
    std::fclose(f);
  }
  return 0;
}
