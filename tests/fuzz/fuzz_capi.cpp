// SPDX-License-Identifier: MIT
// libFuzzer harness: the input is a program of C-API calls with hostile arguments. Each op
// picks a function and its arguments (fuzzed defs and descs, NaN/Inf/huge floats, wrong struct
// sizes, stale and foreign handles and ids); after each call the harness checks the contract
// of sph_c.h: a known result code, a message on failure, a failed call changes nothing, a
// successful step leaves only finite particles, and at the end every object is destroyed and
// nothing leaks. Work per input is bounded (capacity <= 1024, <= 4 substeps per step, grids of
// at most 32^3 voxels, <= 20 iterations per DFSPH solve, gauges of <= 4096 points) so libFuzzer
// stays fast; absurd sizes are still passed where the library must refuse them before it
// allocates or reads anything. The ops added later (step_added_op) cover every method's world
// (DFSPH, springs, density diffusion, collider loads, the user attribute), probes and gauges,
// collider loads, the params of every kind and their descriptions, writing and removing
// particles, asynchronous steps (calls while the step holds the world must answer WORLD_LOCKED)
// and checkpoint files under /tmp.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

#include "fuzz_check.h"
#include "fuzz_input.h"
#include "shape_grid_estimate.h"
#include "sph_c.h"

using sph_fuzz::FuzzInput;
using sph_fuzz::violation;

namespace {

constexpr uint32_t kMaxCapacity = 1024;   // particles per world the harness allows
constexpr uint32_t kMaxSubsteps = 4;      // substeps per sph_world_step
constexpr uint64_t kMaxVoxels = 32768;    // voxels per grid the harness builds
constexpr double kMaxLattice = 1u << 16;  // source lattice points the harness allows
constexpr double kLibraryVoxelLimit = 2147483648.0;
constexpr int kContexts = 3, kWorlds = 4, kSdfs = 6, kIds = 8, kStale = 8;
constexpr uint32_t kMaxSolverIterations = 20;  // DFSPH iterations per solve the harness allows
constexpr double kMaxGaugeSteps = 4096;        // gauge sample points the harness allows (library: 65536)
constexpr uint32_t kKnownFeatures = 0x7fu;     // every SPH_FEATURE_* bit of sph_c.h
// Op bytes 232..253 pick the ops added after the first 29 (step_added_op). The first 29 keep
// every other byte value, and 0xfe and 0xff, which the saved inputs use as ops (fuzzers favour
// 0xff), keep theirs: tests/fuzz/regressions/capi decode as before.
constexpr uint8_t kFirstAddedOp = 232, kLastAddedOp = 253;

struct ContextSlot {
  sph_context* ptr = nullptr;
};
struct WorldSlot {
  sph_world* ptr = nullptr;
  int context = -1;
  uint32_t capacity = 0;  // the most particles it may hold: its max_capacity (it grows on demand)
  uint32_t features = 0;
  uint32_t integrator = 0, viscosity = 0, eos = 0, solver = 0;
  float spacing = 0.0f, kernel_radius = 0.0f;
  // The world tag its object ids carry (bits 16-31: sph_c.h, "Object ids"), once it has issued
  // one; -1 until then. A world keeps its tag (a restore of its own checkpoint keeps it too).
  int32_t id_tag = -1;
  // A cancel that reached an asynchronous step after its last substep stays for the next step
  // (sph_world_cancel_step): set after op_async_step cancelled, cleared by a step that ran.
  bool cancel_maybe_pending = false;
};
struct SdfSlot {
  sph_sdf* ptr = nullptr;
  int context = -1;
  // Its grid's box in the SDF's local frame, m: the bounding box of the index-space corners
  // (0 .. dims - 1 per axis) under index_to_local, in float as the library computes it, the box
  // whose lattice a source keeps (src/core/scene_objects.cpp, lattice_inside).
  float lo[3] = {0.0f, 0.0f, 0.0f}, hi[3] = {0.0f, 0.0f, 0.0f};
  bool has_velocity = false;
};
struct IdSlot {
  uint64_t bits = 0;
  int world = -1;
};

struct Particles {
  std::vector<float> position, velocity;
  std::vector<uint32_t> id;
  // Bitwise (NaN and -0 count as themselves). An empty vector may hold no storage (data() NULL),
  // and memcmp with NULL is undefined even for 0 bytes, so no particles compare without it.
  bool operator==(const Particles& o) const {
    return position.size() == o.position.size() && velocity.size() == o.velocity.size() &&
           (position.empty() ||
            std::memcmp(position.data(), o.position.data(), position.size() * sizeof(float)) == 0) &&
           (velocity.empty() ||
            std::memcmp(velocity.data(), o.velocity.data(), velocity.size() * sizeof(float)) == 0) &&
           id == o.id;
  }
};

class Program {
 public:
  explicit Program(FuzzInput& in) : in_(in) {}
  ~Program() { teardown(); }

  void run() {
    int ops = 0;
    while (!in_.empty() && ops++ < 64) step_op();
    for (int i = 0; i < kWorlds; ++i)
      if (worlds_[i].ptr) round_trip(i);
  }

 private:
  FuzzInput& in_;
  ContextSlot contexts_[kContexts];
  WorldSlot worlds_[kWorlds];
  SdfSlot sdfs_[kSdfs];
  IdSlot colliders_[kIds], sources_[kIds], sinks_[kIds], fields_[kIds], probes_[kIds];
  const void* stale_[kStale] = {};  // destroyed handles (never dereferenced by the harness)
  int stale_next_ = 0;

  // ---- handle choice: live, NULL, stale, or a handle of another kind -------------------------
  bool is_live_pointer(const void* p) const {
    for (const auto& c : contexts_)
      if (c.ptr == p) return true;
    for (const auto& w : worlds_)
      if (w.ptr == p) return true;
    for (const auto& s : sdfs_)
      if (s.ptr == p) return true;
    return false;
  }
  void remember_stale(const void* p) {
    stale_[stale_next_] = p;
    stale_next_ = (stale_next_ + 1) % kStale;
  }
  // A pointer that is not a live handle: NULL, a destroyed one (if its address was not reused),
  // or a pointer into the harness's own memory.
  const void* dead_pointer() {
    switch (in_.u8() % 3) {
      case 0:
        return nullptr;
      case 1: {
        const void* p = stale_[in_.u8() % kStale];
        return is_live_pointer(p) ? nullptr : p;
      }
      default:
        return &stale_;  // foreign memory, never a handle
    }
  }
  int pick_context() { return in_.u8() % kContexts; }
  int pick_world() { return in_.u8() % kWorlds; }
  sph_context* context_arg(int* slot) {
    *slot = pick_context();
    if (in_.chance(24)) {
      *slot = -1;
      if (in_.chance(64)) {  // a live handle of another kind
        for (const auto& w : worlds_)
          if (w.ptr) return reinterpret_cast<sph_context*>(w.ptr);
      }
      return static_cast<sph_context*>(const_cast<void*>(dead_pointer()));
    }
    return contexts_[*slot].ptr;
  }
  sph_world* world_arg(int* slot) {
    *slot = pick_world();
    if (in_.chance(24)) {
      *slot = -1;
      if (in_.chance(64)) {
        for (const auto& c : contexts_)
          if (c.ptr) return reinterpret_cast<sph_world*>(c.ptr);
      }
      return static_cast<sph_world*>(const_cast<void*>(dead_pointer()));
    }
    return worlds_[*slot].ptr;
  }
  sph_sdf* sdf_arg(int* slot) {
    *slot = in_.u8() % kSdfs;
    if (in_.chance(24)) {
      *slot = -1;
      return static_cast<sph_sdf*>(const_cast<void*>(dead_pointer()));
    }
    return sdfs_[*slot].ptr;
  }
  // An id: one of this kind's (maybe destroyed, maybe of another world), null, random bits, or
  // one of this kind's with another world tag (the same object's slot and generation: what a
  // world whose ids ignored their tag would take for its own; expect_foreign_id_refused).
  uint64_t id_arg(IdSlot* ids) {
    switch (in_.u8() % 8) {
      case 0:
        return 0;
      case 1:
        return in_.u64();
      case 2:
        return ids[in_.u8() % kIds].bits ^ (static_cast<uint64_t>(in_.u8() | 1u) << 16);
      default:
        return ids[in_.u8() % kIds].bits;
    }
  }

  // ---- invariants -------------------------------------------------------------------------------
  uint32_t count_of(sph_world* w) {
    uint32_t n = 0;
    if (FUZZ_CALL(sph_world_get_particle_count(w, &n)) != SPH_OK)
      violation("particle count of a live world failed");
    return n;
  }
  Particles snapshot(sph_world* w) {
    Particles p;
    const uint32_t n = count_of(w);
    p.position.resize(3 * static_cast<size_t>(n) + 3);
    p.velocity.resize(3 * static_cast<size_t>(n) + 3);
    p.id.resize(n + 1);
    uint32_t written = 0;
    FUZZ_CALL(sph_world_copy_attribute(w, SPH_ATTRIBUTE_POSITION, p.position.data(),
                                       p.position.size() * sizeof(float), 0, 0, n, &written));
    if (written != n) violation("copied %u positions of %u", written, n);
    FUZZ_CALL(sph_world_copy_attribute(w, SPH_ATTRIBUTE_VELOCITY, p.velocity.data(),
                                       p.velocity.size() * sizeof(float), 0, 0, n, &written));
    FUZZ_CALL(sph_world_copy_attribute(w, SPH_ATTRIBUTE_ID, p.id.data(), p.id.size() * sizeof(uint32_t), 0, 0,
                                       n, &written));
    p.position.resize(3 * static_cast<size_t>(n));
    p.velocity.resize(3 * static_cast<size_t>(n));
    p.id.resize(n);
    return p;
  }
  // The world's whole state as a checkpoint (a live world's save must succeed).
  std::vector<uint8_t> checkpoint(sph_world* w) {
    uint64_t size = 0;
    if (FUZZ_CALL(sph_world_save(w, nullptr, 0, &size)) != SPH_OK)
      violation("saving a live world failed: %s", sph_get_last_error());
    std::vector<uint8_t> bytes(static_cast<size_t>(size));
    if (FUZZ_CALL(sph_world_save(w, bytes.data(), size, &size)) != SPH_OK || size != bytes.size())
      violation("saving a live world failed: %s", sph_get_last_error());
    return bytes;
  }

  // Whatever a world accepted, its own save restores (issue 23, item 6): the checkpoint loads
  // into a new world and restores into the world itself, both save the same bytes again, and
  // the loaded world steps as the original does.
  void round_trip(int slot) {
    WorldSlot& ws = worlds_[slot];
    if (ws.cancel_maybe_pending) {
      // A cancel left by an asynchronous step would stop the world's step below and not its
      // loaded copy's: one step takes it (or, if there was none, steps as any step does).
      FUZZ_CALL(sph_world_step(ws.ptr, 1.0f / 600.0f));
      ws.cancel_maybe_pending = false;
    }
    const std::vector<uint8_t> bytes = checkpoint(ws.ptr);
    sph_world* loaded = nullptr;
    if (FUZZ_CALL(sph_world_load(contexts_[ws.context].ptr, bytes.data(), bytes.size(), &loaded)) != SPH_OK)
      violation("a world's own checkpoint does not load: %s", sph_get_last_error());
    if (checkpoint(loaded) != bytes) violation("a loaded world saves other bytes than it was loaded from");
    if (FUZZ_CALL(sph_world_restore(ws.ptr, bytes.data(), bytes.size())) != SPH_OK)
      violation("a world's own checkpoint does not restore: %s", sph_get_last_error());
    if (checkpoint(ws.ptr) != bytes)
      violation("a restored world saves other bytes than it was restored from");
    // The step budget belongs to the handle, not to the checkpoint (a loaded world has none),
    // and a wall-clock bound would make the two steps differ: both step without one.
    double budget = 0.0;
    FUZZ_CALL(sph_world_get_step_budget(ws.ptr, &budget));
    FUZZ_CALL(sph_world_set_step_budget(ws.ptr, 0.0));
    const float dt = 1.0f / 600.0f;
    const sph_result a = FUZZ_CALL(sph_world_step(ws.ptr, dt));
    const sph_result b = FUZZ_CALL(sph_world_step(loaded, dt));
    if (FUZZ_CALL(sph_world_set_step_budget(ws.ptr, budget)) != SPH_OK)
      violation("the step budget could not be put back");
    if (a != b) violation("the world's step answered %d, its loaded copy's %d", a, b);
    const Particles pa = snapshot(ws.ptr), pb = snapshot(loaded);
    if (!(pa == pb)) violation("a loaded world stepped to other particles than the original");
    if (a == SPH_OK || a == SPH_INCOMPLETE) check_particles(ws, pa);
    if (FUZZ_CALL(sph_world_destroy(loaded)) != SPH_OK) violation("destroying a loaded world failed");
  }

  void check_particles(const WorldSlot& slot, const Particles& p) {
    if (p.id.size() > slot.capacity)
      violation("%zu particles in a world of capacity %u", p.id.size(), slot.capacity);
    for (float v : p.position)
      if (!std::isfinite(v)) violation("a non-finite position after a successful step");
    for (float v : p.velocity)
      if (!std::isfinite(v)) violation("a non-finite velocity after a successful step");
    std::vector<uint32_t> ids = p.id;
    std::sort(ids.begin(), ids.end());
    if (std::adjacent_find(ids.begin(), ids.end()) != ids.end()) violation("two particles share an id");
  }

  // ---- values -----------------------------------------------------------------------------------
  sph_vec3 vec3(float lo, float hi) {
    return sph_vec3{in_.maybe_hostile(lo, hi), in_.maybe_hostile(lo, hi), in_.maybe_hostile(lo, hi)};
  }
  sph_transform transform() {
    sph_transform t = sph_transform_identity();
    if (in_.chance(128)) return t;
    t.position = vec3(-1.0f, 1.0f);
    t.rotation = sph_quat{in_.maybe_hostile(-1, 1), in_.maybe_hostile(-1, 1), in_.maybe_hostile(-1, 1),
                          in_.maybe_hostile(-1, 1)};
    return t;
  }
  // An enum value: usually one of [0, count) (the last ones may be invalid on purpose); with
  // chance invalid_in_256 an invalid one, half of those with the top bits set (0x80000000 + v,
  // 0xffffffff, raw bits): the library must read caller enums as integers, since loading such a
  // value as the enum type in C++ is undefined behaviour (UBSan: "not a valid value for type").
  uint32_t enum_value(uint32_t count, uint8_t invalid_in_256 = 32) {
    if (!in_.chance(invalid_in_256)) return in_.u8() % count;
    switch (in_.u8() % 4) {
      case 0:
        return 0x80000000u | (in_.u8() % count);
      case 1:
        return 0xffffffffu;
      case 2:
        return count + in_.u8();
      default:
        return in_.u32();
    }
  }

  // struct_size: nearly always right; sometimes too small, too large or zero.
  uint32_t struct_size(uint32_t right) {
    if (!in_.chance(16)) return right;
    switch (in_.u8() % 4) {
      case 0:
        return 0;
      case 1:
        return right - 4;
      case 2:
        return right + 4;
      default:
        return in_.u32() % 256;  // a def lives in a 256-byte buffer, so reading it stays inside
    }
  }
  // Bytes that hold a struct of type T, padded to 256 so that a fuzzed struct_size up to 256
  // never makes the library read outside the caller's memory.
  template <class T>
  struct Padded {
    union {
      T value;
      unsigned char bytes[256];
    };
    uint32_t painted_from = 256;
    Padded() { std::memset(bytes, 0, sizeof bytes); }
    // Paints the bytes past a struct_size of `size` with a canary ("only that many bytes are
    // written"). It starts after the struct_size field even when `size` is below 4: painting over
    // the field would hand the library a struct_size of 0xABABABAB instead of `size`.
    void paint_past(uint32_t size) {
      painted_from = std::min<uint32_t>(std::max<uint32_t>(size, sizeof(uint32_t)), 256);
      std::memset(bytes + painted_from, 0xAB, 256 - painted_from);
    }
    // Whether the call left every painted byte as it was.
    bool paint_intact() const {
      for (uint32_t i = painted_from; i < 256; ++i)
        if (bytes[i] != 0xAB) return false;
      return true;
    }
  };

  // ---- ops --------------------------------------------------------------------------------------
  void step_op() {
    const uint8_t op = in_.u8();
    if (op >= kFirstAddedOp && op <= kLastAddedOp) return step_added_op(op - kFirstAddedOp);
    switch (op % 29) {
      case 0:
        return op_context_create();
      case 1:
        return op_context_destroy();
      case 2:
        return op_world_create();
      case 3:
        return op_world_destroy();
      case 4:
        return op_set_params();
      case 5:
        return op_queries();
      case 6:
        return op_spawn();
      case 7:
        return op_fill_box();
      case 8:
        return op_fill_sphere();
      case 9:
        return op_step();
      case 10:
        return op_copy_attribute();
      case 11:
        return op_sdf_create();
      case 12:
        return op_sdf_create_shape();
      case 13:
        return op_sdf_update();
      case 14:
        return op_sdf_queries();
      case 15:
        return op_sdf_destroy();
      case 16:
        return op_collider_create();
      case 17:
        return op_collider_ops();
      case 18:
        return op_source_create();
      case 19:
        return op_source_ops();
      case 20:
        return op_sink();
      case 21:
        return op_force_field_create();
      case 22:
        return op_force_field_ops();
      case 23:
        return op_events();
      case 24:
        return op_physics_params();
      case 25:
        return op_init_sized();
      case 26:
        return op_step_budget();
      case 27:
        return op_sdf_create_from_mesh();
      default:
        return op_misc();
    }
  }

