// Smoke is smoke (issue 46; docs/sources.md "Smoke is smoke", docs/scene-format.md
// "default_lights"): which exports emit, how smoke is shaded and placed, the
// default rig for a scene with no light, and the messages that name the cause.
#include <gtest/gtest.h>

#include <cmath>

#include "image/DisplayTransform.h"
#include "render/SceneSetup.h"
#include "scene/MediumVolume.h"
#include "support/SmokeLook.h"
#include "support/VdbScenes.h"
#include "util/Error.h"
#include "volume/SourceConventions.h"
#include "volume/StoredVolume.h"
#include "volume/VdbInfo.h"
#include "volume/VdbLoader.h"

using namespace pyrolume;
using namespace pyrolume::test;
namespace fs = std::filesystem;

namespace {

// A 10×10×14-voxel puff along `up`, densest at its centre.
FloatGridSpec smoke_puff(const std::string& name, float peak, bool z_up, float voxel = 0.1f) {
  return upright_grid(name, voxel, 10, 14, z_up, [=](int i, int j, int k) {
    const double a = (i - 4.5) / 5.0, b = (j - 4.5) / 5.0, h = (k - 6.5) / 7.0;
    return peak * float(std::max(0.0, 1.0 - (a * a + b * b + h * h)));
  });
}
FloatGridSpec zeros(const std::string& name, bool z_up, float voxel) { return smoke_puff(name, 0.0f, z_up, voxel); }
FloatGridSpec shadow(bool z_up, float voxel) {
  return make_float_grid("shadow", Lattice{voxel, glm::dvec3(0.0)},
                         VoxelBox{{0, 0, 0}, z_up ? glm::ivec3(9, 9, 13) : glm::ivec3(9, 13, 9)},
                         [](int, int, int) { return -1.0f; });
}

// Blender-style smoke (Mantaflow: no creator; temperature 0..1, flame written
// but zero everywhere, shadow; 2.8 units tall, like a Quick Smoke domain's
// first puff) and Houdini-style smoke (density only).
constexpr float kBlenderVoxel = 0.2f;
std::vector<FloatGridSpec> blender_smoke() {
  return {smoke_puff("density", 1.0f, true, kBlenderVoxel), smoke_puff("temperature", 1.0f, true, kBlenderVoxel),
          zeros("flame", true, kBlenderVoxel), shadow(true, kBlenderVoxel)};
}
// Houdini's units are metres: a 5 m puff of density up to 3, as thick as Pyro smoke.
std::vector<FloatGridSpec> houdini_smoke() { return {smoke_puff("density", 3.0f, false, 0.5f)}; }
const FileMetadata kHoudini{{"creator", "Houdini/SOP_OpenVDB_Write"}};

class SmokeIsSmoke : public ::testing::Test {
 protected:
  fs::path dir = temp_dir("smoke-is-smoke");
  void TearDown() override { fs::remove_all(dir); }

  SourceConvention convention(const std::vector<FloatGridSpec>& grids, const FileMetadata& meta,
                              VolumeSource source = VolumeSource::Auto) {
    const fs::path f = write_vdb(dir / "c.vdb", grids, meta);
    SourceConvention c = source_convention(read_volume_file_info(f, false), source);
    fit_temperature_mapping(c, f.string());
    settle_emission(c, f.string());
    return c;
  }
  // The shortest scene (plus `keys` in the medium, `top` at the top level), completed.
  Scene completed(const std::vector<FloatGridSpec>& grids, const FileMetadata& meta, const std::string& keys = "",
                  const std::string& top = "", SceneSetup* setup = nullptr) {
    write_vdb(dir / "s.vdb", grids, meta);
    write_file(dir / "s.json", "{" + top + R"("media": [{"type": "vdb", "file": "s.vdb")" + keys + "}]}");
    Scene s = load_scene(dir / "s.json");
    const SceneSetup out = complete_scene(s, false);
    if (setup) *setup = out;
    return s;
  }
};

}  // namespace

