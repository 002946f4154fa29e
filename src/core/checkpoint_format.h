// SPDX-License-Identifier: MIT
// The checkpoint layout shared by the writer and the reader (docs/checkpoint.md). All numbers
// little-endian; floats IEEE 754. Version 15 (the u32 after next_id in TIME, reserved 0 before,
// is the world tag of the object ids, below 65536: an older file loads with tag 0, the ids it was
// saved with). Version 8 (version 7's DFSPH block in PARM lacks
// linear_solver, read by field count, so it loads with the default solve). Version 6 (version 5
// lacks the probes' section PROB and the colliders' load points: such a file loads with no probes,
// sph_world_restore keeps the world's own, and load points at the colliders' origins; version 4
// also lacks max_capacity at the end of CONF, which then equals the capacity: a fixed world, and
// SPH_EVENT_CAPACITY_GROWN; version 3 lacks the density diffusion's block in PARM, read by name
// like every block, so a version 3 file loads with its defaults; version 2 lacks the solver in
// CONF, the solves' report in TIME and DFSPH's warm starts in PART; version 1 differs from 2 only
// in the parameters section, checkpoint_params.h; all load). A world with
// SPH_FEATURE_USER_ATTRIBUTE adds its values to PART and each source's to SRCE: a layout only that feature
// bit in CONF selects, so it needed no new version (a library without the feature refuses the bit):
//   header (48 bytes): magic[8] "SPHCKPT\x1a", u32 format version, u32 flags, u32 writer
//     backend, u32 writer library version, u64 payload size, u64 checksum, u32 section count,
//     u32 reserved (0). The checksum is FNV-1a 64 over the header with the checksum field
//     left out, then the payload.
//   payload: sections in the order of kSectionOrder, each u32 tag, u32 reserved (0), u64 body
//     length, body.
// Flags: 0 for a world's checkpoint; kFlagRankPart for one rank's part of a distributed world
// (include/sph_mpi.h: one such file per rank and a manifest, src/mpi/rank_manifest.h): PART then
// ends with each particle's u64 sort key (the order of the next sort; docs/distributed.md). A
// reader before that flag refuses such a file as unknown flags, as it should: it cannot resume it.
#pragma once

#include <stddef.h>
#include <stdint.h>

namespace sph {
namespace checkpoint {

constexpr uint8_t kMagic[8] = {'S', 'P', 'H', 'C', 'K', 'P', 'T', 0x1a};
constexpr uint32_t kFormatVersion = 15;            // what the writer writes
constexpr uint32_t kFirstProbeVersion = 6;         // the first with probes (PROB) and load points
constexpr uint32_t kFirstThresholdVersion = 7;     // the first with load and pressure thresholds
constexpr uint32_t kFirstLargestErrorVersion = 9;  // the solves' largest particle error in TIME
constexpr uint32_t kFirstGuardedVersion = 13;      // the solves' guarded count in TIME
constexpr uint32_t kFirstSourceDebtVersion = 14;   // a source's rate budget may be negative (a debt)
constexpr uint32_t kFirstWorldTagVersion = 15;     // the world tag of the object ids in TIME
constexpr uint32_t kFirstSolverVersion = 3;        // the first with the solver, its report and warm starts
constexpr uint32_t kFirstGrowableVersion = 5;      // the first with max_capacity in CONF
constexpr uint32_t kOldestReadableVersion = 1;     // the oldest the reader still loads
constexpr uint32_t kFlagRankPart = 1u << 0;
constexpr size_t kHeaderSize = 48;
constexpr size_t kChecksumOffset = 32;
constexpr size_t kSectionHeaderSize = 16;

constexpr uint32_t tag(char a, char b, char c, char d) {
  return static_cast<uint32_t>(static_cast<uint8_t>(a)) |
         (static_cast<uint32_t>(static_cast<uint8_t>(b)) << 8) |
         (static_cast<uint32_t>(static_cast<uint8_t>(c)) << 16) |
         (static_cast<uint32_t>(static_cast<uint8_t>(d)) << 24);
}

struct SectionInfo {
  uint32_t tag;
  const char* name;
};

// Every section, in the only order the format accepts.
constexpr SectionInfo kSectionOrder[] = {
    {tag('C', 'O', 'N', 'F'), "world definition"},
    {tag('P', 'A', 'R', 'M'), "parameters"},
    {tag('T', 'I', 'M', 'E'), "clock and statistics"},
    {tag('P', 'A', 'R', 'T'), "particles"},
    {tag('S', 'D', 'F', 'A'), "SDF assets"},
    {tag('C', 'O', 'L', 'L'), "colliders"},
    {tag('S', 'R', 'C', 'E'), "sources"},
    {tag('S', 'I', 'N', 'K'), "sinks"},
    {tag('F', 'F', 'L', 'D'), "force fields"},
    {tag('P', 'R', 'O', 'B'), "probes"},  // from version 6 (kFirstProbeVersion)
};
constexpr uint32_t kSectionCount = sizeof(kSectionOrder) / sizeof(kSectionOrder[0]);
// The format version of a checkpoint that loaded (its header's bytes 8-11, little-endian).
inline uint32_t format_version_of(const void* data) {
  const uint8_t* b = static_cast<const uint8_t*>(data);
  return static_cast<uint32_t>(b[8]) | (static_cast<uint32_t>(b[9]) << 8) |
         (static_cast<uint32_t>(b[10]) << 16) | (static_cast<uint32_t>(b[11]) << 24);
}
// The sections a file of `version` has: all but PROB before version 6.
constexpr uint32_t section_count_of(uint32_t version) {
  return version >= kFirstProbeVersion ? kSectionCount : kSectionCount - 1;
}

constexpr uint32_t kNoAsset = 0xffffffffu;       // an object without this asset
constexpr uint32_t kAssetHasVelocity = 1u << 0;  // SDF asset channel bits
constexpr uint32_t kAssetHasFriction = 1u << 1;
constexpr uint32_t kMaxObjectSlots = 65536;  // the C layer's limit per kind

}  // namespace checkpoint
}  // namespace sph
