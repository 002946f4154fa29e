// SPDX-License-Identifier: MIT
// Generational ids for the small objects inside a world (colliders, sources, sinks, fields,
// probes): kind tag (8 bits, 56-63) | generation (24 bits, 32-55) | world tag (16 bits, 16-31) |
// slot (16 bits), so a stale id, one of another kind and one of another world (another world
// tag) is recognised in every build. Id 0 is never issued. A map of world tag 0 issues the ids
// of before the world tag (bits 16-31 zero: slots were always below 65536).
//
// An id is never issued twice by one map: each slot keeps, besides its live generation, the
// highest generation it ever issued (not saved in checkpoints), and a restore of a saved table
// keeps the map's marks (World::keep_issued_ids) unless the map is new (a loaded world starts
// from the table's generations).
#pragma once

#include <stdint.h>

#include <algorithm>
#include <optional>
#include <vector>

#include "host_memory.h"
#include "status.h"

namespace sph {

// The raw table of a SlotMap (checkpoints): one generation and an optional value per slot,
// and the free slots in the order they will be reused.
template <class T>
struct SlotTable {
  HostVector<uint32_t> generations;
  HostVector<std::optional<T>> values;
  HostVector<uint32_t> free_list;
};

template <class T>
class SlotMap {
 public:
  // The most slots a map holds: the slot's 16 bits of an id (the C layer allows 65536 live
  // objects of a kind, and a freed slot is reused before a new one is made).
  static constexpr uint32_t kMaxSlots = 65536;

  explicit SlotMap(uint8_t kind_tag) : tag_(kind_tag) {}

  // The world tag of the ids this map issues and accepts (bits 16-31).
  uint16_t world_tag() const { return world_tag_; }
  void set_world_tag(uint16_t world_tag) { world_tag_ = world_tag; }

  // Error(Capacity) when every slot is taken (the callers refuse before: kMaxSlots live objects).
  uint64_t insert(T value) {
    const bool reuse = !free_.empty();
    if (!reuse && slots_.size() >= kMaxSlots)
      throw Error(Status::Capacity, "a world holds at most 65536 objects of a kind");
    const uint32_t slot = reuse ? free_.back() : static_cast<uint32_t>(slots_.size());
    if (issued_.size() <= slot) issued_.resize(slot + 1, 0u);  // a mark of 0: nothing issued
    if (reuse)
      free_.pop_back();
    else
      slots_.push_back(Slot{});
    Slot& s = slots_[slot];
    uint32_t generation = (std::max(issued_[slot], s.generation) + 1) & 0xffffffu;
    if (generation == 0) generation = 1;
    s.generation = generation;
    issued_[slot] = generation;
    s.value = std::move(value);
    ++count_;
    return make_id(slot, s.generation);
  }

  T* find(uint64_t id) {
    const uint32_t slot = static_cast<uint32_t>(id & 0xffffu);
    const uint16_t world_tag = static_cast<uint16_t>((id >> 16) & 0xffffu);
    const uint32_t generation = static_cast<uint32_t>((id >> 32) & 0xffffffu);
    const uint8_t tag = static_cast<uint8_t>(id >> 56);
    if (tag != tag_ || world_tag != world_tag_ || slot >= slots_.size()) return nullptr;
    Slot& s = slots_[slot];
    if (!s.value || s.generation != generation) return nullptr;
    return &*s.value;
  }
  const T* find(uint64_t id) const { return const_cast<SlotMap*>(this)->find(id); }
  // The live object `id` names; Error(InvalidHandle) "id: ..." for a null, stale or foreign id.
  T& at(uint64_t id) {
    T* object = find(id);
    if (!object) throw Error(Status::InvalidHandle, "id: is null, stale or not of this world");
    return *object;
  }
  const T& at(uint64_t id) const { return const_cast<SlotMap*>(this)->at(id); }

  bool erase(uint64_t id) {
    if (!find(id)) return false;
    const uint32_t slot = static_cast<uint32_t>(id & 0xffffu);
    slots_[slot].value.reset();
    free_.push_back(slot);
    --count_;
    return true;
  }

  size_t size() const { return count_; }

  // The raw table, for checkpoints: a loaded world issues and accepts the same ids.
  uint32_t slot_count() const { return static_cast<uint32_t>(slots_.size()); }
  uint32_t generation_at(uint32_t slot) const { return slots_[slot].generation; }
  const T* value_at(uint32_t slot) const { return slots_[slot].value ? &*slots_[slot].value : nullptr; }
  const HostVector<uint32_t>& free_slots() const { return free_; }
  // Replaces the whole table (the world tag stays). The caller has validated it: at most
  // kMaxSlots slots, generations in [1, 2^24), and the free list names every empty slot exactly
  // once. The highest generations issued become at least the table's.
  void restore(SlotTable<T> table) {
    HostVector<Slot> slots(table.generations.size());
    HostVector<uint32_t> issued = issued_;
    if (issued.size() < slots.size()) issued.resize(slots.size(), 0u);
    size_t count = 0;
    for (size_t i = 0; i < slots.size(); ++i) {
      slots[i].generation = table.generations[i];
      slots[i].value = std::move(table.values[i]);
      issued[i] = std::max(issued[i], table.generations[i]);
      if (slots[i].value) ++count;
    }
    slots_ = std::move(slots);
    free_ = std::move(table.free_list);
    issued_ = std::move(issued);
    count_ = count;
  }
  // Raises this map's highest issued generations to at least `other`'s, slot by slot (a
  // restore: the ids the replaced map issued are never issued again).
  void keep_issued(const SlotMap& other) {
    if (issued_.size() < other.issued_.size()) issued_.resize(other.issued_.size(), 0u);
    for (size_t i = 0; i < other.issued_.size(); ++i) issued_[i] = std::max(issued_[i], other.issued_[i]);
  }

  // Visits live values in slot order (deterministic).
  template <class F>
  void for_each(F&& f) {
    for (uint32_t i = 0; i < slots_.size(); ++i)
      if (slots_[i].value) f(make_id(i, slots_[i].generation), *slots_[i].value);
  }
  template <class F>
  void for_each(F&& f) const {
    for (uint32_t i = 0; i < slots_.size(); ++i)
      if (slots_[i].value) f(make_id(i, slots_[i].generation), *slots_[i].value);
  }

 private:
  struct Slot {
    uint32_t generation = 0;
    std::optional<T> value;
  };
  uint64_t make_id(uint32_t slot, uint32_t generation) const {
    return (static_cast<uint64_t>(tag_) << 56) | (static_cast<uint64_t>(generation) << 32) |
           (static_cast<uint64_t>(world_tag_) << 16) | slot;
  }
  uint8_t tag_;
  uint16_t world_tag_ = 0;
  HostVector<Slot> slots_;
  HostVector<uint32_t> free_;
  // Per slot, the highest generation ever issued in it (may be longer than slots_: a restore to
  // a smaller table keeps the marks of the slots it dropped).
  HostVector<uint32_t> issued_;
  size_t count_ = 0;
};

}  // namespace sph
