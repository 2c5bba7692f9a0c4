// What a scene file may leave out (host/render/SceneSetup, host/volume/
// SourceConventions; docs/sources.md, docs/scene-format.md): the simulator a
// VDB came from, its temperature mapping and up axis, and the camera.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "color/Blackbody.h"
#include "image/DisplayTransform.h"
#include "render/SceneSetup.h"
#include "support/VdbScenes.h"
#include "volume/DenseGrid.h"
#include "volume/SourceConventions.h"
#include "volume/StoredVolume.h"
#include "volume/VdbInfo.h"

using namespace pyrolume;
using namespace pyrolume::test;
namespace fs = std::filesystem;

namespace {

// A 6×20×6-voxel plume, taller than wide along `up`, its values rising to
// plume_max(peak) at the bottom centre: what a fire export looks like to the loader.
float plume_max(float peak) { return peak * (1.0f - 0.5f / 9.0f); }
FloatGridSpec plume(const std::string& name, float peak, bool z_up) {
  const VoxelBox box{{0, 0, 0}, z_up ? glm::ivec3(5, 5, 19) : glm::ivec3(5, 19, 5)};
  return make_float_grid(name, Lattice{0.1, glm::dvec3(0.0)}, box, [=](int i, int j, int k) {
    const int h = z_up ? k : j, a = i, b = z_up ? j : k;
    const float r = float((a - 2.5) * (a - 2.5) + (b - 2.5) * (b - 2.5)) / 9.0f;
    return peak * std::max(0.0f, 1.0f - r) * (1.0f - float(h) / 25.0f);
  });
}

class SceneSetupTest : public ::testing::Test {
 protected:
  fs::path dir = temp_dir("scene-setup");
  void TearDown() override { fs::remove_all(dir); }

  SourceConvention convention(const std::vector<FloatGridSpec>& grids, const FileMetadata& meta,
                              VolumeSource source = VolumeSource::Auto, const std::string& temperature_grid = "") {
    const fs::path f = write_vdb(dir / "f.vdb", grids, meta);
    SourceConvention c = source_convention(read_volume_file_info(f, false), source, temperature_grid);
    fit_temperature_mapping(c, f.string());
    return c;
  }
};

}  // namespace

TEST_F(SceneSetupTest, BlenderIsToldByCreatorMetadataOrGridNames) {
  // Blender 2.7x smoke: creator "Blender/Smoke", heat; Cycles' Temperature 1000 K.
  SourceConvention c = convention({plume("density", 0.2f, true), plume("heat", 1.5f, true), plume("flame", 1.0f, true)},
                                  {{"creator", "Blender/Smoke"}});
  EXPECT_EQ(c.source, VolumeSource::Blender);
  EXPECT_FALSE(c.guessed);
  EXPECT_NE(c.why.find("Blender/Smoke"), std::string::npos) << c.why;
  EXPECT_EQ(c.up_axis, UpAxis::Z);
  EXPECT_EQ(c.temperature_grid, "heat");
  EXPECT_EQ(c.mapping.scale, 1000.0);
  EXPECT_EQ(c.mapping.offset, 0.0);
  // Mantaflow (no creator): "temperature" is its heat, "shadow" gives it away.
  c = convention({plume("density", 0.5f, true), plume("temperature", 2.0f, true), plume("shadow", -1.0f, true)}, {});
  EXPECT_EQ(c.source, VolumeSource::Blender);
  EXPECT_NE(c.why.find("shadow"), std::string::npos) << c.why;
  EXPECT_EQ(c.temperature_grid, "temperature");
  EXPECT_EQ(c.mapping.scale, 1000.0);
  // Blender metadata without a creator.
  c = convention({plume("density", 0.5f, true)}, {{"blender/smoke/obmat", "1 0 0 0"}});
  EXPECT_EQ(c.source, VolumeSource::Blender);
  EXPECT_TRUE(c.temperature_grid.empty());  // smoke only: nothing to glow from
  // The fluid domain's fire temperature when the scene names flame.
  c = convention({plume("density", 0.2f, true), plume("flame", 1.0f, true)}, {{"creator", "Blender/Smoke"}},
                 VolumeSource::Auto, "flame");
  EXPECT_EQ(c.temperature_grid, "flame");
  EXPECT_EQ((1.0 - c.mapping.offset) * c.mapping.scale, 3000.0);  // flame 1: the maximum, 3000 K
  EXPECT_EQ((0.01 - c.mapping.offset) * c.mapping.scale, c.mapping.cutoff_k);  // flame 0.01: the ignition threshold
}

