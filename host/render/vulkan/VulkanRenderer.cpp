#include "render/vulkan/VulkanRenderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>

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
}

VulkanRenderer::~VulkanRenderer() = default;

std::string VulkanRenderer::device_name() const { return context_->info().name; }

uint64_t VulkanRenderer::validation_messages() const { return context_->validation_messages(); }

void VulkanRenderer::set_frame_reuse(bool on) {
  frame_reuse_ = on;
  if (!on) kept_.reset();
}

int VulkanRenderer::spp_per_pass(int width, int height, int spp) {
  // About 2^19 paths per dispatch: tens of milliseconds on lavapipe for simple
  // scenes, far below any GPU watchdog, and large enough that per-dispatch
  // overhead (~1.3 ms on lavapipe, LAVAPIPE.md) stays small.
  const double paths_per_pass = 524288.0;
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
    fresh = std::make_unique<RenderSession>(*context_, scene, settings);
  }
  if (fresh && frame_reuse_) kept_ = std::move(fresh);
  RenderSession& session = fresh ? *fresh : *kept_;
  RenderResult result;
  result.backend = name();
  result.device = device_name();
  result.warnings = session.warnings();
  result.load_seconds = since(load_start) + context_seconds_;
  context_seconds_ = 0.0;

  // Progressive passes of a fixed size (see spp_per_pass).
  auto render_start = Clock::now();
  const int per_pass = spp_per_pass(settings.width, settings.height, settings.spp);
  while (session.spp_done() < settings.spp) {
    session.run_pass(std::min(per_pass, settings.spp - session.spp_done()));
    if (control.progress) control.progress(session.spp_done(), settings.spp);
    if (control.cancel && control.cancel->load()) {
      result.cancelled = true;
      break;
    }
    if (settings.time_limit > 0 && since(render_start) >= settings.time_limit) break;
  }
  session.read(result);
  result.seconds = since(render_start);
  return result;
}

}  // namespace pyrolume
