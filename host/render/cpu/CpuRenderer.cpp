#include "render/cpu/CpuRenderer.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <cmath>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <thread>
#include <vector>

#include "geometry/SceneSurfaces.h"
#include "geometry/Surfaces.h"
#include "light/EmissionCdf.h"
#include "light/EnvironmentMap.h"
#include "light/LightSelection.h"
#include "render/Limits.h"
#include "render/LineEstimator.h"
#include "render/SceneChecks.h"
#include "render/cpu/Aovs.h"
#include "render/cpu/Lights.h"
#include "render/cpu/Media.h"
#include "render/cpu/Rng.h"
#include "render/cpu/Walk.h"

namespace pyrolume {
namespace cpu {

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

namespace {

using Clock = std::chrono::steady_clock;
using namespace cpu;

// The CPU's AccumulationState layout (host byte order): Σ L and Σ L² as
// doubles (width·height·3 each), then the counters collisions, density
// lookups and non-finite samples as uint64.
struct CpuCounters {
  uint64_t collisions = 0, density_lookups = 0, nonfinite = 0;
  // A thread's pass added in; returns its majorant violations (not saved).
  uint64_t add(const ThreadCounters& t) {
    collisions += t.collisions;
    nonfinite += t.nonfinite;
    density_lookups += t.density_lookups;
    return t.majorant_violations;
  }
};

AccumulationState save_state(const RenderResult& res, const CpuCounters& c) {
  AccumulationState st;
  st.backend = "cpu";
  st.width = res.width;
  st.height = res.height;
  st.spp = res.spp;
  const size_t n = res.sum.size() * sizeof(double), na = res.alpha_sum.size() * sizeof(double);
  st.data.resize(2 * n + 2 * na + sizeof c);
  std::memcpy(st.data.data(), res.sum.data(), n);
  std::memcpy(st.data.data() + n, res.sum_sq.data(), n);
  std::memcpy(st.data.data() + 2 * n, res.alpha_sum.data(), na);
  std::memcpy(st.data.data() + 2 * n + na, res.alpha_sum_sq.data(), na);
  std::memcpy(st.data.data() + 2 * n + 2 * na, &c, sizeof c);
  return st;
}

void load_state(const AccumulationState& st, RenderResult& res, CpuCounters& c) {
  const size_t n = res.sum.size() * sizeof(double);
  if (st.backend != "cpu" || st.width != res.width || st.height != res.height ||
      st.data.size() != CpuRenderer::accumulation_bytes(res.width, res.height))
    throw std::invalid_argument("cpu reference: the resumed accumulation is not a " + std::to_string(res.width) + "x" +
                                std::to_string(res.height) + " cpu one");
  const size_t na = res.alpha_sum.size() * sizeof(double);
  std::memcpy(res.sum.data(), st.data.data(), n);
  std::memcpy(res.sum_sq.data(), st.data.data() + n, n);
  std::memcpy(res.alpha_sum.data(), st.data.data() + 2 * n, na);
  std::memcpy(res.alpha_sum_sq.data(), st.data.data() + 2 * n + na, na);
  std::memcpy(&c, st.data.data() + 2 * n + 2 * na, sizeof c);
  res.spp = res.resumed_spp = st.spp;
}

// What a render's walks read, built once per render: the media (their grids
// loaded), the surfaces, the environment map and the lights. Not movable:
// WalkLights and WalkScene refer into it.
struct CpuFrame {
  MediaData media;
  geometry::Surfaces surfaces;
  std::optional<EnvironmentMap> environment;
  std::vector<std::optional<EmissionCdf>> cdfs;  // per scene medium: its emission CDF, when it is a light
  WalkLights lights;
  CpuFrame() = default;
  CpuFrame(const CpuFrame&) = delete;
  CpuFrame& operator=(const CpuFrame&) = delete;
};

void prepare_frame(const Scene& scene, CpuFrame& f) {
  check_scene_ranges(scene);
  f.media = prepare_media(scene);  // loads the vdb media's grids
  for (size_t i = 0; i < f.media.media.size(); ++i)
    if (f.media.media[i].volume) check_loaded_medium(scene, i, *f.media.media[i].volume);
  f.surfaces = geometry::build_surfaces(scene);  // meshes, textures, BVH
  if (scene.environment)
    f.environment = EnvironmentMap::load(scene.environment->file, scene.environment->scale,
                                         scene.environment->rotation_deg,
                                         scene.up_axis.value_or(UpAxis::Z) == UpAxis::Y);
  // Lights for next-event estimation: the environment map and every grid
  // medium that emits (its emission CDF over the grid as stored), where the
  // scene may sample them (light_candidates). The selection also resolves the
  // emission estimator ("auto"), as it does for the Vulkan backend.
  WalkLights& lights = f.lights;
  lights.environment = f.environment ? &*f.environment : nullptr;
  f.cdfs.resize(scene.media.size());
  lights.cdf.assign(scene.media.size(), nullptr);
  if (light_candidates(scene).media)
    for (size_t i = 0; i < scene.media.size(); ++i)
      if (f.media.media[i].is_vdb() && f.media.media[i].volume && scene.media[i].emission.emits()) {
        f.cdfs[i] = EmissionCdf::build_light(scene.media[i], *f.media.media[i].volume);
        if (!f.cdfs[i]->empty()) lights.cdf[i] = &*f.cdfs[i];
      }
  // The media the line estimator collects (the file's "line", or "auto"'s choice).
  std::vector<const StoredVolume*> volumes(scene.media.size(), nullptr);
  for (size_t i = 0; i < scene.media.size(); ++i) volumes[i] = f.media.media[i].volume.get();
  const LineMedia line = line_media(scene, volumes);
  lights.selection = select_lights(scene, lights.environment, lights.cdf, line.any());
  for (size_t i = 0; i < scene.media.size(); ++i)
    if (line.line[i]) f.media.media[i].line_rate = line_rate(f.media.media[i]);
  lights.analytic = analytic_lights(scene.lights);
}

// A pass's sums: those of the passes before it plus its own samples.
struct PassSums {
  std::vector<double> sum, sum_sq, alpha, alpha_sq, aov;
};

// Samples [s_begin, s_end) of pixel (x, y) added to its sums in res, into next.
void render_pixel(const WalkScene& ws, const Scene& scene, const RenderSettings& settings, const RenderResult& res,
                  int x, int y, int s_begin, int s_end, ThreadCounters& cnt, Scratch& scratch, PassSums& next) {
  const int W = res.width, H = res.height;
  const size_t pix = size_t(y) * W + x;
  double sum[3], sum_sq[3];
  for (int c = 0; c < 3; ++c) {
    sum[c] = res.sum[pix * 3 + c];
    sum_sq[c] = res.sum_sq[pix * 3 + c];
  }
  double alpha_sum = res.alpha_sum[pix], alpha_sq = res.alpha_sum_sq[pix];
  double aov_sum[kAovValues] = {};
  if (settings.aovs) std::copy_n(res.aov_sum.data() + pix * kAovValues, kAovValues, aov_sum);
  if (settings.aovs && s_begin == 0) pixel_guide(ws, scene.camera, W, H, x, y, scratch, aov_sum);
  for (int si = s_begin; si < s_end; ++si) {
    cnt.step();
    Pcg32 rng = Pcg32::for_sample(settings.seed, settings.frame, pix, uint64_t(si));
    // Box filter: a uniform point in the pixel.
    double fx = x + rng.uniform(), fy = y + rng.uniform();
    glm::dvec3 dir = camera_ray_direction(scene.camera, W, H, fx, fy);
    glm::dvec3 L;
    // Alpha (docs/compositing.md): each channel's walk is a grey delta
    // tracker whose camera ray escapes with probability T_c, so
    // 1 − (escapes)/3 has mean 1 − avg_c T_c.
    int escapes = 0;
    WalkAov aov[3];
    for (int c = 0; c < 3; ++c) {
      bool escaped = false;
      L[c] = walk_channel(ws, c, scene.camera.position, dir, rng, cnt, scratch, ws.max_depth, WalkRole::Path,
                          &escaped, settings.aovs ? &aov[c] : nullptr);
      escapes += escaped ? 1 : 0;
    }
    const double alpha = 1.0 - escapes / 3.0;
    alpha_sum += alpha;
    alpha_sq += alpha * alpha;
    // NaN, Inf and beyond MAX_SAMPLE_RADIANCE (where float sums of
    // squares could overflow): recorded as 0, counted in nonfinite_samples.
    const double kMaxL = kMaxSampleRadiance;
    const bool recorded = std::abs(L.x) <= kMaxL && std::abs(L.y) <= kMaxL && std::abs(L.z) <= kMaxL;
    if (!recorded) {
      ++cnt.nonfinite;
      L = glm::dvec3(0.0);
    }
    for (int c = 0; c < 3; ++c) {
      sum[c] += L[c];
      sum_sq[c] += L[c] * L[c];
    }
    if (settings.aovs) add_sample_aovs(L, recorded, aov, aov_sum);
  }
  if (settings.aovs) std::copy_n(aov_sum, kAovValues, next.aov.data() + pix * kAovValues);
  for (int c = 0; c < 3; ++c) {
    next.sum[pix * 3 + c] = sum[c];
    next.sum_sq[pix * 3 + c] = sum_sq[c];
  }
  next.alpha[pix] = alpha_sum;
  next.alpha_sq[pix] = alpha_sq;
}

void check_settings(const Scene& scene, const RenderSettings& settings) {
  if (settings.width <= 0 || settings.height <= 0 || !spp_in_range(settings.spp))
    throw std::invalid_argument("cpu reference: width, height and spp must be positive (spp at most 2^24)");
  const glm::dvec3 f = scene.camera.look_at - scene.camera.position;
  if (!(glm::length(glm::cross(f, scene.camera.up)) > 0.0))
    throw std::invalid_argument("cpu reference: camera up is parallel to the view direction");
}

// A render's result before its first sample: zero sums of the film's size.
RenderResult empty_result(const RenderSettings& settings, const LightSelection& selection) {
  RenderResult res;
  const int W = settings.width, H = settings.height;
  res.width = W;
  res.height = H;
  res.light_strategy = strategy_name(selection.strategy);
  res.emission_estimator = to_string(selection.estimator);
  res.spp_target = settings.spp;
  res.sum.assign(size_t(W) * H * 3, 0.0);
  res.sum_sq.assign(size_t(W) * H * 3, 0.0);
  res.alpha_sum.assign(size_t(W) * H, 0.0);
  res.alpha_sum_sq.assign(size_t(W) * H, 0.0);
  if (settings.aovs) res.aov_sum.assign(size_t(W) * H * kAovValues, 0.0);
  return res;
}

}  // namespace

uint64_t CpuRenderer::accumulation_bytes(int width, int height) {
  return uint64_t(width) * uint64_t(height) * 8 * sizeof(double) + sizeof(CpuCounters);
}

uint64_t CpuRenderer::nonfinite_sums(const AccumulationState& state) {
  const size_t sums = size_t(state.width) * size_t(state.height) * 8;  // the doubles before the counters
  if (state.data.size() < sums * sizeof(double)) throw std::logic_error("cpu reference: accumulation too short");
  uint64_t count = 0;
  for (size_t i = 0; i < sums; ++i) {
    double v;
    std::memcpy(&v, state.data.data() + i * sizeof v, sizeof v);
    count += !std::isfinite(v);
  }
  return count;
}

CpuRenderer::CpuRenderer(int threads) {
  if (threads <= 0) threads = int(std::thread::hardware_concurrency());
  threads_ = std::max(1, threads);
}

std::string CpuRenderer::device_name() const {
  return "CPU reference (" + std::to_string(threads_) + (threads_ == 1 ? " thread)" : " threads)");
}

RenderResult CpuRenderer::render(const Scene& scene, const RenderSettings& settings, const RenderControl& control) {
  auto load_start = Clock::now();
  check_settings(scene, settings);
  // Σ L, Σ L², Σα and Σα² in double, the pass being accumulated beside them,
  // and one copy of them for a checkpoint.
  check_accumulation_fits_memory(scene.file.string(), settings.width, settings.height, 3 * 8 * sizeof(double));
  CpuFrame frame;
  prepare_frame(scene, frame);
  const WalkLights& lights = frame.lights;
  const int W = settings.width, H = settings.height;
  const bool collision_estimator = lights.selection.estimator != EmissionEstimator::Absorption;
  const WalkScene walk_scene{frame.media,    frame.surfaces, scene.background, std::max(0, scene.integrator.max_depth),
                             collision_estimator, lights,         scene.film.transparent};
  RenderResult res = empty_result(settings, lights.selection);
  res.warnings = frame.media.warnings;  // the CLI prints them ("pyrolume: warning: ...")
  res.backend = name();
  res.device = device_name();
  // Resumed: the sums continue in sample order, so the result is bit-identical
  // to an uninterrupted render's (per-pixel sums never depend on passes).
  CpuCounters totals;
  if (control.resume) load_state(*control.resume, res, totals);

  constexpr int kTile = 16;
  const int tiles_x = (W + kTile - 1) / kTile, tiles_y = (H + kTile - 1) / kTile;
  const int n_tiles = tiles_x * tiles_y;
  const int n_threads = std::min(threads_, n_tiles);
  auto render_start = Clock::now();
  res.load_seconds = std::chrono::duration<double>(render_start - load_start).count();

  uint64_t total_violations = 0;
  auto last_checkpoint = render_start;
  int spp_done = res.spp;
  // A pass accumulates into `next` (the sums so far plus its samples, added in
  // sample order as before, so results are bit-identical) and is swapped in
  // only when complete: a pass abandoned by a signal leaves res as the passes
  // before it made it.
  PassSums next{std::vector<double>(res.sum.size()), std::vector<double>(res.sum_sq.size()),
                std::vector<double>(res.alpha_sum.size()), std::vector<double>(res.alpha_sum_sq.size()),
                std::vector<double>(res.aov_sum.size())};
  while (spp_done < settings.spp) {
    const int s_begin = spp_done, s_end = std::min(settings.spp, spp_done + kPassSpp);
    std::atomic<int> next_tile{0};
    std::atomic<bool> abandoned{false};
    std::vector<ThreadCounters> counters(n_threads);
    // The pass's tiles, taken from a shared counter until none are left.
    auto worker = [&](int tid) {
      Scratch scratch;
      ThreadCounters& cnt = counters[tid];
      cnt.cancel = control.cancel;
      try {
        for (int tile; !abandoned.load(std::memory_order_relaxed) && (tile = next_tile.fetch_add(1)) < n_tiles;) {
          const int x0 = (tile % tiles_x) * kTile, y0 = (tile / tiles_x) * kTile;
          for (int y = y0; y < std::min(H, y0 + kTile); ++y)
            for (int x = x0; x < std::min(W, x0 + kTile); ++x)
              render_pixel(walk_scene, scene, settings, res, x, y, s_begin, s_end, cnt, scratch, next);
        }
      } catch (const PassCancelled&) {
        abandoned = true;  // the other threads stop at their next poll or tile
      }
    };
    std::vector<std::thread> pool;
    for (int t = 1; t < n_threads; ++t) pool.emplace_back(worker, t);
    worker(0);
    for (auto& th : pool) th.join();
    if (abandoned) {  // interrupted within the pass: it never happened
      res.cancelled = true;
      break;
    }
    res.sum.swap(next.sum);
    res.sum_sq.swap(next.sum_sq);
    res.alpha_sum.swap(next.alpha);
    res.alpha_sum_sq.swap(next.alpha_sq);
    res.aov_sum.swap(next.aov);
    for (const auto& cnt : counters) total_violations += totals.add(cnt);

    spp_done = s_end;
    res.spp = spp_done;
    if (control.progress) control.progress(spp_done, settings.spp);
    if (spp_done >= settings.spp) break;
    if (control.checkpoint && control.checkpoint_seconds > 0.0 &&
        std::chrono::duration<double>(Clock::now() - last_checkpoint).count() >= control.checkpoint_seconds) {
      control.checkpoint(save_state(res, totals));
      last_checkpoint = Clock::now();
    }
    if (control.cancel && control.cancel->load()) {
      res.cancelled = true;
      break;
    }
    if (settings.time_limit > 0.0 &&
        std::chrono::duration<double>(Clock::now() - render_start).count() > settings.time_limit)
      break;
  }
  res.seconds = std::chrono::duration<double>(Clock::now() - render_start).count();
  // Both counters are summed over camera samples of the average over the three
  // channel walks (each walk's count, all three added, divided by 3):
  //  - events: real collisions (absorptions + scatterings) and surface
  //    bounces, including the one that max_depth ends;
  //  - density_lookups: trilinear density-texture samples, one per vdb medium
  //    present at each tentative collision (real or null); homogeneous media
  //    read no texture. (Shadow rays, when MIS lands, add their ratio-tracking
  //    lookups the same way.) Temperature lookups are not counted.
  res.events = double(totals.collisions) / 3.0;
  res.density_lookups = double(totals.density_lookups) / 3.0;
  majorant_violations_ = total_violations;
  if (total_violations)
    std::fprintf(stderr, "warning: cpu reference: %llu tentative collisions had sigma_t above the majorant\n",
                 (unsigned long long)total_violations);
  res.nonfinite_samples = totals.nonfinite;
  if (res.spp < settings.spp) res.state = save_state(res, totals);
  return res;
}

}  // namespace pyrolume
