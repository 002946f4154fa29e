// SPDX-License-Identifier: MIT
// The device's pair distance (src/physics/lane_math.h): r = r2 rsqrtf(r2) and x / r as
// x rsqrtf(r2), against the same quantities in double from the same r2, on a million random
// pairs in the kernel's ball at three kernel radii:
//   - r within 4e-7 relative and 1 / r within 3e-7 (rsqrtf is within 2 ulp, 2.4e-7 relative, of
//     the quotient, CUDA C Programming Guide, "Mathematical functions"; the product r2 (1 / r)
//     adds half an ulp);
//   - grad W_spiky (the pressure force's and DFSPH's pair gradient) and W_spiky (DFSPH's density
//     pair term) within 2e-6 of their values at r = 0 (the error of r enters as 2 (h - r) dr and
//     3 (h - r)^2 dr, the float formula's own roundings about as much again). The host's float
//     formula is measured the same way, for the comparison.
// And the guards: r2 = 0 (a coincident pair) gives r = 0, a zero gradient and W_spiky(0) bit for
// bit as on the host; r2 below the smallest normal float gives finite values; a NaN r2 a NaN r.
// Built with nvcc's default arithmetic, as cuda/dfsph_solver.cu is; the WCSPH force pass's file
// adds -ftz=true, which changes only what a subnormal r2 gives (zero there, so r = 0).
#include <cuda_runtime.h>

#include <cfloat>
#include <cmath>
#include <random>
#include <vector>

#include "gpu_check.h"
#include "physics/kernels.h"

using namespace gpu_check;
using sph::KernelCoefficients;
using sph::Vec3;

namespace {

struct Sample {
  float r;
  float inverse;  // over(1) = 1 / r
  Vec3 gradient;
  float value;
};

SPH_HD Sample evaluate(const KernelCoefficients& c, Vec3 d, float r2) {
  const sph::DistanceOf<float> distance = sph::distance_from_squared(r2);
  return Sample{distance.r, distance.over(1.0f), sph::spiky_gradient(c, d, distance),
                sph::spiky_value(c, distance.r)};
}

__global__ void evaluate_kernel(KernelCoefficients c, const Vec3* d, const float* r2, uint32_t n,
                                Sample* out) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < n) out[i] = evaluate(c, d[i], r2[i]);
}

void cuda_require(cudaError_t e, const char* what) {
  if (e != cudaSuccess) {
    std::printf("FAIL %s: %s\n", what, cudaGetErrorString(e));
    std::exit(1);
  }
}

std::vector<Sample> on_device(const KernelCoefficients& c, const std::vector<Vec3>& d,
                              const std::vector<float>& r2) {
  const uint32_t n = static_cast<uint32_t>(d.size());
  Vec3* dd = nullptr;
  float* dr2 = nullptr;
  Sample* ds = nullptr;
  cuda_require(cudaMalloc(&dd, n * sizeof(Vec3)), "cudaMalloc");
  cuda_require(cudaMalloc(&dr2, n * sizeof(float)), "cudaMalloc");
  cuda_require(cudaMalloc(&ds, n * sizeof(Sample)), "cudaMalloc");
  cuda_require(cudaMemcpy(dd, d.data(), n * sizeof(Vec3), cudaMemcpyHostToDevice), "copy in");
  cuda_require(cudaMemcpy(dr2, r2.data(), n * sizeof(float), cudaMemcpyHostToDevice), "copy in");
  evaluate_kernel<<<(n + 127) / 128, 128>>>(c, dd, dr2, n, ds);
  cuda_require(cudaGetLastError(), "launch");
  std::vector<Sample> out(n);
  cuda_require(cudaMemcpy(out.data(), ds, n * sizeof(Sample), cudaMemcpyDeviceToHost), "copy out");
  cudaFree(dd);
  cudaFree(dr2);
  cudaFree(ds);
  return out;
}

struct Errors {
  double r = 0.0, inverse = 0.0, gradient = 0.0, value = 0.0;
};

