#include "cli/Sequence.h"

#include <cctype>
#include <climits>

#include "util/Error.h"

namespace pyrolume {
namespace {

// A non-negative decimal integer filling [begin, end) of s.
bool parse_uint(const std::string& s, size_t begin, size_t end, int& out) {
  if (begin >= end || end - begin > 9) return false;
  long long v = 0;
  for (size_t i = begin; i < end; ++i) {
    if (!std::isdigit(static_cast<unsigned char>(s[i]))) return false;
    v = v * 10 + (s[i] - '0');
  }
  out = int(v);
  return true;
}

}  // namespace

FrameRange parse_frame_range(const std::string& text) {
  auto bad = [&](const std::string& why) {
    return input_error("--frames", "", "\"" + text + "\": " + why);
  };
  FrameRange r;
  const size_t colon = text.find(':');
  const size_t body_end = colon == std::string::npos ? text.size() : colon;
  const size_t dash = text.find('-');
  if (dash != std::string::npos && dash < body_end) {
    if (!parse_uint(text, 0, dash, r.first) || !parse_uint(text, dash + 1, body_end, r.last))
      throw bad("expected A-B[:step] with frames >= 0, e.g. 1-120 or 1-120:2");
  } else {
    if (!parse_uint(text, 0, body_end, r.first)) throw bad("expected A-B[:step] with frames >= 0, e.g. 1-120 or 1-120:2");
    r.last = r.first;
  }
  if (colon != std::string::npos && (!parse_uint(text, colon + 1, text.size(), r.step) || r.step < 1))
    throw bad("the step after ':' must be an integer >= 1");
  if (r.last < r.first) throw bad("the last frame comes before the first");
  return r;
}

}  // namespace pyrolume
