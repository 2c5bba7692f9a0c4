#pragma once
// The scene as parsed and validated from scene JSON (format v1, docs/scene-format.md).
// Units: lengths in scene units, sigma in 1/scene-unit, temperatures in kelvin,
// radiance linear sRGB.
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "color/BlackbodyMode.h"
#include "volume/VolumeOptions.h"

namespace pyrolume {

// A keyframed parameter: {"keys": [[frame, value], ...]} in the scene JSON
// (docs/animation.md). Frames increase strictly; between keys the value is
// interpolated linearly, outside the key range it is held at the first / last
// key (clamped). Empty = not animated (the plain value applies to every frame).
template <typename T>
struct Keyframes {
  std::vector<double> frames;
  std::vector<T> values;

  bool animated() const { return !frames.empty(); }
  T at(double frame) const {
    if (frame <= frames.front()) return values.front();
    if (frame >= frames.back()) return values.back();
    size_t hi = 1;
    while (frames[hi] < frame) ++hi;
    if (frames[hi] == frame) return values[hi];  // exact at a key, no rounding
    const double t = (frame - frames[hi - 1]) / (frames[hi] - frames[hi - 1]);
    return values[hi - 1] + (values[hi] - values[hi - 1]) * t;
  }
};

// The world's up axis as a vector.
inline glm::dvec3 up_axis_vector(UpAxis axis) { return axis == UpAxis::Z ? glm::dvec3(0, 0, 1) : glm::dvec3(0, 1, 0); }

// A camera's up when the file gives none: the scene's up axis, unless the view
// runs (nearly) along it; a view from above or below then has the world's
// front-to-back axis at the top of the image, as Blender's top view has +Y
// (Z up) and Maya's and Houdini's have −Z (Y up).
inline glm::dvec3 default_camera_up(UpAxis axis, const glm::dvec3& view_direction) {
  const glm::dvec3 up = up_axis_vector(axis);
  const double len = glm::length(view_direction);
  if (!(len > 0.0) || glm::length(glm::cross(view_direction / len, up)) > 1e-3) return up;
  return axis == UpAxis::Z ? glm::dvec3(0, 1, 0) : glm::dvec3(0, 0, -1);
}

struct Camera {
  glm::dvec3 position{0, 1, -6};
  glm::dvec3 look_at{0, 1, 0};
  // The file gives neither position nor look_at: the camera frames the scene's
  // media and shapes (host/render/SceneSetup, docs/scene-format.md "camera").
  bool framed_automatically = false;
  bool up_given = false;  // else `up` follows the up axis (default_camera_up)
  Keyframes<glm::dvec3> position_keys, look_at_keys;
  glm::dvec3 up{0, 1, 0};
  double fov_deg = 40.0;  // vertical field of view
};

// film.view: how display output (PNG, the preview) shows the linear render
// (docs/view-transform.md). EXR output is never transformed.
enum class ViewTransform { AgX, Standard, AgXPunchy, Filmic };
// The views as the scene file, --view and errors name them, in that order.
inline constexpr ViewTransform kViewTransforms[] = {ViewTransform::AgX, ViewTransform::AgXPunchy,
                                                    ViewTransform::Filmic, ViewTransform::Standard};
// The default: Filmic, the view closest to Blender 3.4's default view (its
// Filmic) in core and edge hue and luminance range on two Blender fires
// (docs/view-transform.md "Choosing the default"; tools/cycles/compare_views).
inline constexpr ViewTransform kDefaultView = ViewTransform::Filmic;
inline const char* to_string(ViewTransform v) {
  switch (v) {
    case ViewTransform::AgX: return "agx";
    case ViewTransform::Standard: return "standard";
    case ViewTransform::AgXPunchy: return "agx_punchy";
    case ViewTransform::Filmic: return "filmic";
  }
  return "agx";
}
// The names of kViewTransforms, in its order (the scene file, --view, errors).
inline std::vector<std::string> view_names() {
  std::vector<std::string> names;
  for (ViewTransform v : kViewTransforms) names.push_back(to_string(v));
  return names;
}
// The view a name stands for; nullopt for no view's name.
inline std::optional<ViewTransform> view_from_name(const std::string& name) {
  for (ViewTransform v : kViewTransforms)
    if (name == to_string(v)) return v;
  return std::nullopt;
}

// Samples per pixel are 1 to 2^24 (16 777 216) everywhere (film.spp, --spp,
// both backends, a checkpoint's count): per-pixel counts and the GPU's uint
// sample indices then stay exact, float-accumulated per-pixel counters too,
// and image totals (pixels × spp, up to 2^28 · 2^24) need 64-bit arithmetic:
// total_samples() (render/Render.h). The loader and the CLI hand these bounds
// to their range checks, whose messages users see.
inline constexpr int kMinSpp = 1, kMaxSpp = 1 << 24;
inline constexpr bool spp_in_range(long long spp) { return spp >= kMinSpp && spp <= kMaxSpp; }
// A film side is 1..16384 pixels everywhere (film keys, --width/--height,
// checkpoints): 16384² pixels is also the largest EXR that is read.
inline constexpr int kMaxFilmSide = 16384;

// Exposure is at most this many stops either way (film.exposure, --exposure,
// auto exposure): 2^30 already takes the dimmest visible value past white.
inline constexpr double kMaxExposureStops = 30.0;

struct Film {
  int width = 640;
  int height = 360;
  // The file gives width or height: auto-framing keeps the film as it is
  // (otherwise a tall subject turns the default film upright).
  bool size_given = false;
  int spp = 64;
  double exposure = 0.0;  // stops, applied to display output (PNG, preview) only
  Keyframes<double> exposure_keys;
  bool exposure_auto = false;  // "exposure": "auto": chosen from the rendered image (docs/view-transform.md)
  ViewTransform view = kDefaultView;
  uint32_t seed = 1;
  // Camera rays that leave the scene add no radiance (the background or sky
  // still lights it), so RGB over A composites over a plate; PNG then has
  // alpha (docs/compositing.md).
  bool transparent = false;
  // EXR: the light layers and first-hit features (docs/compositing.md "AOVs").
  bool aovs = false;
};

// How emission in media is collected: at absorptions only, at every
// tentative collision, or at tentative collisions plus points along the ray
// at a rate set by the emission (docs/rendering.md "Emission estimators").
enum class EmissionEstimator { Absorption, Collision, Line };
// Per-cell majorants walked by DDA, or one bound per grid (integrator.majorant).
enum class Majorant { Grid, Global };

// Their names in the scene file and in --stats.
inline const char* to_string(EmissionEstimator e) {
  return e == EmissionEstimator::Line ? "line" : e == EmissionEstimator::Collision ? "collision" : "absorption";
}
inline const char* to_string(Majorant m) { return m == Majorant::Global ? "global" : "grid"; }

struct Integrator {
  int max_depth = 8;
  // Light sampling: next-event estimation + MIS (docs/mis.md "When light
  // sampling runs by default"). Absent: wherever something can be lit; true:
  // whenever a light can reach a scattering vertex; false: never. The choice is
  // resolved by select_lights (host/light/LightSelection.h), for both backends.
  std::optional<bool> mis;
  int surface_light_samples = 1;  // next-event samples per surface vertex (with MIS; docs/mis.md)
  // With MIS: a surface vertex's continuation collects its first segment by a ratio-tracked ray (docs/mis.md)
  bool ratio_tracked_continuation = false;
  // With MIS: the share of continuations drawn from the lights instead of the
  // vertex's own lobe, in [0, 1) (unset: 1 − kContinueOwn; docs/mis.md "Guided continuation")
  std::optional<double> guided_continuation;
  // Debug: next-event estimation only, no BSDF/phase-found light (docs/mis.md);
  // asks for light sampling as "mis": true does.
  bool light_only = false;
  // The file's "absorption" | "collision" | "line"; unset: "auto", which is
  // line where a medium's emission is thin (host/render/LineEstimator.h), else
  // collision where lights are sampled (what MIS needs), otherwise absorption.
  // LightSelection::estimator is the value a render uses.
  std::optional<EmissionEstimator> emission_estimator;
  Majorant majorant = Majorant::Grid;
  std::optional<glm::ivec3> majorant_grid;

