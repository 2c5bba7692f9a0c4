// The real exports (read in place from the shared data folder's vdb/,
// test::real_vdb_dir; skipped when that folder is absent): the source each is detected as, and the first-try check
// of issue 22 on the fire: a scene that names only the file shows a visible,
// unclipped fire coloured by temperature (docs/sources.md).
#include <gtest/gtest.h>

#include <sstream>

#include "support/FirstTry.h"
#include "support/TestSupport.h"
#include "volume/SourceConventions.h"
#include "volume/VdbInfo.h"

namespace pyrolume {
namespace {

namespace fs = std::filesystem;

class RealSources : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = test::real_vdb_dir();
    if (dir.empty()) GTEST_SKIP() << test::kRealVdbAbsent;
  }
  SourceConvention detect(const std::string& name) {
    SourceConvention c = source_convention(read_volume_file_info(dir / name, false), VolumeSource::Auto);
    fit_temperature_mapping(c, (dir / name).string());
    return c;
  }
  fs::path dir;
};

TEST_F(RealSources, EachExportIsDetectedAsItsSimulator) {
  const SourceConvention fire = detect("blender279_fire_frame075.vdb");
  EXPECT_EQ(fire.source, VolumeSource::Blender);
  EXPECT_NE(fire.why.find("creator \"Blender/Smoke\""), std::string::npos) << fire.why;
  EXPECT_EQ(fire.temperature_grid, "heat");
  EXPECT_EQ(fire.up_axis, UpAxis::Z);
  const SourceConvention manta = detect("blender50_mantaflow_smoke_frame0001.vdb");
  EXPECT_EQ(manta.source, VolumeSource::Blender);
  EXPECT_FALSE(manta.guessed);
  EXPECT_EQ(manta.temperature_grid, "temperature");
  EXPECT_EQ(manta.mapping.scale, 1000.0);
  const SourceConvention smoke = detect("openvdb_smoke1_houdini.vdb");
  EXPECT_EQ(smoke.source, VolumeSource::Houdini);
  EXPECT_EQ(smoke.up_axis, UpAxis::Y);
  EXPECT_TRUE(smoke.temperature_grid.empty());  // density only: nothing glows
}

TEST_F(RealSources, InfoPrintsMetadataTheSourceAndAScene) {
  const test::CliResult r = test::run_cli("info '" + (dir / "blender279_fire_frame075.vdb").string() + "'");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("metadata \"blender/smoke/obmat\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("source blender (creator \"Blender/Smoke\"), up axis z"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("{\"media\": [{\"type\": \"vdb\", \"file\": "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("temperature from grid \"heat\": T = 1000·heat K"), std::string::npos) << r.out;
}

TEST_F(RealSources, BlenderFireLooksLikeAFireOnTheFirstTry) {
  const fs::path out = test::temp_dir("real-first-try");
  test::write_file(out / "s.json",
                   R"({"media": [{"type": "vdb", "file": ")" + (dir / "blender279_fire_frame075.vdb").string() + R"("}]})");
  const test::CliResult r = test::run_cli("render '" + (out / "s.json").string() + "' -o '" + (out / "s.png").string() +
                                          "' --spp 8");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const test::FirstTryLook look = test::first_try_look(out / "s.png");
  std::printf("blender 2.79 fire: %s\n", look.summary().c_str());
  EXPECT_TRUE(look.looks_like_fire()) << look.summary();
  fs::remove_all(out);
}

}  // namespace
}  // namespace pyrolume
