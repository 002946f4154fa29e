// SPDX-License-Identifier: MIT
// The per-particle array registry (src/core/particle_arrays.h) as the CPU backend's store
// (src/cpu/cpu_particle_store.h) applies it: each role gets its bookkeeping and nothing more
// (a permutation moves Sorted and Carried arrays and leaves Scratch ones; the rollback snapshot
// holds the Carried ones; new particles start at the record's initial value; spring partners
// follow the permutation through the record's index rewrite), and a snapshot's carried arrays
// round-trip by name (src/core/particle_snapshot.h). The reorder gives the same bytes on any
// number of workers. Every expected value is written out by hand
// from the permutation.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
extern "C" {
#include <cmocka.h>
}

#include <cmath>
#include <cstring>
#include <vector>

#include "core/particle_snapshot.h"
#include "core/status.h"
#include "cpu/cpu_particle_store.h"
#include "physics/springs.h"

namespace {

using sph::CpuArrayRef;
using sph::CpuParticleStore;
using sph::ParticleArrayRole;
using sph::ParticleArraySpec;

ParticleArraySpec spec(const char* name, ParticleArrayRole role) {
  return ParticleArraySpec{name, sizeof(uint32_t), role, 1, nullptr, nullptr};
}

// order[i] is the old index of the particle that goes to place i.
const uint32_t kOrder[4] = {2, 0, 3, 1};

void test_roles_under_permutation(void**) {
  CpuParticleStore store;
  CpuArrayRef<uint32_t> carried = store.add_typed<uint32_t>(spec("carried", ParticleArrayRole::Carried));
  CpuArrayRef<uint32_t> sorted = store.add_typed<uint32_t>(spec("sorted", ParticleArrayRole::Sorted));
  CpuArrayRef<uint32_t> scratch = store.add_typed<uint32_t>(spec("scratch", ParticleArrayRole::Scratch));
  store.resize(4);
  for (uint32_t i = 0; i < 4; ++i) {
    carried[i] = 10 + i;
    sorted[i] = 20 + i;
    scratch[i] = 30 + i;
  }
  store.permute(kOrder, 4);
  const uint32_t moved_carried[4] = {12, 10, 13, 11}, moved_sorted[4] = {22, 20, 23, 21};
  for (uint32_t i = 0; i < 4; ++i) {
    assert_int_equal(carried[i], moved_carried[i]);
    assert_int_equal(sorted[i], moved_sorted[i]);
    assert_int_equal(scratch[i], 30 + i);  // scratch keeps its place: it is rewritten every pass
  }
  // A removal (a sink): particles 1 and 3 of the new order survive, in order.
  const uint32_t keep[2] = {1, 3};
  store.permute(keep, 2);
  store.resize(2);
  assert_int_equal(store.particles(), 2);
  assert_int_equal(carried[0], 10);
  assert_int_equal(carried[1], 11);
  assert_int_equal(sorted[1], 21);
}

void test_snapshot_holds_carried_only(void**) {
  CpuParticleStore store;
  CpuArrayRef<uint32_t> carried = store.add_typed<uint32_t>(spec("carried", ParticleArrayRole::Carried));
  CpuArrayRef<uint32_t> sorted = store.add_typed<uint32_t>(spec("sorted", ParticleArrayRole::Sorted));
  store.resize(3);
  for (uint32_t i = 0; i < 3; ++i) carried[i] = sorted[i] = i;
  const auto saved = store.snapshot();
  assert_int_equal(saved.size(), 1);  // one Carried array
  const uint32_t order[3] = {2, 1, 0};
  store.permute(order, 3);
  store.resize(5);  // the frame appended two particles
  carried[4] = sorted[4] = 99;
  store.resize(3);  // the rollback: back to the frame's count, then the copies
  store.restore(saved);
  for (uint32_t i = 0; i < 3; ++i) assert_int_equal(carried[i], i);
  assert_int_not_equal(sorted[0], 0u);  // not restored: a Sorted array is rebuilt every substep
}

void test_initial_values_and_world_words(void**) {
  const float fresh = std::nanf("");
  const uint32_t none = 0xffffffffu;
  CpuParticleStore store;
  CpuArrayRef<float> factor = store.add_typed<float>(
      ParticleArraySpec{"factor", sizeof(float), ParticleArrayRole::Carried, 1, &fresh, nullptr});
  CpuArrayRef<uint32_t> word = store.add_typed<uint32_t>(
      ParticleArraySpec{"word", sizeof(uint32_t), ParticleArrayRole::Carried, 0, &none, nullptr});
  CpuArrayRef<uint32_t> zero = store.add_typed<uint32_t>(spec("zero", ParticleArrayRole::Carried));
  assert_int_equal(word[0], none);  // a world word exists before any particle
  store.resize(2);
  factor[0] = 1.5f;
  store.resize(4);
  assert_true(factor[0] == 1.5f);
  assert_true(std::isnan(factor[1]) && std::isnan(factor[3]));
  assert_int_equal(zero[3], 0);
  word[0] = 7;
  store.resize(1);  // a world word has no per-particle size, and no permutation moves it
  const uint32_t identity[1] = {0};
  store.permute(identity, 1);
  assert_int_equal(word[0], 7);
}

void test_same_name_is_one_array(void**) {
  CpuParticleStore store;
  CpuArrayRef<uint32_t> a = store.add_typed<uint32_t>(spec("counts", ParticleArrayRole::Scratch));
  CpuArrayRef<uint32_t> b = store.add_typed<uint32_t>(spec("counts", ParticleArrayRole::Sorted));
  assert_ptr_equal(a.array(), b.array());
  assert_int_equal(static_cast<int>(a.array()->spec.role), static_cast<int>(ParticleArrayRole::Sorted));
  assert_int_equal(store.arrays().size(), 1);
  bool threw = false;
  try {
    store.add(ParticleArraySpec{"counts", 8, ParticleArrayRole::Sorted, 1, nullptr, nullptr});
  } catch (const sph::Error& e) {
    threw = e.status() == sph::Status::Internal;
  }
  assert_true(threw);  // one name, two sizes
}

// The springs of a world (method_particle_arrays) keep pointing at the same particles after a
// permutation, and a spring to a removed particle is dropped.
void test_spring_partners_follow(void**) {
  sph::WorldConfig config;
  config.features = sph::kFeatureSprings;
  CpuParticleStore store;
  for (const ParticleArraySpec& s : sph::method_particle_arrays(config)) store.add(s);
  CpuArrayRef<sph::SpringList> springs = store.find_typed<sph::SpringList>(sph::kArraySprings);
  assert_true(static_cast<bool>(springs));
  store.resize(4);
  for (uint32_t k = 0; k < sph::kSpringSlots; ++k) assert_int_equal(springs[3].partner[k], sph::kNoSpring);
  springs[0].partner[0] = 2;  // particle 0 (old index) links to particle 2 and to particle 1
  springs[0].rest[0] = 0.5f;
  springs[0].partner[1] = 1;
  springs[0].rest[1] = 0.25f;
  store.permute(kOrder, 4);  // old 0 -> new 1, old 2 -> new 0, old 1 -> new 3
  assert_int_equal(springs[1].partner[0], 0);
  assert_int_equal(springs[1].partner[1], 3);
  assert_true(springs[1].rest[1] == 0.25f);
  const uint32_t keep[2] = {0, 1};  // new 3 (old 1) is removed
  store.permute(keep, 2);
  store.resize(2);
  assert_int_equal(springs[1].partner[0], 0);
  assert_int_equal(springs[1].partner[1], sph::kNoSpring);
  assert_true(springs[1].rest[1] == 0.0f);
}

void test_snapshot_arrays_by_name(void**) {
  sph::WorldConfig config;
  config.features = sph::kFeatureNormalizedDensity | sph::kFeatureSprings;
  const std::vector<ParticleArraySpec> specs = sph::method_particle_arrays(config);
  sph::ParticleSnapshot s;
  s.set_carried(sph::kArrayDensityFactor, std::vector<float>{1.0f, 2.0f});
  sph::check_carried_arrays(s, specs, 2);
  assert_int_equal(s.carried_as<float>(sph::kArrayDensityFactor).size(), 2);
  // Missing arrays start fresh: the factor NaN, the link word "none waits".
  const ParticleArraySpec* link = sph::find_array_spec(specs, sph::kArraySpringLinkFrom);
  const auto word = sph::carried_bytes(s, *link, 2);
  uint32_t value = 0;
  assert_int_equal(word.size(), 4);
  std::memcpy(&value, word.data(), 4);
  assert_int_equal(value, sph::kNoPendingLinks);
  // The wrong length, and an array the world does not carry, are internal errors.
  for (int bad = 0; bad < 2; ++bad) {
    sph::ParticleSnapshot t = s;
    if (bad == 0)
      t.set_carried(sph::kArrayDensityFactor, std::vector<float>{1.0f});
    else
      t.set_carried("unknown", std::vector<float>{1.0f, 2.0f});
    bool threw = false;
    try {
      sph::check_carried_arrays(t, specs, 2);
    } catch (const sph::Error& e) {
      threw = e.status() == sph::Status::Internal;
    }
    assert_true(threw);
  }
}

// The reorder runs on several workers, in blocks of particles: with more particles than one
// block, 1 and 3 workers move every element to where the order says (a value that names its old
// index lands at its new place) and rewrite the spring partners alike, byte for byte.
void test_permute_on_workers(void**) {
  const uint32_t n = 10007;  // a few blocks and a ragged end
  std::vector<uint32_t> order(n);
  for (uint32_t i = 0; i < n; ++i) order[i] = (i * 7919u) % n;  // 7919 is prime: a permutation
  sph::WorldConfig config;
  config.features = sph::kFeatureSprings;
  std::vector<std::vector<unsigned char>> results[2];
  const unsigned workers[2] = {1u, 3u};
  for (int run = 0; run < 2; ++run) {
    CpuParticleStore store;
    for (const ParticleArraySpec& sp : sph::method_particle_arrays(config)) store.add(sp);
    CpuArrayRef<uint32_t> carried = store.add_typed<uint32_t>(spec("carried", ParticleArrayRole::Carried));
    CpuArrayRef<sph::SpringList> springs = store.find_typed<sph::SpringList>(sph::kArraySprings);
    store.resize(n);
    for (uint32_t i = 0; i < n; ++i) {
      carried[i] = 1000000u + i;
      springs[i].partner[0] = (i + 1) % n;  // each old particle links to the next one
    }
    store.permute(order.data(), n, workers[run]);
    for (uint32_t i = 0; i < n; ++i) {
      assert_int_equal(carried[i], 1000000u + order[i]);
      // New place i holds old particle order[i]; its partner is the new place of old order[i] + 1.
      assert_int_equal(order[springs[i].partner[0]], (order[i] + 1) % n);
    }
    for (const auto& a : store.arrays()) results[run].emplace_back(a->bytes.begin(), a->bytes.end());
  }
  assert_true(results[0] == results[1]);
}

}  // namespace

int main() {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_roles_under_permutation),
      cmocka_unit_test(test_snapshot_holds_carried_only),
      cmocka_unit_test(test_initial_values_and_world_words),
      cmocka_unit_test(test_same_name_is_one_array),
      cmocka_unit_test(test_spring_partners_follow),
      cmocka_unit_test(test_snapshot_arrays_by_name),
      cmocka_unit_test(test_permute_on_workers),
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
