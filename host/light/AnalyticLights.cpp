#include "light/AnalyticLights.h"

#include <algorithm>
#include <cmath>

#include "color/Blackbody.h"
#include "color/ColorSpace.h"
#include "util/Math.h"

namespace pyrolume {

namespace {
double radians(double deg) { return deg * (kPi / 180.0); }
}  // namespace

glm::dvec3 light_value(const Light& l) {
  if (l.rgb) return l.scale * *l.rgb;
  const glm::dvec3 c = color::blackbody_rgb(*l.temperature_k, BlackbodyMode::Seed);
  const double y = color::srgb_luminance(c);
  return y > 0.0 ? (l.scale / y) * c : glm::dvec3(0.0);
}

double disc_half_angle(const Light& l) { return l.type == Light::Type::Distant ? 0.5 * radians(l.angle_deg) : 0.0; }

double disc_one_minus_cos(const Light& l) {
  const double s = std::sin(0.5 * disc_half_angle(l));
  return 2.0 * s * s;
}

glm::dvec3 disc_radiance(const Light& l) {
  const double s = std::sin(disc_half_angle(l));
  return s > 0.0 ? light_value(l) / (kPi * s * s) : glm::dvec3(0.0);
}

SpotCone spot_cone(const Light& l) {
  return {std::cos(radians(l.cone_deg)), std::cos(radians(l.cone_deg - l.falloff_deg))};
}

double spot_falloff(const SpotCone& c, double cos_theta) {
  if (cos_theta >= c.cos_start) return 1.0;
  if (cos_theta < c.cos_end) return 0.0;
  const double t = (cos_theta - c.cos_end) / (c.cos_start - c.cos_end);
  return t * t * (3.0 - 2.0 * t);
}

double light_power(const Light& l) {
  const double y = color::srgb_luminance(light_value(l));
  switch (l.type) {
    case Light::Type::Point:
      return 4.0 * kPi * y;
    case Light::Type::Spot: {
      const SpotCone c = spot_cone(l);
      return 2.0 * kPi * y * (1.0 - 0.5 * (c.cos_start + c.cos_end));
    }
    case Light::Type::Sphere:
      return kPi * y * 4.0 * kPi * l.radius * l.radius;
    case Light::Type::Distant:
      return y;
  }
  return 0.0;
}

}  // namespace pyrolume
