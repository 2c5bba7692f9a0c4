#pragma once
// What a scene file may leave to pyrolume, settled before rendering
// (docs/scene-format.md, docs/sources.md): each vdb medium's source convention
// (grids, temperature mapping), the scene's up axis, and a camera that frames
// the scene when the file places none. Both backends then render the completed
// Scene as written.
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "scene/Scene.h"

namespace pyrolume {

// A world-space axis-aligned box around something that renders.
struct WorldBox {
  glm::dvec3 min{0.0}, max{0.0};
  std::string what;  // "media[0] (fire.vdb)", "shapes[1]"
};

struct SceneSetup {
  std::vector<std::string> notes;  // one stderr line each, for the user (e.g. a guessed source)
  std::vector<WorldBox> boxes;     // the media and bounded shapes (unbounded planes left out)
};

// Completes `scene` in place. Frame patterns in medium files are read at
// `frame` (a missing file is skipped here; the render reports it). When the
// camera is framed automatically and neither the file nor the command line
// (`film_size_fixed`) sets the film's size, a subject taller than wide turns
// the film upright (width and height swapped) when it is over 1.2 times taller than wide. Throws InputError for
// unreadable files.
SceneSetup complete_scene(Scene& scene, int frame, bool film_size_fixed);

// Where a camera sits to frame `boxes` from the front (looking along +Z for a
// Y-up scene, along +Y for a Z-up one) with a vertical field of view of
// fov_deg: every corner inside the picture with a 5 % margin.
Camera framing_camera(const std::vector<WorldBox>& boxes, UpAxis up, double fov_deg, double aspect);

// The default rig (docs/scene-format.md "default_lights"): a dim grey
// background and a sun keyed from above and beside the camera.
inline constexpr double kDefaultRigBackground = 0.05;
inline constexpr double kDefaultRigSunIrradiance = 10.0;
inline constexpr double kDefaultRigSunK = 5500.0;
inline constexpr double kDefaultRigSunAngleDeg = 0.53;  // the Sun's angular diameter

// Adds the default rig to a scene in which nothing emits or gives light
// (nothing_emits would say so) when its default_lights allows; after the
// camera is settled. The note line to print, or "" when nothing was added.
std::string add_default_rig(Scene& scene);

// "" when something in the scene gives light (an emitting medium, a
// background, an environment, or `lights` with something to light: a
// surface or a scattering medium); otherwise a one-line reason.
std::string nothing_emits(const Scene& scene);

// "" when some box is in the camera's view; otherwise a one-line reason.
std::string nothing_in_view(const Camera& camera, const std::vector<WorldBox>& boxes, double aspect);

}  // namespace pyrolume
