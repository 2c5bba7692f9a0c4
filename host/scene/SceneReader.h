#pragma once
// The scene file's reader (SceneLoader.cpp): a JSON object read key by key,
// remembering which keys were consumed so that leftovers are reported as
// unknown, with a "did you mean" among the keys asked about. Every error
// names the file and the key path (docs/scene-format.md). Only SceneLoader.cpp
// includes it.
#include <cmath>
#include <initializer_list>
#include <set>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "scene/Scene.h"
#include "util/Error.h"
#include "util/Json.h"
#include "util/Suggest.h"

namespace pyrolume::scene_file {

using json = nlohmann::json;

// A JSON object being read: remembers which keys were consumed so leftovers are
// reported as unknown.
class Reader {
 public:
  Reader(const json& j, std::string path, const std::string& file) : j_(j), path_(std::move(path)), file_(file) {
    if (!j_.is_object()) fail("", "expected an object");
  }

  [[noreturn]] void fail(const std::string& key, const std::string& reason) const {
    throw input_error(file_, key.empty() ? path_ : join(key), reason);
  }
  std::string join(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }
  // Every key asked about is one this object may hold: finish() suggests among them.
  bool has(const std::string& key) const {
    asked_.insert(key);
    return j_.contains(key);
  }
  const json& raw(const std::string& key) {
    seen_.insert(key);
    return j_.at(key);
  }

  double number(const std::string& key, double fallback) {
    if (!has(key)) return fallback;
    const json& v = raw(key);
    if (!v.is_number()) fail(key, "expected a number, got " + type_name(v));
    double d = v.get<double>();
    if (!std::isfinite(d)) fail(key, "must be finite");
    return d;
  }
  double number_required(const std::string& key) {
    if (!has(key)) fail(key, "missing required key");
    return number(key, 0.0);
  }
  int integer(const std::string& key, int fallback, int min_value, int max_value) {
    if (!has(key)) return fallback;
    const json& v = raw(key);
    if (!v.is_number_integer() && !v.is_number_unsigned()) fail(key, "expected an integer, got " + type_name(v));
    long long i = v.get<long long>();
    if (i < min_value || i > max_value)
      fail(key, "must be in [" + std::to_string(min_value) + ", " + std::to_string(max_value) + "], got " + std::to_string(i));
    return static_cast<int>(i);
  }
  bool boolean(const std::string& key, bool fallback) {
    if (!has(key)) return fallback;
    const json& v = raw(key);
    if (!v.is_boolean()) fail(key, "expected true or false, got " + type_name(v));
    return v.get<bool>();
  }
  std::string string(const std::string& key, const std::string& fallback) {
    if (!has(key)) return fallback;
    const json& v = raw(key);
    if (!v.is_string()) fail(key, "expected a string, got " + type_name(v));
    return v.get<std::string>();
  }
  // One of `allowed`; with `suggest`, the error names the nearest one too.
  std::string choice(const std::string& key, const std::string& fallback, const std::vector<std::string>& allowed,
                     bool suggest = false) {
    std::string s = string(key, fallback);
    for (const auto& a : allowed)
      if (s == a) return s;
    fail(key, not_one_of(s, allowed, suggest));
  }
  // One of `values`, spelled in the file as its to_string names it.
  template <typename E>
  E enum_choice(const std::string& key, E fallback, std::initializer_list<E> values) {
    return *optional_choice(key, to_string(fallback), values);
  }
  // The same with one more spelling, `none`, read as nullopt (e.g. "auto").
  template <typename E>
  std::optional<E> optional_choice(const std::string& key, const std::string& fallback,
                                   std::initializer_list<E> values, const char* none = nullptr) {
    std::vector<std::string> names;
    if (none) names.push_back(none);
    for (E v : values) names.push_back(to_string(v));
    const std::string s = choice(key, fallback, names);
    for (E v : values)
      if (s == to_string(v)) return v;
    return std::nullopt;  // `none`
  }
  glm::dvec3 vec3(const std::string& key, glm::dvec3 fallback) {
    if (!has(key)) return fallback;
    return finite_vec3(raw(key), key, "expected an array of 3 numbers");
  }
  // v as three finite numbers; `at` and `expected` name the key and the
  // shape in the error.
  glm::dvec3 finite_vec3(const json& v, const std::string& at, const char* expected) const {
    if (!v.is_array() || v.size() != 3) fail(at, expected);
    glm::dvec3 r;
    for (int i = 0; i < 3; ++i) {
      if (!v[i].is_number()) fail(at, expected);
      r[i] = v[i].get<double>();
      if (!std::isfinite(r[i])) fail(at, "must be finite");
    }
    return r;
  }
  // A number, or {"keys": [[frame, number], ...]}: returns the value at frame 0
  // and fills `keys` (docs/animation.md).
  double number_keyed(const std::string& key, double fallback, Keyframes<double>& keys) {
    if (!has(key) || !j_.at(key).is_object()) return number(key, fallback);
    read_keys(key, keys, [&](const json& v, const std::string& at) {
      if (!v.is_number()) fail(at, "expected a number as the key's value, got " + type_name(v));
      double d = v.get<double>();
      if (!std::isfinite(d)) fail(at, "must be finite");
      return d;
    });
    return keys.at(0.0);
  }
  glm::dvec3 vec3_keyed(const std::string& key, glm::dvec3 fallback, Keyframes<glm::dvec3>& keys) {
    if (!has(key) || !j_.at(key).is_object()) return vec3(key, fallback);
    read_keys(key, keys, [&](const json& v, const std::string& at) {
      return finite_vec3(v, at, "expected [x, y, z] as the key's value");
    });
    return keys.at(0.0);
  }
  glm::dvec3 vec3_required(const std::string& key) {
    if (!has(key)) fail(key, "missing required key");
    return vec3(key, {});
  }
  glm::dvec3 nonnegative_rgb(const std::string& key, glm::dvec3 fallback) {
    glm::dvec3 v = vec3(key, fallback);
    if (v.x < 0 || v.y < 0 || v.z < 0) fail(key, "must be >= 0 in every channel");
    return v;
  }
  Reader child(const std::string& key) {
    seen_.insert(key);
    return Reader(j_.at(key), join(key), file_);
  }
  // After reading: any key not consumed is a typo or unsupported.
  void finish() const {
    for (auto it = j_.begin(); it != j_.end(); ++it)
      if (!seen_.count(it.key()))
        fail(it.key(), "unknown key" + did_you_mean(it.key(), std::vector<std::string>(asked_.begin(), asked_.end())));
  }
  const std::string& path() const { return path_; }

