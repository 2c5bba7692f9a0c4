#include "render/vulkan/VulkanRenderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "render/vulkan/Context.h"
#include "render/vulkan/RenderSession.h"
#include "scene/Scene.h"

namespace pyrolume {
namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
}  // namespace

VulkanRenderer::VulkanRenderer(const BackendOptions& options) {
  auto t0 = Clock::now();
  vk::Context::Options o;
  o.device_index = options.device_index;
  o.validation = options.validation;
  context_ = std::make_unique<vk::Context>(o);
  context_seconds_ = since(t0);
  frame_reuse_ = options.frame_reuse;
}

VulkanRenderer::~VulkanRenderer() = default;

std::string VulkanRenderer::device_name() const { return context_->info().name; }

uint64_t VulkanRenderer::validation_messages() const { return context_->validation_messages(); }

void VulkanRenderer::set_frame_reuse(bool on) {
  frame_reuse_ = on;
  if (!on) kept_.reset();
}

void VulkanRenderer::set_hooks(const VulkanHooks& hooks) {
  hooks_ = hooks;
  kept_.reset();
}

uint64_t VulkanRenderer::accumulation_bytes(int width, int height) {
  return uint64_t(width) * uint64_t(height) * (sizeof(gpu::AccumTexel) + sizeof(gpu::AlphaTexel));
}

uint64_t VulkanRenderer::nonfinite_sums(const AccumulationState& state) {
  static_assert(sizeof(gpu::AccumTexel) % sizeof(float) == 0 && sizeof(gpu::AlphaTexel) % sizeof(float) == 0,
                "the texels are read as floats");
  uint64_t count = 0;
  for (size_t i = 0; i + sizeof(float) <= state.data.size(); i += sizeof(float)) {
    float v;
    std::memcpy(&v, state.data.data() + i, sizeof v);
    count += !std::isfinite(v);
  }
  return count;
}

int VulkanRenderer::spp_per_pass(int width, int height, int spp, int rays_per_vertex) {
  // About 2^19 paths per dispatch: tens of milliseconds on lavapipe for simple
  // scenes, far below any GPU watchdog, and large enough that per-dispatch
  // overhead (~1.3 ms on lavapipe, docs/rendering.md) stays small. With next-event
  // estimation each vertex also sends light rays (up to rays_per_vertex − 1):
  // proportionally fewer paths, which also keeps passes within llvmpipe's loop budget (PassStatus; a pass that
  // overruns it is redone in halves, wasting it: terrain_explosion at 160×90
  // overran it at 36 spp per pass).
  const double paths_per_pass = 524288.0 / std::max(1, rays_per_vertex);
  int k = static_cast<int>(paths_per_pass / (double(width) * double(height)));
  return std::clamp(k, 1, std::min(spp, 64));
}

