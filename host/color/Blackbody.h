#pragma once
// Blackbody emission: Planck's law -> CIE XYZ -> linear sRGB (docs/blackbody.md).
#include <filesystem>
#include <functional>
#include <iosfwd>
#include <optional>
#include <string>
#include <string_view>

#include <glm/glm.hpp>

#include "color/BlackbodyMode.h"

namespace pyrolume::color {

// Linear sRGB radiance of a blackbody at temperature_k in the given mode, for the
// CIE 1931 2° (observer 2) or CIE 1964 10° (observer 10) observer, optionally
// chromatically adapted to a blackbody white at adapt_to_k. Finite and >= 0 for
// every input (T <= 0, NaN, 1e6 ...).
//   Seed:     Wien-peak-normalised spectrum -> XYZ -> sRGB, negatives clamped,
//             scaled so the largest channel is 1 (0 where there is no light).
//   Peak:     pbrt-v4's convention: XYZ = sum B(l,T)/B(l_max,T) · cmf(l) · 1 nm over
//             360..830 nm (not divided by the integral of ybar), then sRGB,
//             negatives clamped. 6500 K gives about (98.8, 93.1, 98.0).
//   Physical: XYZ = sum B(l,T) [W·sr⁻¹·m⁻²·nm⁻¹] · cmf(l) · 1 nm, so Y is the
//             ybar-weighted radiance in W·sr⁻¹·m⁻² (× 683 lm/W = cd/m²), then sRGB.
//   StefanBoltzmann (the scene default): the spectrum's chromaticity with
//             luminance Y = (T / kStefanBoltzmannReferenceK)⁴, the growth of the
//             total radiance σT⁴/π (what Cycles' Blackbody Intensity does), then
//             sRGB, negatives clamped.
// Throws std::invalid_argument for an observer other than 2 or 10, and for an
// adapt_to_k that is not a temperature with visible light (NaN, <= 0, below ~23 K).
// The temperature at which the Stefan–Boltzmann mode has luminance 1: chosen
// so that a 1000–2500 K fire sits at a sensible exposure under the default
// film settings (docs/blackbody.md "Stefan–Boltzmann").
inline constexpr double kStefanBoltzmannReferenceK = 1500.0;

glm::dvec3 blackbody_rgb(double temperature_k, BlackbodyMode mode, int observer = 2,
                         std::optional<double> adapt_to_k = std::nullopt);

// blackbody_rgb with the CMF sum taken every 5 nm (360, 365, ..., 830 nm) and
// dλ = 5 nm: the CIE's own 5 nm tables are exactly every 5th row of the 1 nm
// tables (CIE 15:2004 §7.1, a published subsampling), so this is the same sum at
// the CIE's coarser standard step, ~5x cheaper. It still evaluates Planck's law
// directly (no LUT), so the CPU reference can be used to check the GPU's
// BlackbodyLut. Difference to blackbody_rgb: below 1e-3 × max(r,g,b) for every
// channel and mode over 500–40 000 K (measured: <= 4e-4 at 500 K in peak mode,
// <= 3e-5 above 1000 K; cpu_vdb_test checks 1e-3), far below Monte Carlo noise in
// any test. The adaptation white (adapt_to_k) is the 1 nm one, as in
// blackbody_rgb, cached per thread for the last (adapt_to_k, observer).
glm::dvec3 blackbody_rgb_5nm(double temperature_k, BlackbodyMode mode, int observer = 2,
                             std::optional<double> adapt_to_k = std::nullopt);

// CIE XYZ of the mode's spectrum (Seed and Peak share the Wien-peak-normalised
// spectrum), before adaptation. Zero for T <= 0, NaN, Inf, or no visible light.
glm::dvec3 blackbody_xyz(double temperature_k, BlackbodyMode mode, int observer = 2);

// CIE xy chromaticity of a blackbody at temperature_k for the observer (the
// Planckian locus); NaN where the spectrum is zero over 360..830 nm.
glm::dvec2 blackbody_xy(double temperature_k, int observer = 2);

// Applies the von Kries/Bradford adaptation that maps the white of a blackbody at
// adapt_to_k (same observer) to D65 (Nguyen et al. 2002; Fairchild 1998).
glm::dvec3 adapt_blackbody_xyz(const glm::dvec3& xyz, double adapt_to_k, int observer = 2);

// "chromaticity" (also read as "seed", its old name) | "peak" | "physical" | "stefan_boltzmann".
const char* to_string(BlackbodyMode mode);
std::optional<BlackbodyMode> parse_blackbody_mode(std::string_view name);

// `pyrolume blackbody`: prints CSV "kelvin,x,y,r,g,b" to `out` for T = from_k,
// from_k + step_k, ... up to and including to_k (x, y: the CIE xy of the spectrum
// for the observer, `nan` where it is zero; r, g, b: the mode's linear sRGB). With
// png_path non-empty it also writes the swatch strip there (seed colours), through
// `write_output` (the CLI passes write_file_atomic, which every output goes
// through: host/color does not write files itself). Bad
// arguments (NaN/Inf, negative, from > to, step <= 0, observer not 2|10, more than
// kMaxBlackbodyRows rows, more swatches than the strip takes, an unwritable PNG
// path): one line to `err`, nothing to `out`, returns 2. Otherwise returns 0.
inline constexpr long kMaxBlackbodyRows = 1000000;
using OutputWriter =
    std::function<void(const std::filesystem::path&, const std::function<void(std::ostream&)>& write)>;
int run_blackbody_command(double from_k, double to_k, double step_k, BlackbodyMode mode, int observer,
                          const std::string& png_path, std::ostream& out, std::ostream& err,
                          const OutputWriter& write_output);

}  // namespace pyrolume::color
