#pragma once
// Finds compiled shaders whatever the working directory, and specialises them.
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace pyrolume::vk {

// name: "render.comp" (reads render.comp.spv) or "render.comp.spv". Looks in
// shaders/ next to the running executable, then in the build tree's SPIR-V
// folder (PYROLUME_SPIRV_DIR); the error names both places.
std::vector<uint32_t> load_spirv(const std::string& name);

// The module with its specialization constants (constant_id, 32-bit value)
// frozen to those values and the code they switch off removed: dead branches,
// then unreachable functions and instructions (SPIRV-Tools' optimizer). The
// pipeline then gets no VkSpecializationInfo. Why: lavapipe turns the whole
// module into NIR, inlines it and runs its optimisation loop before it
// drops the branches a constant turns off, so the megakernel cost ~1 CPU-s
// per pipeline whatever the scene used; specialised first, creation takes
// about a third of that, for ~0.25 CPU-s here, and renders are bit-identical
// (docs/testing.md "Build and CI time"). The module is not validated again
// here (the build ran spirv-val on it): that halved this function's ~0.6 s.
// Returns the module unchanged where
// `specialization` is empty or the optimizer refuses it (the driver then
// specialises as before).
std::vector<uint32_t> specialize_spirv(const std::vector<uint32_t>& spirv,
                                       const std::vector<std::pair<uint32_t, uint32_t>>& specialization);

}  // namespace pyrolume::vk