  // Whether these keys let light sampling run at all: "mis": false turns it
  // off, and so does the absorption estimator (MIS needs the collision one).
  // The one rule behind light_candidates (host/light/LightSelection.h; it
  // also needs max_depth >= 1) and integrator_conflict (which names the key).
  bool allows_light_sampling() const { return mis != false && emission_estimator != EmissionEstimator::Absorption; }
};

struct Environment {
  std::filesystem::path file;  // resolved against the scene folder
  double scale = 1.0;
  double rotation_deg = 0.0;
};

struct Bounds {
  enum class Kind { Sphere, Box };
  Kind kind = Kind::Sphere;
  glm::dvec3 center{0.0};
  double radius = 1.0;
  glm::dvec3 min{0.0}, max{0.0};

  // A sphere's diameter, a box's shortest edge: the thinnest a medium is.
  double smallest_extent() const {
    const glm::dvec3 e = max - min;
    return kind == Kind::Sphere ? 2.0 * radius : std::min({e.x, e.y, e.z});
  }
  double volume() const {
    const glm::dvec3 e = max - min;
    return kind == Kind::Sphere ? 4.0 / 3.0 * 3.14159265358979323846 * radius * radius * radius : e.x * e.y * e.z;
  }
};

struct Emission {
  // Exactly one of rgb / temperature_k is set for homogeneous media; grid media
  // take their temperature from the grid (then neither is set).
  std::optional<glm::dvec3> rgb;
  std::optional<double> temperature_k;
  double scale = 1.0;
  Keyframes<double> scale_keys;
  BlackbodyMode blackbody = BlackbodyMode::StefanBoltzmann;
  int observer = 2;  // CIE 1931 2° or CIE 1964 10°
  std::optional<double> adapt_to_k;
  bool emits() const { return (rgb || temperature_k || is_grid) && scale > 0.0; }
  bool is_grid = false;  // temperature comes from a grid
};

// Which keys of a vdb medium the file wrote: a source convention
// (host/volume/SourceConventions) fills in only the others.
struct ExplicitKeys {
  bool temperature_scale = false, temperature_offset = false, temperature_cutoff = false;
  bool emission = false;  // an "emission" block
  bool temperature_grid = false;
  bool sigma = false;  // sigma_a or sigma_s
  bool density_scale = false;
};

struct Transform {
  glm::dvec3 translate{0.0};
  glm::dvec3 rotate_deg{0.0};  // X, then Y, then Z, right-handed
  glm::dvec3 scale{1.0};
};

struct Medium {
  enum class Type { Homogeneous, Vdb };
  std::string name;
  Type type = Type::Homogeneous;
  Bounds bounds;  // homogeneous only
  glm::dvec3 sigma_a{1.0}, sigma_s{0.0};
  double g = 0.0;  // Henyey–Greenstein, g > 0 scatters forward
  Emission emission;
  // vdb only
  std::filesystem::path file;  // may hold a frame pattern (####, $F4, $F): see scene_at_frame
  std::string density_grid;      // empty: default "density"
  std::string temperature_grid;  // empty: first of temperature, heat, flame
  VolumeSource source = VolumeSource::Auto;
  ExplicitKeys given;
  double density_scale = 1.0;
  TemperatureMapping temperature;
  Transform transform;
  int downsample = 1;
  TextureFormat texture_format = TextureFormat::Auto;  // R32F is also used when values exceed R16F
  double index_offset = 0.0;  // set by the source convention: voxel ijk sits at ijk + this (docs/sources.md)
};

// A surface: a triangle mesh (OBJ), an analytic sphere, or a plane (a
// rectangle, or unbounded along an axis whose size is 0), with a Lambertian
// material whose albedo is a constant or a texture.
struct Shape {
  enum class Type { Mesh, Sphere, Plane };
  Type type = Type::Mesh;
  std::filesystem::path mesh;  // mesh
  Transform transform;         // mesh: scale, rotate (X, Y, Z), translate
  glm::dvec3 center{0.0};      // sphere, plane
  double radius = 1.0;         // sphere
  glm::dvec3 normal{0, 1, 0};  // plane
  glm::dvec2 size{0.0};        // plane: extent along its u and v axes; 0 = unbounded
  glm::dvec3 albedo{0.5};
  std::filesystem::path texture;  // empty: constant albedo
};

// Positions that the renderers intersect in float on the GPU (surface
// vertices, spheres, planes, analytic lights) lie within ±kMaxCoordinate on
// every axis: the products of two coordinates (cross products, squared
// distances, a sphere's r²) then stay within float range.
inline constexpr double kMaxCoordinate = 1e18;

// The most analytic lights a scene may have: every ray loops over all of them
// (the discs it may escape into, the spheres it may hit), so each light costs
// every ray (docs/scene-format.md "lights"; measured in docs/robustness.md).
inline constexpr size_t kMaxLights = 256;
// A distant light's angle_deg is 0 (a delta light) or at least this: a
// narrower disc is finer than a float direction resolves (~6e-8 rad), and its
// 1 − cos θ underflows float long before its angle does.
inline constexpr double kMinDiscAngleDeg = 1e-4;

// A light of the scene's `lights` array (docs/lights.md "Analytic lights").
// Its value is scale × rgb, or scale × the blackbody colour of luminance 1 at
// temperature_k (light_value, host/light/AnalyticLights.h).
struct Light {
  enum class Type { Distant, Point, Spot, Sphere };
  Type type = Type::Point;
  // distant: irradiance (W/m² on a plane facing the light); point, spot:
  // radiant intensity (W/sr); sphere: radiance (W/(m²·sr)). Exactly one of
  // rgb / temperature_k is set.
  std::optional<glm::dvec3> rgb;
  std::optional<double> temperature_k;
  double scale = 1.0;
  glm::dvec3 direction{0, 0, 1};  // unit; distant: toward the light; spot: where it shines
  double angle_deg = 0.0;         // distant: the disc's angular diameter (0: a delta light)
  glm::dvec3 position{0.0};       // point, spot
  double cone_deg = 45.0;         // spot: half-angle of the cone, dark outside
  double falloff_deg = 0.0;       // spot: width of the soft edge inside the cone
  glm::dvec3 center{0.0};         // sphere
  double radius = 1.0;            // sphere
  // Delta lights (point, spot, a distant light of angle 0) are reached only
  // by next-event estimation; the others can also be hit by rays.
  bool is_delta() const { return type == Type::Point || type == Type::Spot || (type == Type::Distant && angle_deg == 0.0); }
};

struct Scene {
  std::filesystem::path file;  // the JSON it came from (for messages)
  // The world's up: the default camera's up, auto-framing's vertical and the
  // environment map's zenith. Unset: from camera.up, else from the media's
  // source, else Y (host/render/SceneSetup).
  std::optional<UpAxis> up_axis;
  Camera camera;
  Film film;
  Integrator integrator;
  glm::dvec3 background{0.0};  // constant radiance seen by escaping rays
  std::optional<Environment> environment;
  std::vector<Medium> media;
  std::vector<Shape> shapes;
  std::vector<Light> lights;
  // "default_lights": a scene where nothing emits or gives light gets the
  // default rig (host/render/SceneSetup, docs/scene-format.md); false: never.
  bool default_lights = true;
};

// Whether anything in the scene can be lit by another light: a surface, or a
// medium that scatters (sigma_s > 0 in some channel). Where nothing is, the
// lights show only themselves and light sampling has nothing to do.
inline bool scene_scatters(const Scene& scene) {
  if (!scene.shapes.empty()) return true;
  for (const Medium& m : scene.media)
    if (m.sigma_s.x > 0.0 || m.sigma_s.y > 0.0 || m.sigma_s.z > 0.0) return true;
  return false;
}

// Integrator keys that contradict each other ("mis": true with the absorption
// estimator; "light_only": true with "mis": false or with absorption): the key
// to name and why. Nullopt: none. The loader refuses such a file; select_lights
// refuses such a Scene built in code.
struct IntegratorConflict {
  std::string key;  // under "integrator"
  std::string reason;
};
// has_lights: the scene has a `lights` array, which only light sampling
// reaches ("mis": false and the absorption estimator contradict it).
std::optional<IntegratorConflict> integrator_conflict(const Integrator& integrator, bool has_lights = false);

// Parse and validate. Throws InputError("FILE: key.path: reason").
// Keyframed values are also stored evaluated at frame 0 (clamped), the frame
// a render without --frames shows; medium files keep their frame patterns.
// A .vdb or .nvdb file (or a frame pattern of them) loads as the shortest
// scene naming it, shortest_scene_text.
Scene load_scene(const std::filesystem::path& file);
// Whether `file` ends in .vdb or .nvdb (any case).
bool is_volume_file(const std::filesystem::path& file);
// {"media": [{"type": "vdb", "file": NAME}]}, NAME the volume's file name.
std::string shortest_scene_text(const std::filesystem::path& volume);
Scene parse_scene(const std::string& json_text, const std::filesystem::path& file);

// ---- animation (host/scene/Animation.cpp, docs/animation.md) ----

// True when `pattern` holds a frame pattern: a run of '#' (zero-padded to the
// run's length) or Houdini's $F<width> / $F (unpadded).
bool has_frame_pattern(const std::string& pattern);
// Every pattern in `pattern` replaced by `frame`.
std::string expand_frame_pattern(const std::string& pattern, int frame);
// The frames whose files exist for a path whose file name holds a frame
// pattern, ascending (the folder's names are read, no file is opened). Empty
// when none exists or the name holds no pattern.
std::vector<int> frames_on_disk(const std::filesystem::path& pattern);
// True when any medium file is a pattern or any parameter has keys.
bool scene_is_animated(const Scene& scene);
bool scene_has_file_patterns(const Scene& scene);
// The scene at `frame`: keyframed values evaluated, medium file patterns
// expanded, keys kept (so it can be evaluated again). Validates what the
// keys may break (camera position vs look_at) with errors naming the frame.
Scene scene_at_frame(const Scene& scene, int frame);

}  // namespace pyrolume
