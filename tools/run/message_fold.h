// SPDX-License-Identifier: MIT
// Repeated frame messages, folded. A scene held at a bound its settings cannot reach (a DFSPH
// solve at its cap, a source at the world's capacity, a load over its threshold) meets the same
// event every frame; printed a line a frame it buries everything else (and --quiet keeps
// warnings). So a message of one kind prints in full for the first kFramesInFull frames it
// occurs in, the last of them saying so; later ones are counted, and the run's end prints one
// line per folded kind: how many more frames, which, and their counts added up.
#ifndef SPH_TOOLS_RUN_MESSAGE_FOLD_H
#define SPH_TOOLS_RUN_MESSAGE_FOLD_H

#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "progress.h"
#include "scene_runtime.h"

namespace sph_tools {

class MessageFold {
 public:
  static constexpr uint32_t kFramesInFull = 3;

  // `prefix` starts every line ("sph-run: warning: ").
  explicit MessageFold(std::string prefix) : prefix_(std::move(prefix)) {}
  // The line to print for message m of `frame`, or "" when it is folded (counted, not printed).
  std::string line(uint32_t frame, const FrameMessage& m);
  // One line per kind that was folded, in the order the kinds first occurred.
  std::vector<std::string> closing() const;

 private:
  struct Kind {
    std::string kind, unit;
    uint32_t frames = 0;  // frames it occurred in, printed or not
    uint32_t last_frame = 0;
    uint32_t first_folded = 0, last_folded = 0;
    uint64_t folded_count = 0;
  };
  std::string prefix_;
  std::vector<Kind> kinds_;
};

// A run's warnings and notices, each folded: what sph-run and sph-run-mpi print for a frame.
class FrameMessages {
 public:
  // `program` heads every line ("sph-run").
  explicit FrameMessages(const std::string& program)
      : warnings_(program + ": warning: "), notices_(program + ": ") {}
  // The frame's messages through `progress`: the runtime's warnings and notices of its last
  // step_frame, and the warning of a step that ended SPH_INCOMPLETE (max_substeps ran out).
  void frame(Progress& progress, uint32_t frame, const SceneRuntime& runtime, sph_result step);
  // The folded kinds' lines, warnings first (after the progress).
  void print_closing(std::FILE* out) const;

 private:
  MessageFold warnings_, notices_;
};

}  // namespace sph_tools

#endif
