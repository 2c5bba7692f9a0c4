#pragma once
// The Vulkan compute backend: uploads the scene's constants and media, then runs
// render.comp in short progressive passes (a real GPU's watchdog never fires),
// accumulating Σ L and Σ L² per pixel on the device, and reads them back.
#include <memory>

#include "render/Backend.h"
#include "render/vulkan/VulkanHooks.h"

namespace pyrolume {

namespace vk {
class Context;
}
class RenderSession;

class VulkanRenderer : public Backend {
 public:
  explicit VulkanRenderer(const BackendOptions& options);
  ~VulkanRenderer() override;
  std::string name() const override { return "vulkan"; }
  std::string device_name() const override;
  RenderResult render(const Scene& scene, const RenderSettings& settings, const RenderControl& control) override;
  uint64_t validation_messages() const override;

  // Bytes of its AccumulationState for a width×height render: one
  // gpu::AccumTexel per pixel, then one gpu::AlphaTexel per pixel (RenderSession::save_state).
  static uint64_t accumulation_bytes(int width, int height);
  // Non-finite values in such a state (every member of both texels is a
  // float sum or count; a checkpoint must have none).
  static uint64_t nonfinite_sums(const AccumulationState& state);

  // Samples per pixel per dispatch: a fixed function of the image size, so the
  // pass schedule (and with it the float summation order) never depends on
  // timing and reruns are bit-identical.
  static int spp_per_pass(int width, int height, int spp, int rays_per_vertex = 1);

  // Sequences (docs/animation.md): keep the session between renders and, when
  // the next scene differs only in its media's grids and keyed values (same
  // image size, shapes, environment and shader variant), reload just the
  // grids, majorants and LUTs into it: the pipeline, BVH and environment are
  // built once per sequence. Off by default: a renderer that renders
  // unrelated scenes (tests, bench) must not hold on to one.
  // BackendOptions::frame_reuse sets it at construction.
  void set_frame_reuse(bool on);
  // Renders that reused the kept session (tests, stats).
  int reused_frames() const { return reused_frames_; }

  // Test and bench switches for the renders that follow (VulkanHooks.h); a
  // kept session of the old ones is dropped.
  void set_hooks(const VulkanHooks& hooks);

 private:
  std::unique_ptr<vk::Context> context_;
  std::unique_ptr<RenderSession> kept_;
  VulkanHooks hooks_;
  bool frame_reuse_ = false;
  int reused_frames_ = 0;
  double context_seconds_ = 0.0;  // instance + device creation, charged to the first render's load_seconds
};

}  // namespace pyrolume
