// A scene that names only a VDB file renders a visible, unclipped fire
// coloured by temperature (issue 22; docs/sources.md), for exports laid out as
// Houdini and Blender's Mantaflow write them; the real files are checked in
// tests/realdata. Also: the warnings a disappointing render gets, and the
// default rig (docs/scene-format.md "default_lights"), which is part of the
// completed scene, so both backends render it: a density-only smoke export
// from the shortest scene, Vulkan against the CPU reference, per pixel
// (z-test, 3×3-pooled variance) and in the image mean. That comparison can
// fail: the same smoke with the sun mirrored to the camera's left is rejected.
#include <gtest/gtest.h>

#include <cmath>

#include "render/SceneSetup.h"
#include "support/BackendSuite.h"
#include "support/FirstTry.h"
#include "support/Stats.h"
#include "support/TestSupport.h"
#include "support/VdbScenes.h"

using namespace pyrolume::test;
namespace fs = std::filesystem;

namespace {

// A plume 12 voxels wide and 40 tall along `up`: density and heat fall off
// from the axis and with height, as a rising fire's do.
FloatGridSpec plume(const std::string& name, float peak, bool z_up, float voxel = 0.1f) {
  return upright_grid(name, voxel, 12, 40, z_up, [=](int a, int b, int h) {
    const float r2 = float((a - 5.5) * (a - 5.5) + (b - 5.5) * (b - 5.5)) / 36.0f;
    return peak * std::max(0.0f, 1.0f - r2) * std::max(0.0f, 1.0f - float(h) / 45.0f);
  });
}

struct FirstTry : ::testing::Test {
  fs::path dir = temp_dir("first-try");
  void TearDown() override { fs::remove_all(dir); }
  // Renders {"media": [{"type": "vdb", "file": F}]} and measures the PNG.
  FirstTryLook render_shortest(const fs::path& vdb, std::string* err = nullptr) {
    write_file(dir / "s.json", R"({"media": [{"type": "vdb", "file": ")" + vdb.filename().string() + R"("}]})");
    const CliResult r = run_cli("render " + q(dir / "s.json") + " -o " + q(dir / "s.png") + " --spp 8");
    EXPECT_EQ(r.status, 0) << r.err;
    if (err) *err = r.err;
    return first_try_look(dir / "s.png");
  }
  static std::string q(const fs::path& p) { return "'" + p.string() + "'"; }
};

}  // namespace

TEST_F(FirstTry, HoudiniPyroExport) {
  // Y up, unitless temperature (burning ~1.3), a flame grid (what makes a
  // Pyro export a fire, docs/sources.md "Smoke is smoke"), creator metadata.
  write_vdb(dir / "pyro.vdb", {plume("density", 3.0f, false), plume("temperature", 1.3f, false),
                               plume("flame", 1.0f, false), plume("vel", 0.5f, false)},
            {{"creator", "Houdini/SOP_OpenVDB_Write"}});
  std::string err;
  const FirstTryLook look = render_shortest(dir / "pyro.vdb", &err);
  std::printf("houdini: %s\n", look.summary().c_str());
  EXPECT_TRUE(look.looks_like_fire()) << look.summary();
  EXPECT_EQ(look.height, 640) << "a tall plume turns the default film upright";
  EXPECT_EQ(err, "") << "nothing to say about a file that names its simulator";
}

TEST_F(FirstTry, MantaflowFireExport) {
  // Blender 2.8+ cache: Z up, no creator; heat is "temperature" (0..2), plus flame and shadow.
  write_vdb(dir / "fluid_data_0040.vdb",
            {plume("density", 1.0f, true), plume("temperature", 2.0f, true), plume("flame", 0.9f, true),
             make_float_grid("shadow", Lattice{0.1, glm::dvec3(0.0)}, VoxelBox{{0, 0, 0}, {11, 11, 39}},
                             [](int, int, int) { return -1.0f; })});
  const FirstTryLook look = render_shortest(dir / "fluid_data_0040.vdb");
  std::printf("mantaflow: %s\n", look.summary().c_str());
  EXPECT_TRUE(look.looks_like_fire()) << look.summary();
}

