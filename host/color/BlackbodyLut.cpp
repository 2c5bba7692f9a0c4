#include "color/BlackbodyLut.h"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "color/Blackbody.h"
#include "color/ColorSpace.h"

namespace pyrolume::color {

BlackbodyLut::BlackbodyLut(BlackbodyMode mode, int observer, std::optional<double> adapt_to_k, uint32_t size,
                           double t_min_k, double t_max_k)
    : mode_(mode), observer_(observer), adapt_to_k_(adapt_to_k) {
  if (size < 2) throw std::invalid_argument("BlackbodyLut: size must be >= 2, got " + std::to_string(size));
  if (!(t_min_k > 0.0) || !(t_max_k > t_min_k) || !std::isfinite(t_max_k))
    throw std::invalid_argument("BlackbodyLut: need 0 < t_min_k < t_max_k, got " + std::to_string(t_min_k) +
                                " .. " + std::to_string(t_max_k));
  t_min_k_ = t_min_k;
  t_max_k_ = t_max_k;
  log_t_min_ = std::log(t_min_k);
  d_log_t_ = (std::log(t_max_k) - log_t_min_) / double(size - 1);

  // Texel i's centre is at s = (i + 0.5)/size, and it holds ln T_i = ln t_min + i·d,
  // so s = (ln T − ln t_min)/(d·size) + 0.5/size.
  params_.t_min_k = float(t_min_k);
  params_.t_max_k = float(t_max_k);
  params_.log_scale = float(1.0 / (d_log_t_ * size));
  params_.log_bias = float((0.5 - log_t_min_ / d_log_t_) / size);
  params_.size = size;

  rgba_.resize(size_t(size) * 4);
  for (uint32_t i = 0; i < size; ++i) {
    const glm::dvec3 rgb = blackbody_rgb(temperature_at(i), mode, observer, adapt_to_k);
    rgba_[4 * i + 0] = float(rgb.r);
    rgba_[4 * i + 1] = float(rgb.g);
    rgba_[4 * i + 2] = float(rgb.b);
    rgba_[4 * i + 3] = float(srgb_luminance(rgb));
  }
}

BlackbodyLut BlackbodyLut::baked(BlackbodyMode mode, int observer, std::optional<double> adapt_to_k) {
  // A few modes, two observers and the scenes' adaptation whites: a short
  // list, trimmed to the latest kKept in case a process sees many whites.
  constexpr size_t kKept = 16;
  static std::mutex mutex;
  static std::vector<BlackbodyLut> luts;
  {
    std::lock_guard lock(mutex);
    for (const BlackbodyLut& lut : luts)
      if (lut.mode() == mode && lut.observer() == observer && lut.adapt_to_k() == adapt_to_k) return lut;
  }
  BlackbodyLut made(mode, observer, adapt_to_k);  // throws before anything is kept
  std::lock_guard lock(mutex);
  if (luts.size() >= kKept) luts.erase(luts.begin());
  luts.push_back(made);
  return made;
}

double BlackbodyLut::temperature_at(uint32_t i) const {
  if (i == 0) return t_min_k_;
  // The last texel sits exactly on t_max so that clamping above it is exact.
  if (i + 1 == params_.size) return t_max_k_;
  return std::exp(log_t_min_ + i * d_log_t_);
}

glm::dvec3 BlackbodyLut::lookup(double temperature_k) const {
  if (!(temperature_k >= t_min_k_)) return glm::dvec3(0.0);  // also NaN
  const double N = params_.size;
  // Unnormalised texel coordinate minus the half-texel offset, as in the Vulkan
  // spec's linear filtering (u = s·N − 0.5, i0 = floor(u), alpha = frac(u)),
  // clamp-to-edge.
  const double T = std::min(temperature_k, t_max_k_);
  const double u = std::clamp((std::log(T) - log_t_min_) / d_log_t_, 0.0, N - 1.0);
  const uint32_t i0 = std::min(uint32_t(u), params_.size - 2);
  const double a = u - i0;
  const float* t0 = &rgba_[4 * size_t(i0)];
  const float* t1 = t0 + 4;
  return glm::dvec3((1.0 - a) * t0[0] + a * t1[0], (1.0 - a) * t0[1] + a * t1[1], (1.0 - a) * t0[2] + a * t1[2]);
}

}  // namespace pyrolume::color
