#include "light/LightSelection.h"

#include <optional>
#include <stdexcept>
#include <string>

#include "light/AnalyticLights.h"
#include "light/EmissionCdf.h"
#include "light/EnvironmentMap.h"

namespace pyrolume {

bool LightSelection::any() const {
  if (p_env > 0.0) return true;
  for (double p : p_medium)
    if (p > 0.0) return true;
  for (double p : p_light)
    if (p > 0.0) return true;
  return false;
}

const char* strategy_name(LightStrategy k) {
  return k == LightStrategy::Mis ? "mis" : k == LightStrategy::LightOnly ? "light_only" : "bsdf";
}

LightCandidates light_candidates(const Scene& scene) {
  const Integrator& in = scene.integrator;
  LightCandidates c;
  if (!in.allows_light_sampling() || in.max_depth < 1) return c;
  const bool surfaces = !scene.shapes.empty();
  const bool scatters = scene_scatters(scene);
  const bool asked = in.mis == true || in.light_only;
  c.environment = scatters;
  c.media = asked ? scatters : surfaces;
  c.lights = scatters && !scene.lights.empty();
  return c;
}

LineMediaRule line_media_rule(const Integrator& in) {
  if (!in.emission_estimator) return LineMediaRule::Thin;
  return *in.emission_estimator == EmissionEstimator::Line ? LineMediaRule::EveryEmitting : LineMediaRule::None;
}

EmissionEstimator choose_emission_estimator(const Integrator& in, bool line_media, LightStrategy strategy) {
  if (in.emission_estimator) return *in.emission_estimator;
  if (line_media) return EmissionEstimator::Line;
  return strategy == LightStrategy::Bsdf ? EmissionEstimator::Absorption : EmissionEstimator::Collision;
}

LightSelection select_lights(const Scene& scene, const EnvironmentMap* env, const std::vector<const EmissionCdf*>& cdfs,
                             bool line_media) {
  const Integrator& in = scene.integrator;
  if (const std::optional<IntegratorConflict> c = integrator_conflict(in, !scene.lights.empty()))
    throw std::invalid_argument("integrator." + c->key + ": " + c->reason);
  const LightCandidates want = light_candidates(scene);
  LightSelection s;
  s.p_medium.assign(cdfs.size(), 0.0);
  const bool env_light = want.environment && env && env->has_distribution();
  auto medium_light = [&](const EmissionCdf* c) { return want.media && c && !c->empty() && c->power() > 0.0; };
  // Weights within the two groups (at infinity, in the scene), then 1/2 per
  // group that has a light.
  constexpr double kFourPi = 4.0 * 3.14159265358979323846;
  double far_power = env_light ? env->power() : 0.0, near_power = 0.0;
  for (const EmissionCdf* c : cdfs)
    if (medium_light(c)) near_power += kFourPi * c->power();
  std::vector<double> power(scene.lights.size(), 0.0);
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    if (!want.lights) break;
    power[i] = light_power(scene.lights[i]);
    (scene.lights[i].type == Light::Type::Distant ? far_power : near_power) += power[i];
  }
  const bool far = far_power > 0.0, near = near_power > 0.0;
  const double far_share = far ? (near ? 0.5 : 1.0) : 0.0, near_share = near ? 1.0 - far_share : 0.0;
  s.p_env = env_light && far ? far_share * env->power() / far_power : 0.0;
  for (size_t i = 0; i < cdfs.size(); ++i)
    if (medium_light(cdfs[i]) && near) s.p_medium[i] = near_share * kFourPi * cdfs[i]->power() / near_power;
  s.p_light.assign(scene.lights.size(), 0.0);
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const bool distant = scene.lights[i].type == Light::Type::Distant;
    if (power[i] > 0.0) s.p_light[i] = distant ? far_share * power[i] / far_power : near_share * power[i] / near_power;
  }
  s.strategy = !s.any() ? LightStrategy::Bsdf : (in.light_only ? LightStrategy::LightOnly : LightStrategy::Mis);
  s.estimator = choose_emission_estimator(in, line_media, s.strategy);
  s.p_continue_own =
      s.strategy == LightStrategy::Bsdf ? 1.0 : 1.0 - in.guided_continuation.value_or(1.0 - kContinueOwn);
  s.surface_light_samples = s.strategy == LightStrategy::Bsdf ? 1 : in.surface_light_samples;
  s.ratio_tracked_continuation = s.strategy != LightStrategy::Bsdf && in.ratio_tracked_continuation;
  return s;
}

}  // namespace pyrolume
