// The committed demo volume (tools/gen_fire_vdb output) and the scene that
// renders it: small, Blender-like grid layout, fire-like temperature range.
#include <gtest/gtest.h>

#include <filesystem>

#include "scene/MediumVolume.h"
#include "scene/Scene.h"
#include "support/VdbScenes.h"
#include "volume/VdbLoader.h"

namespace pyrolume {
namespace {

namespace fs = std::filesystem;
const fs::path kSource = PYROLUME_SOURCE_DIR;

TEST(FireAsset, IsSmallAndLaidOutLikeABlenderExport) {
  const fs::path vdb = kSource / "assets/volumes/fire.vdb";
  ASSERT_TRUE(fs::exists(vdb)) << "regenerate it: see docs/volumes.md";
  EXPECT_LT(fs::file_size(vdb), 1500u * 1000u);
  Medium m = test::vdb_file_medium(vdb);
  const VolumeGrids v = load_volume(m, true);
  EXPECT_TRUE(v.warnings.empty());
  ASSERT_TRUE(v.temperature);
  EXPECT_EQ(v.temperature->name, "temperature");
  // Different voxel sizes, and lattices offset by half a density voxel.
  const double hd = v.density.index_to_world[0][0], ht = v.temperature->index_to_world[0][0];
  EXPECT_NEAR(ht, 2 * hd, 1e-9);
  EXPECT_NEAR(v.density.index_to_world[3][0], 0.5 * hd, 1e-9);
  EXPECT_NEAR(v.temperature->index_to_world[3][0], 0.0, 1e-9);
  // Blender-like dimensionless temperature, density of order 1.
  EXPECT_GT(v.temperature->max_value, 1.2f);
  EXPECT_LT(v.temperature->max_value, 1.7f);
  EXPECT_GE(v.density.min_value, 0.0f);
  EXPECT_GT(v.density.max_value, 0.5f);
  EXPECT_LT(v.density.max_value, 3.0f);
}

TEST(FireAsset, DemoSceneMapsTheCoreToFlameTemperatures) {
  const Scene s = load_scene(kSource / "assets/scenes/fire.json");
  ASSERT_EQ(s.media.size(), 1u);
  const Medium& m = s.media[0];
  ASSERT_EQ(m.type, Medium::Type::Vdb);
  const VolumeGrids v = load_volume(m, true);  // the relative file resolves from any working directory
  ASSERT_TRUE(v.temperature);
  const double hottest_k = (v.temperature->max_value - m.temperature.offset) * m.temperature.scale;
  EXPECT_GT(hottest_k, 1800.0);
  EXPECT_LT(hottest_k, 2500.0);
  EXPECT_GE(m.temperature.cutoff_k, 700.0);
  EXPECT_LE(m.temperature.cutoff_k, 900.0);
  EXPECT_EQ(s.film.width, 480);
  EXPECT_EQ(s.film.height, 270);
}

}  // namespace
}  // namespace pyrolume
