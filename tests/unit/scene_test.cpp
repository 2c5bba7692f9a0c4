// Scene format v1: a full example scene parses; every malformed case names the key.
#include <gtest/gtest.h>

#include <cmath>

#include "scene/Scene.h"
#include "support/TestSupport.h"
#include "util/Error.h"

using namespace pyrolume;

namespace {

const char* kDesignExample = R"({
  "camera": {"position": [0, 1, -6], "look_at": [0, 1, 0], "up": [0, 1, 0], "fov_deg": 40},
  "film": {"width": 640, "height": 360, "spp": 64, "exposure": 0.0, "seed": 1},
  "integrator": {"max_depth": 8, "mis": true},
  "background": {"rgb": [0, 0, 0]},
  "environment": {"file": "sky.exr", "scale": 1.0, "rotation_deg": 0},
  "media": [
    {"name": "ball", "type": "homogeneous",
     "bounds": {"sphere": {"center": [0, 1, 0], "radius": 1}},
     "sigma_a": [1, 1, 1], "sigma_s": [0, 0, 0], "g": 0.0,
     "emission": {"temperature_k": 1500, "scale": 1.0, "blackbody": "seed"}},
    {"name": "fire", "type": "vdb", "file": "fire.vdb",
     "density_grid": "density", "temperature_grid": "temperature",
     "density_scale": 1.0, "sigma_a": [1, 1, 1], "sigma_s": [1, 1, 1], "g": 0.0,
     "temperature": {"scale": 1.0, "offset": 0.0, "cutoff_k": 100},
     "emission": {"scale": 1.0, "blackbody": "seed"},
     "transform": {"translate": [0, 0, 0], "rotate_deg": [0, 0, 0], "scale": [1, 1, 1]}}
  ],
  "shapes": [
    {"mesh": "terrain.obj", "material": {"diffuse": {"rgb": [0.5, 0.5, 0.5], "texture": "rock.png"}}}
  ]
})";

