#include "render/Backend.h"

#include "render/cpu/CpuRenderer.h"
#include "render/vulkan/VulkanRenderer.h"
#include "util/Error.h"

namespace pyrolume {

std::unique_ptr<Backend> make_backend(const std::string& name, const BackendOptions& options) {
  if (name == "cpu") return std::make_unique<CpuRenderer>();
  if (name == "vulkan") return std::make_unique<VulkanRenderer>(options);
  throw input_error("--backend", "", "unknown backend \"" + name + "\" (use vulkan or cpu)");
}

}  // namespace pyrolume
