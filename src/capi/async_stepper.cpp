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

void AsyncStepper::start(std::function<StepOutcome()> step, const TaskSystem& tasks) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!tasks && !thread_.joinable()) thread_ = std::thread([this] { run(); });
    step_ = std::move(step);
    done_ = false;
    finished_.store(false, std::memory_order_release);
    if (!tasks) {
      wake_.notify_all();
      return;
    }
  }
  // Enqueued without mutex_ held: the task system may run the task on this thread at once.
  const TaskFn entry = [](uint32_t, uint32_t, uint32_t, void* self) {
    static_cast<AsyncStepper*>(self)->run_step();
  };
  void* task = tasks.enqueue(entry, 1, 1, this, tasks.user_context);
  std::lock_guard<std::mutex> lock(mutex_);
  tasks_ = tasks;
  task_ = task;
}

StepOutcome AsyncStepper::collect() {
  TaskSystem tasks;
  void* task = nullptr;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    tasks = tasks_;
    std::swap(task, task_);
  }
  // Without mutex_ held: finish may run the step's item on this thread.
  if (task) tasks.finish(task, tasks.user_context);
  std::unique_lock<std::mutex> lock(mutex_);
  wake_.wait(lock, [this] { return done_; });
  done_ = false;
  return std::move(outcome_);
}

void AsyncStepper::run_step() {
  std::function<StepOutcome()> step;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    step = std::move(step_);
    step_ = nullptr;
  }
  publish(step());  // the step catches its own errors
}

void AsyncStepper::publish(StepOutcome outcome) {
  std::lock_guard<std::mutex> lock(mutex_);
  outcome_ = std::move(outcome);
  done_ = true;
  finished_.store(true, std::memory_order_release);
  wake_.notify_all();
}

void AsyncStepper::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return stop_ || step_; });
    if (stop_) return;
    lock.unlock();
    run_step();
    lock.lock();
  }
}

}  // namespace sph
