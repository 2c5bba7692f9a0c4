#pragma once
// Frame ranges for `render --frames A-B[:step]` (docs/animation.md).
#include <cstdint>
#include <string>

namespace pyrolume {

// The frames first, first + step, ... <= last, visited one at a time: a range
// of 10^9 frames holds no list (`for (int f : range)`).
struct FrameRange {
  int first = 0, last = 0, step = 1;

  class Iterator {
   public:
    Iterator(int64_t frame, int step) : frame_(frame), step_(step) {}
    int operator*() const { return int(frame_); }
    Iterator& operator++() {
      frame_ += step_;
      return *this;
    }
    // Only comparisons with end() are meaningful: past it counts as at it.
    bool operator!=(const Iterator& end) const { return frame_ < end.frame_; }

   private:
    int64_t frame_;  // 64-bit: last + step must not overflow
    int step_;
  };
  Iterator begin() const { return {first, step}; }
  Iterator end() const { return {int64_t(last) + 1, step}; }
  uint64_t count() const { return uint64_t(int64_t(last) - first) / uint64_t(step) + 1; }
};

// "A-B", "A-B:step" or "A" (one frame). Frames >= 0, B >= A, step >= 1.
// Throws InputError naming --frames.
FrameRange parse_frame_range(const std::string& text);

}  // namespace pyrolume