// Blender's rule (Quick Smoke's material glows only for its Fire styles): a
// flame grid that holds fire makes a file emit; none, an empty one or one
// that is zero everywhere is smoke. Houdini's fire shading reads flame
// (heat before 17.5). Guessed sources and kelvin files keep glowing.
TEST_F(SmokeIsSmoke, OnlyAFlameGridThatHoldsFireEmits) {
  SourceConvention c = convention(blender_smoke(), {});
  EXPECT_EQ(c.source, VolumeSource::Blender);
  EXPECT_FALSE(c.emits) << c.emission_text;
  EXPECT_NE(c.emission_text.find("\"flame\" is zero everywhere"), std::string::npos) << c.emission_text;
  c = convention({smoke_puff("density", 1.0f, true), smoke_puff("temperature", 1.0f, true), make_empty_grid("flame"),
                  shadow(true, 0.1f)},
                 {});
  EXPECT_FALSE(c.emits) << c.emission_text;
  EXPECT_NE(c.emission_text.find("no flame grid"), std::string::npos) << c.emission_text;
  c = convention({smoke_puff("density", 0.2f, true), smoke_puff("heat", 1.5f, true), smoke_puff("flame", 0.9f, true)},
                 {{"creator", "Blender/Smoke"}});
  EXPECT_TRUE(c.emits) << c.emission_text;  // a fire
  EXPECT_EQ(c.temperature_grid, "heat");
  c = convention({smoke_puff("density", 2.0f, false), smoke_puff("temperature", 1.3f, false)}, kHoudini);
  EXPECT_FALSE(c.emits) << c.emission_text;
  c = convention({smoke_puff("density", 2.0f, false), smoke_puff("temperature", 1.3f, false),
                  smoke_puff("flame", 1.0f, false)},
                 kHoudini);
  EXPECT_TRUE(c.emits) << c.emission_text;
  c = convention({smoke_puff("density", 2.0f, false), smoke_puff("heat", 1.0f, false)}, kHoudini);
  EXPECT_TRUE(c.emits) << c.emission_text;  // Houdini before 17.5
  c = convention({smoke_puff("density", 2.0f, false), smoke_puff("temperature", 1.3f, false)}, {});
  EXPECT_TRUE(c.guessed);
  EXPECT_TRUE(c.emits) << "a guessed source keeps glowing from its temperature";
  c = convention({smoke_puff("density", 2.0f, false), smoke_puff("temperature", 1800.0f, false)}, kHoudini,
                 VolumeSource::Kelvin);
  EXPECT_TRUE(c.emits) << "kelvin files glow from their temperature";
}

// The medium: no emission, the tool's default volume material (Blender's
// Quick Smoke: Density 5, Color 0.5; Houdini: density 1, albedo 0.5), unless
// the scene writes keys that ask otherwise.
TEST_F(SmokeIsSmoke, SmokeScattersWithTheToolsMaterialUnlessTheSceneSaysOtherwise) {
  Scene s = completed(blender_smoke(), {});
  ASSERT_EQ(s.media.size(), 1u);
  EXPECT_FALSE(s.media[0].emission.emits());
  EXPECT_EQ(s.media[0].sigma_s, glm::dvec3(0.5));
  EXPECT_EQ(s.media[0].sigma_a, glm::dvec3(0.5));
  EXPECT_EQ(s.media[0].density_scale, 5.0);
  s = completed(houdini_smoke(), kHoudini);
  EXPECT_FALSE(s.media[0].emission.emits());
  EXPECT_EQ(s.media[0].sigma_s, glm::dvec3(0.5));
  EXPECT_EQ(s.media[0].density_scale, 1.0);
  // Keys the scene writes win.
  s = completed(blender_smoke(), {}, R"(, "sigma_a": [2, 2, 2], "density_scale": 0.5)");
  EXPECT_EQ(s.media[0].sigma_a, glm::dvec3(2.0));
  EXPECT_EQ(s.media[0].sigma_s, glm::dvec3(0.0));
  EXPECT_EQ(s.media[0].density_scale, 0.5);
  for (const char* asks : {R"(, "emission": {"scale": 2})", R"(, "temperature": {"scale": 1500})",
                           R"(, "temperature_grid": "temperature")"}) {
    s = completed(blender_smoke(), {}, asks);
    EXPECT_TRUE(s.media[0].emission.emits()) << asks;
    EXPECT_EQ(s.media[0].sigma_s, glm::dvec3(0.0)) << asks;
    EXPECT_TRUE(s.lights.empty()) << asks;
  }
}