// Parses text and returns the error message ("" when it parsed).
std::string error_of(const std::string& text) {
  try {
    parse_scene(text, "bad.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::string one_medium(const std::string& fields) {
  return R"({"media": [{"type": "homogeneous", "bounds": {"sphere": {"center": [0,0,0], "radius": 1}})" + fields + "}]}";
}

}  // namespace

TEST(Scene, DesignExampleParses) {
  Scene s = parse_scene(kDesignExample, "/scenes/example.json");
  EXPECT_EQ(s.film.width, 640);
  EXPECT_EQ(s.film.spp, 64);
  ASSERT_EQ(s.media.size(), 2u);
  EXPECT_EQ(s.media[0].type, Medium::Type::Homogeneous);
  EXPECT_EQ(s.media[0].bounds.kind, Bounds::Kind::Sphere);
  ASSERT_TRUE(s.media[0].emission.temperature_k.has_value());
  EXPECT_DOUBLE_EQ(*s.media[0].emission.temperature_k, 1500.0);
  EXPECT_EQ(s.media[1].type, Medium::Type::Vdb);
  EXPECT_EQ(s.media[1].file, std::filesystem::path("/scenes/fire.vdb"));  // relative to the scene's folder
  EXPECT_EQ(s.media[1].temperature_grid, "temperature");
  ASSERT_TRUE(s.environment.has_value());
  EXPECT_EQ(s.environment->file, std::filesystem::path("/scenes/sky.exr"));
  ASSERT_EQ(s.shapes.size(), 1u);
  EXPECT_EQ(s.shapes[0].texture, std::filesystem::path("/scenes/rock.png"));
}

// What a scene leaves out: the blackbody normalisation is stefan_boltzmann, a
// vdb medium glows from its grid, a homogeneous one does not; "seed" is still
// read, as "chromaticity"; the camera is framed automatically until the file
// places it; the film remembers whether its size was written.
TEST(Scene, DefaultsForTheShortestFile) {
  const Scene s = parse_scene(R"({"media": [{"type": "vdb", "file": "f.vdb"},
    {"type": "homogeneous", "bounds": {"sphere": {"center": [0, 0, 0], "radius": 1}}},
    {"type": "homogeneous", "bounds": {"sphere": {"center": [0, 0, 0], "radius": 1}},
     "emission": {"temperature_k": 1500, "blackbody": "seed"}},
    {"type": "homogeneous", "bounds": {"sphere": {"center": [0, 0, 0], "radius": 1}},
     "emission": {"temperature_k": 1500}}]})", "s.json");
  EXPECT_EQ(s.media[0].source, VolumeSource::Auto);
  EXPECT_TRUE(s.media[0].emission.is_grid);
  EXPECT_FALSE(s.media[0].given.emission);
  EXPECT_FALSE(s.media[1].emission.emits());
  EXPECT_EQ(s.media[2].emission.blackbody, BlackbodyMode::Seed);
  EXPECT_EQ(s.media[3].emission.blackbody, BlackbodyMode::StefanBoltzmann);
  EXPECT_TRUE(s.camera.framed_automatically);
  EXPECT_FALSE(s.up_axis.has_value());
  EXPECT_FALSE(s.film.size_given);

  const Scene t = parse_scene(R"({"up_axis": "z", "camera": {"fov_deg": 30}, "film": {"height": 100},
    "media": [{"type": "vdb", "file": "f.vdb", "source": "houdini", "temperature": {"offset": 1},
               "emission": {"blackbody": "chromaticity"}}]})", "t.json");
  EXPECT_EQ(t.up_axis, UpAxis::Z);
  EXPECT_TRUE(t.camera.framed_automatically);  // fov alone does not place the camera
  EXPECT_TRUE(t.film.size_given);
  EXPECT_EQ(t.media[0].source, VolumeSource::Houdini);
  EXPECT_TRUE(t.media[0].given.temperature_offset);
  EXPECT_FALSE(t.media[0].given.temperature_scale);
  EXPECT_TRUE(t.media[0].given.emission);
  EXPECT_EQ(t.media[0].emission.blackbody, BlackbodyMode::Seed);
  EXPECT_FALSE(parse_scene(R"({"camera": {"look_at": [0, 0, 1]}})", "u.json").camera.framed_automatically);
}

TEST(Scene, BoxBoundsAndDefaults) {
  Scene s = parse_scene(R"({"media": [{"type": "homogeneous", "bounds": {"box": {"min": [0,0,0], "max": [1,2,3]}},
                             "emission": {"rgb": [1, 0.5, 0.25], "scale": 2}}]})",
                        "a.json");
  ASSERT_EQ(s.media.size(), 1u);
  EXPECT_EQ(s.media[0].bounds.kind, Bounds::Kind::Box);
  EXPECT_EQ(s.media[0].bounds.max, glm::dvec3(1, 2, 3));
  EXPECT_EQ(s.media[0].sigma_a, glm::dvec3(1.0));  // default
  EXPECT_EQ(*s.media[0].emission.rgb, glm::dvec3(1, 0.5, 0.25));
  EXPECT_DOUBLE_EQ(s.media[0].emission.scale, 2.0);
  EXPECT_EQ(s.camera.fov_deg, 40.0);
}

struct BadCase {
  const char* label;
  std::string text;
  const char* expect;  // substring of the message: the key path and reason
};

class SceneBadInput : public ::testing::TestWithParam<BadCase> {};

