#pragma once
// Planck's law for the spectral radiance of a blackbody (Planck 1901), in double.
namespace pyrolume::color {

// SI defining constants (exact since the 2019 SI redefinition; CODATA 2018).
inline constexpr double kPlanckH = 6.62607015e-34;    // J·s
inline constexpr double kSpeedOfLightC = 299792458.0;  // m/s
inline constexpr double kBoltzmannK = 1.380649e-23;   // J/K
// Derived (CODATA 2018): Wien's displacement constant b (lambda_max = b / T) and
// the Stefan–Boltzmann constant sigma (exitance sigma T^4, radiance sigma T^4 / pi).
inline constexpr double kWienB = 2.897771955e-3;               // m·K
inline constexpr double kStefanBoltzmannSigma = 5.670374419e-8;  // W·m⁻²·K⁻⁴

// B(lambda, T) = 2hc² / lambda⁵ / (exp(hc / (lambda k T)) - 1), in W·sr⁻¹·m⁻²·m⁻¹
// (per metre of wavelength). Returns 0 -- never NaN or Inf -- for T <= 0, T or
// lambda NaN/Inf/<= 0, and wherever the value under- or overflows a double (e.g.
// short wavelengths at low T, or T beyond ~1e290 K).
double planck_radiance(double lambda_m, double temperature_k);

// The same radiance per nanometre of wavelength: W·sr⁻¹·m⁻²·nm⁻¹ (= SI × 1e-9).
double planck_radiance_nm(double lambda_nm, double temperature_k);

// Wien's displacement law: the wavelength (m) where B(lambda, T) peaks; 0 for
// invalid T.
double wien_peak_wavelength_m(double temperature_k);

}  // namespace pyrolume::color