TEST_F(SceneSetupTest, HoudiniAndEmberGenTemperaturesAreFittedToTheirRange) {
  SourceConvention c = convention({plume("density", 1.0f, false), plume("temperature", 1.25f, false)},
                                  {{"creator", "Houdini/SOP_OpenVDB_Write"}});
  EXPECT_EQ(c.source, VolumeSource::Houdini);
  EXPECT_EQ(c.up_axis, UpAxis::Y);
  EXPECT_NEAR(c.mapping.scale * plume_max(1.25f), kFittedHottestK, 1e-3);
  c = convention({plume("density", 1.0f, false), plume("temperature", 4.0f, false)}, {{"embergen_version", "1.2.5"}});
  EXPECT_EQ(c.source, VolumeSource::EmberGen);
  EXPECT_NEAR(c.mapping.scale * plume_max(4.0f), kFittedHottestK, 1e-3);
  // Houdini's velocity grid name alone.
  c = convention({plume("density", 1.0f, false), plume("vel", 1.0f, false), plume("temperature", 2.0f, false)}, {});
  EXPECT_EQ(c.source, VolumeSource::Houdini);
  EXPECT_FALSE(c.guessed);
}

TEST_F(SceneSetupTest, AGuessReadsKelvinAsKelvinAndUnitlessValuesAsHoudini) {
  SourceConvention c = convention({plume("density", 1.0f, false), plume("temperature", 1800.0f, false)}, {});
  EXPECT_TRUE(c.guessed);
  EXPECT_EQ(c.source, VolumeSource::Kelvin);
  EXPECT_EQ(c.mapping.scale, 1.0);
  c = convention({plume("density", 1.0f, false), plume("temperature", 1.5f, false)}, {});
  EXPECT_TRUE(c.guessed);
  EXPECT_EQ(c.source, VolumeSource::Houdini);
  EXPECT_NEAR(c.mapping.scale * plume_max(1.5f), kFittedHottestK, 1e-3);
  // The scene's source wins over what the file says.
  c = convention({plume("density", 0.2f, true), plume("heat", 1.5f, true)}, {{"creator", "Blender/Smoke"}},
                 VolumeSource::Kelvin);
  EXPECT_EQ(c.source, VolumeSource::Kelvin);
  EXPECT_EQ(c.temperature_grid, "heat");
  EXPECT_EQ(c.mapping.scale, 1.0);
}

// Numbers in the mapping's words are printed as numbers: a temperature of
// 1e30 came out as -2147483648 (an int cast).
TEST_F(SceneSetupTest, AHugeTemperatureIsPrintedAsANumber) {
  const SourceConvention c = convention({plume("density", 1.0f, false), plume("temperature", 1e30f, false)}, {});
  ASSERT_EQ(c.source, VolumeSource::Kelvin);
  const std::string said = "its largest value, ";
  const size_t at = c.mapping_text.find(said);
  ASSERT_NE(at, std::string::npos) << c.mapping_text;
  const double printed = std::stod(c.mapping_text.substr(at + said.size()));
  EXPECT_NEAR(printed / double(plume_max(1e30f)), 1.0, 1e-5) << c.mapping_text;
}

// Keys the file writes win; the convention fills the rest; a convention with
// nothing to glow from turns the emission off unless the file asked for it.
TEST_F(SceneSetupTest, ExplicitKeysWinOverTheConvention) {
  write_vdb(dir / "b.vdb", {plume("density", 0.2f, true), plume("heat", 1.5f, true)}, {{"creator", "Blender/Smoke"}});
  write_vdb(dir / "smoke.vdb", {plume("density", 0.2f, true)}, {{"creator", "Blender/Smoke"}});
  write_file(dir / "s.json", R"({"media": [
    {"type": "vdb", "file": "b.vdb", "temperature": {"offset": 0.5, "cutoff_k": 900}},
    {"type": "vdb", "file": "b.vdb", "temperature_grid": "density", "density_grid": "heat"},
    {"type": "vdb", "file": "smoke.vdb"},
    {"type": "vdb", "file": "smoke.vdb", "emission": {"rgb": [1, 0.5, 0.2]}}]})");
  Scene s = load_scene(dir / "s.json");
  complete_scene(s, false);
  EXPECT_EQ(s.media[0].temperature_grid, "heat");
  EXPECT_EQ(s.media[0].temperature.scale, 1000.0);   // the convention's
  EXPECT_EQ(s.media[0].temperature.offset, 0.5);     // the file's
  EXPECT_EQ(s.media[0].temperature.cutoff_k, 900.0); // the file's
  EXPECT_EQ(s.media[1].temperature_grid, "density");
  EXPECT_EQ(s.media[1].density_grid, "heat");
  EXPECT_FALSE(s.media[2].emission.emits());
  EXPECT_TRUE(s.media[3].emission.emits());
  EXPECT_EQ(s.up_axis, UpAxis::Z);  // from the Blender source
}