TEST_P(SceneBadInput, NamesFileKeyAndReason) {
  const BadCase& c = GetParam();
  std::string msg = error_of(c.text);
  ASSERT_FALSE(msg.empty()) << c.label << " was accepted";
  EXPECT_NE(msg.find("bad.json"), std::string::npos) << msg;
  EXPECT_NE(msg.find(c.expect), std::string::npos) << "expected '" << c.expect << "' in: " << msg;
  EXPECT_EQ(msg.find('\n'), std::string::npos) << "message must be one line: " << msg;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, SceneBadInput,
    ::testing::Values(
        BadCase{"unknown top key", R"({"camrea": {}})", "camrea: unknown key"},
        BadCase{"unknown nested key", R"({"film": {"widht": 3}})", "film.widht: unknown key"},
        BadCase{"spp zero", R"({"film": {"spp": 0}})", "film.spp: must be in"},
        BadCase{"width type", R"({"film": {"width": "big"}})", "film.width: expected an integer"},
        BadCase{"negative sigma", one_medium(R"(, "sigma_a": [1, -1, 1])"), "media[0].sigma_a: must be >= 0"},
        BadCase{"sigma_s short", one_medium(R"(, "sigma_s": [1, 1])"), "media[0].sigma_s: expected an array of 3"},
        BadCase{"g one", one_medium(R"(, "g": 1.0)"), "media[0].g: must satisfy |g| < 1"},
        BadCase{"g minus one", one_medium(R"(, "g": -1.5)"), "media[0].g"},
        BadCase{"medium typo", one_medium(R"(, "sigma_t": [1,1,1])"), "media[0].sigma_t: unknown key"},
        BadCase{"missing type", R"({"media": [{"bounds": {"sphere": {"center": [0,0,0], "radius": 1}}}]})",
                "media[0].type"},
        BadCase{"bad type", R"({"media": [{"type": "cloud"}]})", "media[0].type: must be one of"},
        BadCase{"no bounds", R"({"media": [{"type": "homogeneous"}]})", "media[0].bounds: missing"},
        BadCase{"radius zero",
                R"({"media": [{"type": "homogeneous", "bounds": {"sphere": {"center": [0,0,0], "radius": 0}}}]})",
                "media[0].bounds.sphere.radius: must be > 0"},
        BadCase{"box inverted",
                R"({"media": [{"type": "homogeneous", "bounds": {"box": {"min": [0,0,0], "max": [1,-1,1]}}}]})",
                "media[0].bounds.box.max"},
        BadCase{"both bounds",
                R"({"media": [{"type": "homogeneous", "bounds": {"box": {"min": [0,0,0], "max": [1,1,1]}, "sphere": {"center": [0,0,0], "radius": 1}}}]})",
                "media[0].bounds: expected exactly one"},
        BadCase{"emission both", one_medium(R"(, "emission": {"rgb": [1,1,1], "temperature_k": 1000})"),
                "media[0].emission.rgb: give either"},
        BadCase{"negative temperature", one_medium(R"(, "emission": {"temperature_k": -3})"),
                "media[0].emission.temperature_k: must be >= 0"},
        BadCase{"blackbody mode", one_medium(R"(, "emission": {"temperature_k": 1000, "blackbody": "cie"})"),
                "media[0].emission.blackbody: must be one of"},
        BadCase{"fov", R"({"camera": {"fov_deg": 180}})", "camera.fov_deg"},
        BadCase{"source", R"({"media": [{"type": "vdb", "file": "f.vdb", "source": "maya"}]})",
                "media[0].source: must be one of \"auto\", \"blender\", \"houdini\", \"embergen\", \"kelvin\", got \"maya\""},
        BadCase{"source type", R"({"media": [{"type": "vdb", "file": "f.vdb", "source": 3}]})",
                "media[0].source: expected a string"},
        BadCase{"source on homogeneous", one_medium(R"(, "source": "blender")"), "media[0].source: unknown key"},
        BadCase{"up axis", R"({"up_axis": "x"})", "up_axis: must be one of \"y\", \"z\", got \"x\""},
        BadCase{"up axis type", R"({"up_axis": [0, 0, 1]})", "up_axis: expected a string"},
        BadCase{"up parallel", R"({"camera": {"position": [0,0,0], "look_at": [0,1,0], "up": [0,1,0]}})", "camera.up"},
        BadCase{"estimator", R"({"integrator": {"emission_estimator": "track"}})", "integrator.emission_estimator"},
        BadCase{"light_only", R"({"integrator": {"light_only": "yes"}})", "integrator.light_only"},
        BadCase{"max_depth", R"({"integrator": {"max_depth": -1}})", "integrator.max_depth"},
        BadCase{"surface_light_samples 0", R"({"integrator": {"surface_light_samples": 0}})",
                "integrator.surface_light_samples: must be in [1, 64]"},
        BadCase{"surface_light_samples fraction", R"({"integrator": {"surface_light_samples": 2.5}})",
                "integrator.surface_light_samples: expected an integer"},
        BadCase{"ratio_tracked_continuation not bool", R"({"integrator": {"ratio_tracked_continuation": 1}})",
                "integrator.ratio_tracked_continuation: expected"},
        BadCase{"guided_continuation 1", R"({"integrator": {"guided_continuation": 1}})",
                "integrator.guided_continuation: expected a number in [0, 1)"},
        BadCase{"guided_continuation negative", R"({"integrator": {"guided_continuation": -0.5}})",
                "integrator.guided_continuation: expected a number in [0, 1)"},
        BadCase{"background", R"({"background": {"rgb": [0, 0, -1]}})", "background.rgb"},
        BadCase{"duplicate names",
                R"({"media": [{"name": "a", "type": "homogeneous", "bounds": {"sphere": {"center": [0,0,0], "radius": 1}}},
                              {"name": "a", "type": "homogeneous", "bounds": {"sphere": {"center": [0,0,0], "radius": 1}}}]})",
                "media[1].name: duplicate"},
        BadCase{"vdb bounds", R"({"media": [{"type": "vdb", "file": "x.vdb", "bounds": {"sphere": {"center": [0,0,0], "radius": 1}}}]})",
                "media[0].bounds"},
        BadCase{"json syntax", R"({"film": {"spp": 4,}})", "invalid JSON"},
        // nlohmann throws out_of_range, not parse_error, for these (found by fuzz_scene).
        BadCase{"number beyond double", R"({"film": {"exposure": 1e400}})", "invalid JSON"},
        BadCase{"negative beyond double", R"({"camera": {"position": [0, -1e3080, 0]}})", "invalid JSON"},
        // nlohmann keeps the last of two equal keys; a second "media" replaced the first silently.
        BadCase{"duplicate top-level key", R"({"media": [], "film": {}, "media": []})", "bad.json: media: duplicate key"},
        BadCase{"duplicate key in an array element",
                R"({"media": [{}, {"type": "homogeneous", "g": 0.1, "g": 0.2}]})", "bad.json: media[1].g: duplicate key"},
        BadCase{"duplicate key nested in arrays",
                R"({"camera": {"position": {"keys": [[0, [0, 0, 1]]], "keys": []}}})",
                "bad.json: camera.position.keys: duplicate key"},
        // film.transparent (docs/compositing.md) takes true or false only.
        BadCase{"transparent not a boolean", R"({"film": {"transparent": 1}})",
                "film.transparent: expected true or false"},
        // film.aovs (docs/compositing.md "AOVs") likewise.
        BadCase{"aovs not a boolean", R"({"film": {"aovs": "yes"}})", "film.aovs: expected true or false"},
        // The lights array (docs/scene-format.md "lights").
        BadCase{"lights not an array", R"({"lights": {}})", "lights: expected an array"},
        BadCase{"light type", R"({"lights": [{"type": "area", "radiance": [1, 1, 1]}]})",
                "lights[0].type: must be one of"},
        BadCase{"light without type", R"({"lights": [{"intensity": [1, 1, 1], "position": [0, 0, 0]}]})",
                "lights[0].type: missing"},
        BadCase{"negative intensity",
                R"({"lights": [{"type": "point", "position": [0, 1, 0], "intensity": [1, -1, 1]}]})",
                "lights[0].intensity: must be >= 0"},
        BadCase{"negative irradiance",
                R"({"lights": [{"type": "distant", "direction": [0, 1, 0], "irradiance": [-1, 1, 1]}]})",
                "lights[0].irradiance: must be >= 0"},
        BadCase{"negative light scale",
                R"({"lights": [{"type": "point", "position": [0, 1, 0], "intensity": [1, 1, 1], "scale": -2}]})",
                "lights[0].scale: must be >= 0"},
        BadCase{"zero distant direction",
                R"({"lights": [{"type": "distant", "direction": [0, 0, 0], "irradiance": [1, 1, 1]}]})",
                "lights[0].direction: must not be zero"},
        BadCase{"zero spot direction",
                R"({"lights": [{"type": "point", "position": [0, 1, 0], "intensity": [1, 1, 1]},
                               {"type": "spot", "position": [0, 1, 0], "direction": [0, 0, 0], "intensity": [1, 1, 1]}]})",
                "lights[1].direction: must not be zero"},
        BadCase{"cone below falloff",
                R"({"lights": [{"type": "spot", "position": [0, 1, 0], "direction": [0, -1, 0], "intensity": [1, 1, 1],
                                "cone_deg": 20, "falloff_deg": 30}]})",
                "lights[0].cone_deg: must be >= falloff_deg"},
        BadCase{"sphere radius zero",
                R"({"lights": [{"type": "sphere", "center": [0, 1, 0], "radius": 0, "radiance": [1, 1, 1]}]})",
                "lights[0].radius: must be > 0"},
        BadCase{"sphere radius negative",
                R"({"lights": [{"type": "sphere", "center": [0, 1, 0], "radius": -0.5, "radiance": [1, 1, 1]}]})",
                "lights[0].radius: must be > 0"},
        BadCase{"sphere without radius",
                R"({"lights": [{"type": "sphere", "center": [0, 1, 0], "radiance": [1, 1, 1]}]})",
                "lights[0].radius: missing"},
        BadCase{"both value and temperature",
                R"({"lights": [{"type": "point", "position": [0, 1, 0], "intensity": [1, 1, 1], "temperature_k": 3000}]})",
                "lights[0].intensity: give either"},
        // Range rules (docs/robustness.md "Analytic lights"): the blackbody
        // range the renderers evaluate, coordinates float keeps finite, a
        // disc that float directions resolve.
        BadCase{"light temperature 10 K",
                R"({"lights": [{"type": "point", "position": [0, 1, 0], "temperature_k": 10}]})",
                "lights[0].temperature_k: must be in [100.0, 1000000.0] kelvin, got 10.0"},
        BadCase{"light temperature 1e300 K",
                R"({"lights": [{"type": "distant", "direction": [0, 1, 0], "temperature_k": 1e300}]})",
                "lights[0].temperature_k: must be in [100.0, 1000000.0] kelvin, got 1e+300"},
        BadCase{"sphere light radius 1e300",
                R"({"lights": [{"type": "sphere", "center": [0, 1, 0], "radius": 1e300, "radiance": [1, 1, 1]}]})",
                "lights[0].radius: the sphere's extent |center| + radius reaches 1e+300, beyond the ±1e+18"},
        BadCase{"sphere light centre beyond 1e18",
                R"({"lights": [{"type": "sphere", "center": [0, -2e18, 0], "radius": 1, "radiance": [1, 1, 1]}]})",
                "lights[0].center: a coordinate reaches -2e+18, beyond the ±1e+18"},
        BadCase{"point light beyond 1e18",
                R"({"lights": [{"type": "point", "position": [1e19, 1, 0], "intensity": [1, 1, 1]}]})",
                "lights[0].position: a coordinate reaches 1e+19"},
        BadCase{"spot light beyond 1e18",
                R"({"lights": [{"type": "spot", "position": [0, 0, 1e300], "direction": [0, -1, 0], "intensity": [1, 1, 1]}]})",
                "lights[0].position: a coordinate reaches 1e+300"},
        BadCase{"disc narrower than float resolves",
                R"({"lights": [{"type": "distant", "direction": [0, 1, 0], "irradiance": [1e-30, 0, 0], "angle_deg": 1e-300}]})",
                "lights[0].angle_deg: must be 0 (a delta light) or at least 0.0001 degrees"},
        BadCase{"neither value nor temperature", R"({"lights": [{"type": "point", "position": [0, 1, 0]}]})",
                "lights[0].intensity: missing"},
        BadCase{"value key of another type",
                R"({"lights": [{"type": "point", "position": [0, 1, 0], "intensity": [1, 1, 1], "radiance": [1, 1, 1]}]})",
                "lights[0].radiance: unknown key"},
        BadCase{"mis false with lights",
                R"({"integrator": {"mis": false},
                    "lights": [{"type": "point", "position": [0, 1, 0], "intensity": [1, 1, 1]}]})",
                "integrator.mis: false turns off light sampling"},
        BadCase{"absorption with lights",
                R"({"integrator": {"emission_estimator": "absorption"},
                    "lights": [{"type": "distant", "direction": [0, 1, 0], "irradiance": [1, 1, 1]}]})",
                "integrator.emission_estimator: \"absorption\" turns off light sampling"}),
    [](const ::testing::TestParamInfo<BadCase>& info) {
      std::string n = info.param.label;
      for (auto& ch : n)
        if (!isalnum(static_cast<unsigned char>(ch))) ch = '_';
      return n;
    });