// The largest errors of `s` against double arithmetic from the same r2 (r2 > 0, r < h).
void measure(const KernelCoefficients& c, const Vec3& d, float r2, const Sample& s, Errors& e) {
  const double h = c.h, r = std::sqrt(static_cast<double>(r2)),
               grad_scale = -static_cast<double>(c.spiky_grad) * h * h;
  const double value_scale = static_cast<double>(c.spiky) * h * h * h;
  const double magnitude = static_cast<double>(c.spiky_grad) * (h - r) * (h - r) / r;
  const double exact[3] = {d.x * magnitude, d.y * magnitude, d.z * magnitude};
  const double got[3] = {s.gradient.x, s.gradient.y, s.gradient.z};
  e.r = std::fmax(e.r, std::fabs(s.r - r) / r);
  e.inverse = std::fmax(e.inverse, std::fabs(s.inverse * r - 1.0));
  for (int k = 0; k < 3; ++k) e.gradient = std::fmax(e.gradient, std::fabs(got[k] - exact[k]) / grad_scale);
  const double value = static_cast<double>(c.spiky) * (h - r) * (h - r) * (h - r);
  e.value = std::fmax(e.value, std::fabs(s.value - value) / value_scale);
}

bool finite(const Sample& s) {
  return std::isfinite(s.r) && std::isfinite(s.inverse) && std::isfinite(s.gradient.x) &&
         std::isfinite(s.gradient.y) && std::isfinite(s.gradient.z) && std::isfinite(s.value);
}

}  // namespace

int main() {
  exit_if_no_cuda();
  std::mt19937 rng(2026);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  for (float h : {0.01f, 0.036f, 1.0f}) {
    const KernelCoefficients c = sph::make_kernel_coefficients(h);
    std::vector<Vec3> d;
    std::vector<float> r2;
    while (d.size() < 1000000) {
      const Vec3 p{h * unit(rng), h * unit(rng), h * unit(rng)};
      const float s = sph::length_squared(p);
      if (!(s > 0.0f && s < c.h2)) continue;
      d.push_back(p);
      r2.push_back(s);
    }
    const std::vector<Sample> device = on_device(c, d, r2);
    Errors on_gpu, on_cpu;
    bool all_finite = true;
    for (size_t i = 0; i < d.size(); ++i) {
      all_finite = all_finite && finite(device[i]);
      measure(c, d[i], r2[i], device[i], on_gpu);
      measure(c, d[i], r2[i], evaluate(c, d[i], r2[i]), on_cpu);
    }
    char name[64];
    std::snprintf(name, sizeof name, "pair_distance/h=%g", h);
    report(all_finite && on_gpu.r <= 4e-7 && on_gpu.inverse <= 3e-7 && on_gpu.gradient <= 2e-6 &&
               on_gpu.value <= 2e-6,
           name,
           "largest errors against double, GPU (CPU): r %.3g (%.3g), 1/r %.3g (%.3g), grad W %.3g (%.3g) and "
           "W %.3g (%.3g) of their values at r = 0 (limits 4e-7, 3e-7, 2e-6, 2e-6)",
           on_gpu.r, on_cpu.r, on_gpu.inverse, on_cpu.inverse, on_gpu.gradient, on_cpu.gradient, on_gpu.value,
           on_cpu.value);
  }

  const KernelCoefficients c = sph::make_kernel_coefficients(0.036f);
  const std::vector<Vec3> d{
      {0.0f, 0.0f, 0.0f}, {1.0e-20f, 0.0f, 0.0f}, {1.0e-19f, 0.0f, 0.0f}, {NAN, 0.0f, 0.0f}};
  std::vector<float> r2;
  for (const Vec3& v : d) r2.push_back(sph::length_squared(v));
  const std::vector<Sample> s = on_device(c, d, r2);
  const Sample host_zero = evaluate(c, d[0], 0.0f);
  report(s[0].r == 0.0f && s[0].gradient.x == 0.0f && s[0].gradient.y == 0.0f && s[0].gradient.z == 0.0f &&
             !std::signbit(s[0].gradient.x) && s[0].value == host_zero.value,
         "pair_distance/coincident", "r2 = 0: r %g, grad W (%g, %g, %g), W %.9g (host %.9g)", s[0].r,
         s[0].gradient.x, s[0].gradient.y, s[0].gradient.z, s[0].value, host_zero.value);
  report(finite(s[1]) && finite(s[2]) && r2[1] < FLT_MIN && r2[2] < FLT_MIN, "pair_distance/subnormal",
         "r2 = %g: r %g, grad W.x %g; r2 = %g: r %g, grad W.x %g (all finite)", r2[1], s[1].r,
         s[1].gradient.x, r2[2], s[2].r, s[2].gradient.x);
  report(std::isnan(s[3].r), "pair_distance/nan", "r2 = NaN: r %g (as sqrt(NaN) on the host)", s[3].r);
  return finish();
}