// The check itself can fail: a fire mapped below the cutoff renders black and
// a hundredfold brighter one clips; both are also said on stderr.
TEST_F(FirstTry, TheCheckRejectsBlackAndClippedRenders) {
  write_vdb(dir / "pyro.vdb", {plume("density", 3.0f, false), plume("temperature", 1.3f, false)},
            {{"creator", "Houdini/SOP_OpenVDB_Write"}});
  write_file(dir / "cold.json",
             R"({"media": [{"type": "vdb", "file": "pyro.vdb", "temperature": {"scale": 50}}]})");
  CliResult r = run_cli("render " + q(dir / "cold.json") + " -o " + q(dir / "cold.png") + " --spp 2");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("pyrolume: warning: " + (dir / "pyro.vdb").string() +
                       ": temperature grid \"temperature\": the hottest voxel maps to"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("pyrolume: warning: " + (dir / "cold.png").string() + ": the image is almost entirely black"),
            std::string::npos)
      << r.err;
  const FirstTryLook cold = first_try_look(dir / "cold.png");
  EXPECT_FALSE(cold.looks_like_fire()) << cold.summary();
  write_file(dir / "s.json", R"({"media": [{"type": "vdb", "file": "pyro.vdb"}]})");
  r = run_cli("render " + q(dir / "s.json") + " -o " + q(dir / "hot.png") + " --spp 2 --exposure 9");
  EXPECT_EQ(r.status, 0) << r.err;
  const FirstTryLook hot = first_try_look(dir / "hot.png");
  EXPECT_GT(hot.clipped, 0.10) << hot.summary();
  EXPECT_FALSE(hot.looks_like_fire()) << hot.summary();
}

// A camera the file places looking away from everything is said before rendering.
TEST_F(FirstTry, ACameraThatSeesNothingIsSaid) {
  write_vdb(dir / "pyro.vdb", {plume("density", 3.0f, false), plume("temperature", 1.3f, false)},
            {{"creator", "Houdini/SOP_OpenVDB_Write"}});
  write_file(dir / "s.json", R"({"camera": {"position": [0.6, 2, 5], "look_at": [0.6, 2, 10]},
    "film": {"width": 16, "height": 12, "spp": 1}, "media": [{"type": "vdb", "file": "pyro.vdb"}]})");
  const CliResult r = run_cli("render " + q(dir / "s.json") + " -o " + q(dir / "s.exr"));
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("pyrolume: warning: " + (dir / "s.json").string() + ": nothing is in the camera's view"),
            std::string::npos)
      << r.err;
}

namespace pyrolume::test {
namespace {

class DefaultRig : public BackendFixture {
 protected:
  DefaultRig() : BackendFixture("vulkan") {}
  fs::path dir = temp_dir("default-rig");
  void TearDown() override {
    BackendFixture::TearDown();
    fs::remove_all(dir);
  }
  // A 5-unit puff of density up to 3 (as thick as Pyro smoke), Houdini's
  // creator, no temperature: smoke lit only by the rig.
  Scene smoke_scene(int spp, uint32_t seed) {
    const VoxelBox box{{0, 0, 0}, {9, 13, 9}};
    write_vdb(dir / "smoke.vdb",
              {make_float_grid("density", Lattice{0.5, glm::dvec3(0.0)}, box,
                               [](int i, int j, int k) {
                                 const double a = (i - 4.5) / 5.0, b = (k - 4.5) / 5.0, h = (j - 6.5) / 7.0;
                                 return 3.0f * float(std::max(0.0, 1.0 - (a * a + b * b + h * h)));
                               })},
              {{"creator", "Houdini/SOP_OpenVDB_Write"}});
    write_file(dir / "s.json", R"({"film": {"width": 24, "height": 24, "spp": )" + std::to_string(spp) +
                                   R"(, "seed": )" + std::to_string(seed) +
                                   R"(}, "media": [{"type": "vdb", "file": "smoke.vdb"}]})");
    Scene s = load_scene(dir / "s.json");
    complete_scene(s, true);
    return s;
  }
};

TEST_F(DefaultRig, BothBackendsRenderItAlike) {
  const Scene s = smoke_scene(128, 1);
  ASSERT_EQ(s.lights.size(), 1u) << "the rig's sun";
  const RenderResult gpu = render(s);
  const Scene c = smoke_scene(128, 2);
  const RenderResult cpu = cpu_renderer().render(c, settings_for(c), {});
  const ZTestReport rep = ztest_images(gpu, cpu, pooled(0.02));
  std::printf("default rig, vulkan vs cpu: %s\n", rep.summary().c_str());
  EXPECT_TRUE(rep.ok) << rep.summary();
  // Mirrored sun: a different image, which the same test must reject.
  Scene mirrored = c;
  const glm::dvec3 forward = glm::normalize(c.camera.look_at - c.camera.position);
  const glm::dvec3 right = glm::normalize(glm::cross(forward, c.camera.up));
  mirrored.lights[0].direction -= 2.0 * glm::dot(mirrored.lights[0].direction, right) * right;
  const RenderResult other = cpu_renderer().render(mirrored, settings_for(mirrored), {});
  const ZTestReport bad = ztest_images(gpu, other, pooled(0.02));
  std::printf("deliberately wrong (sun on the left): %s\n", bad.summary().c_str());
  EXPECT_FALSE(bad.fraction_ok) << bad.summary();
}

}  // namespace
}  // namespace pyrolume::test