RenderResult VulkanRenderer::render(const Scene& scene, const RenderSettings& settings, const RenderControl& control) {
  auto load_start = Clock::now();
  std::unique_ptr<RenderSession> fresh;
  if (frame_reuse_ && kept_ && kept_->load_frame(scene, settings)) {
    ++reused_frames_;
  } else {
    kept_.reset();  // free the previous frame's memory before allocating the next
    fresh = std::make_unique<RenderSession>(*context_, scene, settings, hooks_);
  }
  if (fresh && frame_reuse_) kept_ = std::move(fresh);
  RenderSession& session = fresh ? *fresh : *kept_;
  RenderResult result;
  result.backend = name();
  result.device = device_name();
  result.light_strategy = strategy_name(session.light_selection().strategy);
  result.emission_estimator = to_string(session.light_selection().estimator);
  for (const gpu::GpuGrid& g : session.gpu_scene().grids)
    result.majorant_grids.push_back({int(g.majorant_res.x), int(g.majorant_res.y), int(g.majorant_res.z)});
  result.warnings = session.warnings();
  result.load_seconds = since(load_start) + context_seconds_;
  context_seconds_ = 0.0;

  if (!spp_in_range(settings.spp))
    throw std::invalid_argument("vulkan: spp must be in 1..2^24, not " + std::to_string(settings.spp));
  result.spp_target = settings.spp;
  if (control.resume) {
    session.load_state(*control.resume);
    result.resumed_spp = control.resume->spp;
  }

  // Progressive passes of a fixed size (see spp_per_pass). A host copy of the
  // accumulation (`saved`) is refreshed after the first pass, at every
  // checkpoint and otherwise at most every max(1 s, 20 readbacks' time), so
  // the readbacks cost under 5 %: it is what a lost device still lets us save.
  auto render_start = Clock::now();
  const uint64_t dropped_before = session.dropped_samples();  // a kept session counts across frames
  const double guide_before = session.guide_seconds();
  const int per_pass =
      spp_per_pass(settings.width, settings.height, settings.spp, session.rays_per_vertex());
  AccumulationState saved;
  if (control.resume) saved = *control.resume;  // a failure in the first pass still has the resumed samples
  double save_interval = 0.0;
  auto last_save = render_start, last_checkpoint = render_start;
  try {
    while (session.spp_done() < settings.spp) {
      if (!session.run_pass(std::min(per_pass, settings.spp - session.spp_done()), control.cancel)) {
        result.cancelled = true;  // within the pass: it was undone
        break;
      }
      if (control.progress) control.progress(session.spp_done(), settings.spp);
      if (session.spp_done() >= settings.spp) break;
      const bool checkpoint_due = control.checkpoint && control.checkpoint_seconds > 0.0 &&
                                  since(last_checkpoint) >= control.checkpoint_seconds;
      if (checkpoint_due || since(last_save) >= save_interval) {
        const auto t0 = Clock::now();
        saved = session.save_state();
        save_interval = std::max(1.0, 20.0 * since(t0));
        last_save = Clock::now();
        if (checkpoint_due) {
          control.checkpoint(saved);
          last_checkpoint = Clock::now();
        }
      }
      if (control.cancel && control.cancel->load()) {
        result.cancelled = true;
        break;
      }
      if (settings.time_limit > 0 && since(render_start) >= settings.time_limit) break;
    }
    saved = {};  // (memory: the final readback replaces it)
    AccumulationState final_state = session.save_state();
    RenderSession::result_from_state(final_state, result);
    session.read_aovs(result);
    result.dropped_samples = session.dropped_samples() - dropped_before;
    result.guide_seconds = session.guide_seconds() - guide_before;
    if (result.dropped_samples > 0)
      result.warnings.push_back(std::to_string(result.dropped_samples) +
                                " samples did not finish even at 1 spp per pass (the driver's loop limit: llvmpipe runs "
                                "at most 65535 loop iterations per dispatch); they count in spp and add nothing, so "
                                "those pixels are darker than they should be. A real GPU has no such limit");
    if (result.spp < settings.spp) result.state = std::move(final_state);
  } catch (const vk::VulkanError& e) {
    const bool out_of_memory = e.result == VK_ERROR_OUT_OF_DEVICE_MEMORY || e.result == VK_ERROR_OUT_OF_HOST_MEMORY;
    // Out of memory leaves the device usable: read what the passes before the
    // failed one accumulated. A lost device has nothing left to read, and
    // after any other failure the device is not trusted: the host copy it is.
    if (out_of_memory) {
      try {
        saved = session.save_state();
      } catch (const vk::VulkanError&) {
      }
    }
    if (saved.data.empty()) {  // failed before anything was saved: 0 spp
      saved = AccumulationState{"vulkan", settings.width, settings.height, 0, {}};
      saved.data.assign(accumulation_bytes(settings.width, settings.height), 0);
    }
    RenderResult partial = result;
    RenderSession::result_from_state(saved, partial);
    partial.seconds = since(render_start);
    partial.state = saved;
    const std::string what =
        e.result == VK_ERROR_DEVICE_LOST ? "the device was lost (VK_ERROR_DEVICE_LOST: a driver reset, hang or removal)"
        : e.result == VK_ERROR_OUT_OF_DEVICE_MEMORY ? "the device ran out of memory (VK_ERROR_OUT_OF_DEVICE_MEMORY)"
        : e.result == VK_ERROR_OUT_OF_HOST_MEMORY   ? "the host ran out of memory (VK_ERROR_OUT_OF_HOST_MEMORY)"
                                                    : std::string("the device failed: ") + e.what();
    throw RenderFailed(what, std::move(partial));
  }
  result.seconds = since(render_start);
  return result;
}

}  // namespace pyrolume
