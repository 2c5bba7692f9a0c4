// Scene JSON: parse_scene (nlohmann parse + every key's validation) and the
// per-frame evaluation of keyframes and file patterns. No file a scene names
// is opened: that is the VDB, OBJ and image targets' job, and reading paths
// from fuzzed JSON would make this target read arbitrary files.
#include <cmath>
#include <cstdint>
#include <string>

#include "fuzz/FuzzSupport.h"
#include "scene/Scene.h"

using namespace pyrolume;

namespace {

void check_camera(const Scene& s) {
  for (int a = 0; a < 3; ++a) {
    fuzz::require_finite(s.camera.position[a], "camera.position");
    fuzz::require_finite(s.camera.look_at[a], "camera.look_at");
  }
  const glm::dvec3 f = glm::normalize(s.camera.look_at - s.camera.position);
  for (int a = 0; a < 3; ++a) fuzz::require_finite(f[a], "view direction");
  fuzz::require_finite(s.film.exposure, "film.exposure");
  for (const Medium& m : s.media) fuzz::require_finite(m.emission.scale, "emission.scale");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string file = "fuzz/scene.json";
  const std::string text(reinterpret_cast<const char*>(data), size);
  Scene scene;
  try {
    scene = parse_scene(text, file);
  } catch (const InputError& e) {
    fuzz::check_input_error(e, file);
    return 0;
  }
  check_camera(scene);
  // Frames a sequence would render: before, on and after any keys.
  for (int frame : {0, 1, 7, -3, 1000000}) {
    try {
      check_camera(scene_at_frame(scene, frame));
    } catch (const InputError& e) {
      fuzz::check_input_error(e, file);
    }
  }
  return 0;
}
