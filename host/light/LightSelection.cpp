#include "light/LightSelection.h"

#include <string>

#include "light/EmissionCdf.h"
#include "light/EnvironmentMap.h"

namespace pyrolume {

bool LightSelection::any() const {
  if (p_env > 0.0) return true;
  for (double p : p_medium)
    if (p > 0.0) return true;
  return false;
}

namespace {
bool scene_scatters(const Scene& scene) {
  if (!scene.shapes.empty()) return true;
  for (const Medium& m : scene.media)
    if (m.sigma_s.x > 0.0 || m.sigma_s.y > 0.0 || m.sigma_s.z > 0.0) return true;
  return false;
}
}  // namespace

LightSelection select_lights(const Scene& scene, const EnvironmentMap* env, const std::vector<const EmissionCdf*>& cdfs) {
  LightSelection s;
  s.p_medium.assign(cdfs.size(), 0.0);
  const bool env_light = env && env->has_distribution();
  double media_power = 0.0;
  for (const EmissionCdf* c : cdfs)
    if (c && !c->empty() && c->power() > 0.0) media_power += c->power();
  const double media_share = media_power > 0.0 ? (env_light ? 0.5 : 1.0) : 0.0;
  s.p_env = env_light ? 1.0 - media_share : 0.0;
  for (size_t i = 0; i < cdfs.size(); ++i)
    if (cdfs[i] && !cdfs[i]->empty() && cdfs[i]->power() > 0.0)
      s.p_medium[i] = media_share * cdfs[i]->power() / media_power;
  const Integrator& in = scene.integrator;
  const bool eligible = in.mis && in.emission_estimator == "collision" && in.max_depth >= 1 && s.any() &&
                        scene_scatters(scene);
  s.strategy = !eligible ? LightStrategy::Bsdf : (in.light_only ? LightStrategy::LightOnly : LightStrategy::Mis);
  s.p_continue_own = s.strategy == LightStrategy::Bsdf ? 1.0 : kContinueOwn;
  s.surface_light_samples = s.strategy == LightStrategy::Bsdf ? 1 : in.surface_light_samples;
  s.ratio_tracked_continuation = s.strategy != LightStrategy::Bsdf && in.ratio_tracked_continuation;
  return s;
}

std::string light_strategy_warning(const Scene& scene) {
  const Integrator& in = scene.integrator;
  if (!in.mis || !in.mis_in_file || in.emission_estimator == "collision" || !scene_scatters(scene)) return "";
  bool lights = scene.environment.has_value();
  for (const Medium& m : scene.media) lights = lights || (m.type == Medium::Type::Vdb && m.emission.emits());
  if (!lights) return "";
  return "integrator.mis needs \"emission_estimator\": \"collision\"; with \"absorption\" the lights are "
         "found by BSDF/phase sampling only";
}

}  // namespace pyrolume
