// When light sampling runs and which emission estimator a render uses
// (host/light/LightSelection.h, docs/mis.md "When light sampling runs by
// default"): the resolution table from the scene's integrator keys and what
// it holds (surfaces, scattering media, an environment map, emissive grids),
// the integrator keys a scene file may not combine, and that the automatic
// choice on a fire alone renders today's image, sample for sample.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "light/EmissionCdf.h"
#include "light/EnvironmentMap.h"
#include "light/LightSelection.h"
#include "render/cpu/CpuRenderer.h"
#include "scene/Scene.h"
#include "support/MisScenes.h"
#include "util/Error.h"
#include "volume/StoredVolume.h"

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
  s.integrator.emission_estimator = "auto";
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
  EXPECT_EQ(s.integrator.emission_estimator, "auto");
  const Scene t = parse_scene(R"({"integrator": {"mis": false, "emission_estimator": "collision"}})", "t.json");
  EXPECT_EQ(t.integrator.mis, std::optional<bool>(false));
  EXPECT_EQ(t.integrator.emission_estimator, "collision");
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
  collision.integrator.emission_estimator = "collision";
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
  off.integrator.emission_estimator = "collision";
  EXPECT_EQ(resolve(off).estimator, EmissionEstimator::Collision);

  Scene absorption = fire_over_plane();
  absorption.integrator.emission_estimator = "absorption";
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
                         R"({"light_only": true, "mis": true})", R"({"light_only": true})"})
    EXPECT_EQ(parse_error(ok), "") << ok;

  Scene s = fire_over_plane();
  s.integrator.mis = true;
  s.integrator.emission_estimator = "absorption";
  EXPECT_THROW(select_lights(s, nullptr, {nullptr}), std::invalid_argument);
  s.integrator.emission_estimator = "auto";
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
  before.integrator.emission_estimator = "absorption";
  const RenderResult ra = cpu.render(a, test::settings_for(a), {});
  const RenderResult rb = cpu.render(before, test::settings_for(before), {});
  EXPECT_EQ(ra.light_strategy, "bsdf");
  EXPECT_EQ(ra.emission_estimator, "absorption");
  EXPECT_EQ(ra.sum, rb.sum);
  // And it can differ: the collision estimator does not give these samples.
  Scene collision = a;
  collision.integrator.emission_estimator = "collision";
  const RenderResult rc = cpu.render(collision, test::settings_for(collision), {});
  EXPECT_EQ(rc.emission_estimator, "collision");
  EXPECT_NE(rc.sum, ra.sum);
}

}  // namespace
}  // namespace pyrolume
