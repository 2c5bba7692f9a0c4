#pragma once
// Finds compiled shaders whatever the working directory.
#include <cstdint>
#include <string>
#include <vector>

namespace pyrolume::vk {

// name: "render.comp" (reads render.comp.spv) or "render.comp.spv". Looks in
// shaders/ next to the running executable, then in the build tree's SPIR-V
// folder (PYROLUME_SPIRV_DIR); the error names both places.
std::vector<uint32_t> load_spirv(const std::string& name);

}  // namespace pyrolume::vk