// Mantaflow writes cell ijk's corner at index ijk and Cycles reads it so: the
// grid sits half a voxel higher on every axis than OpenVDB's cell-centred
// rule (Houdini's, and Blender 2.7x's, whose transform carries the half).
TEST_F(SmokeIsSmoke, MantaflowVoxelsSitHalfAVoxelHigher) {
  const fs::path manta = write_vdb(dir / "manta.vdb", blender_smoke());
  const fs::path plain = write_vdb(dir / "plain.vdb", blender_smoke(), {{"creator", "Blender/Smoke"}});
  auto box_of = [&](const fs::path& f) {
    Medium m;
    m.type = Medium::Type::Vdb;
    m.file = f;
    apply_source_convention(m, source_convention(read_volume_file_info(f, false), VolumeSource::Auto));
    const VolumeGrids g = load_volume(m, false);
    glm::dvec3 lo, hi;
    g.density.world_bounds(lo, hi);
    return std::make_pair(lo, hi);
  };
  const auto [mlo, mhi] = box_of(manta);
  const auto [plo, phi] = box_of(plain);
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(mlo[a] - plo[a], 0.5 * kBlenderVoxel, 1e-6) << a;  // half a voxel
    EXPECT_NEAR(mhi[a] - phi[a], 0.5 * kBlenderVoxel, 1e-6) << a;
  }
}

// A scene with no light gets the rig (a grey background, a sun from the
// camera's right, 45° up) and one note; "default_lights": false, a light of
// its own, or a medium that glows keeps it out.
TEST_F(SmokeIsSmoke, ASceneWithNoLightGetsTheDefaultRig) {
  SceneSetup setup;
  Scene s = completed(houdini_smoke(), kHoudini, "", "", &setup);
  EXPECT_EQ(s.background, glm::dvec3(kDefaultRigBackground));
  ASSERT_EQ(s.lights.size(), 1u);
  const Light& sun = s.lights[0];
  EXPECT_EQ(sun.type, Light::Type::Distant);
  EXPECT_EQ(sun.angle_deg, 0.53);
  EXPECT_EQ(sun.temperature_k, 5500.0);
  EXPECT_EQ(sun.scale, 10.0);
  const glm::dvec3 forward = glm::normalize(s.camera.look_at - s.camera.position);
  const glm::dvec3 right = glm::normalize(glm::cross(forward, s.camera.up));
  EXPECT_NEAR(glm::dot(sun.direction, right), std::sqrt(0.5), 1e-9);
  EXPECT_NEAR(glm::dot(sun.direction, s.camera.up), std::sqrt(0.5), 1e-9);
  ASSERT_EQ(setup.notes.size(), 1u);
  EXPECT_NE(setup.notes[0].find("lit by the default rig"), std::string::npos) << setup.notes[0];
  EXPECT_NE(setup.notes[0].find("\"default_lights\": false"), std::string::npos) << setup.notes[0];
  EXPECT_EQ(nothing_emits(s), "");

  s = completed(houdini_smoke(), kHoudini, "", R"("default_lights": false, )", &setup);
  EXPECT_TRUE(s.lights.empty());
  EXPECT_EQ(s.background, glm::dvec3(0.0));
  EXPECT_TRUE(setup.notes.empty());
  EXPECT_NE(nothing_emits(s).find("\"default_lights\" is false"), std::string::npos) << nothing_emits(s);
  s = completed(houdini_smoke(), kHoudini, "", R"("background": {"rgb": [0.2, 0.2, 0.2]}, )");
  EXPECT_TRUE(s.lights.empty());
  s = completed(houdini_smoke(), kHoudini, "", R"("integrator": {"mis": false}, )");
  EXPECT_TRUE(s.lights.empty()) << "no sun where light sampling is off";
  EXPECT_EQ(s.background, glm::dvec3(kDefaultRigBackground));
  s = completed(houdini_smoke(), kHoudini, R"(, "emission": {"scale": 1})");
  EXPECT_TRUE(s.lights.empty()) << "a glowing medium lights itself";
}

TEST(DefaultLights, MustBeABoolean) {
  EXPECT_THROW(parse_scene(R"({"default_lights": 1})", "s.json"), InputError);
  EXPECT_FALSE(parse_scene(R"({"default_lights": false})", "s.json").default_lights);
  EXPECT_TRUE(parse_scene(R"({})", "s.json").default_lights);
}

