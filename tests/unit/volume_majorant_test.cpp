// Majorant bound (issue 5): brute force over random points shows that no
// trilinearly interpolated density exceeds its cell's majorant — on the
// procedural fire (as stored in R16F) and on a real VDB.
#include <random>

#include <gtest/gtest.h>

#include "scene/MediumVolume.h"
#include "scene/Scene.h"
#include "support/TestSupport.h"
#include "support/VdbScenes.h"
#include "render/LineEstimator.h"
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
  const std::filesystem::path vdb = test::real_vdb_dir();
  if (vdb.empty() || !std::filesystem::exists(vdb / "openvdb_smoke1_houdini.vdb"))
    GTEST_SKIP() << test::kRealVdbAbsent << ": real-data majorant check skipped";
  Medium m = test::vdb_file_medium(vdb / "openvdb_smoke1_houdini.vdb");
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

// A 64³ texture (unit voxels, one texel of zero padding) filled by f(x, y, z).
template <class F>
DenseGrid field_grid(F f) {
  DenseGrid g;
  g.dims = glm::ivec3(64);
  g.values.assign(g.texel_count(), 0.0f);
  for (int k = 1; k < 63; ++k)
    for (int j = 1; j < 63; ++j)
      for (int i = 1; i < 63; ++i) g.values[(size_t(k) * 64 + j) * 64 + i] = f(i + 0.5, j + 0.5, k + 0.5);
  g.max_value = 1.0f;
  return g;
}

// Where the default cells already bound the density tightly (a uniform dense
// block), finer cells only add DDA steps: the cost model keeps the default.
TEST(MajorantChoice, KeepsTheDefaultWhereTheDefaultIsTight) {
  const DenseGrid block = field_grid([](double, double, double) { return 1.0f; });
  EXPECT_EQ(choose_majorant_resolution(block, 1.0, 0.5), default_majorant_resolution(block.dims));
  const MajorantGrid coarse = build_majorant_grid(block, default_majorant_resolution(block.dims));
  const MajorantGrid fine = build_majorant_grid(block, default_majorant_resolution(block.dims) * 4);
  EXPECT_LT(tracking_cost(block, coarse, 1.0, 0.5), tracking_cost(block, fine, 1.0, 0.5));
}

// A dense shell 2 texels thick (radius 24, empty inside): a 16³ cell it
// crosses is bounded by the shell's density but mostly empty, so most
// tentative collisions there are null. Finer cells cost less, and the cost
// model picks them; the density lookups it saves are real (the
// simulated cost falls by more than a third).
TEST(MajorantChoice, PicksFinerCellsForAThinDenseShell) {
  const DenseGrid shell = field_grid([](double x, double y, double z) {
    const double r = glm::length(glm::dvec3(x, y, z) - 32.0);
    return std::abs(r - 24.0) < 1.0 ? 1.0f : 0.0f;
  });
  const glm::ivec3 def = default_majorant_resolution(shell.dims), chosen = choose_majorant_resolution(shell, 4.0, 0.0);
  EXPECT_GT(chosen.x, def.x);
  EXPECT_EQ(chosen.x, chosen.y);
  EXPECT_EQ(chosen.x, chosen.z);
  const double c_def = tracking_cost(shell, build_majorant_grid(shell, def), 4.0, 0.0);
  const double c_chosen = tracking_cost(shell, build_majorant_grid(shell, chosen), 4.0, 0.0);
  EXPECT_LT(c_chosen, 0.67 * c_def) << "default " << c_def << ", chosen " << c_chosen;
  // Deterministic: the same choice every time (the same image every run).
  EXPECT_EQ(choose_majorant_resolution(shell, 4.0, 0.0), chosen);
}

// When free flights walk the cells (a grid that is the scene's only medium:
// kWalkedFlightCosts) a crossing costs less, so on a smooth fire-like blob the
// model picks finer cells (16 per axis against 8: simulated costs 5.7 against
// 6.1 lookups per ray walked, 8.9 against 8.7 restarted);
// majorant_resolution uses the walked costs exactly when the scene has one
// medium.
TEST(MajorantChoice, WalkedFlightsPickFinerCells) {
  const DenseGrid blob = field_grid([](double x, double y, double z) {
    const double r = glm::length(glm::dvec3(x, y, z) - 32.0);
    return float(std::max(0.0, 1.0 - r / 28.0));
  });
  const glm::ivec3 restarted = choose_majorant_resolution(blob, 1.0, 0.5, kRestartedFlightCosts);
  const glm::ivec3 walked = choose_majorant_resolution(blob, 1.0, 0.5, kWalkedFlightCosts);
  EXPECT_GT(walked.x, restarted.x) << "restarted " << restarted.x << ", walked " << walked.x;

  Medium m;
  m.sigma_a = glm::dvec3(0.5);
  m.sigma_s = glm::dvec3(0.5);
  Scene one;
  one.media.push_back(m);
  EXPECT_EQ(majorant_resolution(one, m, blob), walked);
  Scene two = one;
  two.media.push_back(m);
  EXPECT_EQ(majorant_resolution(two, m, blob), restarted);
}

// choose_majorant_resolution max-pools each candidate into the next coarser
// one; that is exactly build_majorant_grid at the coarser resolution (cell c
// of res r spans cells 2c and 2c + 1 of res 2r, and its texel footprint is
// the union of theirs).
TEST(MajorantChoice, MaxPoolingEqualsBuildingTheCoarserGrid) {
  Medium m = test::vdb_file_medium(std::filesystem::path(PYROLUME_SOURCE_DIR) / "assets/volumes/fire.vdb");
  const DenseGrid& g = load_stored_volume(m).density.grid;
  const glm::ivec3 r = default_majorant_resolution(g.dims);
  const MajorantGrid fine = build_majorant_grid(g, r * 2), coarse = build_majorant_grid(g, r);
  int differ = 0;
  for (int z = 0; z < r.z; ++z)
    for (int y = 0; y < r.y; ++y)
      for (int x = 0; x < r.x; ++x) {
        float mx = 0.0f;
        for (int c = 0; c < 8; ++c) mx = std::max(mx, fine.at(2 * x + (c & 1), 2 * y + (c >> 1 & 1), 2 * z + (c >> 2)));
        differ += mx != coarse.at(x, y, z);
      }
  EXPECT_EQ(differ, 0);
}

// What the file says wins: integrator.majorant_grid, and "global" (one cell).
TEST(MajorantChoice, TheFilesChoiceWins) {
  const DenseGrid shell = field_grid([](double x, double, double) { return x < 3.0 ? 1.0f : 0.0f; });
  Medium m;
  m.sigma_a = glm::dvec3(4.0);
  Scene scene;
  scene.media.push_back(m);
  scene.integrator.majorant_grid = glm::ivec3(3, 5, 7);
  EXPECT_EQ(majorant_resolution(scene, m, shell), glm::ivec3(3, 5, 7));
  scene.integrator.majorant = Majorant::Global;
  EXPECT_EQ(majorant_resolution(scene, m, shell), glm::ivec3(1));
}

}  // namespace
}  // namespace pyrolume
