// The real smoke exports (read in place from the shared data folder's vdb/,
// test::shared_data_dir(); skipped when it is absent) render as smoke from
// the shortest scene (issue 46; docs/sources.md "Smoke is smoke"): visible,
// shaded by the default rig, no glow, not clipped (support/SmokeLook.h).
// The Blender fire keeps glowing.
#include <gtest/gtest.h>

#include "support/SmokeLook.h"
#include "support/TestSupport.h"
#include "volume/SourceConventions.h"
#include "volume/VdbInfo.h"

namespace pyrolume {
namespace {

namespace fs = std::filesystem;

class RealSmoke : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = test::real_vdb_dir();
    if (dir.empty()) GTEST_SKIP() << test::kRealVdbAbsent;
    out = test::temp_dir("real-smoke");
  }
  void TearDown() override {
    if (!out.empty()) fs::remove_all(out);
  }
  SourceConvention convention(const std::string& name) {
    SourceConvention c = source_convention(read_volume_file_info(dir / name, false), VolumeSource::Auto);
    fit_temperature_mapping(c, (dir / name).string());
    settle_emission(c, (dir / name).string());
    return c;
  }
  // The smoke check; the default rig's note is the only line on stderr.
  void expect_smoke(const std::string& name, const std::string& label) {
    std::string err;
    const test::SmokeLook look = test::run_smoke_look(out, dir / name, label, &err);
    std::printf("%s: %s\n", name.c_str(), look.summary().c_str());
    EXPECT_TRUE(look.visible_ok()) << look.summary();
    EXPECT_TRUE(look.shaded_ok()) << look.summary();
    EXPECT_TRUE(look.no_glow()) << look.summary();
    EXPECT_TRUE(look.clip_ok()) << look.summary();
    EXPECT_NE(err.find("pyrolume: note: "), std::string::npos) << err;
    EXPECT_NE(err.find("lit by the default rig"), std::string::npos) << err;
    EXPECT_EQ(err.find("warning"), std::string::npos) << err;
  }
  fs::path dir, out;
};

TEST_F(RealSmoke, MantaflowSmokeIsSmoke) {
  const SourceConvention c = convention("blender50_mantaflow_smoke_frame0001.vdb");
  EXPECT_FALSE(c.emits) << c.emission_text;  // its flame grid is empty
  EXPECT_EQ(c.index_offset, 0.5);             // Mantaflow's cell corner
  expect_smoke("blender50_mantaflow_smoke_frame0001.vdb", "smoke_blender50_mantaflow");
}

TEST_F(RealSmoke, HoudiniSmokeIsSmoke) {
  const SourceConvention c = convention("openvdb_smoke1_houdini.vdb");
  EXPECT_TRUE(c.temperature_grid.empty());
  EXPECT_EQ(c.index_offset, 0.0);
  expect_smoke("openvdb_smoke1_houdini.vdb", "smoke_houdini_openvdb");
}

// The fire has flame: it still emits from heat, placed as before (2.7x caches
// carry the half voxel in their transform), and does not scatter by default.
TEST_F(RealSmoke, BlenderFireStillBurns) {
  const SourceConvention c = convention("blender279_fire_frame075.vdb");
  EXPECT_TRUE(c.emits) << c.emission_text;
  EXPECT_EQ(c.flame_grid, "flame");
  EXPECT_EQ(c.index_offset, 0.0);
}

}  // namespace
}  // namespace pyrolume