// The black-image warning names the cause that holds: nothing gives light,
// light too dim for the exposure (and the exposure that shows it), or no
// light at all reaching the camera; emission.scale only where something emits.
TEST(FilmLookCause, TheBlackImageWarningNamesTheCause) {
  Image img;
  img.width = 20;
  img.height = 10;
  img.rgb.assign(600, 0.0f);
  FilmCause unlit{"nothing in the scene gives light (test)", false};
  std::string w = film_look_warning(img, 0.0, ViewTransform::AgX, true, unlit);
  EXPECT_NE(w.find("almost entirely black"), std::string::npos) << w;
  EXPECT_NE(w.find("nothing in the scene gives light (test)"), std::string::npos) << w;
  EXPECT_EQ(w.find("emission.scale"), std::string::npos) << w;
  EXPECT_EQ(w.find("--exposure"), std::string::npos) << w;
  w = film_look_warning(img, 0.0, ViewTransform::AgX, true, FilmCause{"", true});
  EXPECT_NE(w.find("no light reaches the camera"), std::string::npos) << w;
  EXPECT_EQ(w.find("--exposure"), std::string::npos) << w;
  // Dim light everywhere: the exposure is the cause, and the fix is a number.
  std::fill(img.rgb.begin(), img.rgb.end(), 1e-5f);
  w = film_look_warning(img, 0.0, ViewTransform::AgX, true, FilmCause{"", false});
  EXPECT_NE(w.find("too dim for this exposure; --exposure +"), std::string::npos) << w;
  EXPECT_EQ(w.find("emission.scale"), std::string::npos) << w;
  EXPECT_NE(w.find("brighter lights"), std::string::npos) << w;
  w = film_look_warning(img, 0.0, ViewTransform::AgX, true, FilmCause{"", true});
  EXPECT_NE(w.find("larger emission.scale"), std::string::npos) << w;
  // At the exposure it proposes, the warning is gone: the fix changes the image.
  const double stops = auto_exposure(img, ViewTransform::AgX).stops;
  EXPECT_EQ(film_look_warning(img, stops, ViewTransform::AgX, true, FilmCause{"", true}), "");
}

// The cold-temperature warning proposes only what changes the image: never
// the scale in use, and for a constant grid (an all-zero flame) no scale.
TEST(ColdTemperatureFix, NeverProposesTheScaleInUse) {
  DenseGrid flame;
  flame.name = "flame";
  flame.values = {0.0f, 0.0f};
  flame.min_value = flame.max_value = 0.0f;
  const TemperatureMapping blender_flame{1500.0, -1.0, 1515.0};  // 1500 K at flame 0, cutoff 1515 K
  std::string w = cold_temperature_warning(flame, blender_flame);
  EXPECT_NE(w.find("every voxel holds 0"), std::string::npos) << w;
  EXPECT_EQ(w.find("temperature.scale"), std::string::npos) << w;
  DenseGrid t;
  t.name = "temperature";
  t.values = {0.0f, 1.0f};
  t.min_value = 0.0f;
  t.max_value = 1.0f;
  // 1500 K already, cut off at 2000 K: the proposal must clear the cutoff.
  w = cold_temperature_warning(t, TemperatureMapping{1500.0, 0.0, 2000.0});
  EXPECT_NE(w.find("temperature.scale 3000 would put it at 3000 K"), std::string::npos) << w;
  EXPECT_EQ(cold_temperature_warning(t, TemperatureMapping{3000.0, 0.0, 2000.0}), "");
}

// The synthetic smoke-only exports rendered from the shortest scene: visible,
// shaded, no glow, not clipped (support/SmokeLook.h; CPU, 48×48, 8 spp).
TEST_F(SmokeIsSmoke, BlenderStyleSmokeWithAnAllZeroFlameLooksLikeSmoke) {
  write_vdb(dir / "fluid_data_0001.vdb", blender_smoke());
  std::string err;
  const SmokeLook look = run_smoke_look(dir, dir / "fluid_data_0001.vdb", "smoke_blender_style", &err);
  std::printf("blender-style smoke: %s\n", look.summary().c_str());
  EXPECT_TRUE(look.looks_like_smoke()) << look.summary();
  EXPECT_NE(err.find("lit by the default rig"), std::string::npos) << err;
  EXPECT_EQ(err.find("warning"), std::string::npos) << err;
}

