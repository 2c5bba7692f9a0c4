#pragma once
// The backend interface: the Vulkan renderer and the CPU reference render the
// same Scene into the same RenderResult.
#include <memory>
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

struct BackendOptions {
  int device_index = -1;    // -1: PYROLUME_DEVICE or automatic choice
  bool validation = false;  // also on when PYROLUME_VALIDATION=1
};

// "vulkan" or "cpu"; throws InputError for an unknown name, and a clear error
// pointing at --backend cpu when no Vulkan device exists.
std::unique_ptr<Backend> make_backend(const std::string& name, const BackendOptions& options = {});

}  // namespace pyrolume
