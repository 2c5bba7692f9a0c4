#include "color/Planck.h"

#include <cmath>

namespace pyrolume::color {

double planck_radiance(double lambda_m, double temperature_k) {
  if (!(temperature_k > 0.0) || !std::isfinite(temperature_k) || !(lambda_m > 0.0) || !std::isfinite(lambda_m))
    return 0.0;
  constexpr double c1L = 2.0 * kPlanckH * kSpeedOfLightC * kSpeedOfLightC;  // first radiation constant for radiance
  constexpr double c2 = kPlanckH * kSpeedOfLightC / kBoltzmannK;            // second radiation constant, m·K
  const double x = c2 / (lambda_m * temperature_k);
  double B;
  if (x > 700.0) {
    // Wien limit: expm1(x) = exp(x) to double precision; work in logs so that
    // neither exp(x) nor 1/lambda^5 overflows on its own.
    B = std::exp(std::log(c1L) - 5.0 * std::log(lambda_m) - x);
  } else {
    // expm1 keeps full precision in the Rayleigh–Jeans limit x -> 0, where
    // exp(x) - 1 would cancel catastrophically.
    const double l2 = lambda_m * lambda_m;
    B = c1L / (l2 * l2 * lambda_m * std::expm1(x));
  }
  return std::isfinite(B) && B > 0.0 ? B : 0.0;
}

double planck_radiance_nm(double lambda_nm, double temperature_k) {
  return planck_radiance(lambda_nm * 1e-9, temperature_k) * 1e-9;
}

double wien_peak_wavelength_m(double temperature_k) {
  if (!(temperature_k > 0.0) || !std::isfinite(temperature_k)) return 0.0;
  return kWienB / temperature_k;
}

}  // namespace pyrolume::color
