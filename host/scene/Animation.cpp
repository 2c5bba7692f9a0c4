// Frames of an animated scene: frame patterns in medium files (Blender's and
// Houdini's conventions) and keyframed parameters evaluated at a frame
// (docs/animation.md).
#include <algorithm>
#include <cstdio>
#include <regex>

#include "scene/Scene.h"
#include "util/Error.h"

namespace pyrolume {
namespace {

// One pattern occurrence in `s` at or after `from`: [pos, pos + len), padded
// to `width` digits (0 = no padding).
struct PatternMatch {
  size_t pos = std::string::npos, len = 0;
  int width = 0;
};

PatternMatch find_pattern(const std::string& s, size_t from) {
  for (size_t i = from; i < s.size(); ++i) {
    if (s[i] == '#') {
      size_t j = i;
      while (j < s.size() && s[j] == '#') ++j;
      return {i, j - i, int(j - i)};
    }
    // Houdini: $F4 = zero-padded to 4 digits, $F = the plain number.
    if (s[i] == '$' && i + 1 < s.size() && s[i + 1] == 'F') {
      size_t j = i + 2;
      int width = 0;
      if (j < s.size() && s[j] >= '1' && s[j] <= '9') {
        width = s[j] - '0';
        ++j;
      }
      return {i, j - i, width};
    }
  }
  return {};
}

std::string padded(int frame, int width) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%0*d", width, frame);
  return buf;
}

}  // namespace

bool has_frame_pattern(const std::string& pattern) { return find_pattern(pattern, 0).pos != std::string::npos; }

std::string expand_frame_pattern(const std::string& pattern, int frame) {
  std::string out;
  size_t at = 0;
  for (PatternMatch m = find_pattern(pattern, 0); m.pos != std::string::npos; m = find_pattern(pattern, at)) {
    out += pattern.substr(at, m.pos - at);
    out += padded(frame, m.width);
    at = m.pos + m.len;
  }
  return out + pattern.substr(at);
}

std::vector<int> frames_on_disk(const std::filesystem::path& pattern) {
  const std::string name = pattern.filename().string();
  if (!has_frame_pattern(name)) return {};
  // The name as a regex: literal text escaped, each pattern a run of digits.
  std::string re;
  size_t at = 0;
  auto literal = [&](const std::string& text) {
    for (char c : text) {
      if (std::string("\\^$.|?*+()[]{}").find(c) != std::string::npos) re += '\\';
      re += c;
    }
  };
  for (PatternMatch m = find_pattern(name, 0); m.pos != std::string::npos; m = find_pattern(name, at)) {
    literal(name.substr(at, m.pos - at));
    re += "([0-9]{1,9})";
    at = m.pos + m.len;
  }
  literal(name.substr(at));
  const std::regex match(re);
  const std::filesystem::path folder = pattern.has_parent_path() ? pattern.parent_path() : std::filesystem::path(".");
  std::vector<int> frames;
  std::error_code ec;
  for (std::filesystem::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string entry = it->path().filename().string();
    std::smatch found;
    if (!std::regex_match(entry, found, match)) continue;
    const int frame = std::stoi(found[1].str());
    // "00007" is not frame 7 of "####": the name must be the pattern's own spelling.
    if (expand_frame_pattern(name, frame) == entry) frames.push_back(frame);
  }
  std::sort(frames.begin(), frames.end());
  frames.erase(std::unique(frames.begin(), frames.end()), frames.end());
  return frames;
}

bool scene_has_file_patterns(const Scene& scene) {
  for (const Medium& m : scene.media)
    if (m.type == Medium::Type::Vdb && has_frame_pattern(m.file.string())) return true;
  return false;
}

bool scene_is_animated(const Scene& scene) {
  if (scene_has_file_patterns(scene)) return true;
  if (scene.camera.position_keys.animated() || scene.camera.look_at_keys.animated() ||
      scene.film.exposure_keys.animated())
    return true;
  for (const Medium& m : scene.media)
    if (m.emission.scale_keys.animated()) return true;
  return false;
}

Scene scene_at_frame(const Scene& scene, int frame) {
  Scene s = scene;
  const double f = double(frame);
  if (s.camera.position_keys.animated()) s.camera.position = s.camera.position_keys.at(f);
  if (s.camera.look_at_keys.animated()) s.camera.look_at = s.camera.look_at_keys.at(f);
  if (s.film.exposure_keys.animated()) s.film.exposure = s.film.exposure_keys.at(f);
  for (Medium& m : s.media) {
    if (m.emission.scale_keys.animated()) m.emission.scale = m.emission.scale_keys.at(f);
    if (m.type == Medium::Type::Vdb) m.file = expand_frame_pattern(m.file.string(), frame);
  }
  // What keys can break: the parse-time checks, now at this frame.
  const glm::dvec3 forward = s.camera.look_at - s.camera.position;
  if (!s.camera.up_given) s.camera.up = default_camera_up(s.up_axis.value_or(UpAxis::Y), forward);
  const std::string at = " at frame " + std::to_string(frame);
  if (glm::length(forward) == 0)
    throw input_error(scene.file.string(), "camera.look_at", "must differ from position" + at);
  if (glm::length(glm::cross(glm::normalize(forward), s.camera.up)) < 1e-9)
    throw input_error(scene.file.string(), "camera.up", "must not be parallel to the view direction" + at);
  return s;
}

}  // namespace pyrolume
