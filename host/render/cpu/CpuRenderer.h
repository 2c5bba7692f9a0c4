#pragma once
// The CPU reference renderer: plain, double precision, written independently of
// the GLSL path so that it can catch the GPU path's mistakes (issue 2, part 3).
// Homogeneous media (sphere / box bounds) and grid (vdb) media, overlapping media
// add; delta tracking with one global majorant per medium (Media.h); opaque
// two-sided Lambertian surfaces (meshes, spheres, planes, albedo textures;
// geometry/Surfaces.h); a constant background or a lat-long environment map
// (light/EnvironmentMap.h) for escaping rays; the scene's analytic lights
// (sun, point, spot, sphere; docs/lights.md); the "absorption" and "collision"
// emission estimators; Henyey–Greenstein scattering. Directions come from the
// BSDF / phase function and, with light sampling, next-event estimation
// combined by MIS (docs/mis.md).
#include <string>

#include <glm/glm.hpp>

#include "render/Backend.h"
#include "scene/Scene.h"

namespace pyrolume {

class CpuRenderer : public Backend {
 public:
  // threads <= 0: std::thread::hardware_concurrency(). The image does not depend
  // on the thread count (per-sample RNG streams, per-pixel sums in sample order).
  explicit CpuRenderer(int threads = 0);

  std::string name() const override { return "cpu"; }
  std::string device_name() const override;  // "CPU reference (N threads)"
  int threads() const { return threads_; }

  // Throws InputError for unreadable grids, meshes, textures and environment
  // maps (naming the file) and std::invalid_argument for bad settings.
  RenderResult render(const Scene& scene, const RenderSettings& settings, const RenderControl& control) override;

  // Bytes of its AccumulationState for a width×height render: Σ L, Σ L², Σα
  // and Σα² as doubles, then three uint64 counters (CpuRenderer.cpp save_state).
  static uint64_t accumulation_bytes(int width, int height);
  // Non-finite sums in such a state (a checkpoint must have none: resumed,
  // each would be a NaN pixel however many samples follow).
  static uint64_t nonfinite_sums(const AccumulationState& state);

  // Samples per pixel per progressive pass (progress/cancel/time-limit granularity).
  static constexpr int kPassSpp = 4;

  // Tentative collisions of the last render() where σt(x) exceeded the majorant
  // (a negative null-collision probability). Must be 0; tests check it.
  uint64_t majorant_violations() const { return majorant_violations_; }

 private:
  int threads_;
  uint64_t majorant_violations_ = 0;
};

namespace cpu {

// Camera ray through the continuous film position (fx, fy) in pixels, (0,0) =
// top-left corner of the image, y down (docs/scene-format.md "camera": vertical
// fov, image x along normalize(cross(forward, up))). Returns a unit direction.
glm::dvec3 camera_ray_direction(const Camera& camera, int width, int height, double fx, double fy);

}  // namespace cpu
}  // namespace pyrolume
