#pragma once
// The backend interface: the Vulkan renderer and the CPU reference render the
// same Scene into the same RenderResult. The factory that picks one by name
// is backends/Backends.h.
#include <cstdint>
#include <string>

#include "render/Render.h"

namespace pyrolume {

class Backend {
 public:
  virtual ~Backend() = default;
  virtual std::string name() const = 0;         // "vulkan" | "cpu"
  virtual std::string device_name() const = 0;  // e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  virtual RenderResult render(const Scene& scene, const RenderSettings& settings,
                              const RenderControl& control) = 0;
  // Vulkan validation messages seen so far (tests require 0).
  virtual uint64_t validation_messages() const { return 0; }
};

// What backends/Backends.h make_backend passes on; a backend ignores what it
// has no use for.
struct BackendOptions {
  int device_index = -1;    // -1: PYROLUME_DEVICE or automatic choice
  bool validation = false;  // also on when PYROLUME_VALIDATION=1
  // Sequences (docs/animation.md): keep what the last render built for the
  // next frame of the same scene (Vulkan: VulkanRenderer::set_frame_reuse).
  bool frame_reuse = false;
};

}  // namespace pyrolume
