#pragma once
// What a scene file may leave to pyrolume, settled before rendering
// (docs/scene-format.md, docs/sources.md): each vdb medium's source convention
// (grids, temperature mapping), the scene's up axis, and a camera that frames
// the scene when the file places none. Both backends then render the completed
// Scene as written.
#include <optional>
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
  // A scene with frame patterns: the shot's key frame, the middle one of the
  // first pattern's frames on disk. Its file decides the source convention,
  // and auto exposure is chosen from its render (docs/render-farm.md).
  std::optional<int> key_frame;
};

// Completes `scene` in place. A medium file that is a frame pattern stands
// for its whole shot, every frame on disk, whatever frames are rendered: the
// source convention comes from the key frame's file and the framing from the
// union of every frame's box (file metadata; voxels only where a file stores
// no box). When the camera is framed automatically and neither the file nor
// the command line (`film_size_fixed`) sets the film's size, a subject over
// 1.2 times taller than wide turns the film upright (width and height
// swapped). An omitted camera.up follows the up axis (default_camera_up).
// Throws InputError for unreadable files.
SceneSetup complete_scene(Scene& scene, bool film_size_fixed);

// Where a camera sits to frame `boxes` from the front (looking along +Z for a
// Y-up scene, along +Y for a Z-up one), tilted down by tilt_deg, with a
// vertical field of view of fov_deg: every corner inside the picture with a
// 5 % margin.
Camera framing_camera(const std::vector<WorldBox>& boxes, UpAxis up, double fov_deg, double aspect,
                      double tilt_deg = 0.0);

// The automatic camera's downward tilt over a ground plane: the horizon then
// lies a third of the way from the centre to the top of the picture.
double ground_tilt_deg(double fov_deg);

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
