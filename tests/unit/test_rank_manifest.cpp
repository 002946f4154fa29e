// SPDX-License-Identifier: MIT
// The manifest of a distributed world's checkpoint (src/mpi/rank_manifest.h) across its versions:
// version 2 holds the slabs' cuts in sub-layers (a sixteenth of a cell layer) and reads back as
// written; version 1 held whole cell layers, and a version-1 manifest still loads, each cut
// becoming its layer's first sub-layer (16 times it; INT32_MAX, the cut past every particle,
// staying; cuts past the layers int32 sub-layers hold saturating at the last whole one). A newer
// version is VERSION_MISMATCH, and cuts that are no decomposition CORRUPT_DATA.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

#include <cstring>
#include <vector>

#include "core/byte_io.h"
#include "core/status.h"
#include "mpi/rank_manifest.h"

namespace {

sph::RankManifest manifest_of(const std::vector<int32_t>& cuts) {
  sph::RankManifest m;
  m.rebalance_percent = 20;
  m.state.axis = 1;
  m.state.cut = true;
  m.state.cuts = cuts;
  for (size_t r = 0; r <= cuts.size(); ++r) {
    sph::RankFileEntry e;
    e.particles = 10;
    e.name = "set.rank" + std::to_string(r);
    m.ranks.push_back(e);
    m.particles += 10;
  }
  return m;
}

// The manifest's bytes with another version and cuts (at byte 40, i32 each), checksum renewed.
sph::HostVector<uint8_t> rewritten(sph::HostVector<uint8_t> bytes, uint32_t version,
                                   const std::vector<int32_t>& cuts) {
  std::memcpy(bytes.data() + 8, &version, 4);
  for (size_t k = 0; k < cuts.size(); ++k) std::memcpy(bytes.data() + 40 + 4 * k, &cuts[k], 4);
  sph::Fnv1a64 h;
  h.add(bytes.data(), bytes.size() - 8);
  uint64_t sum = h.value();
  for (size_t k = 0; k < 8; ++k, sum >>= 8) bytes[bytes.size() - 8 + k] = static_cast<uint8_t>(sum & 0xffu);
  return bytes;
}

sph::Status read_status(const sph::HostVector<uint8_t>& bytes) {
  try {
    sph::read_rank_manifest(bytes.data(), bytes.size());
  } catch (const sph::Error& e) {
    return e.status();
  }
  return sph::Status::Ok;
}

void test_version_2_round_trip(void**) {
  const std::vector<int32_t> cuts{198, 237, 275};
  const sph::HostVector<uint8_t> bytes = sph::write_rank_manifest(manifest_of(cuts));
  uint32_t version = 0;
  std::memcpy(&version, bytes.data() + 8, 4);
  assert_int_equal(version, 2);
  const sph::RankManifest m = sph::read_rank_manifest(bytes.data(), bytes.size());
  assert_true(m.state.cuts == cuts);
  assert_int_equal(m.state.axis, 1);
}

void test_version_1_reads_layers(void**) {
  const sph::HostVector<uint8_t> v2 = sph::write_rank_manifest(manifest_of({0, 0, 0, 0}));
  // Layers -3, 5, 6 (a slab of one whole layer) and INT32_MAX.
  const sph::HostVector<uint8_t> v1 = rewritten(v2, 1, {-3, 5, 6, INT32_MAX});
  const sph::RankManifest m = sph::read_rank_manifest(v1.data(), v1.size());
  assert_true(m.state.cuts == (std::vector<int32_t>{-48, 80, 96, INT32_MAX}));
  // Cuts past 2^27 layers saturate at INT32_MAX - 15, INT32_MIN stays.
  const sph::HostVector<uint8_t> far = rewritten(v2, 1, {INT32_MIN, 1 << 29, 1 << 29, 1 << 29});
  const sph::RankManifest f = sph::read_rank_manifest(far.data(), far.size());
  assert_true(f.state.cuts ==
              (std::vector<int32_t>{INT32_MIN, INT32_MAX - 15, INT32_MAX - 15, INT32_MAX - 15}));
}

void test_refusals(void**) {
  const sph::HostVector<uint8_t> v2 = sph::write_rank_manifest(manifest_of({0, 0}));
  assert_int_equal(static_cast<int>(read_status(rewritten(v2, 3, {0, 0}))),
                   static_cast<int>(sph::Status::VersionMismatch));
  assert_int_equal(static_cast<int>(read_status(rewritten(v2, 0, {0, 0}))),
                   static_cast<int>(sph::Status::VersionMismatch));
  // A middle slab of 8 sub-layers that is not whole layers: no decomposition.
  assert_int_equal(static_cast<int>(read_status(rewritten(v2, 2, {4, 12}))),
                   static_cast<int>(sph::Status::CorruptData));
  assert_int_equal(static_cast<int>(read_status(rewritten(v2, 2, {4, 28}))),
                   static_cast<int>(sph::Status::Ok));
}

}  // namespace

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_version_2_round_trip),
      cmocka_unit_test(test_version_1_reads_layers),
      cmocka_unit_test(test_refusals),
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
