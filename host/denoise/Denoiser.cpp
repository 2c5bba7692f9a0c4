#include "denoise/Denoiser.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include "render/vulkan/Memory.h"
#include "render/vulkan/Spirv.h"
#include "shared/denoise_types.h"
#include "util/Error.h"

namespace pyrolume {

namespace {

using gpu::vec4;

float finite_or_0(float v) { return std::isfinite(v) ? v : 0.0f; }

// Pixel i's alpha, or 1 for an image without one.
float alpha_or_1(const Image& img, size_t i) { return img.has_alpha() ? finite_or_0(img.alpha[i]) : 1.0f; }

// Variance of the mean of the luminance l = Σ w_c·c from the per-channel
// variances. The channels' covariances are not stored; they are nearly
// perfectly correlated in blackbody light, so take the bound of full
// correlation, Var(l) ≤ (Σ w_c σ_c)², which can only make the filter stop at
// fewer edges, never more.
// In double, then scaled by inv_scale² (radiance_scale): the square of a
// sum of standard deviations near 1e19 would overflow a float.
float luminance_variance(const float* var, double inv_scale) {
  const double w[3] = {0.2126, 0.7152, 0.0722};
  double s = 0.0;
  for (int c = 0; c < 3; ++c) s += w[c] * std::sqrt(std::max(double(finite_or_0(var[c])), 0.0));
  return float(s * s * inv_scale * inv_scale);
}

// The filter squares radiance differences and sums weighted radiance over
// 25 taps (and the guided one divides by albedos down to 0.02) in single
// precision: past ~1e19 that overflows to infinity and then to NaN (∞ − ∞,
// ∞/∞), which spread through every later pass. So it filters radiance
// divided by a power of two that brings the image's largest finite radiance,
// and the square root of its largest variance, to at most kMaxFilteredRadiance,
// and multiplies the result back. A power of two divides exactly, and an image
// already in range (every render of a scene within the scene format's limits)
// is filtered exactly as before.
constexpr double kMaxFilteredRadiance = 0x1p48;  // ~2.8e14: squares ×2500 (albedo floor) ×25 taps stay below 3.4e38

double largest_finite_abs(const std::vector<float>& v, double m = 0.0) {
  for (float x : v)
    if (std::isfinite(x)) m = std::max(m, double(std::abs(x)));
  return m;
}

// The power of two the radiance is divided by (1 for an image in range).
double radiance_scale(const Image& img, bool guided) {
  double m = std::sqrt(largest_finite_abs(img.variance));
  m = largest_finite_abs(img.rgb, m);
  if (guided)
    for (const std::vector<float>* layer : {&img.aovs.emission, &img.aovs.scatter, &img.aovs.surface,
                                            &img.aovs.background, &img.aovs.guide})
      m = largest_finite_abs(*layer, m);
  if (m <= kMaxFilteredRadiance) return 1.0;
  return std::ldexp(1.0, int(std::ceil(std::log2(m / kMaxFilteredRadiance))));
}

// |∇depth| at each pixel: the larger one-sided difference towards a neighbour
// on the same surface would need the surfaces; the larger central difference
// over x and y is SVGF's fwidth(z), which the depth weight scales by the tap's
// distance.
std::vector<float> depth_gradient(const Image& img) {
  const int w = img.width, h = img.height;
  const std::vector<float>& z = img.aovs.depth;
  std::vector<float> g(img.pixel_count(), 0.0f);
  auto at = [&](int x, int y) { return finite_or_0(z[size_t(std::clamp(y, 0, h - 1)) * w + std::clamp(x, 0, w - 1)]); };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      g[size_t(y) * w + x] = 0.5f * std::max(std::abs(at(x + 1, y) - at(x - 1, y)), std::abs(at(x, y + 1) - at(x, y - 1)));
  return g;
}

}  // namespace

Denoiser::Denoiser(vk::Context& ctx)
    : ctx_(ctx),
      pipeline_(ctx, vk::load_spirv("denoise.comp"),
                {{gpu::DENOISE_BINDING_COLOR_IN, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                 {gpu::DENOISE_BINDING_VAR_IN, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                 {gpu::DENOISE_BINDING_COLOR_OUT, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                 {gpu::DENOISE_BINDING_VAR_OUT, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                 {gpu::DENOISE_BINDING_NORMAL_DEPTH, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                 {gpu::DENOISE_BINDING_ALBEDO_DZ, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                 {gpu::DENOISE_BINDING_VAR_BLURRED, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                 {gpu::DENOISE_BINDING_GUIDE, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}},
                sizeof(gpu::DenoiseConstants), {}, "denoise") {}

std::vector<vec4> Denoiser::filter(int width, int height, const std::vector<vec4>& color, const std::vector<float>& var,
                                   const Features& f, const Pass& pass) {
  const size_t n = size_t(width) * size_t(height);
  const VkBufferUsageFlags usage =
      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
  const auto kind = vk::MemoryKind::DeviceLocal;
  vk::Buffer color_buf[2] = {vk::Buffer(ctx_, n * sizeof(vec4), usage, kind, "denoise colour 0"),
                             vk::Buffer(ctx_, n * sizeof(vec4), usage, kind, "denoise colour 1")};
  vk::Buffer var_buf[2] = {vk::Buffer(ctx_, n * sizeof(float), usage, kind, "denoise variance 0"),
                           vk::Buffer(ctx_, n * sizeof(float), usage, kind, "denoise variance 1")};
  vk::Buffer var_blurred(ctx_, n * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, kind, "denoise blurred variance");
  const vec4 none(0.0f);
  auto upload = [&](const std::vector<vec4>& v, const char* what) {
    vk::Buffer b(ctx_, std::max<size_t>(v.size(), 1) * sizeof(vec4), usage, kind, what);
    b.upload(ctx_, v.empty() ? &none : v.data(), std::max<size_t>(v.size(), 1) * sizeof(vec4));
    return b;
  };
  vk::Buffer nz_buf = upload(f.normal_depth, "denoise normal, depth");
  vk::Buffer alb_buf = upload(f.albedo_dz, "denoise albedo, depth gradient");
  vk::Buffer guide_buf = upload(f.guide, "denoise guide");
  color_buf[0].upload(ctx_, color.data(), n * sizeof(vec4));
  var_buf[0].upload(ctx_, var.data(), n * sizeof(float));

  // Two descriptor sets, ping-pong: set k reads buffers k and writes 1 − k.
  vk::DescriptorSet sets[2] = {vk::DescriptorSet(ctx_, pipeline_, "denoise 0 -> 1"),
                               vk::DescriptorSet(ctx_, pipeline_, "denoise 1 -> 0")};
  for (int k = 0; k < 2; ++k) {
    sets[k].write_buffer(gpu::DENOISE_BINDING_COLOR_IN, color_buf[k]);
    sets[k].write_buffer(gpu::DENOISE_BINDING_VAR_IN, var_buf[k]);
    sets[k].write_buffer(gpu::DENOISE_BINDING_COLOR_OUT, color_buf[1 - k]);
    sets[k].write_buffer(gpu::DENOISE_BINDING_VAR_OUT, var_buf[1 - k]);
    sets[k].write_buffer(gpu::DENOISE_BINDING_NORMAL_DEPTH, nz_buf);
    sets[k].write_buffer(gpu::DENOISE_BINDING_ALBEDO_DZ, alb_buf);
    sets[k].write_buffer(gpu::DENOISE_BINDING_VAR_BLURRED, var_blurred);
    sets[k].write_buffer(gpu::DENOISE_BINDING_GUIDE, guide_buf);
  }
  const uint32_t groups_x = (uint32_t(width) + gpu::DENOISE_WORKGROUP_SIZE - 1) / gpu::DENOISE_WORKGROUP_SIZE;
  const uint32_t groups_y = (uint32_t(height) + gpu::DENOISE_WORKGROUP_SIZE - 1) / gpu::DENOISE_WORKGROUP_SIZE;
  // A blur is two passes (x, then y); an à-trous filter `iterations`, each
  // after its variance prefilter. Each pass's output is the next one's input.
  const int passes = pass.blur ? 2 : pass.iterations;
  vk::submit_and_wait(ctx_, [&](VkCommandBuffer cmd) {
    for (int i = 0; i < passes; ++i) {
      pipeline_.bind(cmd, sets[i % 2].set());
      const std::vector<uint32_t> stages =
          pass.blur ? std::vector<uint32_t>{gpu::DENOISE_PASS_BLUR} : std::vector<uint32_t>{gpu::DENOISE_PASS_PREFILTER, 0u};
      for (uint32_t stage : stages) {
        gpu::DenoiseConstants dc{};
        const uint32_t step = pass.blur ? uint32_t(i + 1) : (1u << i);
        dc.size_step_flags = gpu::uvec4(uint32_t(width), uint32_t(height), step, pass.flags | stage);
        dc.sigmas = pass.sigmas;
        dc.guide_sigmas = pass.guide_sigmas;
        pipeline_.push(cmd, dc);
        vkCmdDispatch(cmd, groups_x, groups_y, 1);
        vk::memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                           VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_SHADER_READ_BIT,
                           VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                           VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT);
      }
    }
  });
  std::vector<vec4> out(n);
  color_buf[passes % 2].download(ctx_, out.data(), n * sizeof(vec4));
  return out;
}

void Denoiser::check_size(int width, int height, const std::string& name) const {
  const uint64_t bytes = uint64_t(width) * uint64_t(height) * sizeof(vec4);
  const VkDeviceSize range = std::min<VkDeviceSize>(ctx_.properties().limits.maxStorageBufferRange, ctx_.max_allocation_size());
  if (bytes > range)
    throw input_error(name, "", std::to_string(width) + " x " + std::to_string(height) +
                                    " pixels are too many to denoise on this device (" + std::to_string(bytes) +
                                    " bytes per buffer exceed its storage-buffer range of " + std::to_string(range) + ")");
}

Image Denoiser::run(const Image& noisy, const DenoiseOptions& options, const std::string& name) {
  const size_t n = noisy.pixel_count();
  if (noisy.width <= 0 || noisy.height <= 0 || noisy.rgb.size() != n * 3)
    throw std::logic_error("denoise: image size does not match its pixel data");
  if (!noisy.has_variance() || noisy.variance.size() != n * 3)
    throw std::logic_error("denoise: the image has no variance (render --variance)");
  if (options.iterations < 0 || options.iterations > 12) throw std::logic_error("denoise: iterations out of range");
  for (const float sigma : {options.sigma_l, options.sigma_n, options.sigma_z, options.sigma_a})
    if (!std::isfinite(sigma) || !(sigma > 0.0f)) throw std::logic_error("denoise: an edge-stopping sigma is not finite and positive");
  check_size(noisy.width, noisy.height, name);

  // The luminance variance, and the features (all three groups present, or
  // none: Aovs says all or nothing).
  const Aovs& a = noisy.aovs;
  const bool guided = denoise_uses_guide(noisy, options);
  const double scale = radiance_scale(noisy, guided);
  const float inv = float(1.0 / scale);  // a power of two: exact
  std::vector<float> var(n);
  for (size_t i = 0; i < n; ++i) var[i] = luminance_variance(&noisy.variance[i * 3], inv);
  const bool features = guided || denoise_uses_features(noisy, options);
  Features f;
  if (features) {
    const std::vector<float> dz = depth_gradient(noisy);
    f.normal_depth.resize(n);
    f.albedo_dz.resize(n);
    for (size_t i = 0; i < n; ++i) {
      f.normal_depth[i] = vec4(finite_or_0(a.normal[i * 3]), finite_or_0(a.normal[i * 3 + 1]),
                               finite_or_0(a.normal[i * 3 + 2]), finite_or_0(a.depth[i]));
      f.albedo_dz[i] = vec4(finite_or_0(a.albedo[i * 3]), finite_or_0(a.albedo[i * 3 + 1]),
                            finite_or_0(a.albedo[i * 3 + 2]), dz[i]);
    }
  }
  std::vector<vec4> color(n);
  if (!guided) {
    for (size_t i = 0; i < n; ++i)
      color[i] = vec4(finite_or_0(noisy.rgb[i * 3]) * inv, finite_or_0(noisy.rgb[i * 3 + 1]) * inv,
                      finite_or_0(noisy.rgb[i * 3 + 2]) * inv, alpha_or_1(noisy, i));
    Pass p;
    p.iterations = options.iterations;
    p.flags = features ? (gpu::DENOISE_USE_NORMAL_DEPTH | gpu::DENOISE_USE_ALBEDO) : 0u;
    p.sigmas = vec4(options.sigma_l, options.sigma_n, options.sigma_z, options.sigma_a);
    color = filter(noisy.width, noisy.height, color, var, f, p);
  } else {
    color = run_guided(noisy, var, f, inv);
  }

  Image out = make_image(noisy.width, noisy.height);
  out.spp = noisy.spp;
  out.spp_target = noisy.spp_target;
  out.transparent = noisy.transparent;
  if (noisy.has_alpha()) out.alpha.resize(n);
  size_t nonfinite = 0;
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) {
      out.rgb[i * 3 + c] = float(double(color[i][c]) * scale);
      nonfinite += !std::isfinite(out.rgb[i * 3 + c]);
    }
    if (noisy.has_alpha()) out.alpha[i] = color[i].w;
    nonfinite += !std::isfinite(color[i].w);
  }
  // Never written: an image with a value the filter could not represent.
  if (nonfinite > 0) {
    char limit[32];
    std::snprintf(limit, sizeof limit, "%.3g", scale * kMaxFilteredRadiance);
    throw input_error(name, "", "the denoised image would have " + std::to_string(nonfinite) +
                                    " non-finite values (its radiance was filtered in a range up to " + limit +
                                    "); nothing is denoised");
  }
  return out;
}

// The guided filter (docs/compositing.md "Denoiser"): the beauty in three
// parts, each filtered as its noise and structure call for, then summed.
//   emission + background: the ratio estimator E' = G·(g∗E)/(g∗G) per
//     channel, G the guide (the expected emission + background,
//     noise-free), g a Gaussian: the guide gives the structure, the noisy
//     layers only a smooth correction;
//   surface: divided by the albedo (texture is not noise), à-trous with the
//     features, multiplied back;
//   scatter and alpha: à-trous whose weight adds the guide's and the guide
//     alpha's differences to the features.
// The layers sum to the beauty (the AOVs' contract), so the three parts do.
// Each à-trous pass leaves alone the pixels its weights would not change
// much and that cost the most time: the surface pass all but surfaces, the
// scatter pass those with no scatter, alpha or guide alpha (open sky):
// together a third of the time at 1080p (docs/benchmarks.md "Denoiser").
std::vector<vec4> Denoiser::run_guided(const Image& noisy, const std::vector<float>& var, const Features& f,
                                       float inv) {
  const size_t n = noisy.pixel_count();
  const Aovs& a = noisy.aovs;
  const int w = noisy.width, h = noisy.height;
  Features g = f;
  g.guide.resize(n);
  std::vector<vec4> E(n), S(n), R(n), albedo(n);
  std::vector<float> var_s(n);
  for (size_t i = 0; i < n; ++i) {
    g.guide[i] = vec4(finite_or_0(a.guide[i * 3]) * inv, finite_or_0(a.guide[i * 3 + 1]) * inv,
                      finite_or_0(a.guide[i * 3 + 2]) * inv, finite_or_0(a.guide_alpha[i]));
    vec4 al(0.0f);
    for (int c = 0; c < 3; ++c) {
      const size_t k = i * 3 + c;
      E[i][c] = finite_or_0(a.emission[k]) * inv + finite_or_0(a.background[k]) * inv;
      al[c] = std::max(finite_or_0(a.albedo[k]), kMinAlbedo);
      S[i][c] = finite_or_0(a.surface[k]) * inv / al[c];
      R[i][c] = finite_or_0(a.scatter[k]) * inv;
    }
    albedo[i] = al;
    R[i][3] = alpha_or_1(noisy, i);
    const float l = 0.2126f * al[0] + 0.7152f * al[1] + 0.0722f * al[2];
    var_s[i] = var[i] / (l * l);
  }
  Pass blur;
  blur.blur = true;
  blur.guide_sigmas = vec4(0.0f, 0.0f, 0.0f, kRatioSigmaPx);
  const std::vector<vec4>& G = g.guide;  // its alpha is blurred along, unused
  const std::vector<vec4> bE = filter(w, h, E, var, Features{}, blur), bG = filter(w, h, G, var, Features{}, blur);

  const uint32_t feature_flags = gpu::DENOISE_USE_NORMAL_DEPTH | gpu::DENOISE_USE_ALBEDO | gpu::DENOISE_GUIDED_FEATURES;
  Pass ps;
  ps.iterations = kSurfaceIterations;
  ps.flags = feature_flags | gpu::DENOISE_ONLY_SURFACES;
  ps.sigmas = vec4(kGuidedSigmaL, kGuidedSigmaN, kGuidedSigmaZ, kGuidedSigmaA);
  const std::vector<vec4> Sf = filter(w, h, S, var_s, f, ps);

  Pass pr = ps;
  pr.iterations = kRestIterations;
  pr.flags = feature_flags | gpu::DENOISE_USE_GUIDE | gpu::DENOISE_SKIP_EMPTY;
  pr.guide_sigmas = vec4(kGuideSigma, kGuideFloor, kGuideAlphaSigma, 0.0f);
  const std::vector<vec4> Rf = filter(w, h, R, var, g, pr);

  std::vector<vec4> out(n);
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) {
      const float e = bG[i][c] > 0.0f ? G[i][c] * bE[i][c] / bG[i][c] : 0.0f;
      out[i][c] = e + Rf[i][c] + albedo[i][c] * Sf[i][c];
    }
    out[i][3] = Rf[i][3];
  }
  return out;
}

struct DenoiserSession::Device {
  explicit Device(int device_index) : ctx([&] {
    vk::Context::Options o;
    o.device_index = device_index;
    return o;
  }()), denoiser(ctx) {}
  vk::Context ctx;
  Denoiser denoiser;
};

DenoiserSession::DenoiserSession() = default;
DenoiserSession::~DenoiserSession() = default;

Image DenoiserSession::run(const Image& noisy, const DenoiseOptions& options, const std::string& name) {
  if (!device_) device_ = std::make_unique<Device>(options.device_index);
  return device_->denoiser.run(noisy, options, name);
}

void DenoiserSession::check_size(int width, int height, int device_index, const std::string& name) {
  if (!device_) device_ = std::make_unique<Device>(device_index);
  device_->denoiser.check_size(width, height, name);
}

static bool has_features(const Image& img) {
  const size_t n = img.pixel_count();
  const Aovs& a = img.aovs;
  return a.albedo.size() == n * 3 && a.normal.size() == n * 3 && a.depth.size() == n;
}

bool denoise_uses_guide(const Image& noisy, const DenoiseOptions& options) {
  const size_t n = noisy.pixel_count();
  const Aovs& a = noisy.aovs;
  return options.use_guide && has_features(noisy) && a.guide.size() == n * 3 && a.guide_alpha.size() == n &&
         a.emission.size() == n * 3 && a.surface.size() == n * 3 && a.background.size() == n * 3;
}

bool denoise_uses_features(const Image& noisy, const DenoiseOptions& options) {
  return options.use_features && has_features(noisy);
}

std::string denoise_inputs(const Image& noisy, const DenoiseOptions& options) {
  if (denoise_uses_guide(noisy, options)) return "the guided filter (light layers, features and guide)";
  const std::string reads =
      denoise_uses_features(noisy, options) ? "beauty, variance, albedo, normal, depth" : "beauty and variance";
  const bool could_guide = options.use_guide && !noisy.aovs.has_guide();
  return "the plain filter (" + reads + (could_guide ? "; renders with --aovs get the guided filter" : "") + ")";
}

Image denoise(const Image& noisy, const DenoiseOptions& options, const std::string& name) {
  return DenoiserSession().run(noisy, options, name);
}

}  // namespace pyrolume
