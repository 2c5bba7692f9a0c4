#include "render/cpu/Aovs.h"

#include <algorithm>
#include <limits>

#include "geometry/SceneSurfaces.h"
#include "render/Render.h"
#include "render/cpu/CpuRenderer.h"

namespace pyrolume::cpu {

// Each channel's walk is its own path, so each channel splits at its own
// first vertex. The features are averaged over the channel walks that have a
// first event: hits counts them in thirds (for surfaces and grey media every
// channel has the same chance).
void add_sample_aovs(const glm::dvec3& L, bool recorded, const WalkAov aov[3], double* sum) {
  for (int c = 0; c < 3; ++c) {
    const WalkAov& a = aov[c];
    if (recorded) {
      const double before = a.first_vertex == WalkAov::Vertex::None ? L[c] : a.before_vertex;
      sum[kAovEmission + c] += before - a.direct;
      sum[kAovBackground + c] += a.direct;
      sum[(a.first_vertex == WalkAov::Vertex::Surface ? kAovSurface : kAovScatter) + c] += L[c] - before;
    }
    if (!a.has_feature) continue;
    sum[kAovAlbedo + c] += a.albedo;
    for (int k = 0; k < 3; ++k) sum[kAovNormal + k] += a.normal[k] / 3.0;
    sum[kAovDepth] += a.depth / 3.0;
    sum[kAovHits] += 1.0 / 3.0;
  }
}

namespace {

// The media part of the guide: emission and transmittance along the spans
// in s (ray_spans) up to t_end.
constexpr double kGuideMinTransmittance = 1e-6;
void guide_media(const WalkScene& ws, const glm::dvec3& o, const glm::dvec3& d, double t_end, Scratch& s,
                 glm::dvec3& L, glm::dvec3& T) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  double h = inf;  // ray parameter per density texel, the finest grid's
  for (const Span& sp : s.spans) {
    const MediumData& m = ws.md.media[sp.medium];
    if (!m.is_vdb()) continue;
    const glm::dvec3 du(m.volume->density.grid.world_to_index * glm::dvec4(d, 0.0));
    h = std::min(h, 1.0 / std::max(glm::length(du), 1e-300));
  }
  for (size_t k = 0; k + 1 < s.cuts.size(); ++k) {
    const double a = s.cuts[k], b = std::min(s.cuts[k + 1], t_end);
    if (!(b > a)) break;
    media_present(ws.md, s.spans, a, b, 0, s.present);
    if (s.present.empty()) continue;
    bool vdb = false;
    for (int i : s.present) vdb = vdb || ws.md.media[i].is_vdb();
    const double steps = vdb ? std::ceil((b - a) / h) : 1.0;
    const int n = int(std::clamp(steps, 1.0, 1e6));
    const double dt = (b - a) / n;
    for (int j = 0; j < n; ++j) {
      const glm::dvec3 x = o + d * (a + (j + 0.5) * dt);
      glm::dvec3 sigma_t(0.0), E(0.0);
      for (int i : s.present) {
        const MediumData& m = ws.md.media[i];
        const double rho = m.is_vdb() ? grid_density(m, x) : 1.0;
        for (int c = 0; c < 3; ++c) {
          sigma_t[c] += (m.sigma_a[c] + m.sigma_s[c]) * rho;
          E[c] += m.is_vdb() ? grid_sigma_a_Le(m, i, c, x, rho, s.Le_cache) : m.sigma_a_Le[c];
        }
      }
      for (int c = 0; c < 3; ++c) {
        const double tr = std::exp(-sigma_t[c] * dt);
        L[c] += T[c] * (sigma_t[c] * dt > 1e-4 ? E[c] * (1.0 - tr) / sigma_t[c] : E[c] * dt);
        T[c] *= tr;
      }
      // Nothing behind this adds more than 1e-6 of its own light (the GPU's
      // GUIDE_MIN_TRANSMITTANCE).
      if (std::max({T.x, T.y, T.z}) < kGuideMinTransmittance) return;
    }
  }
}

// The denoiser's guide along a camera ray (film.aovs; docs/compositing.md
// "Denoiser"; the GPU's shaders/guide.glsl is written apart from this): what
// the ray sees unscattered, without random numbers. The media's emission
// ∫ T σaLe dt up to the first surface or sphere light, by a midpoint ray
// march: steps of at most one density texel where a vdb medium is present (a
// segment with homogeneous media only is one step), each exact for constant
// coefficients, L += T·E/σt·(1 − e^(−σt·Δt)), T ·= e^(−σt·Δt). Then T times
// what ends the ray: a sphere light's radiance (from outside), the
// background unless film.transparent, nothing at a surface; T is 0 at a
// surface or sphere light, as alpha is 1 there.
void guide_march(const WalkScene& ws, const glm::dvec3& o, const glm::dvec3& d, Scratch& s, glm::dvec3& L,
                 glm::dvec3& T) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  L = glm::dvec3(0.0);
  T = glm::dvec3(1.0);
  geometry::SurfaceHit hit;
  const bool surface = !ws.surfaces.empty() && geometry::intersect(ws.surfaces, geometry::Ray{o, d}, inf, hit);
  const SphereLightHit sphere = intersect_sphere_lights(ws.lights, o, d, surface ? hit.t : inf);
  const double t_end = sphere.light >= 0 ? sphere.t : surface ? hit.t : inf;
  ray_spans(ws.md, o, d, s.spans, s.cuts);
  guide_media(ws, o, d, t_end, s, L, T);
  if (sphere.light >= 0) {
    if (sphere.outside) L += T * ws.lights.analytic[sphere.light].value;
    T = glm::dvec3(0.0);
  } else if (surface) {
    T = glm::dvec3(0.0);
  } else if (!ws.transparent) {
    for (int c = 0; c < 3; ++c) L[c] += T[c] * ws.escaped(d, c);
  }
}

}  // namespace

void pixel_guide(const WalkScene& ws, const Camera& camera, int W, int H, int x, int y, Scratch& s,
                 double* aov_sum) {
  // 2D Simpson-like rule over the pixel's box (docs/compositing.md "The
  // guide"): 2/3 of the centre's value and 1/12 of each corner's. The GPU
  // shares each corner between four pixels; here every pixel marches its own.
  glm::dvec3 sum_L(0.0);
  double sum_alpha = 0.0;
  for (int j = 0; j < 5; ++j) {
    const bool centre = j == 4;
    const double w = centre ? 2.0 / 3.0 : 1.0 / 12.0;
    const double fx = x + (centre ? 0.5 : double(j & 1)), fy = y + (centre ? 0.5 : double(j >> 1));
    glm::dvec3 L, T;
    guide_march(ws, camera.position, camera_ray_direction(camera, W, H, fx, fy), s, L, T);
    sum_L += w * L;
    sum_alpha += w * (1.0 - (T.x + T.y + T.z) / 3.0);
  }
  for (int c = 0; c < 3; ++c) aov_sum[kAovGuide + c] = sum_L[c];
  aov_sum[kAovGuideAlpha] = sum_alpha;
}

}  // namespace pyrolume::cpu
