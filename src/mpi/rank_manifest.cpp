// SPDX-License-Identifier: MIT
#include "rank_manifest.h"

#include <cstring>

#include "../core/byte_io.h"
#include "../core/slab_decomposition.h"
#include "../core/slab_rules.h"
#include "../core/status.h"

namespace sph {

namespace {

constexpr uint8_t kManifestMagic[8] = {'S', 'P', 'H', 'R', 'A', 'N', 'K', 0x1a};
// Version 2: the cuts in sub-layers (a sixteenth of a cell layer, core/slab_rules.h); version 1's
// were whole cell layers, read as their first sub-layers.
constexpr uint32_t kManifestVersion = 2;
constexpr uint32_t kMaxRanks = 1u << 24;

[[noreturn]] void corrupt(const std::string& message) {
  throw Error(Status::CorruptData, "manifest: " + message);
}

}  // namespace

namespace {

std::string last_component(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

std::string rank_stem(const std::string& manifest_path, int rank) {
  return last_component(manifest_path) + ".rank" + std::to_string(rank);
}

}  // namespace

std::string rank_file_name(const std::string& manifest_path, int rank, uint64_t hash) {
  static const char digits[] = "0123456789abcdef";
  std::string hex(16, '0');
  for (int i = 15; i >= 0; --i, hash >>= 4) hex[static_cast<size_t>(i)] = digits[hash & 0xfu];
  return rank_stem(manifest_path, rank) + "." + hex;
}

std::string staged_rank_file_name(const std::string& manifest_path, int rank) {
  return rank_stem(manifest_path, rank) + ".staged";
}

bool is_rank_file_name(const std::string& manifest_path, int rank, const std::string& name) {
  const std::string stem = rank_stem(manifest_path, rank);
  if (name == stem) return true;
  if (name.size() != stem.size() + 17 || name.compare(0, stem.size(), stem) != 0 || name[stem.size()] != '.')
    return false;
  for (size_t i = stem.size() + 1; i < name.size(); ++i)
    if (!((name[i] >= '0' && name[i] <= '9') || (name[i] >= 'a' && name[i] <= 'f'))) return false;
  return true;
}

std::string rank_file_path(const std::string& manifest_path, const std::string& name) {
  const size_t slash = manifest_path.find_last_of('/');
  return slash == std::string::npos ? name : manifest_path.substr(0, slash + 1) + name;
}

uint64_t file_hash(const HostVector<uint8_t>& bytes) {
  Fnv1a64 h;
  h.add(bytes.data(), bytes.size());
  return h.value();
}

HostVector<uint8_t> write_rank_manifest(const RankManifest& m) {
  ByteWriter w;
  for (uint8_t b : kManifestMagic) w.u8(b);
  w.u32(kManifestVersion);
  w.u32(static_cast<uint32_t>(m.ranks.size()));
  w.u64(m.particles);
  w.u32(m.rebalance_percent);
  w.u32(static_cast<uint32_t>(m.state.axis));
  w.u32(m.state.cut ? 1u : 0u);
  w.u32(m.state.counters.rebalances);
  for (int32_t c : m.state.cuts) w.u32(static_cast<uint32_t>(c));
  for (const RankFileEntry& e : m.ranks) {
    w.u32(e.particles);
    w.u32(e.counters.ghosts);
    w.u32(e.counters.migrated_in);
    w.u32(e.counters.migrated_out);
    w.u64(e.size);
    w.u64(e.hash);
    w.u32(static_cast<uint32_t>(e.name.size()));
    w.bytes(e.name.data(), e.name.size());
  }
  HostVector<uint8_t>& bytes = w.buffer();
  const uint64_t sum = file_hash(bytes);
  w.u64(sum);
  return std::move(bytes);
}

RankManifest read_rank_manifest(const uint8_t* data, size_t size) {
  if (size < sizeof kManifestMagic + 8 || std::memcmp(data, kManifestMagic, sizeof kManifestMagic) != 0)
    corrupt("not a manifest of a distributed world's checkpoint (wrong magic bytes or too short)");
  Fnv1a64 sum;
  sum.add(data, size - 8);
  uint64_t stored = 0;
  for (int k = 7; k >= 0; --k) stored = (stored << 8) | data[size - 8 + static_cast<size_t>(k)];
  ByteReader r(data + sizeof kManifestMagic, size - sizeof kManifestMagic - 8, "manifest");
  const uint32_t version = r.u32();
  if (version < 1 || version > kManifestVersion)
    throw Error(Status::VersionMismatch, "manifest: version " + std::to_string(version) +
                                             "; this library reads versions 1 to " +
                                             std::to_string(kManifestVersion));
  if (sum.value() != stored) corrupt("checksum mismatch: the manifest is damaged");
  RankManifest m;
  const uint32_t ranks = r.u32();
  if (ranks == 0 || ranks > kMaxRanks) corrupt("a rank count of " + std::to_string(ranks));
  m.particles = r.u64();
  m.rebalance_percent = r.u32();
  if (m.rebalance_percent < 1 || m.rebalance_percent > 10000)
    corrupt("a rebalance threshold of " + std::to_string(m.rebalance_percent) + " percent");
  m.state.axis = static_cast<int32_t>(r.u32());
  const uint32_t cut = r.u32();
  if (cut > 1) corrupt("the cut flag is " + std::to_string(cut));
  m.state.cut = cut != 0;
  m.state.counters.rebalances = r.u32();
  r.need_elements(ranks - 1u, 4, "cuts");
  m.state.cuts.resize(ranks - 1u);
  for (int32_t& c : m.state.cuts) {
    c = static_cast<int32_t>(r.u32());
    // (Version 1: a cut at INT32_MAX, past every particle, stays there; the others, far inside
    // int32, saturate at the last whole layer that int32 sub-layers hold.)
    if (version == 1 && c != INT32_MAX)
      c = c > INT32_MAX / kSlabSubLayers - 1 ? INT32_MAX - (kSlabSubLayers - 1) : slab_sublayer(c, 0);
  }
  if (!SlabDecomposition::valid(static_cast<int>(ranks), m.state.axis, m.state.cuts))
    corrupt(
        "the slabs' axis or cuts are not a decomposition (axis 0-2, cuts non-decreasing, each slab "
        "between the first and the last empty, 24 sub-layers wide or more, or of whole layers)");
  r.need_elements(ranks, 36, "rank entries");
  m.ranks.resize(ranks);
  uint64_t total = 0;
  for (uint32_t k = 0; k < ranks; ++k) {
    RankFileEntry& e = m.ranks[k];
    e.particles = r.u32();
    e.counters.ghosts = r.u32();
    e.counters.migrated_in = r.u32();
    e.counters.migrated_out = r.u32();
    e.size = r.u64();
    e.hash = r.u64();
    const uint32_t length = r.u32();
    if (length == 0 || length > kMaxRankFileName)
      corrupt("rank " + std::to_string(k) + "'s file name has " + std::to_string(length) + " bytes");
    r.need(length);
    for (uint32_t i = 0; i < length; ++i) e.name.push_back(static_cast<char>(r.u8()));
    if (e.name.find('/') != std::string::npos || e.name.find('\0') != std::string::npos || e.name == "." ||
        e.name == "..")
      corrupt("rank " + std::to_string(k) + "'s file name is not a name in the manifest's directory");
    total += e.particles;
  }
  r.expect_end();
  if (total != m.particles)
    corrupt("the ranks hold " + std::to_string(total) + " particles, the world " +
            std::to_string(m.particles));
  return m;
}

}  // namespace sph
