// SPDX-License-Identifier: MIT
// Warp-cooperative variants of the two gather passes (issue 18, session 15), for
// neighbor_search_variants.cu (through neighbor_search_tiles_check.cuh, the runner): read after
// that file's anonymous namespace (Grid, Consts, for_each_run, kH27), which this one reopens
// (not a standalone header).
//
// Why: one thread a particle makes a warp's 32 lanes walk 32 different candidate runs whose hits
// fall in different lanes (ncu: 17-23 of 32 lanes active). Here a warp takes a chunk of up to 32
// consecutive particles of one cell; all of them have the same 27 cells, so the warp walks the
// cell's nine row runs once, loads each run in tiles of 32 candidates into shared memory
// (coalesced, one float4 a lane) and every lane tests tile entries: the trip counts are the same
// in every lane. With m particles in the chunk (8 on average at h = 1.8 spacings), G = 32 / m
// lanes share a particle: lane a G + s takes tile entries s, s + G, ... of particle a, and the
// G partial sums are added in lane order by shuffles (a fixed order: the same bits on every run).
//
// The force pass's pair terms are costly and only about one candidate in five is a neighbour, so
// testing and evaluating in the same loop leaves most lanes idle while a few evaluate. The list
// variant compacts the hits first: per step, __ballot_sync of the hits, and each hit is appended
// at its rank among its group's hits (__popc) to its particle's list in shared memory; then the
// G lanes of each particle evaluate its list, every G-th entry, so lanes stay busy whichever
// candidates hit. A list that could overflow is evaluated early (a flush), so any count works.
// One queue for the whole warp (the issue's first idea) would mix particles in a batch of 32 and
// need a segmented reduction per batch to sum them in a fixed order; per-particle lists keep each
// particle's pairs in one group of lanes and need only the final G-lane sum.
//
// Determinism: the lists' order (tile, step, lane) and the final sums' order are fixed, so a
// result depends on the data and m only, never on timing. The order differs from the thread-a-
// particle passes (partial sums over every G-th candidate, then their sum), so results equal the
// reference's to rounding, not bit for bit (the library requires the same bits run to run, not
// the old order; neighbor_search_tiles_check.cuh compares within limits and reruns for equal bits).
#pragma once

