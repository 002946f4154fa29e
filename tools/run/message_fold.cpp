// SPDX-License-Identifier: MIT
#include "message_fold.h"

namespace sph_tools {

std::string MessageFold::line(uint32_t frame, const FrameMessage& m) {
  Kind* k = nullptr;
  for (Kind& known : kinds_)
    if (known.kind == m.kind) k = &known;
  if (!k) {
    kinds_.push_back(Kind{m.kind, m.unit});
    k = &kinds_.back();
  }
  // A kind is counted once a frame, however many of its messages the frame holds.
  if (k->last_frame != frame) ++k->frames;
  k->last_frame = frame;
  const std::string head = prefix_ + "frame " + std::to_string(frame) + ": " + m.text;
  if (k->frames < kFramesInFull) return head;
  if (k->frames == kFramesInFull)
    return head + " (from here on, frames with this message are counted and listed at the end)";
  if (k->first_folded == 0) k->first_folded = frame;
  k->last_folded = frame;
  k->folded_count += m.count;
  return "";
}

std::vector<std::string> MessageFold::closing() const {
  std::vector<std::string> lines;
  for (const Kind& k : kinds_) {
    if (k.frames <= kFramesInFull) continue;
    const uint32_t more = k.frames - kFramesInFull;
    std::string text = prefix_ + k.kind + " in " + std::to_string(more) + " more frame" +
                       (more == 1 ? "" : "s") + " (" + std::to_string(k.first_folded) +
                       (more == 1 ? "" : " to " + std::to_string(k.last_folded)) + ", not printed)";
    if (!k.unit.empty()) text += ": " + std::to_string(k.folded_count) + " " + k.unit;
    lines.push_back(text);
  }
  return lines;
}

void FrameMessages::frame(Progress& progress, uint32_t frame, const SceneRuntime& runtime, sph_result step) {
  const auto note = [&](MessageFold& fold, const FrameMessage& m) {
    const std::string line = fold.line(frame, m);
    if (!line.empty()) progress.note(line);
  };
  for (const FrameMessage& w : runtime.warnings()) note(warnings_, w);
  for (const FrameMessage& n : runtime.notices()) note(notices_, n);
  if (step == SPH_INCOMPLETE)
    note(warnings_,
         {"max_substeps ran out before the frame's end",
          "max_substeps ran out before the frame's end (raise params.max_substeps or dt_min)", 0, ""});
}

void FrameMessages::print_closing(std::FILE* out) const {
  for (const MessageFold* fold : {&warnings_, &notices_})
    for (const std::string& line : fold->closing()) std::fprintf(out, "%s\n", line.c_str());
}

}  // namespace sph_tools
