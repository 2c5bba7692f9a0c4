// The view transforms' two builds agree: shared/view_transform.h compiled as
// GLSL (shaders/test_view_transform.comp, as the preview's display shader
// runs it) and as C++ (as PNG output runs it) give the same display values
// for the same colours, for every view (agx, standard, agx_punchy, filmic),
// under the validation layers.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "render/vulkan/Context.h"
#include "render/vulkan/Memory.h"
#include "shared/view_transform.h"
#include "support/GpuCompute.h"

using namespace pyrolume;
using namespace pyrolume::vk;

namespace {

struct ViewQuery {
  glm::vec4 exposed, shown;
};
static_assert(sizeof(ViewQuery) == 32);

void run_queries(Context& ctx, std::vector<ViewQuery>& queries) {
  Buffer qbuf = test::in_out_buffer(ctx, queries, "view queries");
  test::run_compute(ctx, "test_view_transform.comp", {{&qbuf}}, uint32_t(queries.size()), {},
                    "test_view_transform");
  test::read_back(qbuf, queries);
}

}  // namespace

TEST(ViewTransformGpu, GlslMatchesCpp) {
  const uint64_t before = Context::total_validation_messages();
  Context ctx(test::validated());

  // Colours over the whole range the views map: a grey ramp and random
  // chromaticities from 2^-16 to 2^+12 (below the AgX range, through the
  // toe and shoulder, past white), and exact zeros.
  std::vector<ViewQuery> q;
  std::mt19937 rng(22);
  std::uniform_real_distribution<float> U(0.0f, 1.0f), ev(-16.0f, 12.0f);
  for (uint32_t view = 0; view < display::VIEW_COUNT; ++view) {
    for (int k = -64; k <= 48; ++k) {
      const float g = std::exp2(float(k) / 4.0f);
      q.push_back({glm::vec4(g, g, g, float(view)), glm::vec4(0.0f)});
    }
    q.push_back({glm::vec4(0.0f, 0.0f, 0.0f, float(view)), glm::vec4(0.0f)});
    for (int k = 0; k < 2000; ++k) {
      const float s = std::exp2(ev(rng));
      q.push_back({glm::vec4(s * U(rng), s * U(rng), s * U(rng), float(view)), glm::vec4(0.0f)});
    }
  }
  std::vector<ViewQuery> gpu = q;
  run_queries(ctx, gpu);

  // Vulkan lets log2/pow be a few ulp off (more near 0): allow 1e-3 in the
  // encoded value (a quarter of an 8-bit step) and at most one 8-bit step.
  int worse = 0;
  double worst = 0.0;
  for (size_t i = 0; i < q.size(); ++i) {
    const glm::vec3 cpu = display::view_display(glm::vec3(q[i].exposed), uint32_t(q[i].exposed.w));
    for (int c = 0; c < 3; ++c) {
      const double d = std::abs(double(gpu[i].shown[c]) - cpu[c]);
      worst = std::max(worst, d);
      ASSERT_LE(std::abs(std::lround(255.0f * gpu[i].shown[c]) - std::lround(255.0f * cpu[c])), 1)
          << "query " << i << " channel " << c << ": input " << q[i].exposed[c];
      if (d > 1e-3) ++worse;
    }
  }
  EXPECT_EQ(worse, 0) << "largest difference " << worst;
  EXPECT_EQ(ctx.validation_messages(), 0u);
  EXPECT_EQ(Context::total_validation_messages(), before);
}
