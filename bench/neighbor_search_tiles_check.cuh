// SPDX-License-Identifier: MIT
// The warp-cooperative variants' runner (issue 18, session 15): builds the chunk list, times
// each kernel of neighbor_search_tiles.cuh (median of --repeat, CUDA events) and checks it
// against the h27 plain passes of neighbor_search_variants.cu, which includes this file after
// its anonymous namespace (CHECK, median) and reopens it here (not a standalone header).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <cub/device/device_select.cuh>
#include <vector>

#include "neighbor_search_tiles.cuh"

namespace {

// What the tile variants are checked against: the h27 plain passes of the same sort (sorted order).
struct TileReference {
  Grid g;
  Consts k;
  const float4* pos;  // sorted, .w packed (pressure) as for the force pass
  const float4* vel;  // sorted, .w = 1 / density
  unsigned n;
  int repeat;
  double candidates;              // mean candidates a particle (h27's: the tiles test the same)
  const std::vector<float>* rho;  // density_kernel<kH27>
  const std::vector<unsigned>* neighbours;
  const std::vector<float4>* acc;  // force_kernel<kH27>
};

// Limits: the tiles sum the same terms in another order (partial sums of every G-th candidate),
// so densities (positive terms) move by a few float roundings, 1e-6 at most in practice (the
// rsqrt rows differ by 1.2e-6 and 1.3e-7); 1e-5 leaves room. Accelerations sum terms of both
// signs, so cancellation can magnify the same roundings: 1e-4. A wrong neighbour set is caught
// by the exact neighbour counts, not by these limits (a neighbour near r = h adds almost nothing).
constexpr double kTileDensityLimit = 1e-5;
constexpr double kTileForceLimit = 1e-4;

// Runs, times and checks the tile variants; prints a row each. Returns false if a check failed.
inline bool run_tile_variants(const TileReference& ref) {
  const unsigned n = ref.n;
  unsigned *d_index, *d_chunks, *d_num, *d_nb;
  unsigned char* d_flag;
  float* d_rho;
  float4* d_acc;
  CHECK(cudaMalloc(&d_index, n * sizeof(unsigned)));
  CHECK(cudaMalloc(&d_chunks, n * sizeof(unsigned)));
  CHECK(cudaMalloc(&d_num, sizeof(unsigned)));
  CHECK(cudaMalloc(&d_nb, n * sizeof(unsigned)));
  CHECK(cudaMalloc(&d_flag, n));
  CHECK(cudaMalloc(&d_rho, n * sizeof(float)));
  CHECK(cudaMalloc(&d_acc, n * sizeof(float4)));
  size_t temp_bytes = 0;
  CHECK(
      cub::DeviceSelect::Flagged(nullptr, temp_bytes, d_index, d_flag, d_chunks, d_num, static_cast<int>(n)));
  void* temp = nullptr;
  CHECK(cudaMalloc(&temp, temp_bytes));
  cudaEvent_t e0, e1;
  CHECK(cudaEventCreate(&e0));
  CHECK(cudaEventCreate(&e1));
  auto time = [&](auto&& launch) {
    std::vector<float> t;
    for (int r = 0; r < ref.repeat + 3; ++r) {
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
  const unsigned blocks = (n + 127) / 128;
  const float chunk_ms = time([&] {
    chunk_flag_kernel<<<blocks, 128>>>(ref.g, ref.pos, n, d_index, d_flag);
    CHECK(
        cub::DeviceSelect::Flagged(temp, temp_bytes, d_index, d_flag, d_chunks, d_num, static_cast<int>(n)));
  });
  unsigned chunks = 0;
  CHECK(cudaMemcpy(&chunks, d_num, sizeof(unsigned), cudaMemcpyDeviceToHost));
  std::vector<unsigned> begins(chunks);
  CHECK(cudaMemcpy(begins.data(), d_chunks, chunks * sizeof(unsigned), cudaMemcpyDeviceToHost));
  double busy = 0.0;  // lanes with a particle, m (32 / m) of 32
  for (unsigned c = 0; c < chunks; ++c) {
    const unsigned m = (c + 1 < chunks ? begins[c + 1] : n) - begins[c];
    busy += m * (32u / m);
  }
  std::printf(
      "  tiles  %u chunks of one cell (%.2f particles, %.0f %% of lanes hold one), chunk list %.4f ms\n",
      chunks, double(n) / chunks, 100.0 * busy / (32.0 * chunks), chunk_ms);
  const unsigned tile_blocks = (chunks + kTileWarps - 1) / kTileWarps;
  bool ok = true;

  std::vector<float> rho(n), rho_again(n);
  std::vector<unsigned> nb(n);
  auto density_row = [&](const char* name, bool exact, auto&& launch) {
    launch();
    CHECK(cudaGetLastError());
    CHECK(cudaMemcpy(rho.data(), d_rho, n * sizeof(float), cudaMemcpyDeviceToHost));
    double worst = 0.0, neigh = 0.0;
    unsigned wrong = 0;
    for (unsigned i = 0; i < n; ++i)
      worst = std::max(worst, std::fabs(double(rho[i]) - (*ref.rho)[i]) / std::fabs(double((*ref.rho)[i])));
    if (exact) {
      CHECK(cudaMemcpy(nb.data(), d_nb, n * sizeof(unsigned), cudaMemcpyDeviceToHost));
      for (unsigned i = 0; i < n; ++i) {
        neigh += nb[i];
        wrong += nb[i] != (*ref.neighbours)[i];
      }
    }
    const float ms = time(launch);
    CHECK(cudaMemcpy(rho_again.data(), d_rho, n * sizeof(float), cudaMemcpyDeviceToHost));
    const bool same = std::memcmp(rho.data(), rho_again.data(), n * sizeof(float)) == 0;
    const bool pass = worst <= kTileDensityLimit && wrong == 0 && same;
    ok = ok && pass;
    char neigh_text[32] = "-";
    if (exact) std::snprintf(neigh_text, sizeof neigh_text, "%.1f", neigh / n);
    std::printf("  tiles  %-40s %.4f ms  cand %.1f neigh %s  rel %.1e (limit %.0e)  %s%s  %s\n", name, ms,
                ref.candidates, neigh_text, worst, kTileDensityLimit,
                exact ? (wrong ? "counts DIFFER, " : "counts equal, ") : "",
                same ? "same bits on rerun" : "bits CHANGED on rerun", pass ? "PASS" : "FAIL");
  };
  density_row("density tiles, exact (sqrt, r < h)", true, [&] {
    density_tile_kernel<false><<<tile_blocks, 128>>>(ref.g, ref.k, ref.pos, d_chunks, chunks, n, d_rho, d_nb);
  });
  density_row("density tiles, rsqrt branchless", false, [&] {
    density_tile_kernel<true><<<tile_blocks, 128>>>(ref.g, ref.k, ref.pos, d_chunks, chunks, n, d_rho, d_nb);
  });

  std::vector<float4> acc(n), acc_again(n);
  auto force_row = [&](const char* name, auto&& launch) {
    launch();
    CHECK(cudaGetLastError());
    CHECK(cudaMemcpy(acc.data(), d_acc, n * sizeof(float4), cudaMemcpyDeviceToHost));
    double worst = 0.0;
    for (unsigned i = 0; i < n; ++i) {
      const float4 a = acc[i], b = (*ref.acc)[i];
      const double dx = a.x - b.x, dy = a.y - b.y, dz = a.z - b.z;
      const double m = std::sqrt(double(b.x) * b.x + double(b.y) * b.y + double(b.z) * b.z);
      worst = std::max(worst, std::sqrt(dx * dx + dy * dy + dz * dz) / std::max(m, 1e-3));
    }
    const float ms = time(launch);
    CHECK(cudaMemcpy(acc_again.data(), d_acc, n * sizeof(float4), cudaMemcpyDeviceToHost));
    const bool same = std::memcmp(acc.data(), acc_again.data(), n * sizeof(float4)) == 0;
    const bool pass = worst <= kTileForceLimit && same;
    ok = ok && pass;
    std::printf("  tiles  %-40s %.4f ms  rel %.1e (limit %.0e)  %s  %s\n", name, ms, worst, kTileForceLimit,
                same ? "same bits on rerun" : "bits CHANGED on rerun", pass ? "PASS" : "FAIL");
  };
  force_row("force tiles, exact, two phases", [&] {
    force_tile_kernel<false, false, false, 1>
        <<<tile_blocks, 128>>>(ref.g, ref.k, ref.pos, ref.vel, d_chunks, chunks, n, d_acc);
  });
  force_row("force tiles, rsqrt, two phases", [&] {
    force_tile_kernel<true, false, false, 1>
        <<<tile_blocks, 128>>>(ref.g, ref.k, ref.pos, ref.vel, d_chunks, chunks, n, d_acc);
  });
  force_row("force tiles, exact, ballot lists", [&] {
    force_tile_kernel<false, true, false, 1>
        <<<tile_blocks, 128>>>(ref.g, ref.k, ref.pos, ref.vel, d_chunks, chunks, n, d_acc);
  });
  force_row("force tiles, rsqrt, ballot lists", [&] {
    force_tile_kernel<true, true, false, 1>
        <<<tile_blocks, 128>>>(ref.g, ref.k, ref.pos, ref.vel, d_chunks, chunks, n, d_acc);
  });
  force_row("force tiles, rsqrt, lists, lean pair", [&] {
    force_tile_kernel<true, true, true, 1>
        <<<tile_blocks, 128>>>(ref.g, ref.k, ref.pos, ref.vel, d_chunks, chunks, n, d_acc);
  });
  force_row("force tiles, rsqrt, lists, lean, 10 blk/SM", [&] {
    force_tile_kernel<true, true, true, 10>
        <<<tile_blocks, 128>>>(ref.g, ref.k, ref.pos, ref.vel, d_chunks, chunks, n, d_acc);
  });
  force_row("force tiles, rsqrt, lists, lean, 12 blk/SM", [&] {
    force_tile_kernel<true, true, true, 12>
        <<<tile_blocks, 128>>>(ref.g, ref.k, ref.pos, ref.vel, d_chunks, chunks, n, d_acc);
  });
  force_row("force tiles, rsqrt, 2 phases, lean, 12 blk", [&] {
    force_tile_kernel<true, false, true, 12>
        <<<tile_blocks, 128>>>(ref.g, ref.k, ref.pos, ref.vel, d_chunks, chunks, n, d_acc);
  });

  CHECK(cudaEventDestroy(e0));
  CHECK(cudaEventDestroy(e1));
  CHECK(cudaFree(temp));
  CHECK(cudaFree(d_index));
  CHECK(cudaFree(d_chunks));
  CHECK(cudaFree(d_num));
  CHECK(cudaFree(d_nb));
  CHECK(cudaFree(d_flag));
  CHECK(cudaFree(d_rho));
  CHECK(cudaFree(d_acc));
  return ok;
}

}  // namespace
