#include "denoise/Denoiser.h"

#include <algorithm>
#include <cmath>
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

// Variance of the mean of the luminance l = Σ w_c·c from the per-channel
// variances. The channels' covariances are not stored; they are nearly
// perfectly correlated in blackbody light, so take the bound of full
// correlation, Var(l) ≤ (Σ w_c σ_c)², which can only make the filter stop at
// fewer edges, never more.
float luminance_variance(const float* var) {
  const float w[3] = {0.2126f, 0.7152f, 0.0722f};
  float s = 0.0f;
  for (int c = 0; c < 3; ++c) s += w[c] * std::sqrt(std::max(finite_or_0(var[c]), 0.0f));
  return s * s;
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
                 {gpu::DENOISE_BINDING_VAR_BLURRED, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}},
                sizeof(gpu::DenoiseConstants), {}, "denoise") {}

Image Denoiser::run(const Image& noisy, const DenoiseOptions& options, const std::string& name) {
  const size_t n = noisy.pixel_count();
  if (noisy.width <= 0 || noisy.height <= 0 || noisy.rgb.size() != n * 3)
    throw std::logic_error("denoise: image size does not match its pixel data");
  if (!noisy.has_variance() || noisy.variance.size() != n * 3)
    throw std::logic_error("denoise: the image has no variance (render --variance)");
  if (options.iterations < 0 || options.iterations > 12) throw std::logic_error("denoise: iterations out of range");
  const VkDeviceSize range = std::min<VkDeviceSize>(ctx_.properties().limits.maxStorageBufferRange, ctx_.max_allocation_size());
  if (n * sizeof(vec4) > range)
    throw input_error(name, "", std::to_string(noisy.width) + " x " + std::to_string(noisy.height) +
                                    " pixels are too many to denoise on this device (" + std::to_string(n * sizeof(vec4)) +
                                    " bytes per buffer exceed its storage-buffer range of " + std::to_string(range) + ")");

  // Pack: colour and alpha, the luminance variance, and the features (all
  // three groups present, or none: Aovs says all or nothing).
  std::vector<vec4> color(n);
  std::vector<float> var(n);
  for (size_t i = 0; i < n; ++i) {
    color[i] = vec4(finite_or_0(noisy.rgb[i * 3]), finite_or_0(noisy.rgb[i * 3 + 1]), finite_or_0(noisy.rgb[i * 3 + 2]),
                    noisy.has_alpha() ? finite_or_0(noisy.alpha[i]) : 1.0f);
    var[i] = luminance_variance(&noisy.variance[i * 3]);
  }
  const Aovs& a = noisy.aovs;
  const bool features = options.use_features && a.albedo.size() == n * 3 && a.normal.size() == n * 3 &&
                        a.depth.size() == n;
  std::vector<vec4> nz(features ? n : 1, vec4(0.0f)), alb(features ? n : 1, vec4(0.0f));
  if (features) {
    const std::vector<float> dz = depth_gradient(noisy);
    for (size_t i = 0; i < n; ++i) {
      nz[i] = vec4(finite_or_0(a.normal[i * 3]), finite_or_0(a.normal[i * 3 + 1]), finite_or_0(a.normal[i * 3 + 2]),
                   finite_or_0(a.depth[i]));
      alb[i] = vec4(finite_or_0(a.albedo[i * 3]), finite_or_0(a.albedo[i * 3 + 1]), finite_or_0(a.albedo[i * 3 + 2]), dz[i]);
    }
  }

  const VkBufferUsageFlags usage =
      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
  const auto kind = vk::MemoryKind::DeviceLocal;
  vk::Buffer color_buf[2] = {vk::Buffer(ctx_, n * sizeof(vec4), usage, kind, "denoise colour 0"),
                             vk::Buffer(ctx_, n * sizeof(vec4), usage, kind, "denoise colour 1")};
  vk::Buffer var_buf[2] = {vk::Buffer(ctx_, n * sizeof(float), usage, kind, "denoise variance 0"),
                           vk::Buffer(ctx_, n * sizeof(float), usage, kind, "denoise variance 1")};
  vk::Buffer var_blurred(ctx_, n * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, kind, "denoise blurred variance");
  vk::Buffer nz_buf(ctx_, nz.size() * sizeof(vec4), usage, kind, "denoise normal, depth");
  vk::Buffer alb_buf(ctx_, alb.size() * sizeof(vec4), usage, kind, "denoise albedo, depth gradient");
  color_buf[0].upload(ctx_, color.data(), n * sizeof(vec4));
  var_buf[0].upload(ctx_, var.data(), n * sizeof(float));
  nz_buf.upload(ctx_, nz.data(), nz.size() * sizeof(vec4));
  alb_buf.upload(ctx_, alb.data(), alb.size() * sizeof(vec4));

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
  }
  const uint32_t flags = features ? (gpu::DENOISE_USE_NORMAL_DEPTH | gpu::DENOISE_USE_ALBEDO) : 0u;
  const uint32_t groups_x = (uint32_t(noisy.width) + gpu::DENOISE_WORKGROUP_SIZE - 1) / gpu::DENOISE_WORKGROUP_SIZE;
  const uint32_t groups_y = (uint32_t(noisy.height) + gpu::DENOISE_WORKGROUP_SIZE - 1) / gpu::DENOISE_WORKGROUP_SIZE;
  vk::submit_and_wait(ctx_, [&](VkCommandBuffer cmd) {
    for (int i = 0; i < options.iterations; ++i) {
      pipeline_.bind(cmd, sets[i % 2].set());
      // The variance prefilter, then the iteration; each pass's output is
      // the next one's input, and the next one overwrites what this one read.
      for (uint32_t pass : {gpu::DENOISE_PASS_PREFILTER, 0u}) {
        gpu::DenoiseConstants dc{};
        dc.size_step_flags = gpu::uvec4(uint32_t(noisy.width), uint32_t(noisy.height), 1u << i, flags | pass);
        dc.sigmas = vec4(options.sigma_l, options.sigma_n, options.sigma_z, options.sigma_a);
        pipeline_.push(cmd, dc);
        vkCmdDispatch(cmd, groups_x, groups_y, 1);
        vk::memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                           VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_SHADER_READ_BIT,
                           VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                           VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT);
      }
    }
  });
  color_buf[options.iterations % 2].download(ctx_, color.data(), n * sizeof(vec4));

  Image out = make_image(noisy.width, noisy.height);
  out.spp = noisy.spp;
  out.spp_target = noisy.spp_target;
  out.transparent = noisy.transparent;
  if (noisy.has_alpha()) out.alpha.resize(n);
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) out.rgb[i * 3 + c] = color[i][c];
    if (noisy.has_alpha()) out.alpha[i] = color[i].w;
  }
  return out;
}

Image DenoiserSession::run(const Image& noisy, const DenoiseOptions& options, const std::string& name) {
  if (!denoiser_) {
    vk::Context::Options o;
    o.device_index = options.device_index;
    ctx_ = std::make_unique<vk::Context>(o);
    denoiser_ = std::make_unique<Denoiser>(*ctx_);
  }
  return denoiser_->run(noisy, options, name);
}

Image denoise(const Image& noisy, const DenoiseOptions& options, const std::string& name) {
  return DenoiserSession().run(noisy, options, name);
}

}  // namespace pyrolume
