#pragma once
// The CPU reference's random walk (Walk.cpp): one channel of one path through
// the media, surfaces and lights, and what every walk reads. Written apart
// from the GPU's shaders (path.glsl, tracking.glsl) so that each can catch the
// other's mistakes.
#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "geometry/Surfaces.h"
#include "render/cpu/Lights.h"
#include "render/cpu/Media.h"
#include "render/cpu/Rng.h"

namespace pyrolume::cpu {

// Per-thread working memory of the walks.
struct Scratch {
  std::vector<Span> spans;
  std::vector<double> cuts;
  std::vector<int> present;
  std::vector<double> rho;  // density looked up at the current collision, per present medium
  std::vector<double> lobe_w, lobe_g;  // the phase mixture at a scattering: σs_i/σs and g_i
  LeCache Le_cache;
  // The walk of a light ray runs inside the walk that sampled it and needs
  // scratch of its own.
  std::unique_ptr<Scratch> nested;
  Scratch& light_ray() {
    if (!nested) nested = std::make_unique<Scratch>();
    return *nested;
  }
};

// SIGINT/SIGTERM inside a pass (RenderControl::cancel): one path in a
// pathologically dense medium may take minutes of null collisions, so the
// flag is polled every kCancelPollSteps tracking steps (and samples), not only
// between passes, and the pass is abandoned by this exception.
struct PassCancelled {};
constexpr uint32_t kCancelPollSteps = 4096;

struct ThreadCounters {
  uint64_t collisions = 0;       // real collisions (absorption + scattering)
  uint64_t density_lookups = 0;  // trilinear density-texture samples
  uint64_t majorant_violations = 0;
  uint64_t nonfinite = 0;
  const std::atomic<bool>* cancel = nullptr;
  uint32_t until_poll = kCancelPollSteps;
  // One step of work (a tentative collision, a sample): throws PassCancelled
  // once the cancel flag is seen.
  void step() {
    if (--until_poll != 0) return;
    until_poll = kCancelPollSteps;
    if (cancel && cancel->load(std::memory_order_relaxed)) throw PassCancelled{};
  }
};

// What every walk reads: the media, the surfaces, what escaping rays see, the
// lights and the integrator's settings.
struct WalkScene {
  const MediaData& md;
  const geometry::Surfaces& surfaces;
  glm::dvec3 background;
  int max_depth;
  bool collision_estimator;
  const WalkLights& lights;
  bool transparent;  // film.transparent: the camera ray adds nothing where it escapes

  // Radiance of channel c seen by a ray escaping along d (camera and scattered
  // rays alike): the environment map replaces background.rgb (docs/scene-format.md "environment");
  // each disc sun whose cone holds d adds its radiance (docs/lights.md).
  double escaped(const glm::dvec3& d, int c) const {
    double L = lights.environment ? lights.environment->radiance(d)[c] : background[c];
    for (const AnalyticLight& l : lights.analytic)
      if (l.is_disc() && in_cone(d, l.light.direction, l.disc_omc)) L += l.disc_L[c];
    return L;
  }
};

// What the media are at a point, channel c: σa and σs summed over the media
// present (s.present), one record; s.rho keeps each one's density for the
// phase mixture and the emission. The walk decides absorb, scatter or null.
struct MediumCoefficients {
  double sigma_a = 0.0, sigma_s = 0.0;
};
MediumCoefficients coefficients_at(const MediaData& md, int c, const glm::dvec3& x, Scratch& s, ThreadCounters& cnt);

// Σ σa_i Le_i of channel c at x over the media present (after coefficients_at).
double emitted_at(const MediaData& md, int c, const glm::dvec3& x, Scratch& s);

// A light ray (next-event estimation) or a path: how the walk treats tentative collisions.
enum class WalkRole { Path, LightRay };

// film.aovs (docs/compositing.md "AOVs"): what a camera path's channel walk
// tells the layers and features. The walk's L splits at its first vertex:
// before_vertex (all of L when it has none) less direct (the background or
// sphere light the camera ray sees) is emission; direct is background; the
// rest is scatter or surface, by the first vertex's kind.
struct WalkAov {
  enum class Vertex { None, Medium, Surface } first_vertex = Vertex::None;
  double direct = 0.0, before_vertex = 0.0;
  // The camera ray's first event (a real collision, a surface, a sphere light).
  bool has_feature = false;
  double albedo = 0.0;  // this channel's
  glm::dvec3 normal{0.0};
  double depth = 0.0;
};

// One random walk of channel c from o along d (Walk.cpp says how).
// camera_escaped: set when the walk's first ray (a camera ray) leaves the scene.
// aov: filled for a camera path (role Path) when given.
double walk_channel(const WalkScene& ws, int c, glm::dvec3 o, glm::dvec3 d, Pcg32& rng, ThreadCounters& cnt,
                    Scratch& s, int max_depth, WalkRole role = WalkRole::Path, bool* camera_escaped = nullptr,
                    WalkAov* aov = nullptr);

}  // namespace pyrolume::cpu
