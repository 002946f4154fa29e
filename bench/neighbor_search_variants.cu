// SPDX-License-Identifier: MIT
// Neighbour-search variants for the two gather passes, measured alone on the GPU (issue 18):
// how many candidates each cell layout makes a particle test, and what a density pass and a
// force-like pass cost with each, on the benchmark's rest sphere (FCC lattice, h = 1.8
// spacings). Standalone: it reimplements the hash, sort and cell table so variants can be
// swapped without touching the library; the library's formulas are not needed to compare
// search strategies (the pair terms here have the library's shape and cost: W_spiky for the
// density, grad W_spiky pressure plus Laplacian viscosity for the force).
//
// Variants (cell size c, dense cell-start table over a wrapped grid, as in the library):
//   h27     c = h, 9 rows of 3 cells (the library today)
//   h27p    c = h, the same rows, but rows whose y-z box is farther than h are skipped
//   h2_125  c = h/2, 25 rows of 5 cells, no pruning
//   h2_p    c = h/2, per particle: rows farther than h in y-z skipped, and each row cut to the
//           cells that overlap [x - h, x + h] (4 or 5 of them)
// Each variant's densities are checked against h27's (same neighbours, other summation order:
// relative difference below 1e-5).
//
// The warp-cooperative variants (a warp per chunk of one cell, candidates in shared-memory tiles,
// ballot-compacted neighbour lists) are in neighbor_search_tiles.cuh, their runner in
// neighbor_search_tiles_check.cuh; they run on the h27 layout and are checked against its plain
// passes (the program exits 1 if one fails).
//
// Usage: neighbor_search_variants [--particles N] [--repeat R] [--jitter J] [--layouts all|h27]
#include <cuda_runtime.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <cub/device/device_radix_sort.cuh>
#include <string>
#include <vector>