TEST(Scene, SurfaceLightSamples) {
  EXPECT_EQ(parse_scene("{}", "a.json").integrator.surface_light_samples, 1);
  EXPECT_EQ(parse_scene(R"({"integrator": {"surface_light_samples": 4}})", "a.json").integrator.surface_light_samples, 4);
}

TEST(Scene, GuidedContinuation) {
  EXPECT_FALSE(parse_scene("{}", "a.json").integrator.guided_continuation.has_value());
  EXPECT_DOUBLE_EQ(*parse_scene(R"({"integrator": {"guided_continuation": 0.5}})", "a.json")
                        .integrator.guided_continuation,
                   0.5);
}

TEST(Scene, RatioTrackedContinuation) {
  EXPECT_FALSE(parse_scene("{}", "a.json").integrator.ratio_tracked_continuation);
  EXPECT_TRUE(parse_scene(R"({"integrator": {"ratio_tracked_continuation": true}})", "a.json")
                  .integrator.ratio_tracked_continuation);
}

// A lights array: each type's keys and defaults; directions are normalised;
// an empty array is no lights (and "mis": false is then fine).
TEST(Scene, Lights) {
  const Scene s = parse_scene(R"({"lights": [
    {"type": "distant", "direction": [0, 2, 0], "irradiance": [40, 38, 34], "angle_deg": 0.53},
    {"type": "point", "position": [0, 3, 0], "intensity": [10, 10, 10]},
    {"type": "spot", "position": [0, 3, 0], "direction": [0, -3, 0], "temperature_k": 3200, "scale": 50,
     "cone_deg": 30, "falloff_deg": 10},
    {"type": "spot", "position": [1, 3, 0], "direction": [0, -1, 0], "intensity": [1, 2, 3]},
    {"type": "sphere", "center": [2, 1, 0], "radius": 0.25, "radiance": [5, 5, 5]}]})", "l.json");
  ASSERT_EQ(s.lights.size(), 5u);
  EXPECT_EQ(s.lights[0].type, Light::Type::Distant);
  EXPECT_EQ(s.lights[0].direction, glm::dvec3(0, 1, 0));
  EXPECT_DOUBLE_EQ(s.lights[0].angle_deg, 0.53);
  EXPECT_EQ(*s.lights[0].rgb, glm::dvec3(40, 38, 34));
  EXPECT_FALSE(s.lights[0].is_delta());
  EXPECT_EQ(s.lights[1].type, Light::Type::Point);
  EXPECT_EQ(s.lights[1].position, glm::dvec3(0, 3, 0));
  EXPECT_TRUE(s.lights[1].is_delta());
  EXPECT_EQ(s.lights[2].type, Light::Type::Spot);
  EXPECT_EQ(s.lights[2].direction, glm::dvec3(0, -1, 0));
  EXPECT_FALSE(s.lights[2].rgb.has_value());
  EXPECT_DOUBLE_EQ(*s.lights[2].temperature_k, 3200.0);
  EXPECT_DOUBLE_EQ(s.lights[2].scale, 50.0);
  EXPECT_DOUBLE_EQ(s.lights[2].cone_deg, 30.0);
  EXPECT_DOUBLE_EQ(s.lights[2].falloff_deg, 10.0);
  EXPECT_DOUBLE_EQ(s.lights[3].cone_deg, 45.0);  // defaults
  EXPECT_DOUBLE_EQ(s.lights[3].falloff_deg, 0.0);
  EXPECT_DOUBLE_EQ(s.lights[3].scale, 1.0);
  EXPECT_EQ(s.lights[4].type, Light::Type::Sphere);
  EXPECT_EQ(s.lights[4].center, glm::dvec3(2, 1, 0));
  EXPECT_DOUBLE_EQ(s.lights[4].radius, 0.25);
  EXPECT_FALSE(s.lights[4].is_delta());
  EXPECT_TRUE(parse_scene(R"({"lights": [{"type": "distant", "direction": [1, 1, 1], "irradiance": [1, 1, 1]}]})",
                          "d.json").lights[0].is_delta());  // angle_deg 0
  EXPECT_TRUE(parse_scene(R"({"integrator": {"mis": false}, "lights": []})", "e.json").lights.empty());
}