  void op_context_create() {
    const int slot = pick_context();
    if (contexts_[slot].ptr) return;
    Padded<sph_context_def> def;
    FUZZ_CALL(sph_context_def_init(&def.value));
    // CPU only: the fuzz build has no CUDA; AUTO resolves to the CPU there. Odd values must fail.
    const uint32_t backends[] = {SPH_BACKEND_CPU, SPH_BACKEND_AUTO, SPH_BACKEND_CUDA, 7u, 0x80000000u};
    const uint32_t backend = backends[in_.chance(200) ? 0 : in_.u8() % 5];
    std::memcpy(&def.value.backend, &backend, sizeof backend);
    def.value.cpu_worker_count = in_.chance(240) ? 1 : in_.u32();
    if (def.value.cpu_worker_count > 4 && def.value.cpu_worker_count < 100000) def.value.cpu_worker_count = 2;
    if (in_.chance(8)) def.value.cuda_dfsph_masks = in_.u32();
    if (in_.chance(8)) def.value.header_version = in_.u32();
    if (in_.chance(8)) def.value.device_ordinal = static_cast<int32_t>(in_.u32());
    def.value.struct_size = struct_size(sizeof(sph_context_def));
    sph_context* out = reinterpret_cast<sph_context*>(&stale_);  // must stay untouched on failure
    sph_context* const before = out;
    const sph_result r = FUZZ_CALL(sph_context_create(in_.chance(8) ? nullptr : &def.value, &out));
    if (r == SPH_OK) {
      if (!out) violation("sph_context_create succeeded with a NULL context");
      contexts_[slot].ptr = out;
      sph_backend b;
      FUZZ_CALL(sph_context_get_backend(out, &b));
      if (b != SPH_BACKEND_CPU && b != SPH_BACKEND_CUDA) violation("a context resolved to backend %d", b);
    } else if (out != before) {
      violation("sph_context_create wrote *out on failure");
    }
  }

  void op_context_destroy() {
    int slot;
    sph_context* c = context_arg(&slot);
    const sph_result r = FUZZ_CALL(sph_context_destroy(c));
    if (slot < 0) {
      if (r == SPH_OK && c) violation("sph_context_destroy accepted a dead or foreign handle");
      return;
    }
    if (!c) {
      if (r != SPH_OK) violation("sph_context_destroy(NULL) is not a no-op");
      return;
    }
    bool has_worlds = false;
    for (const auto& w : worlds_) has_worlds |= w.ptr && w.context == slot;
    if (r == SPH_OK) {
      if (has_worlds) violation("sph_context_destroy destroyed a context with live worlds");
      // SDF assets of a destroyed context would dangle: the library must refuse it instead.
      for (const auto& s : sdfs_)
        if (s.ptr && s.context == slot)
          violation("sph_context_destroy destroyed a context with live SDF assets");
      contexts_[slot].ptr = nullptr;
      remember_stale(c);
    } else if (!has_worlds && r != SPH_ERROR_BUSY) {
      violation("sph_context_destroy of an idle context failed with %d", r);
    }
  }

  void op_world_create() {
    const int slot = pick_world();
    if (worlds_[slot].ptr) return;
    int cslot;
    sph_context* c = context_arg(&cslot);
    Padded<sph_world_def> def;
    FUZZ_CALL(sph_world_def_init(&def.value));
    sph_world_def& d = def.value;
    d.capacity = in_.range(1, kMaxCapacity);
    if (in_.chance(16)) {
      const uint32_t raw = in_.u32();
      // Valid capacities above the harness's bound size the neighbour grid (legitimately
      // large); invalid ones (> 2^30) must be refused; 0 is the default, 65536.
      if (raw == 0 || raw > (1u << 30)) d.capacity = raw;
    }
    // The features byte's spare bits choose max_capacity, so that inputs written before the
    // field (the regressions) keep their byte stream.
    uint32_t growth = 0;
    if (in_.chance(224)) {
      const uint8_t bits = in_.u8();
      d.features = bits % 4;
      growth = bits >> 2;
    } else {
      d.features = in_.u32();
    }
    const uint64_t resolved = d.capacity == 0 ? 65536u : d.capacity;
    if (growth >= 32 && growth < 62)  // a growable world, up to 31 x its capacity
      d.max_capacity = static_cast<uint32_t>(std::min<uint64_t>(resolved * (growth - 30), 0xffffffffu));
    else if (growth == 62)
      d.max_capacity = static_cast<uint32_t>(resolved - 1);  // below the capacity: refused (unless 0)
    else if (growth == 63)
      d.max_capacity = (1u << 30) + 1u;  // past the hard limit: refused
    const uint32_t integrator = in_.chance(224) ? in_.u8() % 2 : in_.u32();
    const uint32_t viscosity = in_.chance(224) ? in_.u8() % 2 : in_.u32();
    const uint32_t eos = in_.chance(224) ? in_.u8() % 2 : in_.u32();
    std::memcpy(&d.integrator, &integrator, 4);
    std::memcpy(&d.viscosity_method, &viscosity, 4);
    std::memcpy(&d.equation_of_state, &eos, 4);
    if (in_.chance(128)) {
      d.particle_spacing = in_.maybe_hostile(0.005f, 0.2f);
      d.kernel_radius = in_.chance(128) ? 0.0f : d.particle_spacing * in_.maybe_hostile(0.5f, 6.0f);
      d.rest_density = in_.maybe_hostile(1.0f, 3000.0f);
    }
    if (in_.chance(8)) d.header_version = in_.u32();
    d.struct_size = struct_size(sizeof(sph_world_def));
    const uint32_t max_seen = max_capacity_seen(d);
    sph_world* out = nullptr;
    const sph_result r = FUZZ_CALL(sph_world_create(c, in_.chance(8) ? nullptr : &d, &out));
    adopt_world(slot, cslot, r, out, resolved, max_seen);
  }

  // What the library reads of max_capacity: the bytes of it that struct_size covers (a fuzzed
  // size may end inside the field; the library reads min(struct_size, its size) bytes,
  // docs/versioning.md), so the rest of the field counts as zero.
  static uint32_t max_capacity_seen(const sph_world_def& d) {
    const size_t at = offsetof(sph_world_def, max_capacity);
    uint32_t v = 0;
    if (d.struct_size > at) std::memcpy(&v, &d.max_capacity, std::min<size_t>(sizeof v, d.struct_size - at));
    return v;
  }

  // The checks of a sph_world_create result; a created world goes into `slot` with its work
  // bounded (or is destroyed again when the harness cannot bound it).
  void adopt_world(int slot, int cslot, sph_result r, sph_world* out, uint64_t resolved, uint32_t max_seen) {
    const bool max_refused = max_seen != 0 && (max_seen < resolved || max_seen > (1u << 30));
    if (r != SPH_OK) {
      if (out) violation("sph_world_create wrote *out on failure");
      return;
    }
    if (cslot < 0) violation("sph_world_create succeeded on a dead or foreign context");
    if (max_refused) violation("sph_world_create accepted max_capacity %u", max_seen);
    WorldSlot& w = worlds_[slot];
    w.ptr = out;
    w.context = cslot;
    sph_world_def got;
    sph_world_def_init(&got);
    FUZZ_CALL(sph_world_get_def(out, &got));
    w.capacity = got.max_capacity;
    w.features = got.features;
    w.integrator = static_cast<uint32_t>(got.integrator);
    w.viscosity = static_cast<uint32_t>(got.viscosity_method);
    w.eos = static_cast<uint32_t>(got.equation_of_state);
    w.solver = static_cast<uint32_t>(got.solver);
    w.spacing = got.particle_spacing;
    w.kernel_radius = got.kernel_radius;
    if (w.features & ~kKnownFeatures)
      violation("a world was created with unknown feature bits %#x", w.features);
    if (w.solver > SPH_SOLVER_DFSPH) violation("a world was created with solver %u", w.solver);
    // The combinations sph_solver and SPH_FEATURE_DENSITY_DIFFUSION call UNSUPPORTED.
    if (w.solver == SPH_SOLVER_DFSPH && (w.integrator == SPH_INTEGRATOR_RK4 || w.eos == SPH_EOS_TAIT ||
                                         (w.features & SPH_FEATURE_NORMALIZED_DENSITY)))
      violation("a DFSPH world was created with RK4, Tait or the normalised density");
    if ((w.features & SPH_FEATURE_DENSITY_DIFFUSION) &&
        (w.solver != SPH_SOLVER_WCSPH || !(w.features & SPH_FEATURE_NORMALIZED_DENSITY)))
      violation("density diffusion was created without the normalised density or with DFSPH");
    if (got.capacity != resolved)
      violation("the world's capacity %u is not the def's %u", got.capacity, static_cast<uint32_t>(resolved));
    const uint32_t max_expected = max_seen != 0 ? max_seen : got.capacity;
    if (got.max_capacity != max_expected)
      violation("the world's max_capacity %u is not the def's %u", got.max_capacity, max_expected);
    if (!(got.kernel_radius >= got.particle_spacing)) violation("kernel radius below the spacing");
    if (w.capacity > kMaxCapacity) {
      // Valid but beyond what the harness steps through: drop the world again.
      destroy_world(slot);
      return;
    }
    // Bound the work of every step of this world.
    sph_world_params p;
    sph_world_params_init(&p);
    FUZZ_CALL(sph_world_get_params(out, &p));
    p.max_substeps = kMaxSubsteps;
    if (FUZZ_CALL(sph_world_set_params(out, &p)) != SPH_OK) {
      // The world's own params with a smaller max_substeps are valid, so this should not
      // fail; if it ever does, the harness cannot bound the world's steps and drops it.
      return destroy_world(slot);
    }
    if (w.solver == SPH_SOLVER_DFSPH) {
      // And the iterations of DFSPH's two solves (default 100 each), likewise.
      sph_dfsph_params dp;
      sph_dfsph_params_init(&dp);
      if (FUZZ_CALL(sph_world_get_dfsph_params(out, &dp)) != SPH_OK)
        violation("a DFSPH world's params cannot be read: %s", sph_get_last_error());
      dp.max_iterations = kMaxSolverIterations;
      dp.max_divergence_iterations = kMaxSolverIterations;
      if (FUZZ_CALL(sph_world_set_dfsph_params(out, &dp)) != SPH_OK) destroy_world(slot);
    }
  }

  void destroy_world(int slot) {
    WorldSlot& w = worlds_[slot];
    if (FUZZ_CALL(sph_world_destroy(w.ptr)) != SPH_OK) violation("sph_world_destroy of a live world failed");
    remember_stale(w.ptr);
    w = WorldSlot{};
  }

  void op_world_destroy() {
    int slot;
    sph_world* w = world_arg(&slot);
    if (slot >= 0 && w) return destroy_world(slot);
    const sph_result r = FUZZ_CALL(sph_world_destroy(w));
    if (!w && r != SPH_OK) violation("sph_world_destroy(NULL) is not a no-op");
    if (w && r == SPH_OK) violation("sph_world_destroy accepted a dead or foreign handle");
  }

  void op_set_params() {
    int slot;
    sph_world* w = world_arg(&slot);
    Padded<sph_world_params> buf;
    sph_world_params& p = buf.value;
    sph_world_params_init(&p);
    if (slot >= 0 && w) FUZZ_CALL(sph_world_get_params(w, &p));
    switch (in_.u8() % 10) {
      case 0:
        // Not 0: a 0 takes the default 10000 substeps (zero means default), too slow here.
        p.max_substeps = in_.range(1, kMaxSubsteps);
        break;
      case 1:
        p.gravity = vec3(-20.0f, 20.0f);
        break;
      case 2:
        p.stiffness = in_.maybe_hostile(0.0f, 1000.0f);
        break;
      case 3:
        p.viscosity = in_.maybe_hostile(0.0f, 10.0f);
        break;
      case 4:
        p.step_factor = in_.maybe_hostile(0.0f, 12.0f);
        break;
      case 5:
        p.dt_min = in_.maybe_hostile(0.0f, 1e-3f);
        break;
      case 6:
        p.dt_max = in_.maybe_hostile(0.0f, 1e-2f);
        break;
      case 7:
        p.step_limits = in_.chance(200) ? in_.u8() % 4 : in_.u32();
        break;
      case 8:
        p.reserved0 = in_.u32();
        break;
      default:
        p.struct_size = struct_size(sizeof p);
        break;
    }
    if (p.max_substeps > kMaxSubsteps) p.max_substeps = kMaxSubsteps;
    sph_world_params before;
    sph_world_params_init(&before);
    if (slot >= 0 && w) FUZZ_CALL(sph_world_get_params(w, &before));
    const sph_result r = FUZZ_CALL(sph_world_set_params(w, in_.chance(8) ? nullptr : &p));
    if (slot < 0 || !w) {
      if (r == SPH_OK) violation("sph_world_set_params succeeded on a dead world");
      return;
    }
    sph_world_params after;
    sph_world_params_init(&after);
    FUZZ_CALL(sph_world_get_params(w, &after));
    if (r != SPH_OK && std::memcmp(&before, &after, sizeof before) != 0)
      violation("a failed sph_world_set_params changed the params");
    if (after.max_substeps > kMaxSubsteps) violation("max_substeps grew beyond what was set");
  }

  void op_queries() {
    int slot;
    sph_world* w = world_arg(&slot);
    switch (in_.u8() % 5) {
      case 0: {
        Padded<sph_world_def> d;
        sph_world_def_init(&d.value);
        d.value.struct_size = struct_size(sizeof(sph_world_def));
        FUZZ_CALL(sph_world_get_def(w, in_.chance(16) ? nullptr : &d.value));
        break;
      }
      case 1: {
        float m = 0.0f;
        if (FUZZ_CALL(sph_world_get_particle_mass(w, in_.chance(16) ? nullptr : &m)) == SPH_OK &&
            !(std::isfinite(m) && m > 0.0f))
          violation("particle mass %g", static_cast<double>(m));
        break;
      }
      case 2: {
        Padded<sph_stats> s;
        sph_stats_init(&s.value);
        s.value.struct_size = struct_size(sizeof(sph_stats));
        const uint32_t size = s.value.struct_size;
        s.paint_past(size);
        const sph_result r = FUZZ_CALL(sph_world_get_stats(w, in_.chance(16) ? nullptr : &s.value));
        if (!s.paint_intact()) violation("sph_world_get_stats wrote past struct_size %u (r=%d)", size, r);
        break;
      }
      case 3: {
        Padded<sph_world_params> p;
        sph_world_params_init(&p.value);
        p.value.struct_size = struct_size(sizeof(sph_world_params));
        FUZZ_CALL(sph_world_get_params(w, in_.chance(16) ? nullptr : &p.value));
        break;
      }
      default: {
        uint32_t n;
        FUZZ_CALL(sph_world_get_particle_count(w, in_.chance(16) ? nullptr : &n));
      }
    }
  }

  void op_spawn() {
    int slot;
    sph_world* w = world_arg(&slot);
    const uint32_t count = in_.chance(16) ? in_.u32() : in_.range(0, 300);
    // Caller arrays sized by what the library may read: count particles at the stride.
    const uint64_t pstride =
        in_.chance(200) ? 0 : (in_.chance(128) ? in_.u8() % 32 : 12 + 4 * (in_.u8() % 4));
    const uint64_t vstride =
        in_.chance(200) ? 0 : (in_.chance(128) ? in_.u8() % 32 : 12 + 4 * (in_.u8() % 4));
    const bool with_velocity = in_.chance(128);
    const uint32_t stored = std::min<uint32_t>(count, 300);
    const uint64_t pstep = pstride == 0 ? 12 : std::max<uint64_t>(pstride, 12);
    const uint64_t vstep = vstride == 0 ? 12 : std::max<uint64_t>(vstride, 12);
    std::vector<float> pos(static_cast<size_t>(pstep / 4 * (stored + 1))),
        vel(static_cast<size_t>(vstep / 4 * (stored + 1)));
    const float s = slot >= 0 && w ? worlds_[slot].spacing : 0.02f;
    const float origin = in_.unit(-1.0f, 1.0f);
    for (uint32_t i = 0; i < stored; ++i) {
      float* p = &pos[static_cast<size_t>(pstep / 4 * i)];
      if (in_.chance(240)) {
        // A loose cloud: about one particle per spacing^3, so neighbour counts stay sane.
        p[0] = origin + s * static_cast<float>(i % 8) + in_.unit(0.0f, s);
        p[1] = s * static_cast<float>((i / 8) % 8) + in_.unit(0.0f, s);
        p[2] = s * static_cast<float>(i / 64) + in_.unit(0.0f, s);
      } else {
        p[0] = in_.hostile(), p[1] = in_.hostile(), p[2] = in_.hostile();
      }
      float* v = &vel[static_cast<size_t>(vstep / 4 * i)];
      for (int k = 0; k < 3; ++k) v[k] = in_.maybe_hostile(-2.0f, 2.0f);
    }
    Padded<sph_spawn_desc> buf;
    sph_spawn_desc& d = buf.value;
    sph_spawn_desc_init(&d);
    d.count = count;
    d.positions = in_.chance(8) ? nullptr : pos.data();
    d.velocities = with_velocity ? vel.data() : nullptr;
    d.position_stride = pstride;
    d.velocity_stride = vstride;
    d.struct_size = struct_size(sizeof d);
    if (count > stored) {
      // More particles than the arrays hold: only legal to pass when the library must refuse
      // the count for the world's capacity before reading (capacity <= 1024 < 1025 < count).
      if (count <= kMaxCapacity || (slot >= 0 && w && count <= worlds_[slot].capacity)) return;
    }
    const uint32_t before = (slot >= 0 && w) ? count_of(w) : 0;
    uint32_t first = 0xFFFFFFFFu;
    const sph_result r = FUZZ_CALL(sph_world_spawn(w, in_.chance(8) ? nullptr : &d, &first));
    if (slot < 0 || !w) {
      if (r == SPH_OK) violation("sph_world_spawn succeeded on a dead world");
      return;
    }
    const uint32_t after = count_of(w);
    if (r != SPH_OK && after != before) violation("a failed spawn changed the count %u -> %u", before, after);
    if (r == SPH_OK && after != before + count)
      violation("spawn of %u: count %u -> %u", count, before, after);
  }

