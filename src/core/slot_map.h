// SPDX-License-Identifier: MIT
// Generational ids for the small objects inside a world (colliders, sources, sinks, fields):
// a 32-bit slot, a 24-bit generation and an 8-bit kind tag, so a stale or foreign id is
// recognised in every build. Id 0 is never issued.
#pragma once

#include <stdint.h>

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
  explicit SlotMap(uint8_t kind_tag) : tag_(kind_tag) {}

  uint64_t insert(T value) {
    uint32_t slot;
    if (!free_.empty()) {
      slot = free_.back();
      free_.pop_back();
    } else {
      slot = static_cast<uint32_t>(slots_.size());
      slots_.push_back(Slot{});
    }
    Slot& s = slots_[slot];
    s.generation = (s.generation + 1) & 0xffffffu;
    if (s.generation == 0) s.generation = 1;
    s.value = std::move(value);
    ++count_;
    return make_id(slot, s.generation);
  }

  T* find(uint64_t id) {
    const uint32_t slot = static_cast<uint32_t>(id & 0xffffffffu);
    const uint32_t generation = static_cast<uint32_t>((id >> 32) & 0xffffffu);
    const uint8_t tag = static_cast<uint8_t>(id >> 56);
    if (tag != tag_ || slot >= slots_.size()) return nullptr;
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
    const uint32_t slot = static_cast<uint32_t>(id & 0xffffffffu);
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
  // Replaces the whole table. The caller has validated it: generations in [1, 2^24), and
  // the free list names every empty slot exactly once.
  void restore(SlotTable<T> table) {
    HostVector<Slot> slots(table.generations.size());
    size_t count = 0;
    for (size_t i = 0; i < slots.size(); ++i) {
      slots[i].generation = table.generations[i];
      slots[i].value = std::move(table.values[i]);
      if (slots[i].value) ++count;
    }
    slots_ = std::move(slots);
    free_ = std::move(table.free_list);
    count_ = count;
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
    return (static_cast<uint64_t>(tag_) << 56) | (static_cast<uint64_t>(generation) << 32) | slot;
  }
  uint8_t tag_;
  HostVector<Slot> slots_;
  HostVector<uint32_t> free_;
  size_t count_ = 0;
};

}  // namespace sph
