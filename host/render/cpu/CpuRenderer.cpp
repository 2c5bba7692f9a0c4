#include "render/cpu/CpuRenderer.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <thread>
#include <vector>

#include "color/Blackbody.h"
#include "render/cpu/Intersect.h"
#include "render/cpu/Rng.h"
#include "render/cpu/Sampling.h"

namespace pyrolume {
namespace cpu {
namespace {

using Clock = std::chrono::steady_clock;

// A homogeneous medium reduced to what the walk needs.
struct MediumData {
  Bounds bounds;
  glm::dvec3 sigma_a{0.0}, sigma_s{0.0};
  glm::dvec3 sigma_a_Le{0.0};  // emitted radiance per unit length: σa · Le
  double g = 0.0;
};

// A medium's bounds along the current ray, clipped to t >= 0.
struct Span {
  double t0, t1;
  int medium;
};

struct Scratch {
  std::vector<Span> spans;
  std::vector<double> cuts;
};

MediumData prepare_medium(const Medium& m) {
  if (m.type != Medium::Type::Homogeneous)
    throw std::runtime_error("cpu reference: vdb media not supported yet");
  MediumData d;
  d.bounds = m.bounds;
  d.sigma_a = m.sigma_a;
  d.sigma_s = m.sigma_s;
  d.g = m.g;
  glm::dvec3 Le(0.0);
  if (m.emission.emits()) {
    if (m.emission.rgb)
      Le = m.emission.scale * *m.emission.rgb;
    else if (m.emission.temperature_k)
      Le = m.emission.scale * color::blackbody_rgb(*m.emission.temperature_k, m.emission.blackbody,
                                                   m.emission.observer, m.emission.adapt_to_k);
  }
  d.sigma_a_Le = m.sigma_a * Le;
  return d;
}

// One analog random walk of a *grey* medium: colour channel c alone.
//
// Chromatic σ: each RGB channel is rendered as its own grey medium by an
// independent scalar walk (σa_c, σs_c, Le_c, background_c). Each walk is the
// textbook analog estimator of that channel's radiance, so the per-channel mean
// is unbiased trivially; the walks share only the camera ray, which does not
// bias a per-channel mean. (The GPU path instead tracks a max-channel majorant
// with spectral weights; keeping this one different is the point.)
//
// Estimator ("absorption" estimator, issue 2 part 5): media are piecewise
// constant along the ray, so walk the segments between sorted bounds crossings;
// in each, sample a free flight from p(t) = σt exp(−σt t) and restart at the next
// crossing if it overshoots (the exponential is memoryless). At a collision the
// path is absorbed with probability σa/σt and returns the absorbing mixture's
// Le = Σ σa_i Le_i / σa, or scatters with probability σs/σt by the σs-weighted
// mixture of the media's HG lobes. Escaping all media returns the background.
// The (max_depth+1)-th scattering returns 0.
double walk_channel(const std::vector<MediumData>& media, int c, double background, int max_depth,
                    glm::dvec3 o, glm::dvec3 d, Pcg32& rng, uint64_t& collisions, Scratch& s) {
  int scatters = 0;
  for (;;) {
    s.spans.clear();
    s.cuts.clear();
    for (int i = 0; i < int(media.size()); ++i) {
      RayInterval r = intersect_bounds(o, d, media[i].bounds);
      if (!r.hit) continue;
      double t0 = std::max(r.t0, 0.0), t1 = r.t1;
      if (!(t1 > t0)) continue;  // behind the origin, tangent, or zero length
      s.spans.push_back({t0, t1, i});
      s.cuts.push_back(t0);
      s.cuts.push_back(t1);
    }
    std::sort(s.cuts.begin(), s.cuts.end());
    s.cuts.erase(std::unique(s.cuts.begin(), s.cuts.end()), s.cuts.end());

    bool scattered = false;
    for (size_t k = 0; k + 1 < s.cuts.size() && !scattered; ++k) {
      double a = s.cuts[k], b = s.cuts[k + 1];
      // The cuts are the spans' own endpoints, so containment is exact.
      double sigma_a = 0.0, sigma_s = 0.0;
      for (const Span& sp : s.spans)
        if (sp.t0 <= a && sp.t1 >= b) {
          sigma_a += media[sp.medium].sigma_a[c];
          sigma_s += media[sp.medium].sigma_s[c];
        }
      double sigma_t = sigma_a + sigma_s;
      if (!(sigma_t > 0.0)) continue;
      double t = a + sample_free_flight(sigma_t, rng.uniform());
      if (!(t < b)) continue;  // memoryless: restart the flight at b

      ++collisions;
      if (rng.uniform() * sigma_t < sigma_a) {
        double emitted = 0.0;  // Σ σa_i Le_i of the media present here
        for (const Span& sp : s.spans)
          if (sp.t0 <= a && sp.t1 >= b) emitted += media[sp.medium].sigma_a_Le[c];
        return emitted / sigma_a;
      }
      if (scatters == max_depth) return 0.0;
      ++scatters;
      // Pick the lobe of medium i with probability σs_i/σs (mixture phase function).
      double pick = rng.uniform() * sigma_s;
      double g = 0.0;
      for (const Span& sp : s.spans)
        if (sp.t0 <= a && sp.t1 >= b && media[sp.medium].sigma_s[c] > 0.0) {
          g = media[sp.medium].g;
          pick -= media[sp.medium].sigma_s[c];
          if (pick < 0.0) break;
        }
      glm::dvec2 u(rng.uniform(), rng.uniform());
      o = o + t * d;
      d = sample_hg(d, g, u).direction;
      scattered = true;
    }
    if (!scattered) return background;
  }
}

struct ThreadCounters {
  uint64_t collisions = 0;
  uint64_t nonfinite = 0;
};

}  // namespace

glm::dvec3 camera_ray_direction(const Camera& camera, int width, int height, double fx, double fy) {
  glm::dvec3 forward = glm::normalize(camera.look_at - camera.position);
  glm::dvec3 right = glm::normalize(glm::cross(forward, camera.up));
  glm::dvec3 up = glm::cross(right, forward);
  double tan_half = std::tan(0.5 * camera.fov_deg * std::numbers::pi / 180.0);
  double aspect = double(width) / double(height);
  double sx = (2.0 * fx / width - 1.0) * tan_half * aspect;
  double sy = (1.0 - 2.0 * fy / height) * tan_half;
  return glm::normalize(forward + sx * right + sy * up);
}

}  // namespace cpu

CpuRenderer::CpuRenderer(int threads) {
  if (threads <= 0) threads = int(std::thread::hardware_concurrency());
  threads_ = std::max(1, threads);
}

std::string CpuRenderer::device_name() const {
  return "CPU reference (" + std::to_string(threads_) + (threads_ == 1 ? " thread)" : " threads)");
}

RenderResult CpuRenderer::render(const Scene& scene, const RenderSettings& settings, const RenderControl& control) {
  using namespace cpu;
  auto load_start = Clock::now();
  if (settings.width <= 0 || settings.height <= 0 || settings.spp <= 0)
    throw std::invalid_argument("cpu reference: width, height and spp must be positive");
  {
    glm::dvec3 f = scene.camera.look_at - scene.camera.position;
    if (!(glm::length(glm::cross(f, scene.camera.up)) > 0.0))
      throw std::invalid_argument("cpu reference: camera up is parallel to the view direction");
  }
  std::vector<MediumData> media;
  for (const Medium& m : scene.media) media.push_back(prepare_medium(m));

  const int W = settings.width, H = settings.height;
  const int max_depth = std::max(0, scene.integrator.max_depth);
  RenderResult res;
  res.width = W;
  res.height = H;
  res.backend = name();
  res.device = device_name();
  res.sum.assign(size_t(W) * H * 3, 0.0);
  res.sum_sq.assign(size_t(W) * H * 3, 0.0);

  constexpr int kTile = 16;
  const int tiles_x = (W + kTile - 1) / kTile, tiles_y = (H + kTile - 1) / kTile;
  const int n_tiles = tiles_x * tiles_y;
  const int n_threads = std::min(threads_, n_tiles);
  auto render_start = Clock::now();
  res.load_seconds = std::chrono::duration<double>(render_start - load_start).count();

  uint64_t total_collisions = 0, total_nonfinite = 0;
  int spp_done = 0;
  while (spp_done < settings.spp) {
    const int s_begin = spp_done, s_end = std::min(settings.spp, spp_done + kPassSpp);
    std::atomic<int> next_tile{0};
    std::vector<ThreadCounters> counters(n_threads);
    auto worker = [&](int tid) {
      Scratch scratch;
      ThreadCounters& cnt = counters[tid];
      for (int tile; (tile = next_tile.fetch_add(1)) < n_tiles;) {
        int x0 = (tile % tiles_x) * kTile, y0 = (tile / tiles_x) * kTile;
        for (int y = y0; y < std::min(H, y0 + kTile); ++y)
          for (int x = x0; x < std::min(W, x0 + kTile); ++x) {
            size_t pix = size_t(y) * W + x;
            for (int si = s_begin; si < s_end; ++si) {
              Pcg32 rng = Pcg32::for_sample(settings.seed, settings.frame, pix, uint64_t(si));
              // Box filter: a uniform point in the pixel.
              double fx = x + rng.uniform(), fy = y + rng.uniform();
              glm::dvec3 dir = camera_ray_direction(scene.camera, W, H, fx, fy);
              glm::dvec3 L;
              for (int c = 0; c < 3; ++c)
                L[c] = walk_channel(media, c, scene.background[c], max_depth, scene.camera.position, dir, rng,
                                    cnt.collisions, scratch);
              if (!std::isfinite(L.x) || !std::isfinite(L.y) || !std::isfinite(L.z)) {
                ++cnt.nonfinite;
                L = glm::dvec3(0.0);  // recorded as 0, counted in nonfinite_samples
              }
              for (int c = 0; c < 3; ++c) {
                res.sum[pix * 3 + c] += L[c];
                res.sum_sq[pix * 3 + c] += L[c] * L[c];
              }
            }
          }
      }
    };
    std::vector<std::thread> pool;
    for (int t = 1; t < n_threads; ++t) pool.emplace_back(worker, t);
    worker(0);
    for (auto& th : pool) th.join();
    for (const auto& cnt : counters) {
      total_collisions += cnt.collisions;
      total_nonfinite += cnt.nonfinite;
    }

    spp_done = s_end;
    res.spp = spp_done;
    if (control.progress) control.progress(spp_done, settings.spp);
    if (spp_done >= settings.spp) break;
    if (control.cancel && control.cancel->load()) {
      res.cancelled = true;
      break;
    }
    if (settings.time_limit > 0.0 &&
        std::chrono::duration<double>(Clock::now() - render_start).count() > settings.time_limit)
      break;
  }
  res.seconds = std::chrono::duration<double>(Clock::now() - render_start).count();
  // events: real collisions of all three channel walks divided by 3, i.e. summed
  // over camera samples of the channel-average collision count.
  res.events = double(total_collisions) / 3.0;
  res.density_lookups = 0.0;  // homogeneous media read no density texture
  res.nonfinite_samples = total_nonfinite;
  return res;
}

}  // namespace pyrolume
