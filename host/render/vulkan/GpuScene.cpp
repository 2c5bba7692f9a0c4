#include "render/vulkan/GpuScene.h"

#include <cmath>

#include "color/Blackbody.h"
#include "util/Error.h"

namespace pyrolume {
namespace {
gpu::vec4 v4(glm::dvec3 v, double w) { return gpu::vec4(float(v.x), float(v.y), float(v.z), float(w)); }

glm::dvec3 emitted_radiance(const Emission& e) {
  if (e.rgb) return *e.rgb * e.scale;
  if (e.temperature_k) return color::blackbody_rgb(*e.temperature_k, e.blackbody, e.observer, e.adapt_to_k) * e.scale;
  return glm::dvec3(0.0);
}
}  // namespace

std::vector<gpu::GpuMedium> build_gpu_media(const Scene& scene) {
  std::vector<gpu::GpuMedium> out;
  for (size_t i = 0; i < scene.media.size(); ++i) {
    const Medium& m = scene.media[i];
    if (m.type != Medium::Type::Homogeneous)
      throw input_error(scene.file.string(), "media[" + std::to_string(i) + "].type",
                        "\"vdb\" media are not supported by this build yet");
    gpu::GpuMedium g{};
    bool sphere = m.bounds.kind == Bounds::Kind::Sphere;
    g.sigma_a = v4(m.sigma_a, sphere ? gpu::SHAPE_SPHERE : gpu::SHAPE_BOX);
    g.sigma_s = v4(m.sigma_s, m.g);
    // A medium emits sigma_a·Le per unit length (DESIGN.md).
    g.emission = v4(m.sigma_a * emitted_radiance(m.emission), 0.0);
    if (sphere) {
      g.bounds0 = v4(m.bounds.center, m.bounds.radius);
    } else {
      g.bounds0 = v4(m.bounds.min, 0.0);
      g.bounds1 = v4(m.bounds.max, 0.0);
    }
    out.push_back(g);
  }
  if (out.size() > gpu::MAX_MEDIA)
    throw input_error(scene.file.string(), "media", "at most " + std::to_string(gpu::MAX_MEDIA) + " media are supported");
  return out;
}

gpu::FrameConstants build_frame_constants(const Scene& scene, const RenderSettings& s, uint32_t medium_count) {
  const Camera& c = scene.camera;
  glm::dvec3 forward = glm::normalize(c.look_at - c.position);
  glm::dvec3 right = glm::normalize(glm::cross(forward, c.up));  // image x grows along cross(forward, up)
  glm::dvec3 up = glm::cross(right, forward);
  double tan_half = std::tan(glm::radians(c.fov_deg) * 0.5);
  gpu::FrameConstants f{};
  f.camera_position = v4(c.position, tan_half);
  f.camera_forward = v4(forward, double(s.width) / double(s.height));
  f.camera_right = v4(right, 0.0);
  f.camera_up = v4(up, 0.0);
  f.background = v4(scene.background, 0.0);
  f.image = gpu::uvec4(uint32_t(s.width), uint32_t(s.height), medium_count, uint32_t(scene.integrator.max_depth));
  f.sampling = gpu::uvec4(s.seed, s.frame, 0u, 0u);
  return f;
}

}  // namespace pyrolume
