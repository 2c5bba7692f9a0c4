// When light sampling runs and which emission estimator a render uses
// (host/light/LightSelection.h, docs/mis.md "When light sampling runs by
// default"): the resolution table from the scene's integrator keys and what
// it holds (surfaces, scattering media, an environment map, emissive grids),
// the integrator keys a scene file may not combine, and that the automatic
// choice on a fire alone renders today's image, sample for sample.
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "light/EmissionCdf.h"
#include "light/EnvironmentMap.h"
#include "light/LightSelection.h"
#include "render/cpu/CpuRenderer.h"
#include "scene/MediumVolume.h"
#include "scene/Scene.h"
#include "support/LightScenes.h"
#include "support/MisScenes.h"
#include "support/Stats.h"
#include "util/Error.h"
#include "volume/StoredVolume.h"
#include "util/Math.h"

namespace pyrolume {
namespace {

using test::Strategy;

// What a scene's lights resolve to, with its environment map and emission
// CDFs built as the backends build them (only for the kinds light_candidates
// allows).
LightSelection resolve(const Scene& s) {
  std::optional<EnvironmentMap> env;
  if (s.environment) env = EnvironmentMap::load(s.environment->file);
  std::vector<std::optional<EmissionCdf>> cdfs(s.media.size());
  std::vector<const EmissionCdf*> by_medium(s.media.size(), nullptr);
  if (light_candidates(s).media)
    for (size_t i = 0; i < s.media.size(); ++i)
      if (s.media[i].type == Medium::Type::Vdb && s.media[i].emission.emits()) {
        cdfs[i] = EmissionCdf::build_light(s.media[i], load_stored_volume(s.media[i]));
        if (!cdfs[i]->empty()) by_medium[i] = &*cdfs[i];
      }
  return select_lights(s, env ? &*env : nullptr, by_medium);
}

// The strategy, the resolved estimator and the first medium's light probability.
void expect_resolution(const LightSelection& l, LightStrategy strategy, EmissionEstimator estimator, double p_medium0,
                       const char* what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(l.strategy, strategy);
  EXPECT_EQ(l.estimator, estimator);
  EXPECT_DOUBLE_EQ(l.p_medium[0], p_medium0);
}

// The integrator keys as a file that writes none of them leaves them.
void file_defaults(Scene& s) {
  s.integrator.mis.reset();
  s.integrator.light_only = false;
  s.integrator.emission_estimator = std::nullopt;  // "auto"
}

std::string parse_error(const std::string& integrator) {
  try {
    parse_scene(R"({"integrator": )" + integrator + "}", "bad.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

class LightResolution : public ::testing::Test {
 protected:
  const std::filesystem::path dir = test::temp_dir("light_resolution");
  // An emissive, scattering grid alone (no surfaces, no environment).
  Scene fire_alone() {
    Scene s = test::scattering_fire_scene(dir, Strategy::Bsdf, 8, 8, 4);
    file_defaults(s);
    return s;
  }
  // An emissive, scattering grid over a diffuse plane (no environment).
  Scene fire_over_plane() {
    Scene s = test::fire_over_plane_scene(dir, Strategy::Bsdf, false, true, 8, 8, 4);
    file_defaults(s);
    return s;
  }
  // The emissive, scattering grid alone under an environment map.
  Scene fire_under_sky() {
    Scene s = fire_alone();
    s.environment = Environment{test::write_uniform_sky(dir, glm::vec3(0.2f)), 1.0, 0.0};
    return s;
  }
};

// The defaults read from a file: "mis" absent, the estimator "auto".
TEST(LightDefaults, FileWithoutIntegratorKeysIsAutomatic) {
  const Scene s = parse_scene(R"({"media": [{"type": "vdb", "file": "f.vdb"}]})", "s.json");
  EXPECT_FALSE(s.integrator.mis.has_value());
  EXPECT_FALSE(s.integrator.light_only);
  EXPECT_FALSE(s.integrator.emission_estimator.has_value());  // "auto"
  const Scene t = parse_scene(R"({"integrator": {"mis": false, "emission_estimator": "collision"}})", "t.json");
  EXPECT_EQ(t.integrator.mis, std::optional<bool>(false));
  EXPECT_EQ(t.integrator.emission_estimator, EmissionEstimator::Collision);
  EXPECT_EQ(parse_scene(R"({"integrator": {"mis": true}})", "u.json").integrator.mis, std::optional<bool>(true));
}

// light_candidates from the keys alone: parsed files, nothing loaded.
TEST(LightDefaults, CandidatesFromTheKeys) {
  const std::string fire = R"({"type": "vdb", "file": "f.vdb", "sigma_s": [1, 1, 1]})";
  const std::string flame = R"({"type": "vdb", "file": "f.vdb", "sigma_s": [0, 0, 0]})";
  const std::string plane = R"("shapes": [{"plane": {"center": [0, 0, 0], "normal": [0, 1, 0]}}])";
  const std::string sky = R"("environment": {"file": "sky.exr"})";
  struct Case {
    const char* what;
    std::string json;
    bool environment, media;
  };
  const Case cases[] = {
      {"fire alone", R"({"media": [)" + fire + "]}", true, false},
      {"fire over a plane", R"({"media": [)" + fire + "], " + plane + "}", true, true},
      {"fire under a sky", R"({"media": [)" + fire + "], " + sky + "}", true, false},
      {"non-scattering flame under a sky", R"({"media": [)" + flame + "], " + sky + "}", false, false},
      {"non-scattering flame over a plane", R"({"media": [)" + flame + "], " + plane + "}", true, true},
      {"fire alone, mis true", R"({"integrator": {"mis": true}, "media": [)" + fire + "]}", true, true},
      {"fire alone, light_only", R"({"integrator": {"light_only": true}, "media": [)" + fire + "]}", true, true},
      {"non-scattering flame, mis true", R"({"integrator": {"mis": true}, "media": [)" + flame + "]}", false, false},
      {"fire over a plane, mis false", R"({"integrator": {"mis": false}, "media": [)" + fire + "], " + plane + "}",
       false, false},
      {"fire over a plane, absorption",
       R"({"integrator": {"emission_estimator": "absorption"}, "media": [)" + fire + "], " + plane + "}", false, false},
      {"fire over a plane, collision",
       R"({"integrator": {"emission_estimator": "collision"}, "media": [)" + fire + "], " + plane + "}", true, true},
      {"fire alone, collision", R"({"integrator": {"emission_estimator": "collision"}, "media": [)" + fire + "]}",
       true, false},
      {"fire over a plane, max_depth 0", R"({"integrator": {"max_depth": 0}, "media": [)" + fire + "], " + plane + "}",
       false, false},
      {"fire alone, mis true, max_depth 0", R"({"integrator": {"mis": true, "max_depth": 0}, "media": [)" + fire + "]}",
       false, false},
  };
  for (const Case& c : cases) {
    const LightCandidates l = light_candidates(parse_scene(c.json, "s.json"));
    EXPECT_EQ(l.environment, c.environment) << c.what;
    EXPECT_EQ(l.media, c.media) << c.what;
  }
}

// The estimator is chosen in one place: every estimator the file can name
// (or "auto"), with and without a medium the line estimator would collect,
// with and without light sampling, and which media the line estimator takes.
TEST(LightDefaults, OneChoiceOfEstimator) {
  using E = EmissionEstimator;
  const std::optional<E> asked[] = {std::nullopt, E::Absorption, E::Collision, E::Line};
  for (const std::optional<E>& a : asked)
    for (bool line : {false, true})
      for (LightStrategy k : {LightStrategy::Bsdf, LightStrategy::Mis, LightStrategy::LightOnly}) {
        Integrator in;
        in.emission_estimator = a;
        const E want = a ? *a : line ? E::Line : k == LightStrategy::Bsdf ? E::Absorption : E::Collision;
        EXPECT_EQ(choose_emission_estimator(in, line, k), want)
            << (a ? to_string(*a) : "auto") << " line " << line << " " << strategy_name(k);
      }
  Integrator in;
  EXPECT_EQ(line_media_rule(in), LineMediaRule::Thin);
  in.emission_estimator = E::Line;
  EXPECT_EQ(line_media_rule(in), LineMediaRule::EveryEmitting);
  for (E other : {E::Absorption, E::Collision}) {
    in.emission_estimator = other;
    EXPECT_EQ(line_media_rule(in), LineMediaRule::None) << to_string(other);
  }
}

// A fire alone: BSDF/phase sampling with the absorption estimator, its grid
// not a light; "mis": true written out samples it.
TEST_F(LightResolution, FireAlone) {
  const LightSelection a = resolve(fire_alone());
  expect_resolution(a, LightStrategy::Bsdf, EmissionEstimator::Absorption, 0.0, "fire alone");
  EXPECT_DOUBLE_EQ(a.p_continue_own, 1.0);

  Scene asked = fire_alone();
  asked.integrator.mis = true;
  expect_resolution(resolve(asked), LightStrategy::Mis, EmissionEstimator::Collision, 1.0, "mis true");

  Scene debug = fire_alone();
  debug.integrator.light_only = true;
  const LightSelection d = resolve(debug);
  EXPECT_EQ(d.strategy, LightStrategy::LightOnly);
  EXPECT_EQ(d.estimator, EmissionEstimator::Collision);

  // The collision estimator written out keeps the automatic rule.
  Scene collision = fire_alone();
  collision.integrator.emission_estimator = EmissionEstimator::Collision;
  expect_resolution(resolve(collision), LightStrategy::Bsdf, EmissionEstimator::Collision, 0.0, "collision");
}

// A fire over a plane: MIS with the collision estimator, the grid a light.
TEST_F(LightResolution, FireOverPlane) {
  const LightSelection a = resolve(fire_over_plane());
  expect_resolution(a, LightStrategy::Mis, EmissionEstimator::Collision, 1.0, "fire over plane");
  EXPECT_DOUBLE_EQ(a.p_continue_own, kContinueOwn);
  Scene guided = fire_over_plane();
  guided.integrator.guided_continuation = 0.25;  // a quarter of the continuations from the lights
  EXPECT_DOUBLE_EQ(resolve(guided).p_continue_own, 0.75);

  Scene off = fire_over_plane();
  off.integrator.mis = false;
  expect_resolution(resolve(off), LightStrategy::Bsdf, EmissionEstimator::Absorption, 0.0, "mis false");
  off.integrator.emission_estimator = EmissionEstimator::Collision;
  EXPECT_EQ(resolve(off).estimator, EmissionEstimator::Collision);

  Scene absorption = fire_over_plane();
  absorption.integrator.emission_estimator = EmissionEstimator::Absorption;
  const LightSelection ab = resolve(absorption);
  EXPECT_EQ(ab.strategy, LightStrategy::Bsdf);
  EXPECT_EQ(ab.estimator, EmissionEstimator::Absorption);

  Scene depth0 = fire_over_plane();
  depth0.integrator.max_depth = 0;
  EXPECT_EQ(resolve(depth0).strategy, LightStrategy::Bsdf);
  EXPECT_EQ(resolve(depth0).estimator, EmissionEstimator::Absorption);
}

// Smoke under an environment map: the map is a light, the grid is not.
TEST_F(LightResolution, SmokeUnderSky) {
  const LightSelection a = resolve(fire_under_sky());
  EXPECT_EQ(a.strategy, LightStrategy::Mis);
  EXPECT_EQ(a.estimator, EmissionEstimator::Collision);
  EXPECT_DOUBLE_EQ(a.p_env, 1.0);
  EXPECT_DOUBLE_EQ(a.p_medium[0], 0.0);
  // "mis": true written out: both, half each.
  Scene asked = fire_under_sky();
  asked.integrator.mis = true;
  const LightSelection m = resolve(asked);
  EXPECT_DOUBLE_EQ(m.p_env, 0.5);
  EXPECT_DOUBLE_EQ(m.p_medium[0], 0.5);
  // Nothing scatters: nothing for the map to light.
  Scene flame = fire_under_sky();
  flame.media[0].sigma_s = glm::dvec3(0.0);
  EXPECT_EQ(resolve(flame).strategy, LightStrategy::Bsdf);
  EXPECT_EQ(resolve(flame).estimator, EmissionEstimator::Absorption);
  flame.integrator.mis = true;
  EXPECT_EQ(resolve(flame).strategy, LightStrategy::Bsdf);
}

// A grid the backends built a CDF for, but that the rule does not sample,
// gets probability 0 (both backends' pdfs agree whatever they built).
TEST_F(LightResolution, UnsampledGridGetsNoProbability) {
  Scene asked = fire_alone();
  asked.integrator.mis = true;
  const StoredVolume vol = load_stored_volume(asked.media[0]);
  const EmissionCdf cdf = EmissionCdf::build_light(asked.media[0], vol);
  ASSERT_FALSE(cdf.empty());
  EXPECT_DOUBLE_EQ(select_lights(asked, nullptr, {&cdf}).p_medium[0], 1.0);
  const LightSelection a = select_lights(fire_alone(), nullptr, {&cdf});
  EXPECT_DOUBLE_EQ(a.p_medium[0], 0.0);
  EXPECT_EQ(a.strategy, LightStrategy::Bsdf);
}

// An estimator the loader does not know is refused in one line that names
// the file and the key and lists the values it takes, "line" among them.
TEST_F(LightResolution, UnknownEstimatorIsRefusedNamingTheValues) {
  const std::string msg = parse_error(R"({"emission_estimator": "lines"})");
  EXPECT_NE(msg.find("bad.json: integrator.emission_estimator: "), std::string::npos) << msg;
  for (const char* value : {"\"auto\"", "\"absorption\"", "\"collision\"", "\"line\"", "\"lines\""})
    EXPECT_NE(msg.find(value), std::string::npos) << value << " missing from: " << msg;
  EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
}

// Keys that contradict each other: the file is refused at load, naming the
// key; the same Scene built in code is refused by select_lights.
TEST_F(LightResolution, ContradictionsAreRefused) {
  struct Case {
    const char* integrator;
    const char* key;
  };
  const Case cases[] = {
      {R"({"mis": true, "emission_estimator": "absorption"})", "bad.json: integrator.emission_estimator: "},
      {R"({"light_only": true, "mis": false})", "bad.json: integrator.light_only: "},
      {R"({"light_only": true, "emission_estimator": "absorption"})", "bad.json: integrator.light_only: "},
      {R"({"light_only": true, "mis": false, "emission_estimator": "collision"})", "bad.json: integrator.light_only: "},
  };
  for (const Case& c : cases) {
    const std::string msg = parse_error(c.integrator);
    EXPECT_NE(msg.find(c.key), std::string::npos) << c.integrator << " gave: " << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
  // Consistent choices load.
  for (const char* ok : {R"({"mis": true, "emission_estimator": "collision"})", R"({"mis": true})",
                         R"({"mis": false, "emission_estimator": "absorption"})", R"({"emission_estimator": "absorption"})",
                         R"({"light_only": true, "mis": true})", R"({"light_only": true})",
                         R"({"mis": true, "emission_estimator": "line"})",
                         R"({"light_only": true, "emission_estimator": "line"})"})
    EXPECT_EQ(parse_error(ok), "") << ok;

  Scene s = fire_over_plane();
  s.integrator.mis = true;
  s.integrator.emission_estimator = EmissionEstimator::Absorption;
  EXPECT_THROW(select_lights(s, nullptr, {nullptr}), std::invalid_argument);
  s.integrator.emission_estimator = std::nullopt;  // "auto"
  s.integrator.mis = false;
  s.integrator.light_only = true;
  EXPECT_THROW(select_lights(s, nullptr, {nullptr}), std::invalid_argument);
}

// The automatic choice on a fire alone is the image the absorption estimator
// with BSDF/phase sampling renders: the same samples, bit for bit (CPU
// reference; its per-pixel sums do not depend on threads or passes).
TEST_F(LightResolution, FireAloneRendersAsBefore) {
  CpuRenderer cpu(0);
  const Scene a = fire_alone();
  Scene before = a;
  before.integrator.mis = false;
  before.integrator.emission_estimator = EmissionEstimator::Absorption;
  const RenderResult ra = cpu.render(a, test::settings_for(a), {});
  const RenderResult rb = cpu.render(before, test::settings_for(before), {});
  EXPECT_EQ(ra.light_strategy, "bsdf");
  EXPECT_EQ(ra.emission_estimator, "absorption");
  EXPECT_EQ(ra.sum, rb.sum);
  // And it can differ: the collision estimator does not give these samples.
  Scene collision = a;
  collision.integrator.emission_estimator = EmissionEstimator::Collision;
  const RenderResult rc = cpu.render(collision, test::settings_for(collision), {});
  EXPECT_EQ(rc.emission_estimator, "collision");
  EXPECT_NE(rc.sum, ra.sum);
}

// ------------------------------------------------------ analytic lights ----
// docs/lights.md "Choosing a light": the lights at infinity (the environment,
// distant lights) and the lights in the scene (emissive grids, point, spot and
// sphere lights) get 1/2 each when both have a light (1 when alone), by power
// within; the powers are computed here from their definitions.

double luminance(glm::dvec3 c) { return 0.2126729 * c.r + 0.7151522 * c.g + 0.0721750 * c.b; }

// Every light at (0, 1, 0), the spot shining down and the sun overhead:
// where they are does not change their power.
Light point_light(glm::dvec3 intensity) { return test::point_light({0, 1, 0}, intensity); }
Light distant_light(glm::dvec3 irradiance, double angle_deg) {
  return test::distant_light({0, 1, 0}, irradiance, angle_deg);
}
Light spot_light(glm::dvec3 intensity, double cone_deg, double falloff_deg) {
  return test::spot_light({0, 1, 0}, {0, -1, 0}, intensity, cone_deg, falloff_deg);
}
Light sphere_light(glm::dvec3 radiance, double radius) { return test::sphere_light({0, 1, 0}, radius, radiance); }

class LightSelectionLights : public LightResolution {
 protected:
  // The fire over a plane (surfaces: every kind of light is sampled), with
  // "mis" left out; its sky, emission CDF and light selection built as the
  // backends build them.
  Scene plane(bool sky) {
    Scene s = fire_over_plane();
    if (sky) s.environment = Environment{test::write_uniform_sky(dir, glm::vec3(0.2f, 0.3f, 0.4f)), 1.0, 0.0};
    return s;
  }
  double sky_power(const Scene& s) { return EnvironmentMap::load(s.environment->file).power(); }
  double fire_power(const Scene& s) {
    return 4.0 * kPi * EmissionCdf::build_light(s.media[0], load_stored_volume(s.media[0])).power();
  }
  // The selection without the fire as a light (no emission CDF given).
  LightSelection without_fire(const Scene& s) {
    std::optional<EnvironmentMap> env;
    if (s.environment) env = EnvironmentMap::load(s.environment->file);
    return select_lights(s, env ? &*env : nullptr, {nullptr});
  }
};

void expect_rel(double a, double b, const char* what) { EXPECT_NEAR(a, b, 1e-12 * std::abs(b)) << what; }

// No lights array: the environment against the grids as before, 1/2 each,
// each alone 1; no per-light probabilities.
TEST_F(LightSelectionLights, WithoutLightsUnchanged) {
  Scene s = plane(true);
  s.integrator.mis = true;
  LightSelection l = resolve(s);
  EXPECT_TRUE(l.p_light.empty());
  EXPECT_DOUBLE_EQ(l.p_env, 0.5);
  EXPECT_DOUBLE_EQ(l.p_medium[0], 0.5);
  EXPECT_DOUBLE_EQ(without_fire(s).p_env, 1.0);
  EXPECT_DOUBLE_EQ(resolve(plane(false)).p_medium[0], 1.0);
  EXPECT_EQ(l.strategy, LightStrategy::Mis);
}

// A sky and a sun are both at infinity: by power, ∫Y(L) dω against Y(E).
TEST_F(LightSelectionLights, SkyAndSunByPower) {
  Scene s = plane(true);
  s.lights.push_back(distant_light({3, 2, 1}, 0.53));
  const LightSelection l = without_fire(s);
  const double sky = sky_power(s), sun = luminance({3, 2, 1});
  expect_rel(l.p_env, sky / (sky + sun), "sky");
  expect_rel(l.p_light[0], sun / (sky + sun), "sun");
  EXPECT_EQ(l.strategy, LightStrategy::Mis);
  // A delta sun the same way.
  s.lights[0].angle_deg = 0.0;
  expect_rel(without_fire(s).p_light[0], sun / (sky + sun), "delta sun");
}

// A fire and a point light are both in the scene: by power in watts,
// 4π ∫Y(σa Le) dV against 4π Y(I); a sky beside them takes the other half.
TEST_F(LightSelectionLights, FireAndPointLightByPower) {
  Scene s = plane(false);
  s.lights.push_back(point_light({5, 4, 3}));
  const double fire = fire_power(s), point = 4.0 * kPi * luminance({5, 4, 3});
  LightSelection l = resolve(s);
  expect_rel(l.p_medium[0], fire / (fire + point), "fire");
  expect_rel(l.p_light[0], point / (fire + point), "point");
  // The point light and a sky: 1/2 each.
  Scene t = plane(true);
  t.lights.push_back(point_light({5, 4, 3}));
  l = without_fire(t);
  EXPECT_DOUBLE_EQ(l.p_env, 0.5);
  EXPECT_DOUBLE_EQ(l.p_light[0], 0.5);
  // A point light alone: 1.
  EXPECT_DOUBLE_EQ(without_fire(s).p_light[0], 1.0);
}

// Every kind at once: the sky, a delta and a disc sun share one half by
// power; the fire, a point, a spot (2π Y(I)(1 − (cos θ_start + cos θ_end)/2))
// and a sphere (π Y(L) · 4πr²) the other.
TEST_F(LightSelectionLights, EveryKind) {
  Scene s = plane(true);
  s.lights = {distant_light({1, 1, 1}, 0.0), point_light({2, 1, 0.5}), distant_light({0.5, 2, 1}, 5.0),
              spot_light({4, 4, 4}, 40.0, 15.0), sphere_light({3, 1, 2}, 0.3)};
  const LightSelection l = resolve(s);
  const double far[] = {sky_power(s), luminance({1, 1, 1}), luminance({0.5, 2, 1})};
  const double c_end = std::cos(40.0 * kPi / 180.0), c_start = std::cos(25.0 * kPi / 180.0);
  const double near[] = {fire_power(s), 4.0 * kPi * luminance({2, 1, 0.5}),
                         2.0 * kPi * luminance({4, 4, 4}) * (1.0 - 0.5 * (c_start + c_end)),
                         kPi * luminance({3, 1, 2}) * 4.0 * kPi * 0.3 * 0.3};
  const double far_sum = far[0] + far[1] + far[2], near_sum = near[0] + near[1] + near[2] + near[3];
  expect_rel(l.p_env, 0.5 * far[0] / far_sum, "sky");
  expect_rel(l.p_light[0], 0.5 * far[1] / far_sum, "delta sun");
  expect_rel(l.p_light[2], 0.5 * far[2] / far_sum, "disc sun");
  expect_rel(l.p_medium[0], 0.5 * near[0] / near_sum, "fire");
  expect_rel(l.p_light[1], 0.5 * near[1] / near_sum, "point");
  expect_rel(l.p_light[3], 0.5 * near[2] / near_sum, "spot");
  expect_rel(l.p_light[4], 0.5 * near[3] / near_sum, "sphere");
  double sum = l.p_env + l.p_medium[0];
  for (double p : l.p_light) sum += p;
  EXPECT_NEAR(sum, 1.0, 1e-12);
}

// A light of zero power is never picked, and a group that holds only such
// lights gets nothing: the other group takes all.
TEST_F(LightSelectionLights, ZeroPowerLights) {
  Scene s = plane(true);
  s.lights = {point_light({0, 0, 0}), distant_light({1, 1, 1}, 0.0)};
  s.lights[1].scale = 0.0;
  const LightSelection l = without_fire(s);
  EXPECT_DOUBLE_EQ(l.p_env, 1.0);
  EXPECT_DOUBLE_EQ(l.p_light[0], 0.0);
  EXPECT_DOUBLE_EQ(l.p_light[1], 0.0);
}

// temperature_k: the value's luminance is `scale` (docs/lights.md).
TEST_F(LightSelectionLights, TemperatureLightHasLuminanceScale) {
  Scene s = plane(false);
  Light a = point_light({1, 1, 1}), b;
  a.scale = 3.0;
  b.type = Light::Type::Point;
  b.temperature_k = 2700.0;
  b.scale = 1.0;
  s.lights = {a, b};
  const LightSelection l = without_fire(s);
  // 4π·3·Y(1, 1, 1) = 4π·3 against 4π·1.
  EXPECT_NEAR(l.p_light[0], 0.75, 1e-6);
  EXPECT_NEAR(l.p_light[1], 0.25, 1e-6);
}

// Lights with nothing to light (no surface, nothing scatters) or max_depth 0
// are not sampled: BSDF sampling only (camera rays still see spheres and discs).
TEST_F(LightSelectionLights, NothingToLight) {
  Scene s = fire_alone();
  s.media[0].sigma_s = glm::dvec3(0.0);
  s.lights = {point_light({1, 1, 1}), sphere_light({1, 1, 1}, 0.5)};
  LightSelection l = resolve(s);
  EXPECT_EQ(l.strategy, LightStrategy::Bsdf);
  EXPECT_EQ(l.estimator, EmissionEstimator::Absorption);
  EXPECT_DOUBLE_EQ(l.p_light[0], 0.0);
  EXPECT_DOUBLE_EQ(l.p_light[1], 0.0);
  Scene t = plane(false);
  t.lights = s.lights;
  t.integrator.max_depth = 0;
  l = resolve(t);
  EXPECT_EQ(l.strategy, LightStrategy::Bsdf);
  EXPECT_DOUBLE_EQ(l.p_light[0], 0.0);
  // A smoke that scatters is something to light.
  Scene u = fire_alone();
  u.lights = s.lights;
  l = without_fire(u);
  EXPECT_EQ(l.strategy, LightStrategy::Mis);
  EXPECT_GT(l.p_light[0], 0.0);
}

// "mis": false and the absorption estimator contradict lights: refused.
TEST_F(LightSelectionLights, ContradictionsWithLights) {
  Scene s = plane(false);
  s.lights = {point_light({1, 1, 1})};
  s.integrator.mis = false;
  EXPECT_THROW(resolve(s), std::invalid_argument);
  s.integrator.mis.reset();
  s.integrator.emission_estimator = EmissionEstimator::Absorption;
  EXPECT_THROW(resolve(s), std::invalid_argument);
  s.integrator.emission_estimator = EmissionEstimator::Collision;
  EXPECT_EQ(resolve(s).strategy, LightStrategy::Mis);
}

}  // namespace
}  // namespace pyrolume