  void op_fill_box() {
    int slot;
    sph_world* w = world_arg(&slot);
    Padded<sph_fill_box_desc> buf;
    sph_fill_box_desc& d = buf.value;
    sph_fill_box_desc_init(&d);
    d.min = vec3(-0.3f, 0.3f);
    const sph_vec3 size = vec3(-0.05f, 0.3f);
    d.max = sph_vec3{d.min.x + size.x, d.min.y + size.y, d.min.z + size.z};
    if (in_.chance(32)) d.max = vec3(-1e6f, 1e6f);
    d.velocity = vec3(-1.0f, 1.0f);
    if (in_.chance(8)) d.reserved0 = in_.u32();
    d.struct_size = struct_size(sizeof d);
    fill_common(slot, w, [&](uint32_t* n) { return sph_world_fill_box(w, in_.chance(8) ? nullptr : &d, n); });
  }

  void op_fill_sphere() {
    int slot;
    sph_world* w = world_arg(&slot);
    Padded<sph_fill_sphere_desc> buf;
    sph_fill_sphere_desc& d = buf.value;
    sph_fill_sphere_desc_init(&d);
    d.center = vec3(-0.5f, 0.5f);
    d.radius = in_.chance(32) ? in_.hostile() : in_.unit(0.0f, 0.2f);
    d.velocity = vec3(-1.0f, 1.0f);
    if (in_.chance(8)) d.reserved0 = in_.u32();
    d.struct_size = struct_size(sizeof d);
    fill_common(slot, w,
                [&](uint32_t* n) { return sph_world_fill_sphere(w, in_.chance(8) ? nullptr : &d, n); });
  }

  template <class Fill>
  void fill_common(int slot, sph_world* w, Fill fill) {
    const uint32_t before = (slot >= 0 && w) ? count_of(w) : 0;
    uint32_t added = 0xFFFFFFFFu;
    const sph_result r = FUZZ_CALL(fill(&added));
    if (slot < 0 || !w) {
      if (r == SPH_OK) violation("a fill succeeded on a dead world");
      return;
    }
    const uint32_t after = count_of(w);
    if (r != SPH_OK && after != before) violation("a failed fill changed the count %u -> %u", before, after);
    if (r == SPH_OK && after != before + added)
      violation("fill added %u: count %u -> %u", added, before, after);
  }

  void op_step() {
    int slot;
    sph_world* w = world_arg(&slot);
    const float dt = in_.chance(24) ? in_.hostile() : in_.unit(0.0f, 0.01f);
    if (slot < 0 || !w) {
      if (FUZZ_CALL(sph_world_step(w, dt)) == SPH_OK) violation("sph_world_step succeeded on a dead world");
      return;
    }
    const Particles before = snapshot(w);
    const std::vector<uint8_t> saved = checkpoint(w);
    const sph_result r = FUZZ_CALL(sph_world_step(w, dt));
    check_step(slot, r, before, saved);
  }

  // What a step (or an asynchronous one's wait) answered, against the world before it: a step
  // that ran leaves finite particles and its statistics; a failed one changed nothing.
  void check_step(int slot, sph_result r, const Particles& before, const std::vector<uint8_t>& saved) {
    sph_world* w = worlds_[slot].ptr;
    const Particles after = snapshot(w);
    if (r == SPH_OK || r == SPH_INCOMPLETE) {
      worlds_[slot].cancel_maybe_pending = false;  // a pending cancel stops the step that meets it
      check_particles(worlds_[slot], after);
      sph_stats s;
      sph_stats_init(&s);
      FUZZ_CALL(sph_world_get_stats(w, &s));
      if (s.substeps > kMaxSubsteps) violation("%u substeps with max_substeps %u", s.substeps, kMaxSubsteps);
      if (s.particle_count != after.id.size())
        violation("stats count %u != %zu", s.particle_count, after.id.size());
    } else if (!(before == after)) {
      violation("sph_world_step failed with %d and changed the particles", r);
    } else if (checkpoint(w) != saved) {
      // Every carried field (max speed, max acceleration, events, sources' budgets) too.
      violation("sph_world_step failed with %d and changed the world's checkpoint", r);
    }
  }

  void op_copy_attribute() {
    int slot;
    sph_world* w = world_arg(&slot);
    uint32_t attribute = enum_value(6);
    const uint64_t dst_size = in_.chance(16) ? in_.u64() % (1u << 16) : in_.u32() % 8192;
    const uint64_t stride = in_.chance(128) ? 0 : (in_.chance(224) ? in_.u8() % 40 : in_.u64());
    const uint32_t first = in_.chance(200) ? in_.u8() % 16 : in_.u32();
    const uint32_t count = in_.chance(200) ? in_.range(0, 2048) : in_.u32();
    // The library may write anywhere in [dst, dst + dst_size); canaries past it catch overruns.
    std::vector<unsigned char> buf(static_cast<size_t>(dst_size) + 64, 0xCD);
    uint32_t written = 0xFFFFFFFFu;
    sph_attribute a;
    std::memcpy(&a, &attribute, 4);
    const sph_result r = FUZZ_CALL(sph_world_copy_attribute(w, a, in_.chance(8) ? nullptr : buf.data(),
                                                            dst_size, stride, first, count, &written));
    for (size_t i = static_cast<size_t>(dst_size); i < buf.size(); ++i)
      if (buf[i] != 0xCD) violation("sph_world_copy_attribute wrote past dst_size");
    if (r != SPH_OK) {
      for (unsigned char b : buf)
        if (b != 0xCD) violation("a failed sph_world_copy_attribute wrote to dst");
      return;
    }
    if (slot < 0 || !w) violation("sph_world_copy_attribute succeeded on a dead world");
    const uint32_t n = count_of(w);
    if (written != std::min(count, n - first))
      violation("copy wrote %u of %u from %u", written, count, first);
  }

