#pragma once
// The blackbody colour baked into a 1D texture for the GPU (docs/blackbody.md).
//
// Layout: `size` RGBA32F texels; texel i holds blackbody_rgb(T_i) with
//   ln T_i = ln t_min_k + i · (ln t_max_k − ln t_min_k) / (size − 1),
// i.e. uniform in ln T, first and last texel exactly at the range ends, and alpha
// = the sRGB luminance of that rgb. A shader samples it with linear filtering and
// CLAMP_TO_EDGE at s = ln(T) · log_scale + log_bias (texel centres at (i+0.5)/size).
// Range: T < t_min_k (and NaN) emits nothing -- the shader must test this, the
// sampler would clamp; T > t_max_k reads the last texel (clamped; the CPU
// reference clamps T to t_max_k the same way). Linear interpolation is within
// 1e-3 × max(r,g,b) of direct evaluation for every channel over 500–40 000 K.
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "color/BlackbodyMode.h"
#include "color/EmissionModel.h"

namespace pyrolume::color {

// Everything a shader needs to turn a temperature into a texture coordinate.
// Plain floats so it can be copied into a uniform/push-constant block.
struct BlackbodyLutParams {
  float t_min_k = 0.0f;    // below: no emission
  float t_max_k = 0.0f;    // above: clamped to the last texel
  float log_scale = 0.0f;  // s = ln(T) * log_scale + log_bias
  float log_bias = 0.0f;
  uint32_t size = 0;       // texels
};

class BlackbodyLut {
 public:
  // Defaults: ln-uniform over the emission range (color/EmissionModel.h,
  // 100 K .. 1e6 K); the size is what the 0.1 % bound needs at
  // 500 K in the peak and physical modes, where radiance changes by a factor
  // e^(hc/(lambda k T)) ≈ e^45 per unit of ln T (Wien tail).
  static constexpr double kDefaultMinK = kEmissionMinK;
  static constexpr double kDefaultMaxK = kEmissionMaxK;
  static constexpr uint32_t kDefaultSize = 8192;

  // Throws std::invalid_argument for a bad observer/adapt_to_k, size < 2 or a
  // range that is not 0 < t_min_k < t_max_k.
  BlackbodyLut(BlackbodyMode mode, int observer = 2, std::optional<double> adapt_to_k = std::nullopt,
               uint32_t size = kDefaultSize, double t_min_k = kDefaultMinK, double t_max_k = kDefaultMaxK);

  // The default-size LUT of (mode, observer, adapt_to_k), baked once per
  // process and copied out: its 8192 Planck integrals took ~0.1 CPU-s of
  // every render session (a test process or a tool opens several).
  static BlackbodyLut baked(BlackbodyMode mode, int observer = 2, std::optional<double> adapt_to_k = std::nullopt);

  // 4 floats per texel (r, g, b, luminance), `size` texels, ready for upload.
  const std::vector<float>& rgba() const { return rgba_; }
  const BlackbodyLutParams& params() const { return params_; }
  uint32_t size() const { return params_.size; }
  BlackbodyMode mode() const { return mode_; }
  int observer() const { return observer_; }
  const std::optional<double>& adapt_to_k() const { return adapt_to_k_; }

  // The temperature texel i was evaluated at.
  double temperature_at(uint32_t i) const;

  // What the GPU returns: 0 below t_min_k or for NaN, otherwise linear filtering
  // between texel centres at (i + 0.5)/size with clamp-to-edge (so T above
  // t_max_k gives the last texel). The coordinate is computed in double here;
  // the GPU computes it in float, an error below 1e-3 texel.
  glm::dvec3 lookup(double temperature_k) const;

 private:
  BlackbodyMode mode_;
  int observer_;
  std::optional<double> adapt_to_k_;
  double t_min_k_ = 0.0, t_max_k_ = 0.0;
  double log_t_min_ = 0.0, d_log_t_ = 0.0;
  BlackbodyLutParams params_;
  std::vector<float> rgba_;
};

}  // namespace pyrolume::color
