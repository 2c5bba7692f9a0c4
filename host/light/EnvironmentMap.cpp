#include "light/EnvironmentMap.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "color/ColorSpace.h"
#include "color/EmissionModel.h"
#include "image/ImageIo.h"
#include "light/PiecewiseConstant.h"
#include "util/Error.h"
#include "util/Math.h"

namespace pyrolume {

namespace {


int wrap(int i, int n) {
  i %= n;
  return i < 0 ? i + n : i;
}

}  // namespace

EnvironmentMap EnvironmentMap::load(const std::filesystem::path& file, double scale, double rotation_deg,
                                    bool zenith_y) {
  std::error_code ec;
  if (!std::filesystem::exists(file, ec))
    throw input_error(file.string(), "", "environment map not found");
  Image img = read_image(file);  // names the file in its InputError
  if (img.width < 1 || img.height < 1) throw input_error(file.string(), "", "environment map has no pixels");
  // NaN and Inf texels are refused (from_image would read them as no light,
  // silently); radiance beyond kMaxEmittedRadiance would overflow the
  // renderers' float sums (docs/robustness.md "Finite by construction").
  size_t nonfinite = 0;
  float brightest = 0.0f;
  for (float v : img.rgb) {
    if (!std::isfinite(v)) ++nonfinite;
    else brightest = std::max(brightest, v);
  }
  if (nonfinite > 0)
    throw input_error(file.string(), "",
                      std::to_string(nonfinite) + " texel values are NaN or infinite; an environment map must be finite");
  if (double(brightest) * scale > double(kMaxEmittedRadiance)) {
    char why[160];
    std::snprintf(why, sizeof why, "texels up to %.3g times environment.scale %.3g exceed %.3g, the most a render "
                  "can sum in float without overflowing", double(brightest), scale, double(kMaxEmittedRadiance));
    throw input_error(file.string(), "", why);
  }
  try {
    return from_image(img, scale, rotation_deg, zenith_y, file.string());
  } catch (const std::invalid_argument& e) {
    throw input_error(file.string(), "", e.what());
  }
}

EnvironmentMap EnvironmentMap::from_image(const Image& img, double scale, double rotation_deg, bool zenith_y,
                                          const std::string& name) {
  if (img.width < 1 || img.height < 1 || img.rgb.size() != img.pixel_count() * 3)
    throw std::invalid_argument("environment map: empty image");
  if (!std::isfinite(scale) || scale < 0.0) throw std::invalid_argument("environment map: scale must be finite and >= 0");
  if (!std::isfinite(rotation_deg)) throw std::invalid_argument("environment map: rotation_deg must be finite");
  EnvironmentMap e;
  e.name_ = name;
  e.width_ = img.width;
  e.height_ = img.height;
  e.scale_ = scale;
  e.rotation_deg_ = rotation_deg;
  e.zenith_y_ = zenith_y;
  const double r = rotation_deg * kPi / 180.0;
  e.cos_rot_ = std::cos(r);
  e.sin_rot_ = std::sin(r);
  e.rgb_ = img.rgb;
  for (float& v : e.rgb_)
    if (!(v >= 0.0f) || !std::isfinite(v)) {  // NaN, Inf, negative: no light
      v = 0.0f;
      ++e.sanitized_;
    }
  e.build_distribution();
  return e;
}

// The sampling weight of texel (i, j) is the integral of the bilinear
// radiance's luminance over the texel in (u, v), times the solid angle factor
// of its row:
//   w_ij = (K ∗ Y)_ij · (cos θ_j − cos θ_{j+1}),  K = [1 6 1]/8 ⊗ [1 6 1]/8.
// Over one texel a linear interpolation between centres weighs the texel itself
// 6/8 and each neighbour 1/8, so K ∗ Y is exactly the texel-mean of the
// bilinear luminance (wrapping in u, clamping in v like the lookup). All of K's
// weights are positive: wherever the bilinear radiance is > 0, one of the 3×3
// texels is > 0 and the texel's pdf is > 0 (the sampler covers the integrand).
// cos θ_j − cos θ_{j+1} = ∫ sin θ dθ over the row: the exact sin θ factor of
// dω = sin θ dθ dφ for that band.
void EnvironmentMap::build_distribution() {
  const int W = width_, H = height_;
  std::vector<double> Y(size_t(W) * H);
  for (int j = 0; j < H; ++j)
    for (int i = 0; i < W; ++i) Y[size_t(j) * W + i] = color::srgb_luminance(texel(i, j));
  // Separable [1 6 1]/8: along u (wrap), then along v (clamp).
  std::vector<double> Yu(Y.size()), w(Y.size());
  for (int j = 0; j < H; ++j)
    for (int i = 0; i < W; ++i) {
      const double* row = &Y[size_t(j) * W];
      Yu[size_t(j) * W + i] = (row[wrap(i - 1, W)] + 6.0 * row[i] + row[wrap(i + 1, W)]) / 8.0;
    }
  for (int j = 0; j < H; ++j) {
    const int jm = std::max(j - 1, 0), jp = std::min(j + 1, H - 1);
    const double band = std::cos(kPi * j / H) - std::cos(kPi * (j + 1) / H);
    for (int i = 0; i < W; ++i)
      w[size_t(j) * W + i] =
          band * (Yu[size_t(jm) * W + i] + 6.0 * Yu[size_t(j) * W + i] + Yu[size_t(jp) * W + i]) / 8.0;
  }

  double total = 0.0;
  std::vector<double> row_sum(H, 0.0);
  for (int j = 0; j < H; ++j) {
    for (int i = 0; i < W; ++i) row_sum[j] += w[size_t(j) * W + i];
    total += row_sum[j];
  }
  total_weight_ = scale_ > 0.0 ? total : 0.0;
  // Σ_ij meanY_ij · (2π/W)(cos θ_j − cos θ_{j+1}) ≈ ∫ Y dω.
  power_ = scale_ * total * 2.0 * kPi / W;

  pdf_uv_.assign(size_t(W) * H, 0.0f);
  cdf_.assign(size_t(H + 1) + size_t(H) * (W + 1), 0.0f);
  if (!has_distribution()) return;
  build_cdf(row_sum.data(), H, &cdf_[0]);
  for (int j = 0; j < H; ++j) build_cdf(&w[size_t(j) * W], W, &cdf_[size_t(H + 1) + size_t(j) * (W + 1)]);
  // p_uv from the stored CDFs (not from w): exactly the density the sampler draws.
  for (int j = 0; j < H; ++j) {
    const double pj = bin_probability(&cdf_[0], j);
    const float* row = &cdf_[size_t(H + 1) + size_t(j) * (W + 1)];
    for (int i = 0; i < W; ++i)
      pdf_uv_[size_t(j) * W + i] = row_sum[j] > 0.0 ? float(double(W) * H * pj * bin_probability(row, i)) : 0.0f;
  }
}

glm::dvec2 EnvironmentMap::direction_to_uv(const glm::dvec3& world_dir) const {
  // Into the map's frame: Rz(−rotation)·Rx(90°)·dir for a Y-up scene, Rz(−rotation)·dir for a Z-up one.
  const glm::dvec3 dir = zenith_y_ ? glm::dvec3(world_dir.x, -world_dir.z, world_dir.y) : world_dir;
  const double x = cos_rot_ * dir.x + sin_rot_ * dir.y;
  const double y = -sin_rot_ * dir.x + cos_rot_ * dir.y;
  double u = 0.5 - std::atan2(y, x) / (2.0 * kPi);
  if (u >= 1.0) u -= 1.0;
  if (u < 0.0) u += 1.0;
  // θ from atan2, not acos(z/|dir|): acos loses all precision near the poles
  // (1 − cos θ ≈ θ²/2 falls below double epsilon), and pdf() divides by sin θ.
  return {u, std::atan2(std::hypot(x, y), dir.z) / kPi};
}

glm::dvec3 EnvironmentMap::uv_to_direction(const glm::dvec2& uv) const {
  const double theta = kPi * uv.y, phi = kPi - 2.0 * kPi * uv.x;
  const double s = std::sin(theta);
  const double x = s * std::cos(phi), y = s * std::sin(phi);
  const glm::dvec3 d(cos_rot_ * x - sin_rot_ * y, sin_rot_ * x + cos_rot_ * y, std::cos(theta));
  return zenith_y_ ? glm::dvec3(d.x, d.z, -d.y) : d;  // Rx(−90°) back to a Y-up world
}

glm::dvec3 EnvironmentMap::lookup_uv(const glm::dvec2& uv) const {
  if (width_ == 0) return glm::dvec3(0.0);
  const double x = uv.x * width_ - 0.5, y = uv.y * height_ - 0.5;
  const double fx0 = std::floor(x), fy0 = std::floor(y);
  const double fx = x - fx0, fy = y - fy0;
  const int i0 = wrap(int(fx0), width_), i1 = wrap(int(fx0) + 1, width_);
  const int j0 = std::clamp(int(fy0), 0, height_ - 1), j1 = std::clamp(int(fy0) + 1, 0, height_ - 1);
  return (1.0 - fy) * ((1.0 - fx) * texel(i0, j0) + fx * texel(i1, j0)) +
         fy * ((1.0 - fx) * texel(i0, j1) + fx * texel(i1, j1));
}

glm::dvec3 EnvironmentMap::radiance(const glm::dvec3& dir) const {
  return scale_ * lookup_uv(direction_to_uv(dir));
}

double EnvironmentMap::pdf_uv(const glm::dvec2& uv) const {
  if (!has_distribution()) return 0.0;
  const int i = std::clamp(int(uv.x * width_), 0, width_ - 1);
  const int j = std::clamp(int(uv.y * height_), 0, height_ - 1);
  return pdf_uv_texel(i, j);
}

double EnvironmentMap::pdf(const glm::dvec3& dir) const {
  if (!has_distribution()) return 0.0;
  const glm::dvec2 uv = direction_to_uv(dir);
  const double sin_theta = std::sin(kPi * uv.y);
  if (!(sin_theta > 0.0)) return 0.0;
  return pdf_uv(uv) / (2.0 * kPi * kPi * sin_theta);
}

EnvSample EnvironmentMap::sample(const glm::dvec2& u2) const {
  EnvSample s;
  if (!has_distribution()) return s;
  const int W = width_, H = height_;
  double dv = 0.0, du = 0.0;
  const int j = sample_cdf(&cdf_[0], H, u2.y, &dv);
  const int i = sample_cdf(&cdf_[size_t(H + 1) + size_t(j) * (W + 1)], W, u2.x, &du);
  const glm::dvec2 uv((i + du) / W, (j + dv) / H);
  const double sin_theta = std::sin(kPi * uv.y);
  if (!(sin_theta > 0.0)) return s;  // a pole: zero measure
  s.dir = uv_to_direction(uv);
  s.pdf = pdf_uv_texel(i, j) / (2.0 * kPi * kPi * sin_theta);
  s.radiance = scale_ * lookup_uv(uv);
  return s;
}

}  // namespace pyrolume