// The automatic camera sees every corner of what it frames, with the 5 %
// margin, from the front of the scene's up axis (+X to the right).
TEST(Framing, EveryCornerInsideTheFrameFromTheFront) {
  const std::vector<WorldBox> boxes = {{{-1, 0, 2}, {3, 8, 4}, "a"}, {{0, -2, 0}, {1, 1, 1}, "b"}};
  for (UpAxis up : {UpAxis::Y, UpAxis::Z})
    for (double aspect : {16.0 / 9.0, 9.0 / 16.0}) {
      const Camera cam = framing_camera(boxes, up, 40.0, aspect);
      const glm::dvec3 f = glm::normalize(cam.look_at - cam.position);
      const glm::dvec3 r = glm::normalize(glm::cross(f, cam.up)), u = glm::cross(r, f);
      EXPECT_NEAR(glm::distance(f, up == UpAxis::Z ? glm::dvec3(0, 1, 0) : glm::dvec3(0, 0, -1)), 0.0, 1e-12);
      EXPECT_NEAR(glm::distance(r, glm::dvec3(1, 0, 0)), 0.0, 1e-12);
      const double tan_v = std::tan(20.0 * std::numbers::pi / 180.0), tan_h = tan_v * aspect;
      double fill = 0.0;
      for (const WorldBox& b : boxes)
        for (int c = 0; c < 8; ++c) {
          const glm::dvec3 p((c & 1) ? b.max.x : b.min.x, (c & 2) ? b.max.y : b.min.y, (c & 4) ? b.max.z : b.min.z);
          const glm::dvec3 q = p - cam.position;
          ASSERT_GT(glm::dot(q, f), 0.0);
          fill = std::max({fill, std::abs(glm::dot(q, r)) / glm::dot(q, f) / tan_h,
                           std::abs(glm::dot(q, u)) / glm::dot(q, f) / tan_v});
        }
      // Tight around the boxes' union: its widest corner (here (3, -2, 4)) sits on the margin.
      double union_fill = 0.0;
      for (int c = 0; c < 8; ++c) {
        const glm::dvec3 q = glm::dvec3((c & 1) ? 3 : -1, (c & 2) ? 8 : -2, (c & 4) ? 4 : 0) - cam.position;
        union_fill = std::max({union_fill, std::abs(glm::dot(q, r)) / glm::dot(q, f) / tan_h,
                               std::abs(glm::dot(q, u)) / glm::dot(q, f) / tan_v});
      }
      EXPECT_NEAR(union_fill, 1.0 / 1.05, 1e-9) << "up " << int(up) << " aspect " << aspect;
      EXPECT_LE(fill, union_fill + 1e-12);
      EXPECT_EQ(nothing_in_view(cam, boxes, aspect), "");
      Camera away = cam;
      away.look_at = cam.position - (cam.look_at - cam.position);
      EXPECT_NE(nothing_in_view(away, boxes, aspect).find("nothing is in the camera's view"), std::string::npos);
    }
}

TEST_F(SceneSetupTest, ATallSubjectTurnsTheDefaultFilmUpright) {
  write_vdb(dir / "tall.vdb", {plume("density", 1.0f, false), plume("temperature", 2000.0f, false)},
            {{"creator", "Houdini/SOP_OpenVDB_Write"}});
  write_file(dir / "s.json", R"({"media": [{"type": "vdb", "file": "tall.vdb"}]})");
  Scene s = load_scene(dir / "s.json");
  complete_scene(s, false);
  EXPECT_EQ(s.film.width, 360);
  EXPECT_EQ(s.film.height, 640);
  EXPECT_EQ(s.up_axis, UpAxis::Y);
  EXPECT_EQ(s.camera.up, glm::dvec3(0, 1, 0));
  Scene fixed = load_scene(dir / "s.json");
  complete_scene(fixed, true);  // --width/--height given
  EXPECT_EQ(fixed.film.width, 640);
  // A camera the file places stays; its up decides the axis.
  write_file(dir / "c.json", R"({"camera": {"position": [0, -5, 1], "look_at": [0, 0, 1], "up": [0, 0, 1]},
    "media": [{"type": "vdb", "file": "tall.vdb"}]})");
  Scene c = load_scene(dir / "c.json");
  complete_scene(c, false);
  EXPECT_EQ(c.camera.position, glm::dvec3(0, -5, 1));
  EXPECT_EQ(c.up_axis, UpAxis::Z);
  EXPECT_EQ(c.film.width, 640);
}

