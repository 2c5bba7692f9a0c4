#include "util/Json.h"

#include <set>
#include <vector>

#include "util/Error.h"

namespace pyrolume {

nlohmann::json parse_json_unique_keys(const std::string& text, const std::string& file) {
  using json = nlohmann::json;
  // One frame per open object or array: the keys seen so far, or the index of
  // the element being read, so the message can give the key's full path.
  struct Frame {
    bool array = false;
    size_t index = 0;
    std::string key;
    std::set<std::string> keys;
  };
  std::vector<Frame> stack;
  auto path = [&] {
    std::string p;
    for (const Frame& f : stack) {
      if (f.array) {
        p.push_back('[');
        p.append(std::to_string(f.index));
        p.push_back(']');
      }
      else if (!f.key.empty()) {
        if (!p.empty()) p.push_back('.');
        p.append(f.key);
      }
    }
    return p;
  };
  auto element_done = [&] {
    if (!stack.empty() && stack.back().array) ++stack.back().index;
  };
  json::parser_callback_t check = [&](int /*depth*/, json::parse_event_t event, json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
        stack.push_back(Frame{});
        break;
      case json::parse_event_t::array_start:
        stack.emplace_back();
        stack.back().array = true;
        break;
      case json::parse_event_t::key: {
        Frame& top = stack.back();
        top.key = parsed.get<std::string>();
        if (!top.keys.insert(top.key).second)
          throw input_error(file, path(), "duplicate key (an object may name each key once; which one is meant?)");
        break;
      }
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        stack.pop_back();
        element_done();
        break;
      case json::parse_event_t::value:
        element_done();
        break;
    }
    return true;
  };
  return json::parse(text, check);
}

}  // namespace pyrolume