namespace {

constexpr unsigned kFullMask = 0xffffffffu;
constexpr unsigned kTileWarps = 4;   // 128 threads a block
constexpr unsigned kListPool = 512;  // neighbour-list entries a warp: 2 KiB, 64 a particle at m = 8

// Chunk starts: particle i starts a chunk if it is the 0th, 32nd, ... particle of its cell.
// index[i] = i is the input of the compaction.
__global__ void chunk_flag_kernel(Grid g, const float4* p, unsigned n, unsigned* index, unsigned char* flag) {
  const unsigned i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const float4 q = p[i];
  const int cx = wrap(cell_coord(q.x, g.inv_cell), g.nx), cy = wrap(cell_coord(q.y, g.inv_cell), g.ny),
            cz = wrap(cell_coord(q.z, g.inv_cell), g.nz);
  const unsigned key = static_cast<unsigned>(cx + g.nx * (cy + g.ny * cz));
  index[i] = i;
  flag[i] = ((i - g.start[key]) & 31u) == 0u ? 1 : 0;
}

// A lane's place in its chunk: particle a (of m), slice s (of G).
struct TileLanes {
  unsigned lane, m, G, a, slice, first, group_mask;
  bool active;  // a < m: lanes m G .. 31 only load tiles and vote
};

__device__ inline TileLanes tile_lanes(unsigned m) {
  TileLanes t;
  t.lane = threadIdx.x & 31u;
  t.m = m;
  t.G = 32u / m;
  t.a = t.lane / t.G;
  t.slice = t.lane - t.a * t.G;
  t.first = t.a * t.G;
  t.group_mask = t.G == 32u ? kFullMask : ((1u << t.G) - 1u) << t.first;
  t.active = t.a < m;
  return t;
}

// The sum of x over the lanes of this lane's group, added in lane order (fixed), in every lane.
template <class T>
__device__ inline T group_sum(const TileLanes& t, T x) {
  T s = 0;
  for (unsigned k = 0; k < t.G; ++k) s += __shfl_sync(kFullMask, x, (t.first + k) & 31u);
  return s;
}

// The chunk of warp w: [begin, end), all of one cell.
struct ChunkRange {
  unsigned begin, end;
};
__device__ inline ChunkRange chunk_of(const unsigned* chunk_begin, unsigned chunks, unsigned n, unsigned w) {
  return ChunkRange{chunk_begin[w], w + 1 < chunks ? chunk_begin[w + 1] : n};
}

// The chunk's candidate runs, for_each_run<kH27>'s for its cell (every particle of a cell has the
// same ones, so the candidates are exactly the reference's), in the same order: lane r < 9 finds
// row r's run, two segments where the row wraps (else the second is empty), so that the tile
// loop below carries two registers of walk state instead of the row loops' dozen.
constexpr unsigned kRunSegments = 18;
__device__ inline void load_runs(const Grid& g, float3 x_cell, unsigned lane, uint2* runs) {
  if (lane < 9u) {
    const int cx = cell_coord(x_cell.x, g.inv_cell), cy = cell_coord(x_cell.y, g.inv_cell),
              cz = cell_coord(x_cell.z, g.inv_cell);
    const int wx = wrap(cx, g.nx), wy = wrap_add(wrap(cy, g.ny), static_cast<int>(lane % 3u) - 1, g.ny),
              wz = wrap_add(wrap(cz, g.nz), static_cast<int>(lane / 3u) - 1, g.nz);
    const int a = wrap_add(wx, -1, g.nx), b = wrap_add(wx, 1, g.nx);
    const unsigned row =
        static_cast<unsigned>(g.nx) * (static_cast<unsigned>(wy) + g.ny * static_cast<unsigned>(wz));
    if (a <= b) {
      runs[2 * lane] = make_uint2(__ldg(g.start + row + a), __ldg(g.start + row + b + 1));
      runs[2 * lane + 1] = make_uint2(0u, 0u);
    } else {
      runs[2 * lane] = make_uint2(__ldg(g.start + row + a), __ldg(g.start + row + g.nx));
      runs[2 * lane + 1] = make_uint2(__ldg(g.start + row), __ldg(g.start + row + b + 1));
    }
  }
  __syncwarp();
}

// Calls test(base, cnt) for each tile of up to 32 candidates of the chunk's runs, once the
// tile's positions are in `tile`.
template <class Test>
__device__ inline void for_each_tile(const uint2* runs, const float4* __restrict__ p, float4* tile,
                                     unsigned lane, Test&& test) {
  for (unsigned r = 0; r < kRunSegments; ++r) {
    const uint2 run = runs[r];
    for (unsigned base = run.x; base < run.y; base += 32u) {
      const unsigned cnt = min(32u, run.y - base);
      __syncwarp();
      if (lane < cnt) tile[lane] = p[base + lane];
      __syncwarp();
      test(base, cnt);
    }
  }
}

// Density, a warp a chunk. kFast: branchless with r = r2 rsqrt(r2) (density_fast_kernel's
// arithmetic); else the reference's exact form, counting neighbours.
template <bool kFast>
__global__ void __launch_bounds__(128)
    density_tile_kernel(Grid g, Consts k, const float4* __restrict__ p,
                        const unsigned* __restrict__ chunk_begin, unsigned chunks, unsigned n, float* rho,
                        unsigned* neighbours) {
  __shared__ float4 tiles[kTileWarps][32];
  __shared__ uint2 runs[kTileWarps][kRunSegments];
  const unsigned warp = threadIdx.x / 32u, w = blockIdx.x * kTileWarps + warp;
  if (w >= chunks) return;  // whole warps only
  const ChunkRange c = chunk_of(chunk_begin, chunks, n, w);
  const TileLanes t = tile_lanes(c.end - c.begin);
  const unsigned i = c.begin + min(t.a, t.m - 1u);
  const float4 pi = p[i], p0 = p[c.begin];
  float sum = 0.0f;
  unsigned nb = 0;
  load_runs(g, make_float3(p0.x, p0.y, p0.z), t.lane, runs[warp]);
  for_each_tile(runs[warp], p, tiles[warp], t.lane, [&](unsigned base, unsigned cnt) {
    if (!t.active) return;
    for (unsigned u = t.slice; u < cnt; u += t.G) {
      const float4 q = tiles[warp][u];
      const float dx = pi.x - q.x, dy = pi.y - q.y, dz = pi.z - q.z;
      const float r2 = dx * dx + dy * dy + dz * dz;
      if (kFast) {
        const float d = fmaxf(k.h - r2 * rsqrtf(fmaxf(r2, 1e-30f)), 0.0f);
        sum += d * d * d;
      } else if (r2 < k.h2 && base + u != i) {
        const float d = k.h - sqrtf(r2);
        sum += d * d * d;
        ++nb;
      }
    }
  });
  sum = group_sum(t, sum);
  nb = group_sum(t, nb);
  if (t.active && t.slice == 0u) {
    rho[i] =
        kFast ? k.mass * (k.self + k.spiky * (sum - k.h * k.h * k.h)) : k.mass * (k.self + k.spiky * sum);
    if (!kFast) neighbours[i] = nb;
  }
}

struct PairSums {
  float ax, ay, az, ox, oy, oz, vx, vy, vz;
};

// One pair's terms, as force_kernel (exact) or force_tuned_kernel<true, ...> (kFast). kLean: the
// symmetric pressure term in one sum, -(p_j / rho_j^2 + p_i / rho_i^2) grad W, with
// ci = p_i / rho_i^2 taken once a particle (three accumulators and three products fewer a pair;
// the same value as the reference's two sums, other rounding).
template <bool kFast, bool kLean>
__device__ inline void add_pair(PairSums& s, const Consts& k, const float4& pi, const float4& vi, float ci,
                                const float4& q, const float4& w) {
  const float dx = pi.x - q.x, dy = pi.y - q.y, dz = pi.z - q.z;
  const float r2 = dx * dx + dy * dy + dz * dz;
  float gm, r;
  if (kFast) {
    const float inv_r = rsqrtf(fmaxf(r2, 1e-30f));
    r = r2 * inv_r;
    const float d = k.h - r;
    gm = k.spiky_grad * d * d * inv_r;
  } else {
    r = sqrtf(r2);
    if (r <= 0.0f) return;
    const float d = k.h - r;
    gm = k.spiky_grad * d * d / r;
  }
  const float d = k.h - r;
  if (kLean) {
    const float g = gm * (-q.w * w.w * w.w - ci);
    s.ax += g * dx;
    s.ay += g * dy;
    s.az += g * dz;
  } else {
    const float pj = -q.w * w.w * w.w;
    s.ax += gm * dx * pj;
    s.ay += gm * dy * pj;
    s.az += gm * dz * pj;
    s.ox += gm * dx * -pi.w;
    s.oy += gm * dy * -pi.w;
    s.oz += gm * dz * -pi.w;
  }
  const float l = k.visc_lap * d * w.w;
  s.vx += (w.x - vi.x) * l;
  s.vy += (w.y - vi.y) * l;
  s.vz += (w.z - vi.z) * l;
}

// The force-like pass, a warp a chunk. kLists: hits compacted into per-particle lists (ballot),
// then evaluated by the particle's G lanes; else each lane tests its entries of a tile into a
// mask and evaluates the set bits (the library's two phases, on tiles). kMinBlocks: the
// register cap of __launch_bounds__ (12 blocks of 128: 40 registers).
template <bool kFast, bool kLists, bool kLean, int kMinBlocks>
__global__ void __launch_bounds__(128, kMinBlocks)
    force_tile_kernel(Grid g, Consts k, const float4* __restrict__ p, const float4* __restrict__ v,
                      const unsigned* __restrict__ chunk_begin, unsigned chunks, unsigned n, float4* acc) {
  __shared__ float4 tiles[kTileWarps][32];
  __shared__ uint2 runs[kTileWarps][kRunSegments];
  __shared__ unsigned lists[kLists ? kTileWarps : 1][kLists ? kListPool : 1];
  const unsigned warp = threadIdx.x / 32u, w = blockIdx.x * kTileWarps + warp;
  if (w >= chunks) return;
  const ChunkRange c = chunk_of(chunk_begin, chunks, n, w);
  const TileLanes t = tile_lanes(c.end - c.begin);
  const unsigned i = c.begin + min(t.a, t.m - 1u);
  const float4 pi = p[i], vi = v[i], p0 = p[c.begin];
  const float ci = pi.w * vi.w * vi.w;
  PairSums s{};
  const unsigned cap = kListPool / t.m;  // >= 16 and >= 16 G
  unsigned* list = lists[kLists ? warp : 0] + (kLists ? min(t.a, t.m - 1u) * cap : 0u);
  unsigned count = 0;  // this particle's list length, the same in all its lanes
  const unsigned below = (1u << t.lane) - 1u;
  auto flush = [&]() {
    __syncwarp();
    if (t.active)
      for (unsigned q = t.slice; q < count; q += t.G) {
        const unsigned j = list[q];
        add_pair<kFast, kLean>(s, k, pi, vi, ci, p[j], v[j]);
      }
    count = 0;
    __syncwarp();
  };
  load_runs(g, make_float3(p0.x, p0.y, p0.z), t.lane, runs[warp]);
  for_each_tile(runs[warp], p, tiles[warp], t.lane, [&](unsigned base, unsigned cnt) {
    if (kLists) {
      const unsigned steps = (cnt + t.G - 1u) / t.G;  // the same in every lane
      for (unsigned u = 0; u < steps; ++u) {
        if (__any_sync(kFullMask, t.active && count + t.G > cap)) flush();
        const unsigned e = t.slice + u * t.G;
        bool hit = false;
        if (t.active && e < cnt) {
          const float4 q = tiles[warp][e];
          const float dx = pi.x - q.x, dy = pi.y - q.y, dz = pi.z - q.z;
          hit = dx * dx + dy * dy + dz * dz < k.h2 && base + e != i;
        }
        const unsigned mine = __ballot_sync(kFullMask, hit) & t.group_mask;
        if (hit) list[count + __popc(mine & below)] = base + e;
        count += __popc(mine);
      }
    } else {
      if (!t.active) return;
      unsigned hits = 0;  // bit u: tile entry slice + u G
      for (unsigned e = t.slice, u = 0; e < cnt; e += t.G, ++u) {
        const float4 q = tiles[warp][e];
        const float dx = pi.x - q.x, dy = pi.y - q.y, dz = pi.z - q.z;
        hits |= ((dx * dx + dy * dy + dz * dz < k.h2 && base + e != i) ? 1u : 0u) << u;
      }
      while (hits) {
        const unsigned e = t.slice + static_cast<unsigned>(__ffs(hits) - 1) * t.G;
        hits &= hits - 1u;
        add_pair<kFast, kLean>(s, k, pi, vi, ci, tiles[warp][e], v[base + e]);
      }
    }
  });
  if (kLists) flush();
  s.ax = group_sum(t, s.ax);
  s.ay = group_sum(t, s.ay);
  s.az = group_sum(t, s.az);
  if (!kLean) {
    s.ox = group_sum(t, s.ox);
    s.oy = group_sum(t, s.oy);
    s.oz = group_sum(t, s.oz);
  }
  s.vx = group_sum(t, s.vx);
  s.vy = group_sum(t, s.vy);
  s.vz = group_sum(t, s.vz);
  if (t.active && t.slice == 0u) {
    const float sq = vi.w * vi.w;
    const float m_rho = k.mass * vi.w;
    if (kLean)
      acc[i] = make_float4(s.ax * k.mass + s.vx * k.mu * m_rho, s.ay * k.mass + s.vy * k.mu * m_rho - 9.81f,
                           s.az * k.mass + s.vz * k.mu * m_rho, 0.0f);
    else
      acc[i] = make_float4((s.ax + s.ox * sq) * k.mass + s.vx * k.mu * m_rho,
                           (s.ay + s.oy * sq) * k.mass + s.vy * k.mu * m_rho - 9.81f,
                           (s.az + s.oz * sq) * k.mass + s.vz * k.mu * m_rho, 0.0f);
  }
}

}  // namespace
