// SPDX-License-Identifier: MIT
// What runs a frame begun by sph_world_step_begin until sph_world_step_wait collects it: one
// task of the engine's task system when the world's CPU context has one (core/task_system.h;
// the library then starts no thread), else the world's own thread, started by the world's first
// asynchronous step and kept until the world is destroyed, so its OpenMP team (the CPU
// backend's workers) and the CUDA backend's host thread stay warm from frame to frame.
#pragma once

#include <atomic>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

#include "../core/status.h"
#include "../core/task_system.h"

namespace sph {

// How a step ended: Ok, Incomplete, or an error with the message the synchronous call gives.
struct StepOutcome {
  Status status = Status::Ok;
  std::string message;
};

// Raised once, by whichever comes first: a step's device work is enqueued, or the step ended
// (sph_cuda_world_step_begin_on_stream returns when it is raised).
class StepSignal {
 public:
  void raise() {
    std::lock_guard<std::mutex> lock(mutex_);
    raised_ = true;
    raised_changed_.notify_all();
  }
  void wait() {
    std::unique_lock<std::mutex> lock(mutex_);
    raised_changed_.wait(lock, [this] { return raised_; });
  }

 private:
  std::mutex mutex_;
  std::condition_variable raised_changed_;
  bool raised_ = false;
};

class AsyncStepper {
 public:
  AsyncStepper() = default;
  ~AsyncStepper();  // stops the thread if there is one (no step may be running: the world's lock says so)
  AsyncStepper(const AsyncStepper&) = delete;
  AsyncStepper& operator=(const AsyncStepper&) = delete;

  // Runs `step` as one task of one item of `tasks` when it is a task system: enqueued from the
  // calling thread, which may run it before enqueue returns (the task system's choice; the step
  // has then ended when start returns). Without one, on the world's thread (started here the
  // first time; std::system_error if the system has no thread to give). The caller holds the
  // world's lock and hands it to the step. A world uses one way for its life (its context's).
  void start(std::function<StepOutcome()> step, const TaskSystem& tasks = TaskSystem{});
  // Waits for the step that start() began (through the task system's finish for a task) and
  // returns how it ended.
  StepOutcome collect();
  bool finished() const { return finished_.load(std::memory_order_acquire); }

  // Raised by sph_world_step_begin once the step runs, lowered (under the handle registry's
  // mutex) by the one sph_world_step_wait that collects it: the world's lock belongs to the
  // step meanwhile.
  std::atomic<bool> pending{false};

 private:
  void run();                         // the world's thread
  void run_step();                    // takes step_, runs it, publishes the outcome
  void publish(StepOutcome outcome);  // outcome_, done_ and finished_, under mutex_

  std::mutex mutex_;
  std::condition_variable wake_;
  std::thread thread_;
  std::function<StepOutcome()> step_;  // set: a step to run
  bool stop_ = false;
  bool done_ = false;
  StepOutcome outcome_;
  std::atomic<bool> finished_{false};
  TaskSystem tasks_;      // the task system that holds task_
  void* task_ = nullptr;  // the step's task until collect finishes it (null: none, or it ran inline)
};

}  // namespace sph
