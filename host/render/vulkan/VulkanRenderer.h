#pragma once
// The Vulkan compute backend: uploads the scene's constants and media, then runs
// render.comp in short progressive passes (a real GPU's watchdog never fires),
// accumulating Σ L and Σ L² per pixel on the device, and reads them back.
#include <memory>

#include "render/Backend.h"

namespace pyrolume {

namespace vk {
class Context;
}

class VulkanRenderer : public Backend {
 public:
  explicit VulkanRenderer(const BackendOptions& options);
  ~VulkanRenderer() override;
  std::string name() const override { return "vulkan"; }
  std::string device_name() const override;
  RenderResult render(const Scene& scene, const RenderSettings& settings, const RenderControl& control) override;
  uint64_t validation_messages() const override;

  // Samples per pixel per dispatch: a fixed function of the image size, so the
  // pass schedule (and with it the float summation order) never depends on
  // timing and reruns are bit-identical.
  static int spp_per_pass(int width, int height, int spp);

 private:
  std::unique_ptr<vk::Context> context_;
  double context_seconds_ = 0.0;  // instance + device creation, charged to the first render's load_seconds
};

}  // namespace pyrolume
