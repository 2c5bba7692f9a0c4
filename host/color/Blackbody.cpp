#include "color/Blackbody.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "color/ChromaticAdaptation.h"
#include "color/CieTables.h"
#include "color/ColorSpace.h"
#include "color/Planck.h"

namespace pyrolume::color {

const CmfTable& cmf_table(int observer) {
  if (observer == 2) return cie_1931_2deg();
  if (observer == 10) return cie_1964_10deg();
  throw std::invalid_argument("observer must be 2 (CIE 1931) or 10 (CIE 1964), got " + std::to_string(observer));
}

namespace {

// XYZ of the (Wien-peak-normalised, or absolute) Planck spectrum by a Riemann
// sum over every `step_nm`-th row of the 1 nm table (CIE 15:2004 §7.1). The
// 5 nm table is every 5th row starting at 360 nm.
glm::dvec3 spectrum_xyz(double temperature_k, BlackbodyMode mode, int observer, int step_nm) {
  const CmfTable& cmf = cmf_table(observer);
  if (!(temperature_k > 0.0) || !std::isfinite(temperature_k)) return glm::dvec3(0.0);

  // Seed and Peak divide by B(lambda_max, T) (Wien's displacement law), so the
  // spectrum is 1 at its peak (pbrt-v4's BlackbodySpectrum); Physical keeps the
  // absolute radiance in W·sr⁻¹·m⁻²·nm⁻¹.
  double norm = 1e-9;  // SI per-metre radiance -> per nanometre
  if (mode != BlackbodyMode::Physical) {
    const double B_max = planck_radiance(wien_peak_wavelength_m(temperature_k), temperature_k);
    if (!(B_max > 0.0)) return glm::dvec3(0.0);
    norm = 1.0 / B_max;
  }
  glm::dvec3 xyz(0.0);
  for (int i = 0; i < cmf.size(); i += step_nm) {
    const double B = planck_radiance((cmf.lambda_min_nm + i) * 1e-9, temperature_k) * norm;
    const CmfSample& s = cmf.samples[i];
    xyz += B * glm::dvec3(s.xbar, s.ybar, s.zbar);
  }
  xyz *= double(step_nm);  // d_lambda
  if (!std::isfinite(xyz.x) || !std::isfinite(xyz.y) || !std::isfinite(xyz.z)) return glm::dvec3(0.0);
  return xyz;
}

// The white of a blackbody at adapt_to_k, the source white of the adaptation.
glm::dvec3 adaptation_white(double adapt_to_k, int observer) {
  const glm::dvec3 white = spectrum_xyz(adapt_to_k, BlackbodyMode::Peak, observer, 1);
  if (!(white.y > 0.0))
    throw std::invalid_argument("adapt_to_k: a blackbody at " + std::to_string(adapt_to_k) +
                                " K has no visible light to adapt to");
  return white;
}

// XYZ -> the mode's linear sRGB: out-of-gamut (negative) channels clamped (the
// Planckian locus leaves the sRGB triangle below ~1900 K: blue < 0; green too
// below ~970 K), and seed mode scaled so the largest channel is 1.
glm::dvec3 mode_rgb(const glm::dvec3& xyz, BlackbodyMode mode) {
  glm::dvec3 rgb = glm::max(xyz_to_linear_srgb(xyz), glm::dvec3(0.0));
  if (!std::isfinite(rgb.r) || !std::isfinite(rgb.g) || !std::isfinite(rgb.b)) return glm::dvec3(0.0);
  if (mode == BlackbodyMode::Seed) {
    const double m = std::max({rgb.r, rgb.g, rgb.b});
    rgb = m > 0.0 ? rgb / m : glm::dvec3(0.0);
  }
  return rgb;
}

}  // namespace

// Stefan–Boltzmann mode: the spectrum's chromaticity at luminance
// (T / T_ref)^4, the T⁴ growth of a blackbody's total radiance σT⁴/π
// (Stefan–Boltzmann law, Planck's law integrated over all wavelengths).
static glm::dvec3 stefan_boltzmann_xyz(const glm::dvec3& xyz, double temperature_k) {
  if (!(xyz.y > 0.0)) return glm::dvec3(0.0);
  const double t = temperature_k / kStefanBoltzmannReferenceK;
  return xyz * (t * t * t * t / xyz.y);
}

glm::dvec3 blackbody_xyz(double temperature_k, BlackbodyMode mode, int observer) {
  const glm::dvec3 xyz = spectrum_xyz(temperature_k, mode, observer, 1);
  return mode == BlackbodyMode::StefanBoltzmann ? stefan_boltzmann_xyz(xyz, temperature_k) : xyz;
}

glm::dvec2 blackbody_xy(double temperature_k, int observer) {
  return chromaticity_xy(blackbody_xyz(temperature_k, BlackbodyMode::Peak, observer));
}

glm::dvec3 adapt_blackbody_xyz(const glm::dvec3& xyz, double adapt_to_k, int observer) {
  return von_kries_bradford(xyz, adaptation_white(adapt_to_k, observer), d65_white_xyz());
}

glm::dvec3 blackbody_rgb(double temperature_k, BlackbodyMode mode, int observer, std::optional<double> adapt_to_k) {
  glm::dvec3 xyz = blackbody_xyz(temperature_k, mode, observer);
  if (adapt_to_k) xyz = adapt_blackbody_xyz(xyz, *adapt_to_k, observer);
  return mode_rgb(xyz, mode);
}

glm::dvec3 blackbody_rgb_5nm(double temperature_k, BlackbodyMode mode, int observer,
                             std::optional<double> adapt_to_k) {
  glm::dvec3 xyz = spectrum_xyz(temperature_k, mode, observer, 5);
  if (mode == BlackbodyMode::StefanBoltzmann) xyz = stefan_boltzmann_xyz(xyz, temperature_k);
  if (adapt_to_k) {
    // The white costs a 1 nm sum; callers use one white for millions of calls.
    thread_local double cached_k = -1.0;
    thread_local int cached_observer = 0;
    thread_local glm::dvec3 cached_white(0.0);
    if (cached_k != *adapt_to_k || cached_observer != observer) {
      cached_white = adaptation_white(*adapt_to_k, observer);
      cached_k = *adapt_to_k;
      cached_observer = observer;
    }
    xyz = von_kries_bradford(xyz, cached_white, d65_white_xyz());
  }
  return mode_rgb(xyz, mode);
}

const char* to_string(BlackbodyMode mode) {
  switch (mode) {
    case BlackbodyMode::Seed: return "chromaticity";
    case BlackbodyMode::StefanBoltzmann: return "stefan_boltzmann";
    case BlackbodyMode::Peak: return "peak";
    case BlackbodyMode::Physical: return "physical";
  }
  return "?";
}

std::optional<BlackbodyMode> parse_blackbody_mode(std::string_view name) {
  if (name == "chromaticity" || name == "seed") return BlackbodyMode::Seed;  // "seed": the old name
  if (name == "stefan_boltzmann") return BlackbodyMode::StefanBoltzmann;
  if (name == "peak") return BlackbodyMode::Peak;
  if (name == "physical") return BlackbodyMode::Physical;
  return std::nullopt;
}

}  // namespace pyrolume::color
