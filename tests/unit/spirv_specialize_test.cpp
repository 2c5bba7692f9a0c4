// specialize_spirv (host/render/vulkan/Spirv.h): the megakernel specialised
// on the host keeps no specialization constants and loses the code they
// switch off; without constants the module is handed on unchanged.
#include <gtest/gtest.h>

#include "render/vulkan/Spirv.h"
#include "shared/gpu_types.h"

namespace {

// SPIR-V opcodes OpSpecConstantTrue (48) .. OpSpecConstantOp (52).
int spec_constant_instructions(const std::vector<uint32_t>& words) {
  int n = 0;
  for (size_t i = 5; i < words.size();) {  // 5 header words, then (length << 16 | opcode) per instruction
    const uint32_t opcode = words[i] & 0xffffu, length = words[i] >> 16;
    if (length == 0) return -1;
    if (opcode >= 48 && opcode <= 52) ++n;
    i += length;
  }
  return n;
}

}  // namespace

TEST(SpirvSpecialize, FreezesConstantsAndDropsTheCodeTheyTurnOff) {
  using namespace pyrolume;
  using namespace pyrolume::gpu;
  const std::vector<uint32_t> render = vk::load_spirv("render.comp");
  ASSERT_GT(spec_constant_instructions(render), 10);
  // A grid medium, nothing else: no surfaces, lights, environment or AOVs.
  const std::vector<std::pair<uint32_t, uint32_t>> grid_only{
      {SPEC_HAS_GRIDS, 1},      {SPEC_HAS_ANALYTIC_MEDIA, 0}, {SPEC_HAS_SURFACES, 0}, {SPEC_HAS_ENVIRONMENT, 0},
      {SPEC_LIGHT_COUNT, 0},    {SPEC_AOVS, 0},               {SPEC_MEDIUM_COUNT, 1}, {SPEC_GRID_COUNT, 2},
      {SPEC_SPARSE_GRIDS, 0}};
  const std::vector<uint32_t> grid = vk::specialize_spirv(render, grid_only);
  EXPECT_EQ(grid[0], 0x07230203u);
  EXPECT_EQ(spec_constant_instructions(grid), 0);
  EXPECT_LT(grid.size(), render.size() * 3 / 4);
  // Surfaces switched on keep their code: a larger module than without.
  auto with_surfaces = grid_only;
  with_surfaces[2] = {SPEC_HAS_SURFACES, 1};
  with_surfaces.push_back({SPEC_SURFACE_SHAPE_COUNT, 1});
  EXPECT_GT(vk::specialize_spirv(render, with_surfaces).size(), grid.size());
  EXPECT_EQ(vk::specialize_spirv(render, {}), render);
}