namespace {

#define CHECK(call)                                                                               \
  do {                                                                                            \
    cudaError_t e_ = (call);                                                                      \
    if (e_ != cudaSuccess) {                                                                      \
      std::fprintf(stderr, "%s:%d: %s: %s\n", __FILE__, __LINE__, #call, cudaGetErrorString(e_)); \
      std::exit(1);                                                                               \
    }                                                                                             \
  } while (0)

struct Grid {
  float inv_cell;
  int nx, ny, nz;
  unsigned cells;
  const unsigned* start;  // cells + 1 entries
};

__host__ __device__ inline int wrap(int c, int n) {
  const int m = c % n;
  return m < 0 ? m + n : m;
}

__device__ inline int cell_coord(float x, float inv) { return static_cast<int>(floorf(x * inv)); }

__global__ void hash_kernel(Grid g, const float4* p, unsigned n, unsigned* keys, unsigned* values) {
  const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const float4 q = p[i];
  const int cx = wrap(cell_coord(q.x, g.inv_cell), g.nx), cy = wrap(cell_coord(q.y, g.inv_cell), g.ny),
            cz = wrap(cell_coord(q.z, g.inv_cell), g.nz);
  keys[i] = static_cast<unsigned>(cx + g.nx * (cy + g.ny * cz));
  values[i] = i;
}

__global__ void gather_kernel(const float4* in, const unsigned* order, unsigned n, float4* out) {
  const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i < n) out[i] = in[order[i]];
}

__global__ void cell_start_kernel(const unsigned* keys, unsigned n, unsigned cells, unsigned* start) {
  const unsigned c = blockIdx.x * blockDim.x + threadIdx.x;
  if (c > cells) return;
  unsigned lo = 0, hi = n;
  while (lo < hi) {
    const unsigned mid = lo + (hi - lo) / 2;
    if (keys[mid] < c)
      lo = mid + 1;
    else
      hi = mid;
  }
  start[c] = lo;
}

enum Variant { kH27 = 0, kH27Pruned = 1, kHalf125 = 2, kHalfPruned = 3 };
const char* kVariantNames[] = {"h27", "h27p", "h2_125", "h2_p"};

// w + step wrapped into [0, n) for w in [0, n) and |step| < n: no integer division.
__device__ inline int wrap_add(int w, int step, int n) {
  const int s = w + step;
  return s < 0 ? s + n : (s >= n ? s - n : s);
}

// Calls visit(begin, end) for each contiguous run of candidates of particle at p. One integer
// remainder per axis (as the library's for_each_neighbor_range), the rest by stepping.
template <int V, class Visit>
__device__ inline void for_each_run(const Grid& g, float3 p, float h, Visit&& visit) {
  const float c = 1.0f / g.inv_cell;
  const int cx = cell_coord(p.x, g.inv_cell), cy = cell_coord(p.y, g.inv_cell),
            cz = cell_coord(p.z, g.inv_cell);
  const int wx = wrap(cx, g.nx), wy0 = wrap(cy, g.ny), wz0 = wrap(cz, g.nz);
  constexpr int R = (V == kH27 || V == kH27Pruned) ? 1 : 2;
  const float h2 = h * h;
  int lo_step = -R, hi_step = R;
  if (V == kHalfPruned) {
    lo_step = cell_coord(p.x - h, g.inv_cell) - cx;
    hi_step = cell_coord(p.x + h, g.inv_cell) - cx;
  }
  const int a = wrap_add(wx, lo_step, g.nx), b = wrap_add(wx, hi_step, g.nx);
  for (int dz = -R; dz <= R; ++dz) {
    // Distance in z from p to the slab of cells cz + dz.
    float ez = 0.0f;
    if (V == kH27Pruned || V == kHalfPruned) {
      const float lo = (cz + dz) * c, hi = lo + c;
      ez = p.z < lo ? lo - p.z : (p.z > hi ? p.z - hi : 0.0f);
      if (ez * ez >= h2) continue;
    }
    const int wz = wrap_add(wz0, dz, g.nz);
    for (int dy = -R; dy <= R; ++dy) {
      if (V == kH27Pruned || V == kHalfPruned) {
        const float lo = (cy + dy) * c, hi = lo + c;
        const float ey = p.y < lo ? lo - p.y : (p.y > hi ? p.y - hi : 0.0f);
        if (ey * ey + ez * ez >= h2) continue;
      }
      const int wy = wrap_add(wy0, dy, g.ny);
      const unsigned row =
          static_cast<unsigned>(g.nx) * (static_cast<unsigned>(wy) + g.ny * static_cast<unsigned>(wz));
      if (a <= b) {
        visit(__ldg(g.start + row + a), __ldg(g.start + row + b + 1));
      } else {
        visit(__ldg(g.start + row + a), __ldg(g.start + row + g.nx));
        visit(__ldg(g.start + row), __ldg(g.start + row + b + 1));
      }
    }
  }
}

struct Consts {
  float h, h2, spiky, spiky_grad, visc_lap, mass, self, k, rho0, mu;
};

template <int V>
__global__ void density_kernel(Grid g, Consts k, const float4* __restrict__ p, unsigned n, float* rho,
                               unsigned* candidates, unsigned* neighbours) {
  const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const float4 pi = p[i];
  const float3 xi = make_float3(pi.x, pi.y, pi.z);
  float sum = 0.0f;
  unsigned cand = 0, nb = 0;
  for_each_run<V>(g, xi, k.h, [&](unsigned b, unsigned e) {
    cand += e - b;
#pragma unroll 4
    for (unsigned j = b; j < e; ++j) {
      const float4 q = p[j];
      const float dx = xi.x - q.x, dy = xi.y - q.y, dz = xi.z - q.z;
      const float r2 = dx * dx + dy * dy + dz * dz;
      if (r2 < k.h2 && j != i) {
        const float d = k.h - sqrtf(r2);
        sum += d * d * d;
        ++nb;
      }
    }
  });
  rho[i] = k.mass * (k.self + k.spiky * sum);
  if (candidates) {
    candidates[i] = cand;
    neighbours[i] = nb;
  }
}

// Branchless density: every candidate adds max(h - r, 0)^3, the particle itself included (its
// W(0) is taken back out once), so a warp never diverges on the hit test.
template <int V>
__global__ void density_branchless_kernel(Grid g, Consts k, const float4* __restrict__ p, unsigned n,
                                          float* rho) {
  const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const float4 pi = p[i];
  const float3 xi = make_float3(pi.x, pi.y, pi.z);
  float sum = 0.0f;
  for_each_run<V>(g, xi, k.h, [&](unsigned b, unsigned e) {
#pragma unroll 4
    for (unsigned j = b; j < e; ++j) {
      const float4 q = p[j];
      const float dx = xi.x - q.x, dy = xi.y - q.y, dz = xi.z - q.z;
      const float r2 = dx * dx + dy * dy + dz * dz;
      const float d = fmaxf(k.h - sqrtf(r2), 0.0f);
      sum += d * d * d;
    }
  });
  rho[i] = k.mass * (k.self + k.spiky * (sum - k.h * k.h * k.h));
}

// Neighbour masks: bit t of word w says candidate 32 w + t of the particle's candidate sequence
// (its runs, concatenated in visiting order) is a neighbour. kMaskWords words per particle,
// stored word-major (mask[w * n + i]) so a warp's loads coalesce; a particle with more
// candidates than the mask holds sets overflow[i] and the force pass tests it itself.
constexpr int kMaskWords = 8;

template <int V>
__global__ void density_mask_kernel(Grid g, Consts k, const float4* __restrict__ p, unsigned n, float* rho,
                                    unsigned* __restrict__ mask, unsigned* __restrict__ overflow) {
  const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const float4 pi = p[i];
  const float3 xi = make_float3(pi.x, pi.y, pi.z);
  float sum = 0.0f;
  unsigned seq = 0;  // candidates seen so far
  unsigned words[kMaskWords];
#pragma unroll
  for (int w = 0; w < kMaskWords; ++w) words[w] = 0u;
  for_each_run<V>(g, xi, k.h, [&](unsigned b, unsigned e) {
    for (unsigned base = b; base < e; base += 32u) {
      const unsigned count = min(32u, e - base);
      unsigned hits = 0;
#pragma unroll 4
      for (unsigned t = 0; t < count; ++t) {
        const float4 q = p[base + t];
        const float dx = xi.x - q.x, dy = xi.y - q.y, dz = xi.z - q.z;
        const float r2 = dx * dx + dy * dy + dz * dz;
        hits |= ((r2 < k.h2 && base + t != i) ? 1u : 0u) << t;
      }
      // Record the hits at sequence positions seq .. seq + count (two words at most).
      const unsigned w0 = seq >> 5, sh = seq & 31u;
#pragma unroll
      for (int w = 0; w < kMaskWords; ++w) {
        if (w == static_cast<int>(w0)) words[w] |= hits << sh;
        if (sh != 0u && w == static_cast<int>(w0) + 1) words[w] |= hits >> (32u - sh);
      }
      seq += count;
      while (hits) {
        const unsigned j = base + static_cast<unsigned>(__ffs(hits) - 1);
        hits &= hits - 1u;
        const float4 q = p[j];
        const float dx = xi.x - q.x, dy = xi.y - q.y, dz = xi.z - q.z;
        const float d = k.h - sqrtf(dx * dx + dy * dy + dz * dz);
        sum += d * d * d;
      }
    }
  });
  rho[i] = k.mass * (k.self + k.spiky * sum);
#pragma unroll
  for (int w = 0; w < kMaskWords; ++w) mask[static_cast<size_t>(w) * n + i] = words[w];
  overflow[i] = seq > 32u * kMaskWords ? 1u : 0u;
}

// The force pass from the density pass's masks: no candidate is tested again.
template <int V>
__global__ void force_from_mask_kernel(Grid g, Consts k, const float4* __restrict__ p,
                                       const float4* __restrict__ v, unsigned n,
                                       const unsigned* __restrict__ mask, float4* acc) {
  const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const float4 pi = p[i];
  const float4 vi = v[i];
  const float3 xi = make_float3(pi.x, pi.y, pi.z);
  float ax = 0, ay = 0, az = 0, ox = 0, oy = 0, oz = 0, vx = 0, vy = 0, vz = 0;
  unsigned seq = 0;
  for_each_run<V>(g, xi, k.h, [&](unsigned b, unsigned e) {
    // The bits of this run: candidates seq .. seq + (e - b).
    unsigned pos = seq;
    const unsigned end_seq = seq + (e - b);
    while (pos < end_seq) {
      const unsigned w = pos >> 5;
      unsigned bits = __ldg(mask + static_cast<size_t>(w) * n + i) >> (pos & 31u);
      const unsigned span = min(32u - (pos & 31u), end_seq - pos);
      if (span < 32u) bits &= (1u << span) - 1u;
      while (bits) {
        const unsigned j = b + (pos - seq) + static_cast<unsigned>(__ffs(bits) - 1);
        bits &= bits - 1u;
        const float4 q = p[j];
        const float4 wv = v[j];
        const float dx = xi.x - q.x, dy = xi.y - q.y, dz = xi.z - q.z;
        const float r = sqrtf(dx * dx + dy * dy + dz * dz);
        if (r <= 0.0f) continue;
        const float d = k.h - r;
        const float gm = k.spiky_grad * d * d / r;
        const float pj = -q.w * wv.w * wv.w;
        ax += gm * dx * pj;
        ay += gm * dy * pj;
        az += gm * dz * pj;
        ox += gm * dx * -pi.w;
        oy += gm * dy * -pi.w;
        oz += gm * dz * -pi.w;
        const float l = k.visc_lap * d * wv.w;
        vx += (wv.x - vi.x) * l;
        vy += (wv.y - vi.y) * l;
        vz += (wv.z - vi.z) * l;
      }
      pos += span;
    }
    seq = end_seq;
  });
  const float s = vi.w * vi.w;
  const float m_rho = k.mass * vi.w;
  acc[i] = make_float4((ax + ox * s) * k.mass + vx * k.mu * m_rho,
                       (ay + oy * s) * k.mass + vy * k.mu * m_rho - 9.81f,
                       (az + oz * s) * k.mass + vz * k.mu * m_rho, 0.0f);
}

// The library's two-phase force gather (cuda/substep_kernels.cu): test a run of up to 32
// candidates into a mask, then evaluate the pair terms of the set bits.
template <int V>
__global__ void force_kernel(Grid g, Consts k, const float4* __restrict__ p, const float4* __restrict__ v,
                             unsigned n, float4* acc) {
  const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const float4 pi = p[i];
  const float4 vi = v[i];
  const float3 xi = make_float3(pi.x, pi.y, pi.z);
  float ax = 0, ay = 0, az = 0, ox = 0, oy = 0, oz = 0, vx = 0, vy = 0, vz = 0;
  for_each_run<V>(g, xi, k.h, [&](unsigned b, unsigned e) {
    for (unsigned base = b; base < e; base += 32u) {
      const unsigned count = min(32u, e - base);
      unsigned hits = 0;
#pragma unroll 4
      for (unsigned t = 0; t < count; ++t) {
        const float4 q = p[base + t];
        const float dx = xi.x - q.x, dy = xi.y - q.y, dz = xi.z - q.z;
        const float r2 = dx * dx + dy * dy + dz * dz;
        hits |= ((r2 < k.h2 && base + t != i) ? 1u : 0u) << t;
      }
      while (hits) {
        const unsigned j = base + static_cast<unsigned>(__ffs(hits) - 1);
        hits &= hits - 1u;
        const float4 q = p[j];
        const float4 w = v[j];
        const float dx = xi.x - q.x, dy = xi.y - q.y, dz = xi.z - q.z;
        const float r = sqrtf(dx * dx + dy * dy + dz * dz);
        if (r <= 0.0f) continue;
        const float d = k.h - r;
        const float gm = k.spiky_grad * d * d / r;
        const float pj = -q.w * w.w * w.w;
        ax += gm * dx * pj;
        ay += gm * dy * pj;
        az += gm * dz * pj;
        ox += gm * dx * -pi.w;
        oy += gm * dy * -pi.w;
        oz += gm * dz * -pi.w;
        const float l = k.visc_lap * d * w.w;
        vx += (w.x - vi.x) * l;
        vy += (w.y - vi.y) * l;
        vz += (w.z - vi.z) * l;
      }
    }
  });
  const float s = vi.w * vi.w;
  const float m_rho = k.mass * vi.w;
  acc[i] = make_float4((ax + ox * s) * k.mass + vx * k.mu * m_rho,
                       (ay + oy * s) * k.mass + vy * k.mu * m_rho - 9.81f,
                       (az + oz * s) * k.mass + vz * k.mu * m_rho, 0.0f);
}

// Tuning variants of the h27 force pass: kFast evaluates 1/r with rsqrtf instead of an IEEE
// square root and division (about 16 instructions fewer a pair); kPrefetch loads the next
// neighbour's records before the current pair's arithmetic, so a load's latency overlaps work;
// kMinBlocks caps registers through __launch_bounds__ (more warps in flight); kLean sums the
// symmetric pressure term in one set of three, -(p_j / rho_j^2 + p_i / rho_i^2) grad W (the
// same value, three accumulators fewer; ox, oy, oz stay 0).
template <bool kFast, bool kPrefetch, int kMinBlocks, bool kLean = false>
__global__ void __launch_bounds__(128, kMinBlocks)
    force_tuned_kernel(Grid g, Consts k, const float4* __restrict__ p, const float4* __restrict__ v,
                       unsigned n, float4* acc) {
  const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const float4 pi = p[i];
  const float4 vi = v[i];
  const float3 xi = make_float3(pi.x, pi.y, pi.z);
  float ax = 0, ay = 0, az = 0, ox = 0, oy = 0, oz = 0, vx = 0, vy = 0, vz = 0;
  const float ci = pi.w * vi.w * vi.w;  // kLean: p_i / rho_i^2, once
  auto pair = [&](const float4& q, const float4& w) {
    const float dx = xi.x - q.x, dy = xi.y - q.y, dz = xi.z - q.z;
    const float r2 = dx * dx + dy * dy + dz * dz;
    float r, inv_r;
    if (kFast) {
      inv_r = rsqrtf(fmaxf(r2, 1e-30f));
      r = r2 * inv_r;
    } else {
      r = sqrtf(r2);
      if (r <= 0.0f) return;
      inv_r = 1.0f / r;
    }
    const float d = k.h - r;
    const float gm = k.spiky_grad * d * d * inv_r;
    if (kLean) {
      const float gp = gm * (-q.w * w.w * w.w - ci);
      ax += gp * dx;
      ay += gp * dy;
      az += gp * dz;
    } else {
      const float pj = -q.w * w.w * w.w;
      ax += gm * dx * pj;
      ay += gm * dy * pj;
      az += gm * dz * pj;
      ox += gm * dx * -pi.w;
      oy += gm * dy * -pi.w;
      oz += gm * dz * -pi.w;
    }
    const float l = k.visc_lap * d * w.w;
    vx += (w.x - vi.x) * l;
    vy += (w.y - vi.y) * l;
    vz += (w.z - vi.z) * l;
  };
  for_each_run<kH27>(g, xi, k.h, [&](unsigned b, unsigned e) {
    for (unsigned base = b; base < e; base += 32u) {
      const unsigned count = min(32u, e - base);
      unsigned hits = 0;
#pragma unroll 4
      for (unsigned t = 0; t < count; ++t) {
        const float4 q = p[base + t];
        const float dx = xi.x - q.x, dy = xi.y - q.y, dz = xi.z - q.z;
        const float r2 = dx * dx + dy * dy + dz * dz;
        hits |= ((r2 < k.h2 && base + t != i) ? 1u : 0u) << t;
      }
      if (kPrefetch) {
        if (!hits) continue;
        unsigned j = base + static_cast<unsigned>(__ffs(hits) - 1);
        hits &= hits - 1u;
        float4 q = p[j], w = v[j];
        while (hits) {
          const unsigned jn = base + static_cast<unsigned>(__ffs(hits) - 1);
          hits &= hits - 1u;
          const float4 qn = p[jn], wn = v[jn];
          pair(q, w);
          q = qn;
          w = wn;
        }
        pair(q, w);
      } else {
        while (hits) {
          const unsigned j = base + static_cast<unsigned>(__ffs(hits) - 1);
          hits &= hits - 1u;
          pair(p[j], v[j]);
        }
      }
    }
  });
  const float s = vi.w * vi.w;
  const float m_rho = k.mass * vi.w;
  acc[i] = make_float4((ax + ox * s) * k.mass + vx * k.mu * m_rho,
                       (ay + oy * s) * k.mass + vy * k.mu * m_rho - 9.81f,
                       (az + oz * s) * k.mass + vz * k.mu * m_rho, 0.0f);
}

// The density pass with r = r2 rsqrt(r2), branchless like density_branchless_kernel.
__global__ void density_fast_kernel(Grid g, Consts k, const float4* __restrict__ p, unsigned n, float* rho) {
  const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const float4 pi = p[i];
  const float3 xi = make_float3(pi.x, pi.y, pi.z);
  float sum = 0.0f;
  for_each_run<kH27>(g, xi, k.h, [&](unsigned b, unsigned e) {
#pragma unroll 4
    for (unsigned j = b; j < e; ++j) {
      const float4 q = p[j];
      const float dx = xi.x - q.x, dy = xi.y - q.y, dz = xi.z - q.z;
      const float r2 = dx * dx + dy * dy + dz * dz;
      const float d = fmaxf(k.h - r2 * rsqrtf(fmaxf(r2, 1e-30f)), 0.0f);
      sum += d * d * d;
    }
  });
  rho[i] = k.mass * (k.self + k.spiky * (sum - k.h * k.h * k.h));
}

__global__ void pack_kernel(float4* p, float4* v, const float* rho, Consts k, unsigned n) {
  const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const float r = rho[i];
  p[i].w = fmaxf(0.0f, k.k * (r - k.rho0));
  v[i].w = 1.0f / r;
}

float median(std::vector<float> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

#include "neighbor_search_tiles_check.cuh"

int main(int argc, char** argv) {
  unsigned target = 1000000;
  int repeat = 20;
  float jitter = 0.1f;  // fraction of the spacing: a lattice disturbed like the moving sphere
  int layouts = 4;      // --layouts h27: only the library's layout, its tuning rows and the tiles
  for (int a = 1; a + 1 < argc; a += 2) {
    if (!std::strcmp(argv[a], "--particles")) target = static_cast<unsigned>(std::atof(argv[a + 1]));
    if (!std::strcmp(argv[a], "--repeat")) repeat = std::atoi(argv[a + 1]);
    if (!std::strcmp(argv[a], "--jitter")) jitter = static_cast<float>(std::atof(argv[a + 1]));
    if (!std::strcmp(argv[a], "--layouts")) layouts = std::strcmp(argv[a + 1], "h27") ? 4 : 1;
  }
  const float s = 0.02f, h = 1.8f * s;
  // FCC sphere with about `target` points (4 per cube of side s sqrt 2).
  const double step = s / std::sqrt(2.0);
  const double radius = std::cbrt(3.0 * target * std::pow(s, 3) / (4.0 * M_PI * std::sqrt(2.0)));
  const int m = static_cast<int>(radius / step) + 1;
  std::vector<float4> pos;
  unsigned long long rng = 88172645463325252ull;
  auto uniform = [&]() {
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return static_cast<float>((rng >> 11) * (1.0 / 9007199254740992.0)) - 0.5f;
  };
  for (int z = -m; z <= m; ++z)
    for (int y = -m; y <= m; ++y)
      for (int x = -m; x <= m; ++x) {
        if (((x + y + z) & 1) != 0) continue;
        const double px = x * step, py = y * step, pz = z * step;
        if (px * px + py * py + pz * pz > radius * radius) continue;
        pos.push_back(make_float4(static_cast<float>(px) + jitter * s * uniform(),
                                  static_cast<float>(py) + jitter * s * uniform(),
                                  static_cast<float>(pz) + jitter * s * uniform(), 0.0f));
      }
  const unsigned n = static_cast<unsigned>(pos.size());
  std::vector<float4> vel(n);
  for (auto& w : vel) w = make_float4(0.1f * uniform(), 0.1f * uniform(), 0.1f * uniform(), 0.0f);

  Consts k;
  k.h = h;
  k.h2 = h * h;
  k.spiky = 15.0f / (3.14159265f * std::pow(h, 6.0f));
  k.spiky_grad = -45.0f / (3.14159265f * std::pow(h, 6.0f));
  k.visc_lap = 45.0f / (3.14159265f * std::pow(h, 6.0f));
  k.rho0 = 1000.0f;
  k.mass = k.rho0 * s * s * s / std::sqrt(2.0f);
  k.self = 0.0f;
  k.k = 100.0f;
  k.mu = 1.0f;

  float4 *d_pos, *d_vel, *d_spos, *d_svel, *d_acc;
  unsigned *keys[2], *vals[2], *d_start, *d_cand, *d_nb;
  float *d_rho, *d_rho_ref;
  CHECK(cudaMalloc(&d_pos, n * sizeof(float4)));
  CHECK(cudaMalloc(&d_vel, n * sizeof(float4)));
  CHECK(cudaMalloc(&d_spos, n * sizeof(float4)));
  CHECK(cudaMalloc(&d_svel, n * sizeof(float4)));
  CHECK(cudaMalloc(&d_acc, n * sizeof(float4)));
  for (int b = 0; b < 2; ++b) {
    CHECK(cudaMalloc(&keys[b], n * sizeof(unsigned)));
    CHECK(cudaMalloc(&vals[b], n * sizeof(unsigned)));
  }
  CHECK(cudaMalloc(&d_cand, n * sizeof(unsigned)));
  CHECK(cudaMalloc(&d_nb, n * sizeof(unsigned)));
  CHECK(cudaMalloc(&d_rho, n * sizeof(float)));
  CHECK(cudaMalloc(&d_rho_ref, n * sizeof(float)));
  unsigned *d_mask, *d_overflow;
  CHECK(cudaMalloc(&d_mask, size_t(kMaskWords) * n * sizeof(unsigned)));
  CHECK(cudaMalloc(&d_overflow, n * sizeof(unsigned)));
  CHECK(cudaMemcpy(d_pos, pos.data(), n * sizeof(float4), cudaMemcpyHostToDevice));
  CHECK(cudaMemcpy(d_vel, vel.data(), n * sizeof(float4), cudaMemcpyHostToDevice));
  cudaEvent_t e0, e1;
  CHECK(cudaEventCreate(&e0));
  CHECK(cudaEventCreate(&e1));

  std::printf("particles %u, h %.4f, jitter %.2f spacing, %d repeats (median ms)\n", n, h, jitter, repeat);
  std::printf("%-8s %6s %9s %7s %7s %9s %9s %8s %10s\n", "variant", "cell", "table", "cand", "neigh",
              "density", "force", "sort", "max_rel");
  std::vector<float> rho_ref;
  bool tiles_ok = true;
  for (int v = 0; v < layouts; ++v) {
    const bool half = v == kHalf125 || v == kHalfPruned;
    const float cell = half ? 0.5f * h : h;
    // h cells: about one table slot per particle (the library); h/2 cells: two per particle.
    const int side = std::max(5, static_cast<int>(std::ceil(std::cbrt((half ? 2.0 : 1.0) * n))));
    Grid g;
    g.inv_cell = 1.0f / cell;
    g.nx = g.ny = g.nz = side;
    g.cells = static_cast<unsigned>(side) * side * side;
    CHECK(cudaMalloc(&d_start, (g.cells + 1) * sizeof(unsigned)));
    g.start = d_start;
    const unsigned blocks = (n + 127) / 128;
    // Sort once (timed), reorder positions and velocities.
    size_t temp_bytes = 0;
    cub::DoubleBuffer<unsigned> kb(keys[0], keys[1]), vb(vals[0], vals[1]);
    CHECK(cub::DeviceRadixSort::SortPairs(nullptr, temp_bytes, kb, vb, static_cast<int>(n)));
    void* temp = nullptr;
    CHECK(cudaMalloc(&temp, temp_bytes));
    std::vector<float> sort_ms;
    for (int r = 0; r < repeat; ++r) {
      CHECK(cudaEventRecord(e0));
      hash_kernel<<<blocks, 128>>>(g, d_pos, n, keys[0], vals[0]);
      cub::DoubleBuffer<unsigned> kb2(keys[0], keys[1]), vb2(vals[0], vals[1]);
      CHECK(cub::DeviceRadixSort::SortPairs(temp, temp_bytes, kb2, vb2, static_cast<int>(n)));
      gather_kernel<<<blocks, 128>>>(d_pos, vb2.Current(), n, d_spos);
      gather_kernel<<<blocks, 128>>>(d_vel, vb2.Current(), n, d_svel);
      cell_start_kernel<<<(g.cells + 1 + 127) / 128, 128>>>(kb2.Current(), n, g.cells, d_start);
      CHECK(cudaEventRecord(e1));
      CHECK(cudaEventSynchronize(e1));
      float ms = 0;
      CHECK(cudaEventElapsedTime(&ms, e0, e1));
      sort_ms.push_back(ms);
    }
    std::vector<unsigned> order(n);
    {
      // Recompute the permutation for this variant (the last sort's).
      hash_kernel<<<blocks, 128>>>(g, d_pos, n, keys[0], vals[0]);
      cub::DoubleBuffer<unsigned> kb2(keys[0], keys[1]), vb2(vals[0], vals[1]);
      CHECK(cub::DeviceRadixSort::SortPairs(temp, temp_bytes, kb2, vb2, static_cast<int>(n)));
      CHECK(cudaMemcpy(order.data(), vb2.Current(), n * sizeof(unsigned), cudaMemcpyDeviceToHost));
    }
    auto run_density = [&](bool count) {
      unsigned* c = count ? d_cand : nullptr;
      unsigned* nb = count ? d_nb : nullptr;
      switch (v) {
        case kH27:
          density_kernel<kH27><<<blocks, 128>>>(g, k, d_spos, n, d_rho, c, nb);
          break;
        case kH27Pruned:
          density_kernel<kH27Pruned><<<blocks, 128>>>(g, k, d_spos, n, d_rho, c, nb);
          break;
        case kHalf125:
          density_kernel<kHalf125><<<blocks, 128>>>(g, k, d_spos, n, d_rho, c, nb);
          break;
        default:
          density_kernel<kHalfPruned><<<blocks, 128>>>(g, k, d_spos, n, d_rho, c, nb);
          break;
      }
    };
    auto run_force = [&]() {
      switch (v) {
        case kH27:
          force_kernel<kH27><<<blocks, 128>>>(g, k, d_spos, d_svel, n, d_acc);
          break;
        case kH27Pruned:
          force_kernel<kH27Pruned><<<blocks, 128>>>(g, k, d_spos, d_svel, n, d_acc);
          break;
        case kHalf125:
          force_kernel<kHalf125><<<blocks, 128>>>(g, k, d_spos, d_svel, n, d_acc);
          break;
        default:
          force_kernel<kHalfPruned><<<blocks, 128>>>(g, k, d_spos, d_svel, n, d_acc);
          break;
      }
    };
    run_density(true);
    CHECK(cudaGetLastError());
    CHECK(cudaDeviceSynchronize());
    std::vector<unsigned> cand(n), nb(n);
    std::vector<float> rho(n);
    CHECK(cudaMemcpy(cand.data(), d_cand, n * sizeof(unsigned), cudaMemcpyDeviceToHost));
    CHECK(cudaMemcpy(nb.data(), d_nb, n * sizeof(unsigned), cudaMemcpyDeviceToHost));
    CHECK(cudaMemcpy(rho.data(), d_rho, n * sizeof(float), cudaMemcpyDeviceToHost));
    // Densities by original index, compared with the first variant's.
    std::vector<float> by_index(n);
    for (unsigned i = 0; i < n; ++i) by_index[order[i]] = rho[i];
    double max_rel = 0.0;
    if (v == 0)
      rho_ref = by_index;
    else
      for (unsigned i = 0; i < n; ++i)
        max_rel =
            std::max(max_rel, std::fabs(double(by_index[i]) - rho_ref[i]) / std::fabs(double(rho_ref[i])));
    double mean_c = 0, mean_n = 0;
    for (unsigned i = 0; i < n; ++i) {
      mean_c += cand[i];
      mean_n += nb[i];
    }
    pack_kernel<<<blocks, 128>>>(d_spos, d_svel, d_rho, k, n);
    std::vector<float> dens_ms, force_ms;
    for (int r = 0; r < repeat + 3; ++r) {
      CHECK(cudaEventRecord(e0));
      run_density(false);
      CHECK(cudaEventRecord(e1));
      CHECK(cudaEventSynchronize(e1));
      float ms = 0;
      CHECK(cudaEventElapsedTime(&ms, e0, e1));
      if (r >= 3) dens_ms.push_back(ms);
      CHECK(cudaEventRecord(e0));
      run_force();
      CHECK(cudaEventRecord(e1));
      CHECK(cudaEventSynchronize(e1));
      CHECK(cudaEventElapsedTime(&ms, e0, e1));
      if (r >= 3) force_ms.push_back(ms);
    }
    CHECK(cudaGetLastError());
    std::printf("%-8s %6.4f %9u %7.1f %7.1f %9.4f %9.4f %8.4f %10.2e\n", kVariantNames[v], cell, g.cells + 1,
                mean_c / n, mean_n / n, median(dens_ms), median(force_ms), median(sort_ms), max_rel);
    if (v == kH27 || v == kHalfPruned) {
      // The same layout with the branchless density, and with masks handed to the force pass.
      std::vector<float4> acc_ref(n), acc(n);
      CHECK(cudaMemcpy(acc_ref.data(), d_acc, n * sizeof(float4), cudaMemcpyDeviceToHost));
      auto time = [&](auto&& launch) {
        std::vector<float> t;
        for (int r = 0; r < repeat + 3; ++r) {
          CHECK(cudaEventRecord(e0));
          launch();
          CHECK(cudaEventRecord(e1));
          CHECK(cudaEventSynchronize(e1));
          float ms = 0;
          CHECK(cudaEventElapsedTime(&ms, e0, e1));
          if (r >= 3) t.push_back(ms);
        }
        CHECK(cudaGetLastError());
        return median(t);
      };
      auto rel_rho = [&]() {
        std::vector<float> r2(n);
        CHECK(cudaMemcpy(r2.data(), d_rho, n * sizeof(float), cudaMemcpyDeviceToHost));
        double worst = 0.0;
        for (unsigned i = 0; i < n; ++i)
          worst = std::max(worst, std::fabs(double(r2[i]) - rho[i]) / std::fabs(double(rho[i])));
        return worst;
      };
      const float branchless = time([&] {
        if (v == kH27)
          density_branchless_kernel<kH27><<<blocks, 128>>>(g, k, d_spos, n, d_rho);
        else
          density_branchless_kernel<kHalfPruned><<<blocks, 128>>>(g, k, d_spos, n, d_rho);
      });
      const double branchless_rel = rel_rho();
      const float masked = time([&] {
        if (v == kH27)
          density_mask_kernel<kH27><<<blocks, 128>>>(g, k, d_spos, n, d_rho, d_mask, d_overflow);
        else
          density_mask_kernel<kHalfPruned><<<blocks, 128>>>(g, k, d_spos, n, d_rho, d_mask, d_overflow);
      });
      const double masked_rel = rel_rho();
      const float from_mask = time([&] {
        if (v == kH27)
          force_from_mask_kernel<kH27><<<blocks, 128>>>(g, k, d_spos, d_svel, n, d_mask, d_acc);
        else
          force_from_mask_kernel<kHalfPruned><<<blocks, 128>>>(g, k, d_spos, d_svel, n, d_mask, d_acc);
      });
      CHECK(cudaMemcpy(acc.data(), d_acc, n * sizeof(float4), cudaMemcpyDeviceToHost));
      std::vector<unsigned> overflow(n);
      CHECK(cudaMemcpy(overflow.data(), d_overflow, n * sizeof(unsigned), cudaMemcpyDeviceToHost));
      unsigned overflowed = 0;
      double acc_rel = 0.0;
      for (unsigned i = 0; i < n; ++i) {
        overflowed += overflow[i];
        const double dx = acc[i].x - acc_ref[i].x, dy = acc[i].y - acc_ref[i].y, dz = acc[i].z - acc_ref[i].z;
        const double m = std::sqrt(double(acc_ref[i].x) * acc_ref[i].x + double(acc_ref[i].y) * acc_ref[i].y +
                                   double(acc_ref[i].z) * acc_ref[i].z);
        acc_rel = std::max(acc_rel, std::sqrt(dx * dx + dy * dy + dz * dz) / std::max(m, 1e-3));
      }
      if (v == kH27) {
        // Tuning variants of the h27 passes, each checked against the plain force pass.
        auto check_acc = [&]() {
          CHECK(cudaMemcpy(acc.data(), d_acc, n * sizeof(float4), cudaMemcpyDeviceToHost));
          double worst = 0.0;
          for (unsigned i = 0; i < n; ++i) {
            const double dx = acc[i].x - acc_ref[i].x, dy = acc[i].y - acc_ref[i].y,
                         dz = acc[i].z - acc_ref[i].z;
            const double m =
                std::sqrt(double(acc_ref[i].x) * acc_ref[i].x + double(acc_ref[i].y) * acc_ref[i].y +
                          double(acc_ref[i].z) * acc_ref[i].z);
            worst = std::max(worst, std::sqrt(dx * dx + dy * dy + dz * dz) / std::max(m, 1e-3));
          }
          return worst;
        };
        struct Row {
          const char* name;
          float ms;
          double rel;
        };
        std::vector<Row> rows;
        auto force_row = [&](const char* name, auto&& launch) {
          const float ms = time(launch);
          rows.push_back(Row{name, ms, check_acc()});
        };
        force_row("force plain (launch_bounds 128,1)", [&] {
          force_tuned_kernel<false, false, 1><<<blocks, 128>>>(g, k, d_spos, d_svel, n, d_acc);
        });
        force_row("force fast rsqrt", [&] {
          force_tuned_kernel<true, false, 1><<<blocks, 128>>>(g, k, d_spos, d_svel, n, d_acc);
        });
        force_row("force prefetch", [&] {
          force_tuned_kernel<false, true, 1><<<blocks, 128>>>(g, k, d_spos, d_svel, n, d_acc);
        });
        force_row("force fast + prefetch", [&] {
          force_tuned_kernel<true, true, 1><<<blocks, 128>>>(g, k, d_spos, d_svel, n, d_acc);
        });
        force_row("force fast, min 12 blocks (<= 40 regs)", [&] {
          force_tuned_kernel<true, false, 12><<<blocks, 128>>>(g, k, d_spos, d_svel, n, d_acc);
        });
        force_row("force fast + prefetch, min 12 blocks", [&] {
          force_tuned_kernel<true, true, 12><<<blocks, 128>>>(g, k, d_spos, d_svel, n, d_acc);
        });
        force_row("force fast, lean pair", [&] {
          force_tuned_kernel<true, false, 1, true><<<blocks, 128>>>(g, k, d_spos, d_svel, n, d_acc);
        });
        force_row("force fast, lean pair, min 12 blocks", [&] {
          force_tuned_kernel<true, false, 12, true><<<blocks, 128>>>(g, k, d_spos, d_svel, n, d_acc);
        });
        for (unsigned bs : {64u, 256u}) {
          const unsigned nb = (n + bs - 1) / bs;
          const float ms = time([&] { force_kernel<kH27><<<nb, bs>>>(g, k, d_spos, d_svel, n, d_acc); });
          rows.push_back(
              Row{bs == 64 ? "force plain, 64 threads a block" : "force plain, 256 threads a block", ms,
                  check_acc()});
        }
        const float fast_density =
            time([&] { density_fast_kernel<<<blocks, 128>>>(g, k, d_spos, n, d_rho); });
        rows.push_back(Row{"density fast rsqrt, branchless", fast_density, rel_rho()});
        for (const Row& r : rows) std::printf("  h27    %-42s %.4f ms (rel %.1e)\n", r.name, r.ms, r.rel);
        // The warp-cooperative passes (neighbor_search_tiles.cuh), checked against the plain ones.
        tiles_ok = run_tile_variants(
            TileReference{g, k, d_spos, d_svel, n, repeat, mean_c / n, &rho, &nb, &acc_ref});
      }
      std::printf(
          "  %-6s branchless density %.4f ms (rel %.1e); mask density %.4f ms (rel %.1e) + force from "
          "mask %.4f ms (rel %.1e, %u overflowed)\n",
          kVariantNames[v], branchless, branchless_rel, masked, masked_rel, from_mask, acc_rel, overflowed);
    }
    CHECK(cudaFree(temp));
    CHECK(cudaFree(d_start));
  }
  if (!tiles_ok) std::printf("FAIL: a tile variant differs from the reference beyond its limit\n");
  return tiles_ok ? 0 : 1;
}
