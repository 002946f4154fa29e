// Per-particle arrays of the CPU backend. Every array is registered here once; after the
// neighbour sort, permute() reorders all of them in one pass, so a module that adds an
// attribute never has to remember to sort it.
#pragma once

#include <stddef.h>
#include <stdint.h>

#include <memory>
#include <vector>

namespace sph {

class HostArrayBase {
 public:
  virtual ~HostArrayBase() = default;
  virtual void resize(size_t n) = 0;
  virtual void gather(const uint32_t* order, size_t n) = 0;  // new[i] = old[order[i]]
  virtual size_t bytes() const = 0;
  virtual std::unique_ptr<HostArrayBase> clone() const = 0;
  virtual void assign_from(const HostArrayBase& other) = 0;
};

template <class T>
class HostArray final : public HostArrayBase {
 public:
  std::vector<T> data;

  void resize(size_t n) override { data.resize(n); }
  void gather(const uint32_t* order, size_t n) override {
    scratch_.resize(data.size());
    for (size_t i = 0; i < n; ++i) scratch_[i] = data[order[i]];
    data.swap(scratch_);
  }
  size_t bytes() const override { return (data.capacity() + scratch_.capacity()) * sizeof(T); }
  std::unique_ptr<HostArrayBase> clone() const override {
    auto copy = std::make_unique<HostArray<T>>();
    copy->data = data;
    return copy;
  }
  void assign_from(const HostArrayBase& other) override {
    data = static_cast<const HostArray<T>&>(other).data;
  }

 private:
  std::vector<T> scratch_;
};

class HostParticleStore {
 public:
  template <class T>
  HostArray<T>& add() {
    arrays_.push_back(std::make_unique<HostArray<T>>());
    return static_cast<HostArray<T>&>(*arrays_.back());
  }

  // Registers an array of a custom kind (one whose gather does more than move elements).
  template <class A>
  A& add_array(std::unique_ptr<A> array) {
    A& ref = *array;
    arrays_.push_back(std::move(array));
    return ref;
  }

  void resize(size_t n) {
    for (auto& a : arrays_) a->resize(n);
  }

  void permute(const uint32_t* order, size_t n) {
    for (auto& a : arrays_) a->gather(order, n);
  }

  size_t bytes() const {
    size_t total = 0;
    for (const auto& a : arrays_) total += a->bytes();
    return total;
  }

  // A full copy of every array, to roll a failed step back.
  std::vector<std::unique_ptr<HostArrayBase>> snapshot() const {
    std::vector<std::unique_ptr<HostArrayBase>> copy;
    copy.reserve(arrays_.size());
    for (const auto& a : arrays_) copy.push_back(a->clone());
    return copy;
  }

  void restore(const std::vector<std::unique_ptr<HostArrayBase>>& copy) {
    for (size_t i = 0; i < arrays_.size(); ++i) arrays_[i]->assign_from(*copy[i]);
  }

 private:
  std::vector<std::unique_ptr<HostArrayBase>> arrays_;
};

}  // namespace sph
