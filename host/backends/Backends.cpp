#include "backends/Backends.h"

#include "render/cpu/CpuRenderer.h"
#include "render/vulkan/Devices.h"
#include "render/vulkan/VulkanRenderer.h"
#include "util/Error.h"

namespace pyrolume {

std::unique_ptr<Backend> make_backend(const std::string& name, const BackendOptions& options) {
  if (name == "cpu") return std::make_unique<CpuRenderer>();
  if (name == "vulkan") return std::make_unique<VulkanRenderer>(options);
  throw input_error("--backend", "", "unknown backend \"" + name + "\" (use vulkan or cpu)");
}

std::string device_list(int requested) {
  const auto list = vk::list_devices();
  return vk::format_device_list(list, vk::choose_device(list, requested));
}

uint64_t accumulation_bytes(const std::string& backend, int width, int height) {
  if (backend == "cpu") return CpuRenderer::accumulation_bytes(width, height);
  if (backend == "vulkan") return VulkanRenderer::accumulation_bytes(width, height);
  return 0;
}

Checkpoint read_checkpoint(const std::filesystem::path& file) {
  Checkpoint c = read_checkpoint(file, accumulation_bytes);
  const uint64_t bad = c.state.backend == "cpu" ? CpuRenderer::nonfinite_sums(c.state) : VulkanRenderer::nonfinite_sums(c.state);
  if (bad > 0)
    throw input_error(file.string(), "",
                      "corrupt checkpoint: " + std::to_string(bad) + " of its accumulated sums are NaN or infinite "
                      "(delete it or render without --resume)");
  return c;
}

}  // namespace pyrolume
