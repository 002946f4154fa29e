// SPDX-License-Identifier: MIT
#include "async_stepper.h"

#include <utility>

namespace sph {

AsyncStepper::~AsyncStepper() {
  if (!thread_.joinable()) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void AsyncStepper::start(std::function<StepOutcome()> step) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!thread_.joinable()) thread_ = std::thread([this] { run(); });
  step_ = std::move(step);
  done_ = false;
  finished_.store(false, std::memory_order_release);
  wake_.notify_all();
}

StepOutcome AsyncStepper::collect() {
  std::unique_lock<std::mutex> lock(mutex_);
  wake_.wait(lock, [this] { return done_; });
  done_ = false;
  return std::move(outcome_);
}

void AsyncStepper::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return stop_ || step_; });
    if (stop_) return;
    std::function<StepOutcome()> step = std::move(step_);
    step_ = nullptr;
    lock.unlock();
    StepOutcome outcome = step();  // the step catches its own errors
    lock.lock();
    outcome_ = std::move(outcome);
    done_ = true;
    finished_.store(true, std::memory_order_release);
    wake_.notify_all();
  }
}

}  // namespace sph
