// Planck's law against published spectral radiance, Wien's displacement law and
// the Stefan–Boltzmann law (host/color/Planck.h).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "color/Planck.h"
#include "support/Stats.h"

using namespace pyrolume::color;

using pyrolume::test::relative_error;

TEST(Planck, MatchesPublishedSpectralRadiance) {
  // W·sr⁻¹·m⁻²·m⁻¹ from SpectralCalc's blackbody calculator
  // (https://www.spectralcalc.com/blackbody_calculator/blackbody.php), the values
  // pbrt-v4's Spectrum.Blackbody test uses. SpectralCalc's constants differ from
  // the exact 2019 SI ones in the 5th digit, hence 2e-4.
  struct Case { double lambda_nm, T, B; };
  const Case cases[] = {{483, 6000, 3.1849e13}, {600, 6000, 2.86772e13}, {500, 3700, 1.59845e12}, {600, 4500, 7.46497e12}};
  for (const Case& c : cases) {
    EXPECT_LT(relative_error(planck_radiance(c.lambda_nm * 1e-9, c.T), c.B), 2e-4) << c.lambda_nm << " nm, " << c.T << " K";
    // Per nanometre is the same number × 1e-9.
    EXPECT_LT(relative_error(planck_radiance_nm(c.lambda_nm, c.T), c.B * 1e-9), 2e-4);
  }
}

TEST(Planck, PeaksAtWienWavelength) {
  // Golden-section search for the maximum of B(lambda) and compare with b / T.
  for (double T : {300.0, 1000.0, 2856.0, 6000.0, 20000.0}) {
    double a = 0.2 * kWienB / T, b = 5.0 * kWienB / T;
    const double g = (std::sqrt(5.0) - 1.0) / 2.0;
    for (int i = 0; i < 200; ++i) {
      const double c = b - g * (b - a), d = a + g * (b - a);
      if (planck_radiance(c, T) > planck_radiance(d, T))
        b = d;
      else
        a = c;
    }
    EXPECT_LT(relative_error(0.5 * (a + b), wien_peak_wavelength_m(T)), 1e-5) << T << " K";
    EXPECT_LT(relative_error(wien_peak_wavelength_m(T), 2.897771955e-3 / T), 1e-12);
  }
  // 6000 K peaks at 483 nm (the published case above).
  EXPECT_NEAR(wien_peak_wavelength_m(6000) * 1e9, 483.0, 0.05);
}

TEST(Planck, IntegratesToStefanBoltzmann) {
  // Integral over all wavelengths of B = sigma T^4 / pi (Lambertian radiance of
  // the exitance sigma T^4). Trapezoid rule in ln(lambda) from lambda_max/50
  // (x ≈ 250, the rest is < e^-240) to 1e4 · lambda_max (tail ~ x³ ≈ 1e-10).
  for (double T : {300.0, 1000.0, 1500.0, 5772.0, 10000.0, 1e5, 1e6}) {
    const double lo = std::log(wien_peak_wavelength_m(T) / 50.0), hi = std::log(wien_peak_wavelength_m(T) * 1e4);
    const int n = 20000;
    const double h = (hi - lo) / n;
    double sum = 0.0;
    for (int i = 0; i <= n; ++i) {
      const double lambda = std::exp(lo + i * h);
      sum += (i == 0 || i == n ? 0.5 : 1.0) * planck_radiance(lambda, T) * lambda;  // dλ = λ d(ln λ)
    }
    const double expected = kStefanBoltzmannSigma * std::pow(T, 4) / M_PI;
    EXPECT_LT(relative_error(sum * h, expected), 0.005) << T << " K";
    EXPECT_LT(relative_error(sum * h, expected), 1e-6) << T << " K (the rule is far better than the 0.5 % asked)";
  }
}

TEST(Planck, FiniteAndZeroWhereUndefined) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  for (double T : {0.0, -5.0, nan, inf, -inf}) {
    EXPECT_EQ(planck_radiance(500e-9, T), 0.0) << T;
    EXPECT_EQ(wien_peak_wavelength_m(T), 0.0) << T;
  }
  for (double lambda : {0.0, -1e-9, nan, inf}) EXPECT_EQ(planck_radiance(lambda, 3000.0), 0.0) << lambda;
  // exp(hc/(lambda k T)) overflows at short wavelengths and low T: 0, not NaN.
  EXPECT_EQ(planck_radiance(360e-9, 1e-3), 0.0);
  EXPECT_EQ(planck_radiance(360e-9, 1.0), 0.0);
  // Deep Wien tail still representable: positive, finite.
  const double tail = planck_radiance(830e-9, 30.0);
  EXPECT_GT(tail, 0.0);
  EXPECT_TRUE(std::isfinite(tail));
  // Rayleigh–Jeans limit (x -> 0): B -> 2 c k T / lambda^4, where expm1 matters.
  const double T = 1e9, lambda = 1e-2;
  const double rj = 2.0 * kSpeedOfLightC * kBoltzmannK * T / std::pow(lambda, 4);
  EXPECT_LT(relative_error(planck_radiance(lambda, T), rj), 1e-9);
  for (double T2 : {1e-300, 1e300, 1e6, 1e-3}) {
    for (double l : {1e-12, 360e-9, 830e-9, 1.0, 1e10}) {
      const double B = planck_radiance(l, T2);
      EXPECT_TRUE(std::isfinite(B) && B >= 0.0) << l << " m, " << T2 << " K";
    }
  }
}
