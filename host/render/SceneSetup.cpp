#include "render/SceneSetup.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "geometry/Mesh.h"
#include "scene/MediumVolume.h"
#include "util/Error.h"
#include "volume/SourceConventions.h"
#include "volume/VdbInfo.h"
#include "volume/VdbLoader.h"

namespace pyrolume {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Box {
  glm::dvec3 min{kInf}, max{-kInf};
  bool empty() const { return !(min.x <= max.x); }
  void add(const glm::dvec3& p) {
    min = glm::min(min, p);
    max = glm::max(max, p);
  }
};

// The world box of a local box under an affine map: its 8 corners mapped.
Box mapped(const glm::dvec3& lo, const glm::dvec3& hi, const glm::dmat4& M) {
  Box b;
  for (int c = 0; c < 8; ++c)
    b.add(glm::dvec3(M * glm::dvec4((c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z, 1.0)));
  return b;
}

// The grids' active boxes (from the file's metadata; read from the voxels
// when the file stores none), through the medium's transform.
Box grid_box(const VolumeFileInfo& info, const Medium& m, const std::string& file) {
  Box b;
  for (const std::string& name : {m.density_grid, m.temperature_grid}) {
    const GridInfo* g = name.empty() ? nullptr : info.grid(name);
    if (!g || g->empty()) continue;
    auto wb = g->world_bbox();
    if (!wb) {
      const VolumeFileInfo full = read_volume_file_info(file, true, name);
      if (const GridInfo* f = full.grid(name)) wb = f->world_bbox();
    }
    if (!wb) continue;
    // The source's voxel placement moves every voxel by the same world vector.
    const glm::dvec3 shift(g->index_to_world * glm::dvec4(glm::dvec3(m.index_offset), 0.0));
    const Box t = mapped(wb->first + shift, wb->second + shift, medium_transform_matrix(m.transform));
    b.add(t.min);
    b.add(t.max);
  }
  return b;
}

// The front view's directions (docs/scene-format.md "camera"): Blender's for
// Z up (from −Y), Houdini's and Maya's for Y up (from +Z); both put +X to the
// right of the picture.
glm::dvec3 front_forward(UpAxis up) { return up == UpAxis::Z ? glm::dvec3(0, 1, 0) : glm::dvec3(0, 0, -1); }
glm::dvec3 up_vector(UpAxis up) { return up_axis_vector(up); }

// A plane shape facing along the up axis: the automatic camera then looks down on it.
bool has_ground_plane(const Scene& scene, UpAxis up) {
  for (const Shape& s : scene.shapes)
    if (s.type == Shape::Type::Plane && std::abs(glm::dot(glm::normalize(s.normal), up_vector(up))) > 0.9) return true;
  return false;
}

Box union_of(const std::vector<WorldBox>& boxes) {
  Box all;
  for (const WorldBox& w : boxes) {
    all.add(w.min);
    all.add(w.max);
  }
  if (all.empty()) {  // nothing bounded: the unit box at the origin
    all.add(glm::dvec3(-1.0));
    all.add(glm::dvec3(1.0));
  }
  return all;
}

// Width and height of everything, seen from the front.
glm::dvec2 framed_extent(const std::vector<WorldBox>& boxes, UpAxis up) {
  const Box all = union_of(boxes);
  const glm::dvec3 size = all.max - all.min, right = glm::cross(front_forward(up), up_vector(up));
  return {std::abs(glm::dot(size, right)), std::abs(glm::dot(size, up_vector(up)))};
}

UpAxis axis_of(const glm::dvec3& up) { return std::abs(up.z) > std::abs(up.y) ? UpAxis::Z : UpAxis::Y; }

}  // namespace

double ground_tilt_deg(double fov_deg) {
  return std::atan(std::tan(0.5 * fov_deg * std::numbers::pi / 180.0) / 3.0) * 180.0 / std::numbers::pi;
}

Camera framing_camera(const std::vector<WorldBox>& boxes, UpAxis up_axis, double fov_deg, double aspect,
                      double tilt_deg) {
  const Box all = union_of(boxes);
  Camera cam;
  cam.fov_deg = fov_deg;
  cam.up = up_vector(up_axis);
  // Tilted down about the right axis; view_up is the picture's up.
  const double tilt = tilt_deg * std::numbers::pi / 180.0;
  const glm::dvec3 forward = std::cos(tilt) * front_forward(up_axis) - std::sin(tilt) * cam.up;
  const glm::dvec3 right = glm::cross(front_forward(up_axis), cam.up);
  const glm::dvec3 view_up = glm::cross(right, forward);
  const glm::dvec3 centre = 0.5 * (all.min + all.max);
  // Each corner at lateral offsets (a, b) and depth z behind the centre plane
  // is in the picture when |a| <= (d + z)·tan(fov_h/2) and |b| <= (d + z)·tan(fov_v/2),
  // with 5 % of each half-extent to spare.
  const double tan_v = std::tan(0.5 * fov_deg * std::numbers::pi / 180.0) / 1.05;
  const double tan_h = tan_v * aspect;
  double d = 0.0, half_depth = 0.0;
  for (int c = 0; c < 8; ++c) {
    const glm::dvec3 p((c & 1) ? all.max.x : all.min.x, (c & 2) ? all.max.y : all.min.y, (c & 4) ? all.max.z : all.min.z);
    const glm::dvec3 q = p - centre;
    const double a = std::abs(glm::dot(q, right)), b = std::abs(glm::dot(q, view_up)), z = glm::dot(q, forward);
    d = std::max({d, a / tan_h - z, b / tan_v - z});
    half_depth = std::max(half_depth, std::abs(z));
  }
  d = std::max(d, 1.01 * half_depth + 1e-6);  // outside the box
  cam.look_at = centre;
  cam.position = centre - forward * d;
  return cam;
}

std::string nothing_in_view(const Camera& camera, const std::vector<WorldBox>& boxes, double aspect) {
  if (boxes.empty()) return "";
  const glm::dvec3 forward = glm::normalize(camera.look_at - camera.position);
  const glm::dvec3 right = glm::normalize(glm::cross(forward, camera.up));
  const glm::dvec3 up = glm::cross(right, forward);
  const double tan_v = std::tan(0.5 * camera.fov_deg * std::numbers::pi / 180.0), tan_h = tan_v * aspect;
  // Rays through a 17×17 lattice over the picture (edges included) against
  // each box (slab test): fine enough that a box covering a few percent of
  // the picture is always met.
  constexpr int kRays = 17;
  for (const WorldBox& w : boxes)
    for (int j = 0; j < kRays; ++j)
      for (int i = 0; i < kRays; ++i) {
        const double sx = (2.0 * i / (kRays - 1) - 1.0) * tan_h, sy = (2.0 * j / (kRays - 1) - 1.0) * tan_v;
        const glm::dvec3 dir = forward + sx * right + sy * up;
        double t0 = 0.0, t1 = kInf;
        for (int a = 0; a < 3; ++a) {
          const double inv = 1.0 / dir[a];
          double ta = (w.min[a] - camera.position[a]) * inv, tb = (w.max[a] - camera.position[a]) * inv;
          if (std::isnan(ta) || std::isnan(tb)) continue;  // parallel, on the slab's plane
          if (ta > tb) std::swap(ta, tb);
          t0 = std::max(t0, ta);
          t1 = std::min(t1, tb);
        }
        if (t0 <= t1) return "";
      }
  std::string what;
  for (const WorldBox& w : boxes) what += (what.empty() ? "" : ", ") + w.what;
  return "nothing is in the camera's view (" + what +
         " lie outside it); leave out camera.position and camera.look_at to frame the scene automatically";
}

std::string add_default_rig(Scene& scene) {
  if (!scene.default_lights || !scene.lights.empty() || scene.environment || scene.background != glm::dvec3(0.0))
    return "";
  for (const Medium& m : scene.media)
    if (m.emission.emits()) return "";
  scene.background = glm::dvec3(kDefaultRigBackground);
  std::string sun = "";
  // The sun only where light sampling may run (it is a light no ray hits
  // often enough otherwise; "mis": false or the absorption estimator).
  if (scene.integrator.allows_light_sampling()) {
    const glm::dvec3 forward = glm::normalize(scene.camera.look_at - scene.camera.position);
    const glm::dvec3 right = glm::normalize(glm::cross(forward, scene.camera.up));
    const glm::dvec3 up = glm::cross(right, forward);
    // A modelling key from the side and above: toward the light is the
    // camera's right turned 45° up, so the smoke shows a lit and a shadowed half.
    Light l;
    l.type = Light::Type::Distant;
    l.direction = glm::normalize(right + up);
    l.angle_deg = kDefaultRigSunAngleDeg;
    l.temperature_k = kDefaultRigSunK;
    l.scale = kDefaultRigSunIrradiance;
    scene.lights.push_back(l);
    sun = " and a 5500 K sun (irradiance 10) from the camera's right, 45° up";
  }
  return "nothing in the scene emits or gives light, so it is lit by the default rig: a grey background (0.05)" + sun +
         "; write \"default_lights\": false to turn it off";
}

std::string nothing_emits(const Scene& scene) {
  if (!scene.lights.empty() && !scene_scatters(scene) && scene.integrator.max_depth > 0)
    return "the scene's lights light nothing: no medium scatters (sigma_s is 0 unless set) and there are no "
           "surfaces, so only the lights themselves can show: set the media's sigma_s to light smoke";
  if (!scene.lights.empty()) return "";
  if (scene.environment || scene.background != glm::dvec3(0.0)) return "";
  for (const Medium& m : scene.media)
    if (m.emission.emits()) return "";
  return "nothing in the scene gives light (no medium emits, no lights, the background is black, no environment, and "
         "\"default_lights\" is false), so the image will be black: add lights, background.rgb or an environment";
}

SceneSetup complete_scene(Scene& scene, bool film_size_fixed) {
  SceneSetup out;
  std::optional<UpAxis> source_up;
  for (size_t i = 0; i < scene.media.size(); ++i) {
    Medium& m = scene.media[i];
    const std::string at = "media[" + std::to_string(i) + "]";
    if (m.type == Medium::Type::Homogeneous) {
      WorldBox w{m.bounds.min, m.bounds.max, at};
      if (m.bounds.kind == Bounds::Kind::Sphere) w = {m.bounds.center - m.bounds.radius, m.bounds.center + m.bounds.radius, at};
      out.boxes.push_back(w);
      continue;
    }
    // A frame pattern is read as the whole shot: its key frame decides the
    // source and mapping, every frame's box the framing (docs/render-farm.md).
    std::string file = m.file.string();
    std::vector<std::string> shot{file};
    if (has_frame_pattern(file)) {
      const std::vector<int> frames = frames_on_disk(m.file);
      if (frames.empty()) continue;  // no frame at all: the render says which are missing
      const int middle = frames[(frames.size() - 1) / 2];
      if (!out.key_frame) out.key_frame = middle;
      // A medium without the first pattern's key frame reads its own middle one.
      const int key = std::binary_search(frames.begin(), frames.end(), *out.key_frame) ? *out.key_frame : middle;
      shot.clear();
      for (int f : frames) shot.push_back(expand_frame_pattern(file, f));
      file = expand_frame_pattern(file, key);
    }
    std::error_code ec;
    if (!std::filesystem::exists(file, ec)) continue;  // a missing file: the render says so
    const VolumeFileInfo info = read_volume_file_info(file, false);
    SourceConvention c = source_convention(info, m.source, m.temperature_grid);
    if (!m.given.temperature_scale) fit_temperature_mapping(c, file);
    settle_emission(c, file);
    apply_source_convention(m, c);
    if (!source_up) source_up = c.up_axis;
    // A guess is worth a line where it decides something: the mapping of a
    // grid that glows, or the up axis of an automatic camera.
    const bool mapping_written = m.given.temperature_scale && m.given.temperature_offset && m.given.temperature_cutoff;
    const bool guess_decides = (!c.temperature_grid.empty() && m.emission.is_grid && !mapping_written) ||
                               (scene.camera.framed_automatically && !scene.up_axis && !scene.camera.up_given);
    if (c.guessed && guess_decides)
      out.notes.push_back(file + ": source " + std::string(to_string(c.source)) + " (" + c.why +
                          "; set media[" + std::to_string(i) + "].source to choose): " + c.mapping_text);
    Box b;
    for (const std::string& f : shot) {
      const Box fb = f == file ? grid_box(info, m, f) : grid_box(read_volume_file_info(f, false), m, f);
      if (fb.empty()) continue;
      b.add(fb.min);
      b.add(fb.max);
    }
    const std::string name = std::filesystem::path(shot.size() > 1 ? m.file : std::filesystem::path(file)).filename().string();
    if (!b.empty()) out.boxes.push_back({b.min, b.max, at + " (" + name + ")"});
  }
  for (size_t i = 0; i < scene.shapes.size(); ++i) {
    const Shape& s = scene.shapes[i];
    const std::string at = "shapes[" + std::to_string(i) + "]";
    if (s.type == Shape::Type::Sphere) {
      out.boxes.push_back({s.center - s.radius, s.center + s.radius, at});
    } else if (s.type == Shape::Type::Mesh) {
      const geometry::Mesh mesh = geometry::load_obj(s.mesh);
      Box b;
      const glm::dmat4 M = medium_transform_matrix(s.transform);
      for (const glm::vec3& p : mesh.positions) b.add(glm::dvec3(M * glm::dvec4(glm::dvec3(p), 1.0)));
      if (!b.empty()) out.boxes.push_back({b.min, b.max, at});
    }
  }

  if (!scene.up_axis)
    scene.up_axis = scene.camera.up_given ? axis_of(scene.camera.up) : source_up.value_or(UpAxis::Y);
  if (scene.camera.framed_automatically) {
    const glm::dvec2 extent = framed_extent(out.boxes, *scene.up_axis);
    Film& film = scene.film;
    if (!film_size_fixed && extent.y > 1.2 * extent.x && film.width > film.height) std::swap(film.width, film.height);
    const double aspect = double(film.width) / double(film.height);
    const double tilt = has_ground_plane(scene, *scene.up_axis) ? ground_tilt_deg(scene.camera.fov_deg) : 0.0;
    const Camera c = framing_camera(out.boxes, *scene.up_axis, scene.camera.fov_deg, aspect, tilt);
    scene.camera.position = c.position;
    scene.camera.look_at = c.look_at;
    if (!scene.camera.up_given) scene.camera.up = c.up;
  } else if (!scene.camera.up_given) {
    scene.camera.up = default_camera_up(*scene.up_axis, scene.camera.look_at - scene.camera.position);
  }
  if (const std::string note = add_default_rig(scene); !note.empty()) out.notes.push_back(scene.file.string() + ": " + note);
  return out;
}

}  // namespace pyrolume
