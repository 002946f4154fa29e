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
#include <string>
#include <utility>
#include <vector>

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

// The warning for a frame that ended with SPH_INCOMPLETE (max_substeps ran out).
FrameMessage incomplete_frame_message();

}  // namespace sph_tools

#endif