// Each light's range at its limits is accepted (docs/scene-format.md
// "lights"), and a direction whose length overflows double is still the
// direction it names: scaled by its largest component before normalising.
TEST(Scene, LightRangesAtTheirLimits) {
  const Scene s = parse_scene(R"({"lights": [
    {"type": "distant", "direction": [1e200, 1e200, 0], "temperature_k": 100},
    {"type": "spot", "position": [-1e18, 1e18, 1e18], "direction": [0, -1e-300, 0], "temperature_k": 1e6},
    {"type": "sphere", "center": [0, 5e17, 0], "radius": 5e17, "radiance": [1, 1, 1]},
    {"type": "distant", "direction": [0, 1, 0], "irradiance": [1, 1, 1], "angle_deg": 0.0001}]})", "l.json");
  ASSERT_EQ(s.lights.size(), 4u);
  EXPECT_NEAR(s.lights[0].direction.x, std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(s.lights[0].direction.y, std::sqrt(0.5), 1e-15);
  EXPECT_EQ(s.lights[0].direction.z, 0.0);
  EXPECT_EQ(s.lights[1].direction, glm::dvec3(0, -1, 0));
  EXPECT_DOUBLE_EQ(*s.lights[1].temperature_k, 1e6);
  EXPECT_DOUBLE_EQ(s.lights[2].radius, 5e17);
  EXPECT_FALSE(s.lights[3].is_delta());
}

// At most kMaxLights analytic lights (every ray loops over them): that many
// load, one more is refused naming `lights` (docs/scene-format.md "lights").
TEST(Scene, LightCountIsCapped) {
  auto lights = [](size_t n) {
    std::string text = R"({"lights": [)";
    for (size_t k = 0; k < n; ++k)
      text += std::string(k ? ", " : "") + R"({"type": "point", "position": [0, 1, 0], "intensity": [1, 1, 1]})";
    return text + "]}";
  };
  EXPECT_EQ(parse_scene(lights(kMaxLights), "l.json").lights.size(), kMaxLights);
  const std::string msg = error_of(lights(kMaxLights + 1));
  EXPECT_NE(msg.find("bad.json: lights: " + std::to_string(kMaxLights + 1) + " lights, more than the " +
                     std::to_string(kMaxLights)),
            std::string::npos)
      << msg;
  EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
}