// The default normalisation: the blackbody's chromaticity at luminance
// (T / 1500 K)⁴, the Stefan–Boltzmann growth of its total radiance.
TEST(StefanBoltzmann, LuminanceGrowsAsTheFourthPowerWithPlancksColour) {
  for (double T : {2000.0, 3000.0, 6500.0, 12000.0}) {  // no channel clamped here
    const glm::dvec3 sb = color::blackbody_rgb(T, BlackbodyMode::StefanBoltzmann);
    const glm::dvec3 peak = color::blackbody_rgb(T, BlackbodyMode::Peak);
    const double Y = 0.2126 * sb.r + 0.7152 * sb.g + 0.0722 * sb.b;
    EXPECT_NEAR(Y, std::pow(T / color::kStefanBoltzmannReferenceK, 4.0), 2e-3 * Y) << T;
    EXPECT_NEAR(sb.g / sb.r, peak.g / peak.r, 1e-9) << T;
    EXPECT_NEAR(sb.b / sb.r, peak.b / peak.r, 1e-9) << T;
  }
  EXPECT_EQ(color::blackbody_rgb(0.0, BlackbodyMode::StefanBoltzmann), glm::dvec3(0.0));
  EXPECT_EQ(color::parse_blackbody_mode("seed"), BlackbodyMode::Seed);
  EXPECT_EQ(color::parse_blackbody_mode("stefan_boltzmann"), BlackbodyMode::StefanBoltzmann);
}

TEST(ColdTemperature, WarnsWhenNothingMapsAboveTheCutoff) {
  DenseGrid t;
  t.name = "heat";
  t.values = {0.0f, 1.57f};
  t.min_value = 0.0f;
  t.max_value = 1.57f;
  const std::string w = cold_temperature_warning(t, TemperatureMapping{1.0, 0.0, 100.0});
  EXPECT_NE(w.find("temperature grid \"heat\": the hottest voxel maps to 1.57 K"), std::string::npos) << w;
  EXPECT_NE(w.find("temperature.scale 955.4 would put it at 1500 K"), std::string::npos) << w;
  EXPECT_EQ(cold_temperature_warning(t, TemperatureMapping{1000.0, 0.0, 100.0}), "");
  EXPECT_NE(cold_temperature_warning(t, TemperatureMapping{1000.0, 0.0, 1600.0}), "");  // 1570 K <= 1600 K
}

TEST(FilmLook, WarnsAboutAnAlmostBlackOrAlmostClippedImage) {
  Image img;
  img.width = 10;
  img.height = 10;
  img.rgb.assign(300, 0.0f);
  EXPECT_NE(film_look_warning(img, 0.0, ViewTransform::AgX, true).find("almost entirely black"), std::string::npos);
  std::fill(img.rgb.begin(), img.rgb.begin() + 30, 0.5f);  // 10 % lit
  EXPECT_EQ(film_look_warning(img, 0.0, ViewTransform::AgX, true), "");
  std::fill(img.rgb.begin(), img.rgb.end(), 100.0f);
  EXPECT_NE(film_look_warning(img, 0.0, ViewTransform::Standard, true).find("almost entirely clipped"),
            std::string::npos);
  EXPECT_EQ(film_look_warning(img, 0.0, ViewTransform::Standard, false), "");  // EXR: nothing clips
  EXPECT_EQ(film_look_warning(img, -10.0, ViewTransform::Standard, true), "");
}

// The warning that the image will be black: lights count as light only where
// they have something to light (a surface or a scattering medium).
TEST(NothingEmits, LightsNeedSomethingThatScatters) {
  Scene s;
  Medium smoke;
  smoke.type = Medium::Type::Homogeneous;
  smoke.emission.scale = 0.0;
  s.media.push_back(smoke);
  EXPECT_NE(nothing_emits(s).find("nothing in the scene gives light"), std::string::npos) << nothing_emits(s);
  Light sun;
  sun.type = Light::Type::Distant;
  sun.rgb = glm::dvec3(1.0);
  s.lights.push_back(sun);
  EXPECT_NE(nothing_emits(s).find("lights light nothing"), std::string::npos) << nothing_emits(s);
  s.media[0].sigma_s = glm::dvec3(0.0, 0.5, 0.0);
  EXPECT_EQ(nothing_emits(s), "");
  s.media[0].sigma_s = glm::dvec3(0.0);
  s.shapes.push_back(Shape{});
  EXPECT_EQ(nothing_emits(s), "");
}