  // ---- SDF assets ------------------------------------------------------------------------------
  int free_sdf_slot() {
    const int slot = in_.u8() % kSdfs;
    return sdfs_[slot].ptr ? -1 : slot;
  }
  // A grid desc with dims in [1, 32] per axis (data sized to match) or absurd dims with a
  // small buffer, which the library must refuse before it reads: kept in `storage`.
  void fill_grid(sph_grid_desc& g, uint32_t components, std::vector<float>& storage, bool* absurd) {
    sph_grid_desc_init(&g);
    *absurd = false;
    for (int a = 0; a < 3; ++a) g.dims[a] = in_.range(1, 12);
    if (in_.chance(16)) {
      for (int a = 0; a < 3; ++a) g.dims[a] = in_.chance(128) ? in_.u32() : in_.range(0, 64);
    }
    const double voxels = static_cast<double>(g.dims[0]) * g.dims[1] * g.dims[2];
    if (voxels > kMaxVoxels) *absurd = true;
    const float voxel = in_.chance(224) ? in_.unit(0.005f, 0.1f) : in_.hostile();
    for (int r = 0; r < 3; ++r) {
      g.index_to_local[r * 4 + r] = voxel;
      g.index_to_local[r * 4 + 3] = -0.5f * voxel * static_cast<float>(g.dims[r]);
    }
    if (in_.chance(16)) g.index_to_local[in_.u8() % 12] = in_.hostile();
    g.components = in_.chance(240) ? components : in_.u32() % 5;
    if (in_.chance(8)) {
      const uint32_t memory = enum_value(3, 128);
      std::memcpy(&g.memory, &memory, 4);
    }
    // components 0 means the channel's own count (sph_grid_desc): size the data for that.
    const uint32_t per_voxel = g.components == 0 ? components : g.components;
    const size_t floats = *absurd ? 16 : static_cast<size_t>(voxels) * per_voxel;
    storage.assign(floats, 0.0f);
    // A sphere-ish distance with an occasional hostile value.
    for (size_t i = 0; i < storage.size(); ++i) storage[i] = static_cast<float>(i % 7) * 0.01f - 0.02f;
    if (in_.chance(32) && !storage.empty()) storage[in_.u16() % storage.size()] = in_.hostile();
    g.data = in_.chance(8) ? nullptr : storage.data();
    if (in_.chance(8)) g.struct_size = struct_size(sizeof g);
  }
  // SdfSlot's box of a grid: each corner mapped by index_to_local in float (an all-zero map is the
  // identity, 1 m voxels: sph_grid_desc), so that a large translation swallows a small extent here
  // as it does in the library. The corners' order does not change a min or a max.
  static void grid_box(const sph_grid_desc& g, SdfSlot& slot) {
    static const float kIdentity[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    const bool zero = std::all_of(g.index_to_local, g.index_to_local + 12, [](float v) { return v == 0.0f; });
    const float* m = zero ? kIdentity : g.index_to_local;
    for (int c = 0; c < 8; ++c) {
      const float idx[3] = {(c & 1) ? static_cast<float>(g.dims[0] - 1) : 0.0f,
                            (c & 2) ? static_cast<float>(g.dims[1] - 1) : 0.0f,
                            (c & 4) ? static_cast<float>(g.dims[2] - 1) : 0.0f};
      for (int r = 0; r < 3; ++r) {
        const float p = m[4 * r] * idx[0] + m[4 * r + 1] * idx[1] + m[4 * r + 2] * idx[2] + m[4 * r + 3];
        slot.lo[r] = c == 0 ? p : std::min(slot.lo[r], p);
        slot.hi[r] = c == 0 ? p : std::max(slot.hi[r], p);
      }
    }
  }
  // A library-made grid (shapes, meshes): axis-aligned voxels of `voxel` metres whose origin the
  // harness does not know; their translations are small (the shapes' and the meshes' bounds), so
  // the box is taken from 0.
  static void voxel_box(const uint32_t dims[3], double voxel, SdfSlot& slot) {
    for (int k = 0; k < 3; ++k) {
      slot.lo[k] = 0.0f;
      slot.hi[k] = static_cast<float>((static_cast<double>(dims[k]) - 1.0) * voxel);
    }
  }
  // The FCC candidates the library counts for a source of spacing s in that box (lattice_inside
  // widens it by s / 2 in float, box_lattice takes s / 2 off again in double; floor(L / b) + 1
  // steps of b = s / sqrt 2 per axis, half of them).
  static double lattice_candidates(const SdfSlot& slot, float s) {
    const float widen = 0.5f * s;
    const double margin = 0.5 * s, b = s / std::sqrt(2.0);
    double points = 0.5;
    for (int k = 0; k < 3; ++k) {
      const double lo = static_cast<double>(slot.lo[k] - widen) + margin;
      const double hi = static_cast<double>(slot.hi[k] + widen) - margin;
      points *= hi < lo ? 0.0 : std::floor((hi - lo) / b) + 1.0;
    }
    return points;
  }

  void op_sdf_create() {
    const int slot = free_sdf_slot();
    int cslot;
    sph_context* c = context_arg(&cslot);
    Padded<sph_sdf_desc> buf;
    sph_sdf_desc& d = buf.value;
    sph_sdf_desc_init(&d);
    std::vector<float> dist, vel, fric;
    bool absurd = false, absurd_v = false, absurd_f = false;
    fill_grid(d.distance, 1, dist, &absurd);
    // Padded: their struct_size may be fuzzed up to 255 bytes, which the library may read.
    Padded<sph_grid_desc> vbuf, fbuf;
    sph_grid_desc& vg = vbuf.value;
    sph_grid_desc& fg = fbuf.value;
    const bool with_velocity = in_.chance(64), with_friction = in_.chance(64);
    if (with_velocity) {
      fill_grid(vg, 3, vel, &absurd_v);
      if (in_.chance(200))
        std::memcpy(vg.dims, d.distance.dims, sizeof vg.dims), vel.resize(dist.size() * 3 + 48);
      if (vg.data) vg.data = vel.data();
      d.velocity = &vg;
    }
    if (with_friction) {
      fill_grid(fg, 1, fric, &absurd_f);
      if (in_.chance(200))
        std::memcpy(fg.dims, d.distance.dims, sizeof fg.dims), fric.resize(dist.size() + 16);
      if (fg.data) fg.data = fric.data();
      d.friction = &fg;
    }
    if (in_.chance(8)) d.reserved0 = in_.u32();
    d.struct_size = struct_size(sizeof d);
    // Absurd grids are only passed where the library must refuse them (over 2^31 voxels);
    // anything in between is a legitimate allocation the harness does not make.
    const double voxels = static_cast<double>(d.distance.dims[0]) * d.distance.dims[1] * d.distance.dims[2];
    if (absurd && voxels <= kLibraryVoxelLimit) return;
    if (absurd_v || absurd_f) return;
    sph_sdf* out = nullptr;
    const sph_result r = FUZZ_CALL(sph_sdf_create(c, in_.chance(8) ? nullptr : &d, &out));
    if (r != SPH_OK) {
      if (out) violation("sph_sdf_create wrote *out on failure");
      return;
    }
    if (cslot < 0) violation("sph_sdf_create succeeded on a dead context");
    if (absurd) violation("sph_sdf_create accepted %g voxels", voxels);
    if (slot < 0) {
      FUZZ_CALL(sph_sdf_destroy(out));
      return;
    }
    sdfs_[slot] = SdfSlot{out, cslot, {}, {}, with_velocity};
    grid_box(d.distance, sdfs_[slot]);
  }

  void op_sdf_create_shape() {
    const int slot = free_sdf_slot();
    int cslot;
    sph_context* c = context_arg(&cslot);
    Padded<sph_shape_desc> buf;
    sph_shape_desc& d = buf.value;
    sph_shape_desc_init(&d);
    uint32_t shape = enum_value(6);
    std::memcpy(&d.shape, &shape, 4);
    d.half_extents = vec3(0.0f, 0.3f);
    d.radius = in_.maybe_hostile(0.0f, 0.3f);
    d.half_height = in_.maybe_hostile(0.0f, 0.3f);
    d.wall_thickness = in_.chance(128) ? 0.0f : in_.maybe_hostile(0.0f, 0.05f);
    d.voxel_size = in_.maybe_hostile(0.02f, 0.1f);
    d.flags = in_.chance(224) ? in_.u8() % 2 : in_.u32();
    d.padding_voxels = in_.chance(224) ? in_.u8() % 6 : in_.u32();
    d.struct_size = struct_size(sizeof d);
    // The grid build_shape_sdf would make (src/core/sdf_shapes.cpp): skip sizes that are legal
    // but too slow to build here; pass those the library must refuse.
    const double voxels = sph_fuzz::shape_grid_voxels(d);
    if (std::isfinite(voxels) && voxels > kMaxVoxels && voxels <= 4.0 * kLibraryVoxelLimit) return;
    sph_sdf* out = nullptr;
    const sph_result r = FUZZ_CALL(sph_sdf_create_shape(c, in_.chance(8) ? nullptr : &d, &out));
    if (r != SPH_OK) {
      if (out) violation("sph_sdf_create_shape wrote *out on failure");
      return;
    }
    if (cslot < 0) violation("sph_sdf_create_shape succeeded on a dead context");
    uint32_t dims[3];
    FUZZ_CALL(sph_sdf_get_dims(out, dims));
    const double got = static_cast<double>(dims[0]) * dims[1] * dims[2];
    if (got > kMaxVoxels) violation("shape grid of %g voxels, estimated %g", got, voxels);
    if (slot < 0) {
      FUZZ_CALL(sph_sdf_destroy(out));
      return;
    }
    sdfs_[slot] = SdfSlot{out, cslot, {}, {}, false};
    voxel_box(dims, sph_fuzz::shape_size_or_default(d.voxel_size, 0.01), sdfs_[slot]);
  }

  // A small random triangle mesh (sometimes with an index out of range, a non-finite vertex, an
  // odd stride or hostile sizes); the arrays always hold what the description claims, since the
  // library cannot check a caller's lie about their length. Grids past the harness's voxel cap
  // and wide bands are skipped when the library would accept them (too slow to build here).
  void op_sdf_create_from_mesh() {
    const int slot = free_sdf_slot();
    int cslot;
    sph_context* c = context_arg(&cslot);
    Padded<sph_mesh_desc> buf;
    sph_mesh_desc& d = buf.value;
    sph_mesh_desc_init(&d);
    d.vertex_count = in_.u8() % 12u;
    d.vertex_stride = in_.chance(192) ? 12u + 4u * (in_.u8() % 2u) : in_.u8() % 40u;
    const uint32_t stride_bytes = d.vertex_stride == 0u ? 12u : d.vertex_stride;
    std::vector<float> vertices((d.vertex_count * std::max(stride_bytes, 12u) + 3u) / 4u + 3u);
    for (float& x : vertices) x = in_.chance(4) ? in_.hostile() : in_.unit(-0.3f, 0.3f);
    const uint32_t triangles = in_.u8() % 9u;
    std::vector<uint32_t> indices(triangles * 3u + 2u);
    for (uint32_t& i : indices) i = in_.chance(4) ? in_.u32() : in_.u8() % std::max(d.vertex_count, 1u);
    d.index_count = triangles * 3u + (in_.chance(16) ? 1u + in_.u8() % 2u : 0u);
    d.vertices = in_.chance(8) ? nullptr : vertices.data();
    d.indices = in_.chance(8) ? nullptr : indices.data();
    d.voxel_size = in_.chance(16) ? in_.hostile() : in_.unit(0.04f, 0.1f);
    d.band_width = in_.chance(16) ? in_.hostile() : in_.unit(0.0f, 4.0f);
    d.padding_voxels = in_.chance(224) ? in_.u8() % 6u : in_.u32();
    d.reserved0 = in_.chance(248) ? 0u : in_.u32();
    d.struct_size = struct_size(sizeof d);
    // The grid: the vertices' bounds over the voxel size plus the padding on both sides, per axis.
    float lo[3] = {0.0f, 0.0f, 0.0f}, hi[3] = {0.0f, 0.0f, 0.0f};
    bool finite = true;
    // Over the vertices the triangles use (the library bounds those; an index out of range is
    // refused anyway).
    bool first = true;
    for (uint32_t t = 0; t < d.index_count && t < indices.size(); ++t) {
      const uint32_t v = indices[t];
      if (v >= d.vertex_count) continue;
      for (int k = 0; k < 3; ++k) {
        float x;
        std::memcpy(&x, reinterpret_cast<const unsigned char*>(vertices.data()) + v * stride_bytes + 4u * k,
                    4);
        finite = finite && std::isfinite(x);
        lo[k] = first ? x : std::min(lo[k], x);
        hi[k] = first ? x : std::max(hi[k], x);
      }
      first = false;
    }
    const double voxel = d.voxel_size == 0.0f ? 0.01 : static_cast<double>(d.voxel_size);
    const double padding = d.padding_voxels == 0u ? 4.0 : static_cast<double>(d.padding_voxels);
    double voxels = 1.0;
    for (int k = 0; k < 3; ++k) voxels *= (static_cast<double>(hi[k]) - lo[k]) / voxel + 2.0 * padding + 2.0;
    const double band = d.band_width == 0.0f ? 3.0 : static_cast<double>(d.band_width);
    // Skip (as op_sdf_create_shape does) what the library may accept but is too slow here; pass
    // grids far past its 2^31-voxel limit, which it must refuse.
    const bool accepted_sizes = finite && d.padding_voxels <= 1024u && band >= 1.0 && band <= 64.0 &&
                                voxel > 0.0 && std::isfinite(voxel);
    if (accepted_sizes && ((voxels > kMaxVoxels && voxels <= 4.0 * kLibraryVoxelLimit) || band > 8.0)) return;
    sph_sdf* out = nullptr;
    const sph_result r = FUZZ_CALL(sph_sdf_create_from_mesh(c, in_.chance(8) ? nullptr : &d, &out));
    if (r != SPH_OK) {
      if (out) violation("sph_sdf_create_from_mesh wrote *out on failure");
      return;
    }
    if (cslot < 0) violation("sph_sdf_create_from_mesh succeeded on a dead context");
    uint32_t dims[3];
    FUZZ_CALL(sph_sdf_get_dims(out, dims));
    const double got = static_cast<double>(dims[0]) * dims[1] * dims[2];
    if (got > kMaxVoxels) violation("mesh grid of %g voxels, estimated %g", got, voxels);
    if (slot < 0) {
      FUZZ_CALL(sph_sdf_destroy(out));
      return;
    }
    sdfs_[slot] = SdfSlot{out, cslot, {}, {}, false};
    voxel_box(dims, voxel, sdfs_[slot]);
  }

  // The step budget (refused: NaN, negative, above a day; the old one kept) and a cancel request
  // before a step (that step stops before its first substep and changes no particle).
  void op_step_budget() {
    int slot;
    sph_world* w = world_arg(&slot);
    const bool live = slot >= 0 && w;
    double old_budget = 0.0;
    if (live) FUZZ_CALL(sph_world_get_step_budget(w, &old_budget));
    const double budget = in_.chance(64) ? static_cast<double>(in_.hostile()) : in_.unit(0.0f, 0.05f);
    const sph_result r = FUZZ_CALL(sph_world_set_step_budget(w, budget));
    if (!live) {
      if (r == SPH_OK) violation("sph_world_set_step_budget succeeded on a dead world");
      if (FUZZ_CALL(sph_world_prepare(w)) == SPH_OK) violation("sph_world_prepare succeeded on a dead world");
      if (FUZZ_CALL(sph_world_cancel_step(w)) == SPH_OK)
        violation("sph_world_cancel_step succeeded on a dead world");
      return;
    }
    const bool valid = std::isfinite(budget) && budget >= 0.0 && budget <= 86400.0;
    if ((r == SPH_OK) != valid) violation("sph_world_set_step_budget(%g) answered %d", budget, r);
    double got = -1.0;
    FUZZ_CALL(sph_world_get_step_budget(w, &got));
    if (got != (valid ? budget : old_budget))
      violation("step budget %g after setting %g (was %g)", got, budget, old_budget);
    // sph_world_prepare builds maps and copies ahead of a step: whether it succeeds or not (an
    // allocation), nothing a checkpoint holds may change.
    if (in_.chance(16)) {
      const std::vector<uint8_t> saved = checkpoint(w);
      FUZZ_CALL(sph_world_prepare(w));
      if (checkpoint(w) != saved) violation("sph_world_prepare changed the world's checkpoint");
    }
    if (!in_.chance(128)) return;
    if (FUZZ_CALL(sph_world_cancel_step(w)) != SPH_OK)
      violation("sph_world_cancel_step failed on a live world");
    const Particles before = snapshot(w);
    const sph_result s = FUZZ_CALL(sph_world_step(w, in_.unit(1e-4f, 0.01f)));
    if (s != SPH_INCOMPLETE) violation("a step after a cancel request answered %d, not SPH_INCOMPLETE", s);
    if (!(snapshot(w) == before)) violation("a cancelled step changed the particles");
  }

  void op_sdf_update() {
    int slot;
    sph_sdf* s = sdf_arg(&slot);
    uint32_t dims[3] = {1, 1, 1};
    if (slot >= 0 && s) FUZZ_CALL(sph_sdf_get_dims(s, dims));
    uint32_t channel = enum_value(3);
    uint32_t origin[3], size[3];
    bool inside = true;
    for (int a = 0; a < 3; ++a) {
      origin[a] = in_.chance(224) ? in_.range(0, dims[a] - 1) : in_.u32();
      size[a] = in_.chance(224) ? in_.range(0, dims[a] - std::min(origin[a], dims[a])) : in_.u32();
      inside &= static_cast<uint64_t>(origin[a]) + size[a] <= dims[a];
    }
    const size_t components = channel == SPH_SDF_CHANNEL_VELOCITY ? 3 : 1;
    const size_t floats = inside ? components * size[0] * size[1] * size[2] : 16;
    std::vector<float> data(floats + 1, -0.01f);
    if (in_.chance(32)) data[in_.u16() % data.size()] = in_.hostile();
    uint32_t memory = in_.chance(240) ? 0 : enum_value(3, 128);
    sph_memory_kind m;
    std::memcpy(&m, &memory, 4);
    sph_sdf_channel ch;
    std::memcpy(&ch, &channel, 4);
    const uint32_t* origin_arg = in_.chance(8) ? nullptr : origin;
    const uint32_t* size_arg = in_.chance(8) ? nullptr : size;
    const float* data_arg = in_.chance(8) ? nullptr : data.data();
    const sph_result r = FUZZ_CALL(sph_sdf_update(s, ch, origin_arg, size_arg, data_arg, m));
    if (r == SPH_OK && !inside) violation("sph_sdf_update accepted a box outside the grid");
    if (r == SPH_OK && slot >= 0 && channel == SPH_SDF_CHANNEL_VELOCITY) sdfs_[slot].has_velocity = true;
  }

  void op_sdf_queries() {
    int slot;
    sph_sdf* s = sdf_arg(&slot);
    if (in_.chance(128)) {
      uint32_t dims[3];
      const sph_result r = FUZZ_CALL(sph_sdf_get_dims(s, in_.chance(16) ? nullptr : dims));
      if (r == SPH_OK && (dims[0] == 0 || dims[1] == 0 || dims[2] == 0)) violation("an SDF with a zero dim");
    } else {
      float d = 0.0f;
      const sph_vec3 point = vec3(-0.5f, 0.5f);
      FUZZ_CALL(sph_sdf_sample(s, point, in_.chance(16) ? nullptr : &d));
    }
  }

  void op_sdf_destroy() {
    int slot;
    sph_sdf* s = sdf_arg(&slot);
    const sph_result r = FUZZ_CALL(sph_sdf_destroy(s));
    if (slot >= 0 && s) {
      if (r != SPH_OK) violation("sph_sdf_destroy of a live asset failed");
      remember_stale(s);
      sdfs_[slot] = SdfSlot{};
    } else if (!s && r != SPH_OK) {
      violation("sph_sdf_destroy(NULL) is not a no-op");
    } else if (s && r == SPH_OK) {
      violation("sph_sdf_destroy accepted a dead handle");
    }
  }

  // ---- scene objects ---------------------------------------------------------------------------
  void store_id(IdSlot* ids, int at, uint64_t bits, int world) {
    ids[at % kIds] = IdSlot{bits, world};
    int32_t& tag = worlds_[world].id_tag;
    const int32_t issued = static_cast<int32_t>((bits >> 16) & 0xffffu);
    if (tag >= 0 && tag != issued) violation("a world issued ids with world tags %d and %d", tag, issued);
    tag = issued;
  }
  // An object id with another world tag than the world's (random bits, or another world's id,
  // unless that world shares the tag: one loaded from this world's checkpoint, or a world of
  // another context made in the same order) names nothing in it: no call on it succeeds (the null
  // id is the no-op the destroy calls accept).
  void expect_foreign_id_refused(int slot, sph_world* w, uint64_t bits, sph_result r, const char* call) {
    if (r != SPH_OK || bits == 0 || !world_ok(slot, w) || worlds_[slot].id_tag < 0) return;
    const int32_t tag = static_cast<int32_t>((bits >> 16) & 0xffffu);
    if (tag != worlds_[slot].id_tag)
      violation("%s accepted id %#llx, whose world tag %d is not the world's %d", call,
                static_cast<unsigned long long>(bits), tag, worlds_[slot].id_tag);
  }
  bool world_ok(int slot, sph_world* w) const { return slot >= 0 && w; }

  void op_collider_create() {
    int slot, sslot;
    sph_world* w = world_arg(&slot);
    Padded<sph_collider_def> buf;
    sph_collider_def& d = buf.value;
    sph_collider_def_init(&d);
    d.sdf = sdf_arg(&sslot);
    d.flags = in_.chance(224) ? in_.u8() % 2 : in_.u32();
    d.transform = transform();
    d.restitution = in_.maybe_hostile(0.0f, 1.0f);
    d.friction = in_.maybe_hostile(0.0f, 1.0f);
    d.stickiness = in_.maybe_hostile(0.0f, 5.0f);
    if (in_.chance(8)) d.reserved0 = in_.u32();
    if (in_.chance(8)) d.reserved1 = in_.u32();
    d.struct_size = struct_size(sizeof d);
    sph_collider_id id{0};
    const sph_collider_def* def_arg = in_.chance(8) ? nullptr : &d;
    sph_collider_id* id_arg = in_.chance(8) ? nullptr : &id;
    const sph_result r = FUZZ_CALL(sph_collider_create(w, def_arg, id_arg));
    if (r == SPH_OK) {
      if (!world_ok(slot, w) || sslot < 0 || !d.sdf) violation("sph_collider_create accepted a dead handle");
      if (sdfs_[sslot].context != worlds_[slot].context) violation("a collider from another context's SDF");
      if (id.bits == 0) violation("a null collider id");
      store_id(colliders_, in_.u8(), id.bits, slot);
    }
  }

  void op_collider_ops() {
    int slot;
    sph_world* w = world_arg(&slot);
    const sph_collider_id id{id_arg(colliders_)};
    sph_transform t = transform();
    sph_result r;
    switch (in_.u8() % 6) {
      case 0:
        r = FUZZ_CALL(sph_collider_destroy(w, id));
        break;
      case 4: {
        // A load threshold (any world: FEATURE_DISABLED without the loads bit), then a step
        // reports it or not; negative and non-finite values must be refused.
        const float force = in_.maybe_hostile(0.0f, 100.0f);
        r = FUZZ_CALL(sph_collider_set_load_threshold(w, id, force));
        if (r == SPH_OK && !(force >= 0.0f && std::isfinite(force)))
          violation("sph_collider_set_load_threshold accepted a negative or non-finite threshold");
        break;
      }
      case 1:
        r = FUZZ_CALL(sph_collider_set_target_transform(w, id, in_.chance(8) ? nullptr : &t));
        break;
      case 2:
        r = FUZZ_CALL(sph_collider_teleport(w, id, in_.chance(8) ? nullptr : &t));
        break;
      case 3: {
        sph_transform out;
        r = FUZZ_CALL(sph_collider_get_transform(w, id, in_.chance(8) ? nullptr : &out));
        if (r == SPH_OK && !(std::isfinite(out.position.x) && std::isfinite(out.rotation.w)))
          violation("a collider with a non-finite pose");
        break;
      }
      default: {
        const float restitution = in_.maybe_hostile(0, 1);
        const float friction = in_.maybe_hostile(0, 1);
        const float stickiness = in_.maybe_hostile(0, 5);
        // Set whole (a fuzzed struct_size), then read back what is there.
        Padded<sph_collider_material> m;
        sph_collider_material_init(&m.value);
        m.value.restitution = restitution;
        m.value.friction = friction;
        m.value.stickiness = stickiness;
        m.value.struct_size = struct_size(sizeof m.value);
        r = FUZZ_CALL(sph_collider_set_material(w, id, in_.chance(8) ? nullptr : &m.value));
        sph_collider_material out;
        sph_collider_material_init(&out);
        const sph_result got = FUZZ_CALL(sph_collider_get_material(w, id, &out));
        if (got == SPH_OK && !(out.restitution >= 0.0f && out.restitution <= 1.0f && out.friction >= 0.0f &&
                               out.stickiness >= 0.0f))
          violation("a collider holds a material out of range");
        if (r == SPH_OK && got != SPH_OK) violation("a material was set but cannot be read");
      }
    }
    if (r == SPH_OK && !world_ok(slot, w)) violation("a collider call succeeded on a dead world");
    expect_foreign_id_refused(slot, w, id.bits, r, "a collider call");
  }

  void op_source_create() {
    int slot, sslot;
    sph_world* w = world_arg(&slot);
    Padded<sph_source_def> buf;
    sph_source_def& d = buf.value;
    sph_source_def_init(&d);
    uint32_t mode = enum_value(2);
    std::memcpy(&d.mode, &mode, 4);
    d.region = sdf_arg(&sslot);
    d.transform = transform();
    d.spacing = in_.chance(128) ? 0.0f : in_.maybe_hostile(0.0f, 0.1f);
    d.min_distance = in_.chance(128) ? 0.0f : in_.maybe_hostile(0.0f, 0.1f);
    d.velocity = vec3(-1.0f, 1.0f);
    d.flags = in_.chance(224) ? in_.u8() % 2 : in_.u32();
    d.rate = in_.chance(128) ? 0.0f : in_.maybe_hostile(0.0f, 1e5f);
    if (in_.chance(8)) d.user_attribute = in_.u32();  // FEATURE_DISABLED unless the world has the feature
    if (in_.chance(8)) d.reserved1 = in_.u32();
    d.struct_size = struct_size(sizeof d);
    // The library keeps the region's lattice (up to 2^28 candidates, legitimately); skip regions
    // whose lattice is large but legal, counted as the library counts it (lattice_candidates).
    // Only spacings it accepts are judged (0: the world's; below a quarter of the world's: refused),
    // so its refusals stay covered. (Until session 34 this was the grid's volume times sqrt 2 / s^3,
    // with the all-zero map read as volume 0 and a shape's default voxel as 0: an 8 x 4 x 6 grid of
    // 1 m voxels was estimated at no points, made 3.2 million, and checkpointing them took 35 s
    // under ASan, a fuzz timeout; the library did what its documentation says.)
    const float world_spacing = world_ok(slot, w) ? worlds_[slot].spacing : 0.0f;
    const float s = d.spacing == 0.0f ? world_spacing : d.spacing;
    if (world_ok(slot, w) && sslot >= 0 && d.region && std::isfinite(s) && s >= 0.25f * world_spacing &&
        s > 0.0f) {
      const double points = lattice_candidates(sdfs_[sslot], s);
      if (std::isfinite(points) && points > kMaxLattice && points < 4.0 * (1u << 28)) return;
    }
    sph_source_id id{0};
    const sph_source_def* def_arg = in_.chance(8) ? nullptr : &d;
    sph_source_id* id_arg = in_.chance(8) ? nullptr : &id;
    const sph_result r = FUZZ_CALL(sph_source_create(w, def_arg, id_arg));
    if (r == SPH_OK) {
      if (!world_ok(slot, w) || sslot < 0) violation("sph_source_create accepted a dead handle");
      if (id.bits == 0) violation("a null source id");
      store_id(sources_, in_.u8(), id.bits, slot);
    }
  }

  void op_source_ops() {
    int slot;
    sph_world* w = world_arg(&slot);
    const sph_source_id id{id_arg(sources_)};
    const sph_transform t = transform();
    const sph_result r = in_.chance(128)
                             ? FUZZ_CALL(sph_source_destroy(w, id))
                             : FUZZ_CALL(sph_source_set_transform(w, id, in_.chance(8) ? nullptr : &t));
    if (r == SPH_OK && !world_ok(slot, w)) violation("a source call succeeded on a dead world");
    expect_foreign_id_refused(slot, w, id.bits, r, "a source call");
  }

  void op_sink() {
    int slot, sslot;
    sph_world* w = world_arg(&slot);
    if (in_.chance(96)) {
      const sph_sink_id id{id_arg(sinks_)};
      const sph_result r = FUZZ_CALL(sph_sink_destroy(w, id));
      if (r == SPH_OK && !world_ok(slot, w)) violation("sph_sink_destroy succeeded on a dead world");
      expect_foreign_id_refused(slot, w, id.bits, r, "sph_sink_destroy");
      return;
    }
    Padded<sph_sink_def> buf;
    sph_sink_def& d = buf.value;
    sph_sink_def_init(&d);
    uint32_t mode = enum_value(2);
    std::memcpy(&d.mode, &mode, 4);
    d.region = sdf_arg(&sslot);
    d.transform = transform();
    d.bounds_min = vec3(-1.0f, 0.0f);
    d.bounds_max = vec3(-0.1f, 1.0f);
    if (in_.chance(8)) d.reserved0 = in_.u32();
    d.struct_size = struct_size(sizeof d);
    sph_sink_id id{0};
    const sph_sink_def* def_arg = in_.chance(8) ? nullptr : &d;
    sph_sink_id* id_arg = in_.chance(8) ? nullptr : &id;
    const sph_result r = FUZZ_CALL(sph_sink_create(w, def_arg, id_arg));
    if (r == SPH_OK) {
      if (!world_ok(slot, w)) violation("sph_sink_create accepted a dead world");
      if (id.bits == 0) violation("a null sink id");
      store_id(sinks_, in_.u8(), id.bits, slot);
    }
  }

  void op_force_field_create() {
    int slot, sslot;
    sph_world* w = world_arg(&slot);
    Padded<sph_force_field_def> buf;
    sph_force_field_def& d = buf.value;
    sph_force_field_def_init(&d);
    uint32_t kind = enum_value(4);
    std::memcpy(&d.kind, &kind, 4);
    d.region = in_.chance(128) ? nullptr : sdf_arg(&sslot);
    Padded<sph_grid_desc> gbuf;  // a fuzzed struct_size up to 255 stays inside
    sph_grid_desc& g = gbuf.value;
    std::vector<float> storage;
    bool absurd = false;
    if (in_.chance(128)) {
      fill_grid(g, 3, storage, &absurd);
      const double voxels = static_cast<double>(g.dims[0]) * g.dims[1] * g.dims[2];
      if (absurd && voxels <= kLibraryVoxelLimit) return;
      d.grid = &g;
    }
    d.transform = transform();
    d.vector = vec3(-10.0f, 10.0f);
    d.strength = in_.maybe_hostile(-10.0f, 10.0f);
    d.falloff_radius = in_.chance(128) ? 0.0f : in_.maybe_hostile(0.0f, 1.0f);
    if (in_.chance(8)) d.reserved0 = in_.u32();
    if (in_.chance(8)) d.reserved1 = in_.u32();
    d.struct_size = struct_size(sizeof d);
    sph_force_field_id id{0};
    const sph_force_field_def* def_arg = in_.chance(8) ? nullptr : &d;
    sph_force_field_id* id_arg = in_.chance(8) ? nullptr : &id;
    const sph_result r = FUZZ_CALL(sph_force_field_create(w, def_arg, id_arg));
    if (r == SPH_OK) {
      if (!world_ok(slot, w)) violation("sph_force_field_create accepted a dead world");
      // Only a grid field reads the grid; the other kinds ignore def->grid (documented).
      if (absurd && d.kind == SPH_FORCE_FIELD_GRID)
        violation("sph_force_field_create accepted an absurd grid");
      if (id.bits == 0) violation("a null force field id");
      store_id(fields_, in_.u8(), id.bits, slot);
    }
  }

  void op_force_field_ops() {
    int slot;
    sph_world* w = world_arg(&slot);
    const sph_force_field_id id{id_arg(fields_)};
    const sph_transform t = transform();
    const sph_result r = in_.chance(128)
                             ? FUZZ_CALL(sph_force_field_destroy(w, id))
                             : FUZZ_CALL(sph_force_field_set_transform(w, id, in_.chance(8) ? nullptr : &t));
    if (r == SPH_OK && !world_ok(slot, w)) violation("a force field call succeeded on a dead world");
    expect_foreign_id_refused(slot, w, id.bits, r, "a force field call");
  }

  void op_events() {
    int slot;
    sph_world* w = world_arg(&slot);
    const uint32_t capacity = in_.chance(224) ? in_.u8() % 8 : in_.u32();
    const bool null_buffer = in_.chance(24);
    const uint32_t held = std::min<uint32_t>(capacity, 64);
    if (!null_buffer && capacity > held) return;  // the buffer must hold what capacity says
    uint32_t n = 0xFFFFFFFFu;
    sph_result r;
    if (in_.chance(128)) {
      std::vector<sph_event> events(held + 1);
      r = FUZZ_CALL(sph_world_get_events(w, null_buffer ? nullptr : events.data(), capacity, &n));
    } else {
      std::vector<uint32_t> ids(held + 1);
      r = FUZZ_CALL(sph_world_get_removed_ids(w, null_buffer ? nullptr : ids.data(), capacity, &n));
    }
    if (r == SPH_INCOMPLETE && n <= capacity)
      violation("INCOMPLETE with %u items and capacity %u", n, capacity);
    if (r == SPH_OK && n > capacity) violation("OK with %u items and capacity %u", n, capacity);
  }

  void op_physics_params() {
    int slot;
    sph_world* w = world_arg(&slot);
    sph_result r = SPH_OK;
    const bool set = in_.chance(160);
    switch (in_.u8() % 3) {
      case 0: {
        Padded<sph_surface_tension_params> p;
        sph_surface_tension_params_init(&p.value);
        p.value.coefficient = in_.maybe_hostile(0.0f, 1.0f);
        p.value.normal_threshold = in_.maybe_hostile(0.0f, 100.0f);
        if (in_.chance(8)) p.value.reserved0 = in_.u32();
        p.value.struct_size = struct_size(sizeof p.value);
        r = set ? FUZZ_CALL(sph_world_set_surface_tension_params(w, &p.value))
                : FUZZ_CALL(sph_world_get_surface_tension_params(w, &p.value));
        if (r == SPH_OK && world_ok(slot, w) && !(worlds_[slot].features & SPH_FEATURE_SURFACE_TENSION))
          violation("surface tension params on a world without the feature");
        break;
      }
      case 1: {
        Padded<sph_clavet_viscosity_params> p;
        sph_clavet_viscosity_params_init(&p.value);
        p.value.linear = in_.maybe_hostile(0.0f, 20.0f);
        p.value.quadratic = in_.maybe_hostile(0.0f, 5.0f);
        if (in_.chance(8)) p.value.reserved0 = in_.u32();
        p.value.struct_size = struct_size(sizeof p.value);
        r = set ? FUZZ_CALL(sph_world_set_clavet_viscosity_params(w, &p.value))
                : FUZZ_CALL(sph_world_get_clavet_viscosity_params(w, &p.value));
        if (r == SPH_OK && world_ok(slot, w) && worlds_[slot].viscosity != SPH_VISCOSITY_CLAVET)
          violation("Clavet params on a Mueller world");
        break;
      }
      default: {
        Padded<sph_tait_params> p;
        sph_tait_params_init(&p.value);
        p.value.speed_of_sound = in_.maybe_hostile(0.0f, 50.0f);
        p.value.struct_size = struct_size(sizeof p.value);
        r = set ? FUZZ_CALL(sph_world_set_tait_params(w, &p.value))
                : FUZZ_CALL(sph_world_get_tait_params(w, &p.value));
        if (r == SPH_OK && world_ok(slot, w) && worlds_[slot].eos != SPH_EOS_TAIT)
          violation("Tait params on an ideal-gas world");
      }
    }
    if (r == SPH_OK && !world_ok(slot, w)) violation("physics params on a dead world");
  }

  // Every *_init_sized with a fuzzed size, into a heap buffer of exactly that many bytes
  // (ASan catches a write past it).
  void op_init_sized() {
    const uint32_t size = in_.chance(224) ? in_.u8() : in_.u32() % 4096;
    std::vector<unsigned char> storage(std::max<uint32_t>(size, 1));
    void* p = in_.chance(8) ? nullptr : static_cast<void*>(storage.data());
    sph_result r;
    switch (in_.u8() % 17) {
      case 0:
        r = FUZZ_CALL(sph_context_def_init_sized(static_cast<sph_context_def*>(p), size));
        break;
      case 1:
        r = FUZZ_CALL(sph_world_def_init_sized(static_cast<sph_world_def*>(p), size));
        break;
      case 2:
        r = FUZZ_CALL(sph_world_params_init_sized(static_cast<sph_world_params*>(p), size));
        break;
      case 3:
        r = FUZZ_CALL(
            sph_surface_tension_params_init_sized(static_cast<sph_surface_tension_params*>(p), size));
        break;
      case 4:
        r = FUZZ_CALL(
            sph_clavet_viscosity_params_init_sized(static_cast<sph_clavet_viscosity_params*>(p), size));
        break;
      case 5:
        r = FUZZ_CALL(sph_tait_params_init_sized(static_cast<sph_tait_params*>(p), size));
        break;
      case 6:
        r = FUZZ_CALL(sph_spawn_desc_init_sized(static_cast<sph_spawn_desc*>(p), size));
        break;
      case 7:
        r = FUZZ_CALL(sph_fill_box_desc_init_sized(static_cast<sph_fill_box_desc*>(p), size));
        break;
      case 8:
        r = FUZZ_CALL(sph_fill_sphere_desc_init_sized(static_cast<sph_fill_sphere_desc*>(p), size));
        break;
      case 9:
        r = FUZZ_CALL(sph_stats_init_sized(static_cast<sph_stats*>(p), size));
        break;
      case 10:
        r = FUZZ_CALL(sph_grid_desc_init_sized(static_cast<sph_grid_desc*>(p), size));
        break;
      case 11:
        r = FUZZ_CALL(sph_sdf_desc_init_sized(static_cast<sph_sdf_desc*>(p), size));
        break;
      case 12:
        r = FUZZ_CALL(sph_shape_desc_init_sized(static_cast<sph_shape_desc*>(p), size));
        break;
      case 13:
        r = FUZZ_CALL(sph_collider_def_init_sized(static_cast<sph_collider_def*>(p), size));
        break;
      case 14:
        r = FUZZ_CALL(sph_source_def_init_sized(static_cast<sph_source_def*>(p), size));
        break;
      case 15:
        r = FUZZ_CALL(sph_sink_def_init_sized(static_cast<sph_sink_def*>(p), size));
        break;
      default:
        r = FUZZ_CALL(sph_force_field_def_init_sized(static_cast<sph_force_field_def*>(p), size));
        break;
    }
    if (r == SPH_OK && !p) violation("an init accepted NULL");
  }

  void op_misc() {
    switch (in_.u8() % 4) {
      case 0: {
        const uint32_t code =
            in_.chance(128) ? static_cast<uint32_t>(static_cast<int32_t>(in_.u8() % 20) - 16) : in_.u32();
        sph_result r;
        std::memcpy(&r, &code, 4);
        const char* s = sph_result_string(r);
        if (!s || !s[0]) violation("sph_result_string(%d) is empty", static_cast<int>(code));
        break;
      }
      case 1: {
        uint32_t n;
        FUZZ_CALL(sph_get_live_object_count(in_.chance(16) ? nullptr : &n));
        break;
      }
      case 2: {
        int slot;
        sph_backend b;
        sph_context* c = context_arg(&slot);
        FUZZ_CALL(sph_context_get_backend(c, in_.chance(16) ? nullptr : &b));
        break;
      }
      default:
        if (sph_get_version() == 0 || !sph_get_build_info()) violation("version or build info missing");
    }
  }

  // ---- ops added after the first 29 (op bytes 232..253) -----------------------------------------
  void step_added_op(uint8_t op) {
    switch (op % 11) {
      case 0:
        return op_world_create_methods();
      case 1:
        return op_probe_create();
      case 2:
        return op_probe_ops();
      case 3:
        return op_collider_loads();
      case 4:
        return op_method_params();
      case 5:
        return op_params_by_kind();
      case 6:
        return op_params_info();
      case 7:
        return op_set_attribute();
      case 8:
        return op_remove_particles();
      case 9:
        return op_async_step();
      default:
        return op_checkpoint_file();
    }
  }

  bool live(int slot, const void* w) const { return slot >= 0 && w; }

  // The struct as the library reads it: the bytes struct_size covers, the rest zero
  // (docs/versioning.md; a struct_size past sizeof(T) is refused unless the tail is zero).
  template <class T>
  static T as_read(const T& value) {
    T out;
    std::memset(&out, 0, sizeof out);
    std::memcpy(&out, &value, std::min<size_t>(value.struct_size, sizeof(T)));
    return out;
  }

  static bool finite3(const sph_vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
  }

  // A world made with any method: every feature bit, the DFSPH solver (sph_world_def.solver),
  // mostly in combinations the solvers support, so that their calls and steps get exercised.
  void op_world_create_methods() {
    const int slot = pick_world();
    if (worlds_[slot].ptr) return;
    int cslot;
    sph_context* c = context_arg(&cslot);
    Padded<sph_world_def> def;
    FUZZ_CALL(sph_world_def_init(&def.value));
    sph_world_def& d = def.value;
    d.capacity = in_.range(1, kMaxCapacity);
    uint32_t features = in_.chance(240) ? in_.u8() & kKnownFeatures : in_.u32();
    const uint32_t solver = in_.chance(232) ? in_.u8() % 2 : in_.u32();
    uint32_t integrator = in_.chance(224) ? in_.u8() % 2 : in_.u32();
    const uint32_t viscosity = in_.chance(224) ? in_.u8() % 2 : in_.u32();
    uint32_t eos = in_.chance(224) ? in_.u8() % 2 : in_.u32();
    if (in_.chance(192)) {
      if (solver == SPH_SOLVER_DFSPH) {
        integrator = SPH_INTEGRATOR_SYMPLECTIC_EULER;
        eos = SPH_EOS_IDEAL_GAS;
        features &= ~(SPH_FEATURE_NORMALIZED_DENSITY | SPH_FEATURE_DENSITY_DIFFUSION);
      }
      if (features & SPH_FEATURE_DENSITY_DIFFUSION) features |= SPH_FEATURE_NORMALIZED_DENSITY;
    }
    d.features = features;
    std::memcpy(&d.solver, &solver, 4);
    std::memcpy(&d.integrator, &integrator, 4);
    std::memcpy(&d.viscosity_method, &viscosity, 4);
    std::memcpy(&d.equation_of_state, &eos, 4);
    if (in_.chance(32)) d.max_capacity = std::min(kMaxCapacity, d.capacity * (2u + in_.u8() % 4u));
    if (in_.chance(128)) {
      d.particle_spacing = in_.maybe_hostile(0.005f, 0.2f);
      d.kernel_radius = in_.chance(128) ? 0.0f : d.particle_spacing * in_.maybe_hostile(1.0f, 5.0f);
      d.rest_density = in_.maybe_hostile(1.0f, 3000.0f);
    }
    if (in_.chance(8)) d.header_version = in_.u32();
    d.struct_size = struct_size(sizeof(sph_world_def));
    const uint32_t max_seen = max_capacity_seen(d);
    sph_world* out = nullptr;
    const sph_result r = FUZZ_CALL(sph_world_create(c, in_.chance(8) ? nullptr : &d, &out));
    adopt_world(slot, cslot, r, out, d.capacity, max_seen);
  }

  // sph_probe_create: points and gauges with hostile positions, directions, lengths and spacings.
  void op_probe_create() {
    int slot;
    sph_world* w = world_arg(&slot);
    const bool is_live = live(slot, w);
    Padded<sph_probe_def> buf;
    sph_probe_def& d = buf.value;
    sph_probe_def_init(&d);
    const uint32_t kind = enum_value(2), sampling = enum_value(2);
    std::memcpy(&d.kind, &kind, 4);
    std::memcpy(&d.sampling, &sampling, 4);
    d.position = vec3(-0.5f, 0.5f);
    d.direction = in_.chance(96) ? sph_vec3{0.0f, 0.0f, 0.0f} : vec3(-1.0f, 1.0f);
    d.length = in_.maybe_hostile(0.0f, 0.5f);
    d.sample_spacing = in_.chance(128) ? 0.0f : in_.maybe_hostile(0.0f, 0.05f);
    if (in_.chance(8)) d.reserved0 = in_.u32();
    d.struct_size = struct_size(sizeof d);
    const sph_probe_def seen = as_read(d);
    const bool gauge = static_cast<uint32_t>(seen.kind) == SPH_PROBE_GAUGE;
    const float h = is_live ? worlds_[slot].kernel_radius : 0.036f;
    const double spacing = seen.sample_spacing > 0.0f ? seen.sample_spacing : h / 8.0f;
    const double steps = std::ceil(static_cast<double>(seen.length) / spacing);
    // A legal gauge samples every step along it each substep: skip the long ones (the library's
    // bound is 65536), pass those it must refuse.
    if (gauge && std::isfinite(steps) && steps > kMaxGaugeSteps && steps <= 65536.0) return;
    const std::vector<uint8_t> saved = is_live ? checkpoint(w) : std::vector<uint8_t>{};
    sph_probe_id id{0};
    const sph_result r =
        FUZZ_CALL(sph_probe_create(w, in_.chance(8) ? nullptr : &d, in_.chance(8) ? nullptr : &id));
    if (r != SPH_OK) {
      if (is_live && checkpoint(w) != saved)
        violation("a refused sph_probe_create changed the world (%d)", r);
      return;
    }
    if (!is_live) violation("sph_probe_create succeeded on a dead world");
    if (id.bits == 0) violation("a null probe id");
    const uint32_t k = static_cast<uint32_t>(seen.kind), sm = static_cast<uint32_t>(seen.sampling);
    if (k > SPH_PROBE_GAUGE || sm > SPH_PROBE_EVERY_SUBSTEP)
      violation("a probe of kind %u, sampling %u", k, sm);
    if (seen.reserved0 != 0) violation("a probe def with reserved0 %u was accepted", seen.reserved0);
    if (!finite3(seen.position)) violation("a probe at a non-finite position was accepted");
    if (gauge && !(finite3(seen.direction) && std::isfinite(seen.length) && seen.length > 0.0f &&
                   std::isfinite(seen.sample_spacing) && seen.sample_spacing >= 0.0f && steps <= 65536.0))
      violation("a gauge with a bad direction, length %g or spacing %g was accepted",
                static_cast<double>(seen.length), static_cast<double>(seen.sample_spacing));
    store_id(probes_, in_.u8(), id.bits, slot);
  }

  // sph_probe_destroy, sph_probe_get_reading (struct_size and canary as op_queries' stats) and
  // sph_probe_set_pressure_threshold, with null, stale and foreign ids.
  void op_probe_ops() {
    int slot;
    sph_world* w = world_arg(&slot);
    const bool is_live = live(slot, w);
    const sph_probe_id id{id_arg(probes_)};
    sph_result r;
    switch (in_.u8() % 3) {
      case 0: {
        const std::vector<uint8_t> saved = is_live ? checkpoint(w) : std::vector<uint8_t>{};
        r = FUZZ_CALL(sph_probe_destroy(w, id));
        if (is_live && id.bits == 0 && r != SPH_OK) violation("sph_probe_destroy of id {0} answered %d", r);
        if (r != SPH_OK && is_live && checkpoint(w) != saved)
          violation("a refused sph_probe_destroy changed the world (%d)", r);
        break;
      }
      case 1: {
        Padded<sph_probe_reading> out;
        sph_probe_reading_init(&out.value);
        const uint32_t size = out.value.struct_size = struct_size(sizeof(sph_probe_reading));
        out.paint_past(size);
        r = FUZZ_CALL(sph_probe_get_reading(w, id, in_.chance(16) ? nullptr : &out.value));
        if (!out.paint_intact()) violation("sph_probe_get_reading wrote past struct_size %u (r=%d)", size, r);
        if (r == SPH_OK && size >= sizeof(sph_probe_reading)) {
          const sph_probe_reading& o = out.value;
          if (!(std::isfinite(o.density) && std::isfinite(o.pressure) && finite3(o.velocity) &&
                std::isfinite(o.pressure_max) && std::isfinite(o.kernel_sum) &&
                std::isfinite(o.water_height) && std::isfinite(o.time) && o.time >= 0.0))
            violation("a probe reading with a non-finite value (samples %u)", o.samples);
          if (o.samples == 0 && o.time != 0.0) violation("a probe reading of no samples over %g s", o.time);
        }
        break;
      }
      default: {
        const float pressure = in_.maybe_hostile(0.0f, 1e5f);
        const std::vector<uint8_t> saved = is_live ? checkpoint(w) : std::vector<uint8_t>{};
        r = FUZZ_CALL(sph_probe_set_pressure_threshold(w, id, pressure));
        if (r == SPH_OK && !(std::isfinite(pressure) && pressure >= 0.0f))
          violation("sph_probe_set_pressure_threshold accepted %g", static_cast<double>(pressure));
        if (r != SPH_OK && is_live && checkpoint(w) != saved)
          violation("a refused sph_probe_set_pressure_threshold changed the world (%d)", r);
      }
    }
    if (r == SPH_OK && !is_live) violation("a probe call succeeded on a dead world");
    expect_foreign_id_refused(slot, w, id.bits, r, "a probe call");
  }

  // sph_collider_get_loads (struct_size, canary) and sph_collider_set_load_point, on worlds
  // with and without SPH_FEATURE_COLLIDER_LOADS.
  void op_collider_loads() {
    int slot;
    sph_world* w = world_arg(&slot);
    const bool is_live = live(slot, w);
    const sph_collider_id id{id_arg(colliders_)};
    sph_result r;
    if (in_.chance(128)) {
      Padded<sph_collider_loads> out;
      sph_collider_loads_init(&out.value);
      const uint32_t size = out.value.struct_size = struct_size(sizeof(sph_collider_loads));
      out.paint_past(size);
      r = FUZZ_CALL(sph_collider_get_loads(w, id, in_.chance(16) ? nullptr : &out.value));
      if (!out.paint_intact()) violation("sph_collider_get_loads wrote past struct_size %u (r=%d)", size, r);
      if (r == SPH_OK && size >= sizeof(sph_collider_loads)) {
        const sph_collider_loads& o = out.value;
        if (!(finite3(o.force) && finite3(o.torque) && finite3(o.point) && std::isfinite(o.frame_time) &&
              o.frame_time >= 0.0 && o.reserved0 == 0))
          violation("collider loads with a non-finite value or a non-zero reserved0");
      }
    } else {
      const sph_vec3 point = vec3(-0.5f, 0.5f);
      const std::vector<uint8_t> saved = is_live ? checkpoint(w) : std::vector<uint8_t>{};
      r = FUZZ_CALL(sph_collider_set_load_point(w, id, in_.chance(8) ? nullptr : &point));
      if (r == SPH_OK && !finite3(point))
        violation("sph_collider_set_load_point accepted a non-finite point");
      if (r != SPH_OK && is_live && checkpoint(w) != saved)
        violation("a refused sph_collider_set_load_point changed the world (%d)", r);
    }
    if (r == SPH_OK && !is_live) violation("a collider loads call succeeded on a dead world");
    if (r == SPH_OK && !(worlds_[slot].features & SPH_FEATURE_COLLIDER_LOADS))
      violation("a collider loads call succeeded on a world without SPH_FEATURE_COLLIDER_LOADS");
    expect_foreign_id_refused(slot, w, id.bits, r, "a collider loads call");
  }

  // ---- parameters by kind ------------------------------------------------------------------------
  // Whether a world's def turns on the method whose params struct is `kind`.
  static bool kind_enabled(const WorldSlot& w, uint32_t kind) {
    switch (kind) {
      case SPH_PARAMS_WORLD:
        return true;
      case SPH_PARAMS_SURFACE_TENSION:
        return (w.features & SPH_FEATURE_SURFACE_TENSION) != 0;
      case SPH_PARAMS_CLAVET_VISCOSITY:
        return w.viscosity == SPH_VISCOSITY_CLAVET;
      case SPH_PARAMS_TAIT:
        return w.eos == SPH_EOS_TAIT;
      case SPH_PARAMS_SPRINGS:
        return (w.features & SPH_FEATURE_SPRINGS) != 0;
      case SPH_PARAMS_DFSPH:
        return w.solver == SPH_SOLVER_DFSPH;
      case SPH_PARAMS_DENSITY_DIFFUSION:
        return (w.features & SPH_FEATURE_DENSITY_DIFFUSION) != 0;
      default:
        return false;
    }
  }
  static uint32_t params_size(uint32_t kind) {
    static const uint32_t sizes[SPH_PARAMS_KIND_COUNT] = {sizeof(sph_world_params),
                                                          sizeof(sph_surface_tension_params),
                                                          sizeof(sph_clavet_viscosity_params),
                                                          sizeof(sph_tait_params),
                                                          sizeof(sph_spring_params),
                                                          sizeof(sph_dfsph_params),
                                                          sizeof(sph_density_diffusion_params)};
    return kind < SPH_PARAMS_KIND_COUNT ? sizes[kind] : 0;
  }
  static sph_params_kind kind_arg(uint32_t kind) {
    sph_params_kind k;
    std::memcpy(&k, &kind, 4);
    return k;
  }
  static std::vector<sph_param_field_info> fields_of(uint32_t kind) {
    std::vector<sph_param_field_info> fields;
    sph_params_info info;
    sph_params_info_init(&info);
    if (FUZZ_CALL(sph_params_get_info(kind_arg(kind), &info)) != SPH_OK) return fields;
    for (uint32_t i = 0; i < info.field_count; ++i) {
      sph_param_field_info f;
      sph_param_field_info_init(&f);
      if (FUZZ_CALL(sph_params_get_field_info(kind_arg(kind), i, &f)) != SPH_OK)
        violation("field %u of %u of params kind %u cannot be described", i, info.field_count, kind);
      fields.push_back(f);
    }
    return fields;
  }
  static bool in_bounds(const sph_param_field_info& f, double v) {
    const uint32_t lb = static_cast<uint32_t>(f.lower_bound), ub = static_cast<uint32_t>(f.upper_bound);
    if (lb == SPH_BOUND_INCLUSIVE && !(v >= f.lower)) return false;
    if (lb == SPH_BOUND_EXCLUSIVE && !(v > f.lower)) return false;
    if (ub == SPH_BOUND_INCLUSIVE && !(v <= f.upper)) return false;
    if (ub == SPH_BOUND_EXCLUSIVE && !(v < f.upper)) return false;
    return true;
  }
  // Whether the field at bytes + f.offset holds a value its description allows (a 0 that asks
  // for a default or a derived value is allowed whatever the range).
  static bool field_valid(const sph_param_field_info& f, const unsigned char* bytes) {
    const bool zero_is_value = static_cast<uint32_t>(f.zero) == SPH_PARAM_ZERO_IS_VALUE;
    switch (static_cast<uint32_t>(f.type)) {
      case SPH_PARAM_FLOAT: {
        float v;
        std::memcpy(&v, bytes + f.offset, 4);
        if (v == 0.0f && !zero_is_value) return true;
        return std::isfinite(v) && in_bounds(f, v);
      }
      case SPH_PARAM_VEC3: {
        sph_vec3 v;
        std::memcpy(&v, bytes + f.offset, sizeof v);
        return finite3(v);
      }
      case SPH_PARAM_UINT32: {
        uint32_t v;
        std::memcpy(&v, bytes + f.offset, 4);
        if (v == 0 && !zero_is_value) return true;
        return in_bounds(f, v);
      }
      case SPH_PARAM_FLAGS: {
        uint32_t v;
        std::memcpy(&v, bytes + f.offset, 4);
        return (v & ~static_cast<uint32_t>(f.upper)) == 0;
      }
      default:
        return false;
    }
  }
  static size_t field_bytes(const sph_param_field_info& f) {
    return static_cast<uint32_t>(f.type) == SPH_PARAM_VEC3 ? sizeof(sph_vec3) : 4;
  }
  // A params struct the library accepted or gave out: every described field within its
  // description (sph_params_get_field_info "names the same rules the set calls apply").
  static void check_fields(uint32_t kind, const unsigned char* bytes, const char* what) {
    for (const sph_param_field_info& f : fields_of(kind))
      if (!field_valid(f, bytes))
        violation("%s: field %s of params kind %u out of its described range", what, f.name, kind);
  }
  // The world's params struct of `kind` as bytes (empty when the world does not have it).
  std::vector<unsigned char> params_bytes(sph_world* w, uint32_t kind) {
    const uint32_t size = params_size(kind);
    std::vector<unsigned char> bytes(std::max<uint32_t>(size, 4), 0);
    std::memcpy(bytes.data(), &size, 4);
    if (FUZZ_CALL(sph_world_get_physics_params(w, kind_arg(kind), bytes.data())) != SPH_OK) bytes.clear();
    return bytes;
  }
  // The harness's bounds on a world's work (kMaxSubsteps, kMaxSolverIterations) over a params
  // struct about to be set: a 0 takes the library's default (10000 substeps, 100 iterations), and
  // larger counts are legal but too slow here.
  static void bound_work(uint32_t kind, unsigned char* bytes) {
    const auto bound = [&](size_t offset, uint32_t most) {
      uint32_t v;
      std::memcpy(&v, bytes + offset, 4);
      if (v == 0 || v > most) std::memcpy(bytes + offset, &most, 4);
    };
    if (kind == SPH_PARAMS_WORLD) bound(offsetof(sph_world_params, max_substeps), kMaxSubsteps);
    if (kind == SPH_PARAMS_DFSPH) {
      bound(offsetof(sph_dfsph_params, max_iterations), kMaxSolverIterations);
      bound(offsetof(sph_dfsph_params, max_divergence_iterations), kMaxSolverIterations);
    }
  }
  // After a set call of params `kind` on a live world answered r: a refused one changed nothing,
  // an accepted one had and has values within their descriptions and a world with the method.
  void check_params_set(int slot, uint32_t kind, sph_result r, const std::vector<unsigned char>& before,
                        const unsigned char* sent, uint32_t sent_size) {
    const std::vector<unsigned char> after = params_bytes(worlds_[slot].ptr, kind);
    if (r != SPH_OK) {
      if (after != before) violation("a refused set of params kind %u (%d) changed them", kind, r);
      return;
    }
    if (!kind_enabled(worlds_[slot], kind))
      violation("params kind %u set on a world without its method", kind);
    std::vector<unsigned char> seen(params_size(kind), 0);
    std::memcpy(seen.data(), sent, std::min<size_t>(sent_size, seen.size()));
    check_fields(kind, seen.data(), "an accepted set");
    if (after.empty()) violation("params kind %u were set but cannot be read", kind);
    check_fields(kind, after.data(), "the params read back after a set");
  }

  // The typed calls of the DFSPH, spring and density-diffusion params (each FEATURE_DISABLED on
  // a world without the method; nothing changes on error).
  void op_method_params() {
    int slot;
    sph_world* w = world_arg(&slot);
    const bool is_live = live(slot, w);
    const bool set = in_.chance(160);
    sph_result r;
    uint32_t kind;
    // Each struct in 256 bytes (a fuzzed struct_size stays inside); `sent` is the one passed.
    Padded<sph_dfsph_params> dfsph;
    Padded<sph_spring_params> springs;
    Padded<sph_density_diffusion_params> diffusion;
    const unsigned char* sent = nullptr;
    std::vector<unsigned char> before;
    switch (in_.u8() % 3) {
      case 0: {
        kind = SPH_PARAMS_DFSPH;
        sph_dfsph_params& p = dfsph.value;
        sent = dfsph.bytes;
        sph_dfsph_params_init(&p);
        if (is_live && in_.chance(128)) FUZZ_CALL(sph_world_get_dfsph_params(w, &p));
        p.density_error = in_.maybe_hostile(0.0f, 0.01f);
        p.divergence_error = in_.maybe_hostile(0.0f, 2.0f);
        p.max_iterations = in_.chance(224) ? in_.range(0, kMaxSolverIterations) : in_.u32();
        p.max_divergence_iterations = in_.chance(224) ? in_.range(0, kMaxSolverIterations) : in_.u32();
        p.flags = in_.chance(224) ? in_.u8() % 8 : in_.u32();
        p.linear_solver = in_.chance(224) ? in_.u8() % 4 : in_.u32();
        p.density_error_max = in_.maybe_hostile(0.0f, 0.1f);
        p.depth_step_factor = in_.maybe_hostile(0.0f, 1.0f);
        p.divergence_error_per_step = in_.maybe_hostile(0.0f, 0.01f);
        bound_work(kind, dfsph.bytes);
        p.struct_size = struct_size(sizeof p);
        if (set && is_live) before = params_bytes(w, kind);
        r = set ? FUZZ_CALL(sph_world_set_dfsph_params(w, in_.chance(8) ? nullptr : &p))
                : FUZZ_CALL(sph_world_get_dfsph_params(w, in_.chance(8) ? nullptr : &p));
        break;
      }
      case 1: {
        kind = SPH_PARAMS_SPRINGS;
        sph_spring_params& p = springs.value;
        sent = springs.bytes;
        sph_spring_params_init(&p);
        const float s = is_live ? worlds_[slot].spacing : 0.02f;
        p.stiffness = in_.maybe_hostile(0.0f, 1e4f);
        p.link_radius = in_.chance(128) ? 0.0f : in_.maybe_hostile(0.0f, 2.0f * s);
        p.yield_ratio = in_.maybe_hostile(0.0f, 1.0f);
        p.plasticity = in_.maybe_hostile(0.0f, 10.0f);
        p.damping = in_.maybe_hostile(0.0f, 10.0f);
        if (in_.chance(8)) p.reserved0 = in_.u32();
        p.struct_size = struct_size(sizeof p);
        if (set && is_live) before = params_bytes(w, kind);
        r = set ? FUZZ_CALL(sph_world_set_spring_params(w, in_.chance(8) ? nullptr : &p))
                : FUZZ_CALL(sph_world_get_spring_params(w, in_.chance(8) ? nullptr : &p));
        break;
      }
      default: {
        kind = SPH_PARAMS_DENSITY_DIFFUSION;
        sph_density_diffusion_params& p = diffusion.value;
        sent = diffusion.bytes;
        sph_density_diffusion_params_init(&p);
        p.delta = in_.maybe_hostile(0.0f, 1.0f);
        p.struct_size = struct_size(sizeof p);
        if (set && is_live) before = params_bytes(w, kind);
        r = set ? FUZZ_CALL(sph_world_set_density_diffusion_params(w, in_.chance(8) ? nullptr : &p))
                : FUZZ_CALL(sph_world_get_density_diffusion_params(w, in_.chance(8) ? nullptr : &p));
      }
    }
    if (r == SPH_OK && !is_live) violation("method params on a dead world");
    if (!is_live) return;
    if (set) {
      uint32_t sent_size;
      std::memcpy(&sent_size, sent, 4);
      check_params_set(slot, kind, r, before, sent, sent_size);
    } else if (r == SPH_OK && !kind_enabled(worlds_[slot], kind)) {
      violation("params kind %u read from a world without its method", kind);
    }
  }

  // sph_world_set/get_physics_params: any kind (invalid ones too), one field of the struct set
  // to a hostile or an in-range value at the offset sph_params_get_field_info gives.
  void op_params_by_kind() {
    int slot;
    sph_world* w = world_arg(&slot);
    const bool is_live = live(slot, w);
    const uint32_t kind = enum_value(SPH_PARAMS_KIND_COUNT);
    const bool set = in_.chance(160);
    Padded<sph_world_params> buf;  // 256 bytes, aligned for any params struct
    unsigned char* bytes = buf.bytes;
    const uint32_t size = kind < SPH_PARAMS_KIND_COUNT ? params_size(kind) : 8;
    std::memcpy(bytes, &size, 4);
    if (is_live && kind < SPH_PARAMS_KIND_COUNT)
      FUZZ_CALL(sph_world_get_physics_params(w, kind_arg(kind), bytes));
    const std::vector<sph_param_field_info> fields =
        kind < SPH_PARAMS_KIND_COUNT ? fields_of(kind) : std::vector<sph_param_field_info>{};
    if (set && !fields.empty()) {
      const sph_param_field_info& f = fields[in_.u8() % fields.size()];
      switch (static_cast<uint32_t>(f.type)) {
        case SPH_PARAM_FLOAT: {
          const double lo = static_cast<uint32_t>(f.lower_bound) == SPH_BOUND_NONE ? -100.0 : f.lower;
          const double hi = static_cast<uint32_t>(f.upper_bound) == SPH_BOUND_NONE ? lo + 100.0 : f.upper;
          const float v =
              in_.chance(64) ? in_.hostile() : in_.unit(static_cast<float>(lo), static_cast<float>(hi));
          std::memcpy(bytes + f.offset, &v, 4);
          break;
        }
        case SPH_PARAM_VEC3: {
          const sph_vec3 v = vec3(-20.0f, 20.0f);
          std::memcpy(bytes + f.offset, &v, sizeof v);
          break;
        }
        default: {
          const uint32_t v = in_.chance(64) ? in_.u32() : in_.u8() % 16;
          std::memcpy(bytes + f.offset, &v, 4);
        }
      }
      bound_work(kind, bytes);
    }
    if (in_.chance(16)) {
      const uint32_t fuzzed = struct_size(size);
      std::memcpy(bytes, &fuzzed, 4);
    }
    uint32_t sent_size;
    std::memcpy(&sent_size, bytes, 4);
    const uint32_t canary = std::min<uint32_t>(std::max<uint32_t>(sent_size, sizeof(uint32_t)), 256);
    if (!set) std::memset(bytes + canary, 0xAB, 256 - canary);
    const std::vector<unsigned char> before =
        set && is_live ? params_bytes(w, kind) : std::vector<unsigned char>{};
    void* arg = in_.chance(8) ? nullptr : bytes;
    const sph_result r = set ? FUZZ_CALL(sph_world_set_physics_params(w, kind_arg(kind), arg))
                             : FUZZ_CALL(sph_world_get_physics_params(w, kind_arg(kind), arg));
    if (r == SPH_OK && kind >= SPH_PARAMS_KIND_COUNT) violation("physics params of unknown kind %u", kind);
    if (r == SPH_OK && !is_live) violation("physics params on a dead world");
    if (!set) {
      for (uint32_t i = canary; i < 256; ++i)
        if (bytes[i] != 0xAB)
          violation("sph_world_get_physics_params wrote past struct_size %u (r=%d)", sent_size, r);
      if (r == SPH_OK) {
        if (!kind_enabled(worlds_[slot], kind))
          violation("params kind %u read from a world without its method", kind);
        if (sent_size >= size) check_fields(kind, bytes, "sph_world_get_physics_params");
      }
      return;
    }
    if (is_live && kind < SPH_PARAMS_KIND_COUNT) check_params_set(slot, kind, r, before, bytes, sent_size);
  }

  // The static descriptions: sph_params_get_info, sph_params_get_field_info and
  // sph_get_physics_method_info with invalid kinds and indices, NULL and short structs.
  void op_params_info() {
    switch (in_.u8() % 3) {
      case 0: {
        const uint32_t kind = enum_value(SPH_PARAMS_KIND_COUNT);
        Padded<sph_params_info> out;
        sph_params_info_init(&out.value);
        const uint32_t size = out.value.struct_size = struct_size(sizeof(sph_params_info));
        out.paint_past(size);
        const bool null = in_.chance(16);
        const sph_result r = FUZZ_CALL(sph_params_get_info(kind_arg(kind), null ? nullptr : &out.value));
        if (!out.paint_intact()) violation("sph_params_get_info wrote past struct_size %u", size);
        if (r == SPH_OK && (kind >= SPH_PARAMS_KIND_COUNT || null))
          violation("sph_params_get_info(%u) succeeded", kind);
        if (kind < SPH_PARAMS_KIND_COUNT && !null && size == sizeof(sph_params_info)) {
          if (r != SPH_OK) violation("params kind %u cannot be described: %s", kind, sph_get_last_error());
          const sph_params_info& o = out.value;
          if (o.params_size != params_size(kind) || o.field_count == 0 || o.reserved0 != 0 || !o.name ||
              !o.name[0] || !o.type_name || !o.type_name[0])
            violation("params kind %u described as %u bytes, %u fields", kind, o.params_size, o.field_count);
        }
        break;
      }
      case 1: {
        const uint32_t kind = enum_value(SPH_PARAMS_KIND_COUNT);
        const uint32_t index = in_.chance(224) ? in_.u8() % 16 : in_.u32();
        Padded<sph_param_field_info> out;
        sph_param_field_info_init(&out.value);
        const uint32_t size = out.value.struct_size = struct_size(sizeof(sph_param_field_info));
        out.paint_past(size);
        const bool null = in_.chance(16);
        const size_t count = kind < SPH_PARAMS_KIND_COUNT ? fields_of(kind).size() : 0;
        const sph_result r =
            FUZZ_CALL(sph_params_get_field_info(kind_arg(kind), index, null ? nullptr : &out.value));
        if (!out.paint_intact()) violation("sph_params_get_field_info wrote past struct_size %u", size);
        if (kind >= SPH_PARAMS_KIND_COUNT || null) {
          if (r == SPH_OK) violation("sph_params_get_field_info(%u, %u) succeeded", kind, index);
          break;
        }
        if (r == SPH_OK && index >= count)
          violation("field %u of a params struct of %zu fields", index, count);
        if (index < count && size == sizeof(sph_param_field_info)) {
          if (r != SPH_OK) violation("field %u of params kind %u: %s", index, kind, sph_get_last_error());
          const sph_param_field_info& f = out.value;
          const uint32_t lb = static_cast<uint32_t>(f.lower_bound), ub = static_cast<uint32_t>(f.upper_bound);
          if (static_cast<uint32_t>(f.type) > SPH_PARAM_FLAGS ||
              static_cast<uint32_t>(f.zero) > SPH_PARAM_ZERO_IS_DERIVED || lb > SPH_BOUND_EXCLUSIVE ||
              ub > SPH_BOUND_EXCLUSIVE || f.reserved0 != 0 || !f.name || !f.name[0] || !f.unit)
            violation("field %u of params kind %u has an invalid description", index, kind);
          if (f.offset < sizeof(uint32_t) || f.offset + field_bytes(f) > params_size(kind))
            violation("field %s of params kind %u at offset %u", f.name, kind, f.offset);
          if (lb != SPH_BOUND_NONE && ub != SPH_BOUND_NONE && !(f.lower <= f.upper))
            violation("field %s of params kind %u has the range [%g, %g]", f.name, kind, f.lower, f.upper);
          // The default a 0 takes must itself be a valid value.
          if (static_cast<uint32_t>(f.zero) == SPH_PARAM_ZERO_IS_DEFAULT &&
              static_cast<uint32_t>(f.type) == SPH_PARAM_FLOAT &&
              !(std::isfinite(f.default_value[0]) && in_bounds(f, f.default_value[0])))
            violation("field %s of params kind %u has the default %g outside its range", f.name, kind,
                      static_cast<double>(f.default_value[0]));
        }
        break;
      }
      default: {
        const uint32_t index = in_.chance(224) ? in_.u8() % 24 : in_.u32();
        Padded<sph_physics_method_info> out;
        sph_physics_method_info_init(&out.value);
        const uint32_t size = out.value.struct_size = struct_size(sizeof(sph_physics_method_info));
        out.paint_past(size);
        const bool null = in_.chance(16);
        const sph_result r = FUZZ_CALL(sph_get_physics_method_info(index, null ? nullptr : &out.value));
        if (!out.paint_intact()) violation("sph_get_physics_method_info wrote past struct_size %u", size);
        if (null) {
          if (r == SPH_OK) violation("sph_get_physics_method_info accepted NULL");
          break;
        }
        if (index == 0 && size == sizeof(sph_physics_method_info) && r != SPH_OK)
          violation("method 0 cannot be described: %s", sph_get_last_error());
        if (r != SPH_OK || size != sizeof(sph_physics_method_info)) break;
        const sph_physics_method_info& m = out.value;
        const uint32_t by = static_cast<uint32_t>(m.switch_by);
        if (index >= m.method_count) violation("method %u of %u described", index, m.method_count);
        if (by < SPH_METHOD_SWITCH_FEATURE || by > SPH_METHOD_SWITCH_SOLVER || m.has_params > 1 ||
            static_cast<uint32_t>(m.params_kind) >= SPH_PARAMS_KIND_COUNT || !m.name || !m.name[0])
          violation("method %u has an invalid description", index);
        const bool one_bit =
            m.value != 0 && (m.value & (m.value - 1)) == 0 && (m.value & ~kKnownFeatures) == 0;
        if ((by == SPH_METHOD_SWITCH_FEATURE && !one_bit) || (by != SPH_METHOD_SWITCH_FEATURE && m.value > 1))
          violation("method %s is selected by %u = %u", m.name, by, m.value);
      }
    }
  }

  // ---- writing and removing particles ------------------------------------------------------------
  // sph_world_set_attribute: any attribute, range, stride and buffer size (the buffer is exactly
  // src_size bytes, so ASan sees a read past it), hostile values. All-or-nothing: a refused call
  // changes nothing; an accepted one wrote exactly the range, which reads back as sent.
  void op_set_attribute() {
    int slot;
    sph_world* w = world_arg(&slot);
    const bool is_live = live(slot, w);
    const uint32_t attribute = enum_value(6);
    const Particles before = is_live ? snapshot(w) : Particles{};
    const uint32_t n = static_cast<uint32_t>(before.id.size());
    const uint32_t first = in_.chance(200) ? in_.range(0, n) : in_.u32();
    const uint32_t count = in_.chance(200) ? in_.range(0, n - std::min(first, n)) : in_.u32();
    const bool vector = attribute == SPH_ATTRIBUTE_POSITION || attribute == SPH_ATTRIBUTE_VELOCITY;
    const uint64_t element = vector ? 12 : 4;
    const uint64_t stride = in_.chance(160) ? 0 : (in_.chance(224) ? in_.u8() % 40 : in_.u64());
    const uint64_t step = stride == 0 ? element : stride;
    const double needed =
        count == 0 ? 0.0 : static_cast<double>(count - 1) * static_cast<double>(step) + element;
    const uint64_t src_size =
        in_.chance(200) && needed <= 65536.0 ? static_cast<uint64_t>(needed) : in_.u32() % 8192;
    // A loose cloud near the origin (a few input bytes for any size), now and then a hostile value.
    std::vector<float> src(static_cast<size_t>(src_size / 4) + 1);  // src_size bytes used, rounded up
    const float s = is_live ? worlds_[slot].spacing : 0.02f;
    const float origin = in_.unit(-8.0f * s, 8.0f * s);
    for (size_t i = 0; i < src.size(); ++i) src[i] = origin + s * static_cast<float>(i % 11);
    if (in_.chance(32)) src[in_.u16() % src.size()] = in_.hostile();
    if (in_.chance(16)) {
      // Legal extremes: a position at the particles' reach (65536 spacings from the origin) or
      // just past it, a speed near the velocity limit (1.8e19 m/s).
      const float extremes[] = {65535.0f * s, -65535.0f * s, 65537.0f * s, 1.0e19f, -1.7e19f};
      src[in_.u16() % src.size()] = extremes[in_.u8() % 5];
    }
    std::vector<unsigned char> exact(static_cast<size_t>(src_size));
    if (src_size) std::memcpy(exact.data(), src.data(), static_cast<size_t>(src_size));
    const std::vector<uint8_t> saved = is_live ? checkpoint(w) : std::vector<uint8_t>{};
    sph_attribute a;
    std::memcpy(&a, &attribute, 4);
    const void* arg =
        in_.chance(8) ? nullptr : (exact.empty() ? static_cast<const void*>(&stride) : exact.data());
    const sph_result r = FUZZ_CALL(sph_world_set_attribute(w, a, arg, src_size, stride, first, count));
    if (r != SPH_OK) {
      if (is_live && checkpoint(w) != saved)
        violation("a refused sph_world_set_attribute changed the world (%d)", r);
      return;
    }
    if (!is_live) violation("sph_world_set_attribute succeeded on a dead world");
    if (!vector && attribute != SPH_ATTRIBUTE_USER) violation("attribute %u was written", attribute);
    if (attribute == SPH_ATTRIBUTE_USER && !(worlds_[slot].features & SPH_FEATURE_USER_ATTRIBUTE))
      violation("the user attribute was written on a world without it");
    if (static_cast<uint64_t>(first) + count > n)
      violation("particles %u + %u of %u were written", first, count, n);
    if (count > 0 && (!arg || step < element || needed > static_cast<double>(src_size)))
      violation("sph_world_set_attribute accepted a buffer that cannot hold %u elements", count);
    const Particles after = snapshot(w);
    if (after.id != before.id) violation("sph_world_set_attribute changed the particles' ids or order");
    const unsigned char* base = static_cast<const unsigned char*>(arg);
    for (uint32_t i = 0; i < n; ++i) {
      const bool written = i >= first && i - first < count;
      // A particle given its own position back may lie beyond the bound (a step carried it there).
      const bool own_position =
          written && attribute == SPH_ATTRIBUTE_POSITION &&
          std::memcmp(base + step * (i - first), &before.position[3 * static_cast<size_t>(i)], 12) == 0;
      for (int k = 0; k < 3; ++k) {
        const size_t at = 3 * static_cast<size_t>(i) + k;
        float sent = 0.0f;
        if (written && vector) std::memcpy(&sent, base + step * (i - first) + 4 * k, 4);
        const bool position_written = written && attribute == SPH_ATTRIBUTE_POSITION;
        const bool velocity_written = written && attribute == SPH_ATTRIBUTE_VELOCITY;
        if (after.position[at] != (position_written ? sent : before.position[at]) ||
            after.velocity[at] != (velocity_written ? sent : before.velocity[at]))
          violation("particle %u after sph_world_set_attribute of [%u, +%u) is not as written", i, first,
                    count);
        if (written && vector && !std::isfinite(sent)) violation("a non-finite value was written");
        if (position_written && !own_position && !(std::fabs(sent) <= 65536.0f * worlds_[slot].spacing))
          violation("a position %g beyond 65536 spacings (%g m) was written", static_cast<double>(sent),
                    static_cast<double>(worlds_[slot].spacing));
      }
      if (written && attribute == SPH_ATTRIBUTE_VELOCITY) {
        const double x = after.velocity[3 * i], y = after.velocity[3 * i + 1], z = after.velocity[3 * i + 2];
        if (!(std::sqrt(x * x + y * y + z * z) < 1.8e19))
          violation("a speed of 1.8e19 m/s or more was written");
      }
    }
    if (attribute == SPH_ATTRIBUTE_USER && count > 0) {
      std::vector<uint32_t> user(count);
      uint32_t got = 0;
      FUZZ_CALL(
          sph_world_copy_attribute(w, SPH_ATTRIBUTE_USER, user.data(), 4ull * count, 0, first, count, &got));
      for (uint32_t i = 0; i < count; ++i) {
        uint32_t sent;
        std::memcpy(&sent, base + step * i, 4);
        if (got != count || user[i] != sent)
          violation("user attribute %u reads %u, written %u", first + i, user[i], sent);
      }
    }
  }

  // The ids sph_world_get_removed_ids reports.
  std::vector<uint32_t> removed_ids(sph_world* w) {
    uint32_t n = 0;
    const sph_result r = FUZZ_CALL(sph_world_get_removed_ids(w, nullptr, 0, &n));
    if (r != SPH_OK && r != SPH_INCOMPLETE)
      violation("the removed ids of a live world cannot be read (%d)", r);
    std::vector<uint32_t> ids(n + 1);
    uint32_t m = 0;
    if (FUZZ_CALL(sph_world_get_removed_ids(w, ids.data(), n, &m)) != SPH_OK || m != n)
      violation("the removed ids changed between two reads");
    ids.resize(n);
    return ids;
  }

  // sph_world_remove_particles: ids of the world, repeated, unknown or random; NULL; huge counts
  // with NULL. All-or-nothing; an accepted call removed exactly those particles, kept the others
  // in their order and appended the ids to the removed ids.
  void op_remove_particles() {
    int slot;
    sph_world* w = world_arg(&slot);
    const bool is_live = live(slot, w);
    const Particles before = is_live ? snapshot(w) : Particles{};
    const size_t n = before.id.size();
    const uint32_t count = in_.chance(224) ? in_.u8() % 9 : in_.u32();
    const uint32_t held = std::min<uint32_t>(count, 64);
    std::vector<uint32_t> ids(std::max<uint32_t>(held, 1));  // exactly what count says (ASan)
    for (uint32_t i = 0; i < held; ++i) {
      if (n > 0 && in_.chance(216))
        ids[i] = before.id[in_.u16() % n];
      else
        ids[i] = i > 0 && in_.chance(128) ? ids[in_.u8() % i] : in_.u32();
    }
    const bool null = in_.chance(16);
    if (count > held && !null) return;  // the array must hold what count says
    const std::vector<uint8_t> saved = is_live ? checkpoint(w) : std::vector<uint8_t>{};
    const std::vector<uint32_t> removed_before = is_live ? removed_ids(w) : std::vector<uint32_t>{};
    const sph_result r = FUZZ_CALL(sph_world_remove_particles(w, null ? nullptr : ids.data(), count));
    if (r != SPH_OK) {
      if (is_live && checkpoint(w) != saved)
        violation("a refused sph_world_remove_particles changed the world (%d)", r);
      return;
    }
    if (!is_live) violation("sph_world_remove_particles succeeded on a dead world");
    if (count == 0) {
      if (checkpoint(w) != saved) violation("removing no particle changed the world");
      return;
    }
    if (null) violation("sph_world_remove_particles accepted NULL ids for %u", count);
    std::vector<uint32_t> gone(ids.begin(), ids.begin() + count);
    std::sort(gone.begin(), gone.end());
    if (std::adjacent_find(gone.begin(), gone.end()) != gone.end())
      violation("an id removed twice was accepted");
    Particles expected;
    for (size_t i = 0; i < n; ++i) {
      if (std::binary_search(gone.begin(), gone.end(), before.id[i])) continue;
      expected.id.push_back(before.id[i]);
      for (int k = 0; k < 3; ++k) {
        expected.position.push_back(before.position[3 * i + k]);
        expected.velocity.push_back(before.velocity[3 * i + k]);
      }
    }
    if (expected.id.size() + count != n) violation("an id of no particle of the world was accepted");
    if (!(snapshot(w) == expected))
      violation("the particles left after a removal are not the others in order");
    std::vector<uint32_t> removed = removed_before;
    removed.insert(removed.end(), ids.begin(), ids.begin() + count);
    if (removed_ids(w) != removed) violation("the removed ids do not end with the ids removed");
    // sph_world_get_stats: particle_count is "always current".
    sph_stats stats;
    sph_stats_init(&stats);
    FUZZ_CALL(sph_world_get_stats(w, &stats));
    if (stats.particle_count != n - count)
      violation("stats count %u after removing %u of %zu", stats.particle_count, count, n);
  }

  // ---- asynchronous steps ------------------------------------------------------------------------
  // A call on the world with valid arguments, made while its asynchronous step holds it: each
  // must answer WORLD_LOCKED (sph_world_step_begin: every call but cancel and poll).
  sph_result locked_call(sph_world* w, const std::vector<uint8_t>& saved) {
    switch (in_.u8() % 14) {
      case 0:
        return FUZZ_CALL(sph_world_step(w, 0.001f));
      case 1:
        return FUZZ_CALL(sph_world_step_begin(w, 0.001f));
      case 2: {
        uint32_t n;
        return FUZZ_CALL(sph_world_get_particle_count(w, &n));
      }
      case 3: {
        sph_world_params p;
        sph_world_params_init(&p);
        p.max_substeps = 1;
        return FUZZ_CALL(sph_world_set_params(w, &p));
      }
      case 4: {
        uint64_t size;
        return FUZZ_CALL(sph_world_save(w, nullptr, 0, &size));
      }
      case 5:
        return FUZZ_CALL(sph_world_destroy(w));
      case 6: {
        const float v[3] = {0.0f, 0.0f, 0.0f};
        return FUZZ_CALL(sph_world_set_attribute(w, SPH_ATTRIBUTE_VELOCITY, v, sizeof v, 0, 0, 0));
      }
      case 7:
        return FUZZ_CALL(sph_world_remove_particles(w, nullptr, 0));
      case 8: {
        sph_probe_def d;
        sph_probe_def_init(&d);
        sph_probe_id id;
        return FUZZ_CALL(sph_probe_create(w, &d, &id));
      }
      case 9: {
        sph_stats s;
        sph_stats_init(&s);
        return FUZZ_CALL(sph_world_get_stats(w, &s));
      }
      case 10:
        return FUZZ_CALL(sph_world_restore(w, saved.data(), saved.size()));
      case 11: {
        sph_dfsph_params p;
        sph_dfsph_params_init(&p);
        return FUZZ_CALL(sph_world_get_dfsph_params(w, &p));
      }
      case 12: {
        sph_collider_loads l;
        sph_collider_loads_init(&l);
        return FUZZ_CALL(sph_collider_get_loads(w, sph_collider_id{id_arg(colliders_)}, &l));
      }
      default: {
        float xyz[3];
        uint32_t written;
        return FUZZ_CALL(
            sph_world_copy_attribute(w, SPH_ATTRIBUTE_POSITION, xyz, sizeof xyz, 0, 0, 1, &written));
      }
    }
  }

  // sph_world_step_begin / poll / wait: refusals without a step, calls while the step holds the
  // world, a cancel mid-step, and the wait's result against the step's contract (and, now and
  // then, against sph_world_step of the world's checkpoint loaded into a new world).
  void op_async_step() {
    int slot;
    sph_world* w = world_arg(&slot);
    const float dt = in_.chance(24) ? in_.hostile() : in_.unit(0.0f, 0.01f);
    sph_bool32 done = 7;
    if (!live(slot, w)) {
      if (FUZZ_CALL(sph_world_step_begin(w, dt)) == SPH_OK) violation("sph_world_step_begin on a dead world");
      if (FUZZ_CALL(sph_world_step_poll(w, &done)) == SPH_OK)
        violation("sph_world_step_poll on a dead world");
      if (FUZZ_CALL(sph_world_step_wait(w)) == SPH_OK) violation("sph_world_step_wait on a dead world");
      return;
    }
    WorldSlot& ws = worlds_[slot];
    if (in_.chance(64)) {
      if (FUZZ_CALL(sph_world_step_poll(w, &done)) != SPH_ERROR_INVALID_ARGUMENT)
        violation("sph_world_step_poll without a step did not answer INVALID_ARGUMENT");
      if (FUZZ_CALL(sph_world_step_wait(w)) != SPH_ERROR_INVALID_ARGUMENT)
        violation("sph_world_step_wait without a step did not answer INVALID_ARGUMENT");
    }
    const Particles before = snapshot(w);
    const std::vector<uint8_t> saved = checkpoint(w);
    double budget = 0.0;
    FUZZ_CALL(sph_world_get_step_budget(w, &budget));
    const bool cancel_before = ws.cancel_maybe_pending;
    const sph_result b = FUZZ_CALL(sph_world_step_begin(w, dt));
    if (b != SPH_OK) {
      if (std::isfinite(dt) && dt > 0.0f)
        violation("sph_world_step_begin refused frame_dt %g (%d)", static_cast<double>(dt), b);
      // Nothing runs when begin fails: the world is free, and unchanged.
      if (FUZZ_CALL(sph_world_step_wait(w)) != SPH_ERROR_INVALID_ARGUMENT)
        violation("sph_world_step_wait after a refused begin did not answer INVALID_ARGUMENT");
      if (checkpoint(w) != saved) violation("a refused sph_world_step_begin changed the world");
      return;
    }
    if (!(std::isfinite(dt) && dt > 0.0f))
      violation("sph_world_step_begin accepted frame_dt %g", static_cast<double>(dt));
    bool cancelled = false;
    const int calls = in_.u8() % 5;
    for (int i = 0; i < calls; ++i) {
      switch (in_.u8() % 5) {
        case 0:
          if (FUZZ_CALL(sph_world_cancel_step(w)) != SPH_OK)
            violation("sph_world_cancel_step refused mid-step");
          cancelled = true;
          break;
        case 1:
          done = 7;
          if (FUZZ_CALL(sph_world_step_poll(w, &done)) != SPH_OK || done > 1)
            violation("sph_world_step_poll mid-step failed or said %u", done);
          break;
        case 2:
          if (FUZZ_CALL(sph_world_step_poll(w, nullptr)) != SPH_ERROR_INVALID_ARGUMENT)
            violation("sph_world_step_poll(NULL) mid-step did not answer INVALID_ARGUMENT");
          break;
        case 3:
          if (FUZZ_CALL(sph_context_destroy(contexts_[ws.context].ptr)) == SPH_OK)
            violation("sph_context_destroy destroyed the context of a stepping world");
          break;
        default: {
          const sph_result r = locked_call(w, saved);
          if (r != SPH_ERROR_WORLD_LOCKED) violation("a call mid-step answered %d, not WORLD_LOCKED", r);
        }
      }
    }
    const sph_result r = FUZZ_CALL(sph_world_step_wait(w));
    if (FUZZ_CALL(sph_world_step_wait(w)) != SPH_ERROR_INVALID_ARGUMENT)
      violation("a second sph_world_step_wait did not answer INVALID_ARGUMENT");
    if (FUZZ_CALL(sph_world_step_poll(w, &done)) != SPH_ERROR_INVALID_ARGUMENT)
      violation("sph_world_step_poll after the wait did not answer INVALID_ARGUMENT");
    check_step(slot, r, before, saved);
    // A cancel may have come after the step's last substep; it then waits for the next step.
    if (cancelled) ws.cancel_maybe_pending = true;
    if (cancelled || cancel_before || budget != 0.0 || !in_.chance(128)) return;
    // The frame sph_world_step would run: the same answer and particles as a synchronous step of
    // a copy (a world and its loaded copy step alike: round_trip).
    sph_world* copy = nullptr;
    if (FUZZ_CALL(sph_world_load(contexts_[ws.context].ptr, saved.data(), saved.size(), &copy)) != SPH_OK)
      violation("a world's own checkpoint does not load: %s", sph_get_last_error());
    const sph_result s = FUZZ_CALL(sph_world_step(copy, dt));
    if (s != r) violation("an asynchronous step answered %d, the synchronous step of its copy %d", r, s);
    if (!(snapshot(copy) == snapshot(w))) violation("an asynchronous step and a synchronous one differ");
    if (FUZZ_CALL(sph_world_destroy(copy)) != SPH_OK) violation("destroying a loaded world failed");
  }

  // ---- checkpoint files ----------------------------------------------------------------------------
  // This process's own paths under /tmp (libFuzzer may run several processes at once).
  static const std::string& temp_path(int which) {
    static const std::string base = "/tmp/sph-fuzz-capi-" + std::to_string(static_cast<long>(getpid()));
    static const std::string paths[3] = {base + ".sphc", base + ".dir", base + ".missing/world.sphc"};
    return paths[which];
  }

  // Whether /tmp holds a temporary file of a save to this process's paths (file or directory).
  static bool leftover_temporary() {
    const std::string name = temp_path(0).substr(5), dir_name = temp_path(1).substr(5);
    bool found = false;
    if (DIR* d = opendir("/tmp")) {
      while (const dirent* e = readdir(d)) {
        const std::string entry = e->d_name;
        found |= entry.rfind(name + ".tmp-", 0) == 0 || entry.rfind(dir_name + ".tmp-", 0) == 0;
      }
      closedir(d);
    }
    return found;
  }

  // sph_world_save_file and sph_world_load_file: a saved file loads into a world that saves the
  // same bytes; NULL, empty, missing, directory and device paths are refused and create nothing.
  void op_checkpoint_file() {
    const std::string& file = temp_path(0);
    const std::string& dir = temp_path(1);
    if (in_.chance(128)) {
      int slot;
      sph_world* w = world_arg(&slot);
      const char* paths[] = {file.c_str(), nullptr, "", temp_path(2).c_str(), dir.c_str()};
      const int which = in_.chance(192) ? 0 : in_.u8() % 5;
      if (which == 4) mkdir(dir.c_str(), 0700);  // replacing a directory fails: the save must too
      const sph_result r = FUZZ_CALL(sph_world_save_file(w, paths[which]));
      if (which == 4) {
        struct stat st;
        if (stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) violation("a save replaced a directory");
        rmdir(dir.c_str());
      }
      // Whatever happened, no temporary file of this save is left ("path.tmp-" + a suffix).
      if (leftover_temporary())
        violation("sph_world_save_file (path %d, %d) left a temporary file", which, r);
      if (r != SPH_OK) {
        if (which == 0 && live(slot, w))
          violation("saving a live world to %s failed: %s", paths[0], sph_get_last_error());
        return;
      }
      if (!live(slot, w) || which != 0) violation("sph_world_save_file succeeded (path %d)", which);
      const std::vector<uint8_t> bytes = checkpoint(w);
      int cslot = -1;
      sph_context* c = in_.chance(192) ? contexts_[worlds_[slot].context].ptr : context_arg(&cslot);
      if (c != contexts_[worlds_[slot].context].ptr && (cslot < 0 || !c)) {
        sph_world* out = nullptr;
        if (FUZZ_CALL(sph_world_load_file(c, file.c_str(), &out)) == SPH_OK || out)
          violation("sph_world_load_file succeeded on a dead context");
      } else {
        sph_world* loaded = nullptr;
        if (FUZZ_CALL(sph_world_load_file(c, file.c_str(), &loaded)) != SPH_OK)
          violation("a saved checkpoint file does not load: %s", sph_get_last_error());
        if (checkpoint(loaded) != bytes) violation("a world loaded from its file saves other bytes");
        if (FUZZ_CALL(sph_world_destroy(loaded)) != SPH_OK) violation("destroying a loaded world failed");
      }
      unlink(file.c_str());
      return;
    }
    int cslot;
    sph_context* c = context_arg(&cslot);
    const char* paths[] = {file.c_str(), nullptr, "", "/dev/zero", "/tmp", "/dev/null", temp_path(2).c_str()};
    const int which = in_.u8() % 7;
    unlink(file.c_str());  // (none there: a missing file)
    sph_world* const sentinel = reinterpret_cast<sph_world*>(&stale_);
    sph_world* out = sentinel;
    const sph_result r = FUZZ_CALL(sph_world_load_file(c, paths[which], in_.chance(16) ? nullptr : &out));
    if (r == SPH_OK) violation("sph_world_load_file loaded path %d", which);
    if (out != sentinel) violation("sph_world_load_file wrote *out on failure");
  }

  // Destroys everything; afterwards no handle of this input may be left alive.
  void teardown() {
    for (int i = 0; i < kWorlds; ++i)
      if (worlds_[i].ptr) destroy_world(i);
    for (auto& s : sdfs_)
      if (s.ptr && FUZZ_CALL(sph_sdf_destroy(s.ptr)) != SPH_OK)
        violation("sph_sdf_destroy failed at teardown");
    for (auto& c : contexts_)
      if (c.ptr && FUZZ_CALL(sph_context_destroy(c.ptr)) != SPH_OK)
        violation("sph_context_destroy failed at teardown: %s", sph_get_last_error());
    uint32_t live = 1;
    FUZZ_CALL(sph_get_live_object_count(&live));
    if (live != 0) violation("%u library objects alive after every handle was destroyed", live);
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzInput in(data, size);
  Program program(in);
  program.run();
  return 0;
}