TEST_F(SmokeIsSmoke, HoudiniStyleDensityOnlySmokeLooksLikeSmoke) {
  write_vdb(dir / "smoke.vdb", houdini_smoke(), kHoudini);
  std::string err;
  const SmokeLook look = run_smoke_look(dir, dir / "smoke.vdb", "smoke_houdini_style", &err);
  std::printf("houdini-style smoke: %s\n", look.summary().c_str());
  EXPECT_TRUE(look.looks_like_smoke()) << look.summary();
  EXPECT_NE(err.find("lit by the default rig"), std::string::npos) << err;
}

// The check can fail: the same smoke told to glow fails "no glow", and
// without the rig it is neither visible nor shaded against black.
TEST_F(SmokeIsSmoke, TheSmokeCheckCanFail) {
  write_vdb(dir / "s.vdb", blender_smoke());
  write_file(dir / "glow.json", R"({"media": [{"type": "vdb", "file": "s.vdb", "emission": {"scale": 50},
    "temperature": {"scale": 2000}}]})");
  write_file(dir / "dark.json", R"({"media": [{"type": "vdb", "file": "s.vdb", "emission": {"scale": 0}}]})");
  const SmokeLookFilm film = SmokeLookFilm{};
  auto render = [&](const std::string& scene, const std::string& out, int seed) {
    const CliResult r = run_cli("render '" + (dir / scene).string() + "' -o '" + (dir / out).string() + "' --variance" +
                                film.flags(seed));
    EXPECT_EQ(r.status, 0) << r.err;
    return read_image(dir / out);
  };
  SmokeLook glow = smoke_look(render("glow.json", "glow.exr", 1));
  image_mean(render("dark.json", "dark.exr", 1), glow.mean0, glow.mean0_se);
  EXPECT_FALSE(glow.no_glow()) << glow.summary();
  write_file(dir / "unlit.json", R"({"default_lights": false, "media": [{"type": "vdb", "file": "s.vdb"}]})");
  const CliResult r = run_cli("render '" + (dir / "unlit.json").string() + "' -o '" + (dir / "unlit.exr").string() +
                              "'" + film.flags(1));
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("nothing in the scene gives light"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("EV): nothing in the scene gives light: add lights, background.rgb or an environment"),
            std::string::npos)
      << "the black image's warning names the cause: " << r.err;
  EXPECT_EQ(r.err.find("emission.scale"), std::string::npos) << "nothing emits: " << r.err;
  const SmokeLook unlit = smoke_look(read_image(dir / "unlit.exr"));
  EXPECT_FALSE(unlit.shaded_ok()) << unlit.summary();
}

// `pyrolume info` says what the shortest scene will do with a smoke cache.
TEST_F(SmokeIsSmoke, InfoSaysTheFileIsSmokeAndWhereItsVoxelsSit) {
  write_vdb(dir / "fluid_data_0001.vdb", blender_smoke());
  const CliResult r = run_cli("info '" + (dir / "fluid_data_0001.vdb").string() + "'");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("grid \"flame\" is zero everywhere: smoke, no emission (write an \"emission\" block to make it glow)"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("smoke scatters: albedo 0.5 (sigma_s 0.5, sigma_a 0.5), density_scale 5"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("voxel ijk placed at ijk + 0.5 (Mantaflow's cell corner)"), std::string::npos) << r.out;
}

// Lights with nothing to light (no scattering, no surface): the black image's
// warning says so, not "raise emission.scale".
TEST_F(SmokeIsSmoke, TheBlackImageWarningSaysTheLightsLightNothing) {
  write_file(dir / "l.json", R"({"film": {"width": 16, "height": 16, "spp": 1},
    "lights": [{"type": "distant", "direction": [0, 1, 0], "irradiance": [1, 1, 1]}],
    "media": [{"type": "homogeneous", "bounds": {"sphere": {"center": [0, 1, 0], "radius": 1}}}]})");
  const CliResult r =
      run_cli("render '" + (dir / "l.json").string() + "' -o '" + (dir / "l.png").string() + "' --backend cpu");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("EV): the lights light nothing: set the media's sigma_s (or add a surface)"), std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("emission.scale"), std::string::npos) << r.err;
}