  static std::string type_name(const json& v) { return v.type_name(); }

 private:
  // {"keys": [[frame, value], ...]}: non-empty, frames finite and strictly
  // increasing, every value of the parameter's type (parse_value checks).
  template <typename T, typename Parse>
  void read_keys(const std::string& key, Keyframes<T>& keys, Parse parse_value) {
    Reader k = child(key);
    if (!k.has("keys")) k.fail("keys", "missing: a keyframed value is {\"keys\": [[frame, value], ...]}");
    const json& list = k.raw("keys");
    k.finish();
    if (!list.is_array() || list.empty()) fail(key + ".keys", "expected a non-empty array of [frame, value] pairs");
    keys = {};
    for (size_t n = 0; n < list.size(); ++n) {
      const std::string at = key + ".keys[" + std::to_string(n) + "]";
      const json& e = list[n];
      if (!e.is_array() || e.size() != 2) fail(at, "expected [frame, value]");
      if (!e[0].is_number() || !std::isfinite(e[0].get<double>())) fail(at, "the frame must be a finite number");
      const double frame = e[0].get<double>();
      if (!keys.frames.empty() && !(frame > keys.frames.back()))
        fail(at, "frames must increase strictly (" + json(frame).dump() + " after " + json(keys.frames.back()).dump() + ")");
      keys.frames.push_back(frame);
      keys.values.push_back(parse_value(e[1], at));
    }
  }

  const json& j_;
  std::string path_;
  const std::string& file_;
  std::set<std::string> seen_;
  mutable std::set<std::string> asked_;
};

// d scaled by its largest component: the same direction, of length in [1, √3],
// so that [1e300, 1e300, 0] (whose length overflows to infinity) stays a
// direction; nullopt for the zero vector.

}  // namespace pyrolume::scene_file
