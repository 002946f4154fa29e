// SPDX-License-Identifier: MIT
// The manifest of a distributed world's checkpoint (include/sph_mpi.h): which rank file belongs
// to which rank, each file's size and hash, the decomposition and the counters. Rank 0 writes it
// after every rank has written its file; a load reads it on every rank and refuses a set whose
// rank count, files or hashes do not match. Layout (little-endian, docs/checkpoint.md):
//   magic[8] "SPHRANK\x1a", u32 version (2), u32 rank count, u64 particles of the world,
//   u32 rebalance threshold percent, i32 slab axis, u32 first cut made (0/1), u32 rebalances,
//   i32 cuts[rank count - 1] (sub-layers; version 1: cell layers, read too), then per rank:
//   u32 particles, u32 ghosts of the last substep, u32 migrated in, u32 migrated out, u64 file
//   size, u64 file FNV-1a 64, u32 name length, the file's name (in the manifest's directory);
//   last, the FNV-1a 64 of every byte before it.
#pragma once

#include <stdint.h>

#include <string>
#include <vector>

#include "../core/distributed.h"
#include "../core/host_memory.h"

namespace sph {

struct RankFileEntry {
  uint32_t particles = 0;
  DistributedCounters counters;  // ghosts, migrated_in, migrated_out (rebalances: the world's)
  uint64_t size = 0;
  uint64_t hash = 0;  // FNV-1a 64 of the file's bytes
  std::string name;   // in the manifest's directory
};

struct RankManifest {
  uint64_t particles = 0;
  uint32_t rebalance_percent = 0;
  DistributedState state;  // axis, cuts, whether cut, rebalances (in state.counters)
  std::vector<RankFileEntry> ranks;
};

constexpr uint32_t kMaxRankFileName = 4096;

// The name of rank r's file beside a manifest at `manifest_path`: its last component + ".rank" r
// + "." + the file's FNV-1a 64 in 16 lower-case hex digits. A save never writes over a file the
// current manifest names (another content has another name), so a crash before the new manifest
// is in place leaves the old set whole.
std::string rank_file_name(const std::string& manifest_path, int rank, uint64_t hash);
// Where rank r writes its file before every rank has: the last component + ".rank" r + ".staged".
std::string staged_rank_file_name(const std::string& manifest_path, int rank);
// Whether `name` is a name this library gives rank r's file beside `manifest_path`: the hashed
// form above, or the plain last component + ".rank" r of libraries before it. A save removes
// the files of the set it replaces only when their names pass this, never a file a damaged or
// crafted manifest names otherwise.
bool is_rank_file_name(const std::string& manifest_path, int rank, const std::string& name);
// The path of a file named in a manifest: in the manifest's directory.
std::string rank_file_path(const std::string& manifest_path, const std::string& name);

HostVector<uint8_t> write_rank_manifest(const RankManifest& m);
// Validates everything (hostile input: CorruptData naming what is wrong, VersionMismatch).
RankManifest read_rank_manifest(const uint8_t* data, size_t size);

uint64_t file_hash(const HostVector<uint8_t>& bytes);

}  // namespace sph
