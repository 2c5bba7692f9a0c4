#pragma once
// Frame ranges for `render --frames A-B[:step]` (docs/animation.md).
#include <string>
#include <vector>

namespace pyrolume {

struct FrameRange {
  int first = 0, last = 0, step = 1;
  std::vector<int> frames() const;  // first, first + step, ... <= last
};

// "A-B", "A-B:step" or "A" (one frame). Frames >= 0, B >= A, step >= 1.
// Throws InputError naming --frames.
FrameRange parse_frame_range(const std::string& text);

}  // namespace pyrolume
