// Majorant bound (issue 5): brute force over random points shows that no
// trilinearly interpolated density exceeds its cell's majorant — on the
// procedural fire (as stored in R16F) and on a real VDB.
#include <random>

#include <gtest/gtest.h>

#include "scene/MediumVolume.h"
#include "scene/Scene.h"
#include "support/TestSupport.h"
#include "support/VdbScenes.h"
#include "volume/MajorantGrid.h"
#include "volume/StoredVolume.h"

namespace pyrolume {
namespace {

// Every point of every cell: the interpolated value at u (texel coordinates,
// texel i's centre at i + 0.5) is <= the majorant of the cell containing u. Points
// on a cell face belong to both neighbours, so both are checked.
void check_bound(const DenseGrid& g, const MajorantGrid& m, int samples, uint32_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  const glm::dvec3 dims(g.dims);
  int checked = 0, violations = 0, nonzero = 0;
  double worst = 0.0;
  for (int n = 0; n < samples; ++n) {
    glm::dvec3 u(uni(rng) * dims.x, uni(rng) * dims.y, uni(rng) * dims.z);
    if (n % 4 == 0) {  // snap one axis to a cell face: the hardest points
      int a = n % 3;
      u[a] = std::round(u[a] / m.cell_size[a]) * m.cell_size[a];
    }
    double v = g.sample_index(u - 0.5 + glm::dvec3(g.origin));
    if (v > 0) ++nonzero;
    glm::ivec3 lo = glm::clamp(glm::ivec3(glm::floor((u - 1e-9) / m.cell_size)), glm::ivec3(0), m.res - 1);
    glm::ivec3 hi = glm::clamp(glm::ivec3(glm::floor((u + 1e-9) / m.cell_size)), glm::ivec3(0), m.res - 1);
    for (int z = lo.z; z <= hi.z; ++z)
      for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x) {
          ++checked;
          double bound = m.at(x, y, z);
          if (v > bound) {
            ++violations;
            worst = std::max(worst, v - bound);
          }
        }
  }
  EXPECT_EQ(violations, 0) << "of " << checked << " checks; worst excess " << worst;
  EXPECT_GT(nonzero, samples / 50) << "the points must actually probe the medium";
}

TEST(MajorantGrid, BoundsEveryTrilinearLookupOfTheProceduralFire) {
  Medium m = test::vdb_file_medium(std::filesystem::path(PYROLUME_SOURCE_DIR) / "assets/volumes/fire.vdb");
  StoredVolume v = load_stored_volume(m);
  ASSERT_EQ(v.density.format, TextureFormat::R16F);
  for (glm::ivec3 res : {default_majorant_resolution(v.density.grid.dims), glm::ivec3(7, 5, 3), glm::ivec3(64)}) {
    MajorantGrid grid = build_majorant_grid(v.density.grid, res);
    check_bound(v.density.grid, grid, 200000, 1 + res.x);
  }
}

TEST(MajorantGrid, BoundsEveryTrilinearLookupOfARealVdb) {
  auto data = test::shared_data_dir();
  if (data.empty() || !std::filesystem::exists(data / "vdb/openvdb_smoke1_houdini.vdb"))
    GTEST_SKIP() << "../shared/data/vdb is absent: real-data majorant check skipped";
  Medium m = test::vdb_file_medium(data / "vdb/openvdb_smoke1_houdini.vdb");
  StoredVolume v = load_stored_volume(m);
  MajorantGrid grid = build_majorant_grid(v.density.grid, default_majorant_resolution(v.density.grid.dims));
  check_bound(v.density.grid, grid, 300000, 42);
}

// The bound must come from the values as stored: a cell max taken from the
// unrounded floats can be below a rounded-up half texel (pbrt-v4 issue 33).
TEST(MajorantGrid, UsesTheRoundedHalfValues) {
  StoredGrid g;
  g.grid.dims = glm::ivec3(4, 4, 4);
  g.grid.values.assign(64, 0.0f);
  g.grid.values[21] = 0.3f;  // the nearest half is 0.300048828125: rounding goes up
  g.grid.max_value = 0.3f;
  g.format = TextureFormat::R16F;
  round_to_format(g);
  EXPECT_GT(g.grid.values[21], 0.3f);
  MajorantGrid m = build_majorant_grid(g.grid, glm::ivec3(1));
  EXPECT_EQ(m.at(0, 0, 0), g.grid.values[21]);
}

}  // namespace
}  // namespace pyrolume
