#pragma once
// The denoiser's filters, in GLSL (shaders/denoise.comp) on a Vulkan device
// (docs/compositing.md "Denoiser"; denoise/Denoise.h is what the command
// line sees). Two filters:
//   guided, for renders with the AOVs and their guide (the ray-marched
//     expected emission + background): the ratio estimator (Heitz et al.
//     2018) for those layers, albedo-demodulated à-trous for the surfaces,
//     guide-weighted à-trous for the rest;
//   plain: an edge-avoiding à-trous wavelet filter (Dammertz et al. 2010)
//     with SVGF's variance-guided edge-stopping (Schied et al. 2017) on the
//     beauty, its variance of the mean and optionally the albedo, normal and
//     depth AOVs.
#include <cstdint>
#include <string>
#include <vector>

#include "denoise/Denoise.h"
#include "image/Image.h"
#include "render/vulkan/Context.h"
#include "render/vulkan/Pipeline.h"
#include "shared/denoise_types.h"

namespace pyrolume {

// Runs the filter on one device; holds its pipeline, so a sequence of frames
// (or render --denoise, on the renderer's own context) reuses it.
class Denoiser {
 public:
  explicit Denoiser(vk::Context& ctx);
  // `noisy` must have variance (render --variance); the result has the
  // denoised RGB and alpha (filtered with the same weights: premultiplied RGB
  // and A stay consistent), the noisy image's spp and transparency, and no
  // variance or AOVs. Non-finite input values are read as 0. Radiance is
  // filtered divided by a power of two that keeps single precision finite
  // (any finite input works), and the result is checked finite: one that is
  // not is an InputError naming `name`, never written. An image too large
  // for the device's storage buffers is an InputError naming `name`.
  Image run(const Image& noisy, const DenoiseOptions& options, const std::string& name = "image");

  // Throws that InputError for a width×height image too large for this
  // device's storage buffers (every buffer of the filter holds at most a vec4
  // per pixel): known from the film size alone, so a render can be refused
  // before it is spent.
  void check_size(int width, int height, const std::string& name) const;

 private:
  // The guided filter's settings (measured: docs/benchmarks.md "Denoiser").
  static constexpr float kMinAlbedo = 0.02f;        // demodulation: albedo floor
  static constexpr float kRatioSigmaPx = 4.5f;      // the ratio estimator's Gaussian
  static constexpr int kSurfaceIterations = 3, kRestIterations = 2;
  static constexpr float kGuidedSigmaL = 6.0f, kGuidedSigmaN = 64.0f, kGuidedSigmaZ = 0.05f, kGuidedSigmaA = 0.1f;
  static constexpr float kGuideSigma = 0.2f, kGuideFloor = 0.02f, kGuideAlphaSigma = 0.2f;

  struct Features {  // per pixel; empty: not used
    std::vector<gpu::vec4> normal_depth, albedo_dz, guide;
  };
  struct Pass {
    int iterations = 1;
    uint32_t flags = 0;
    gpu::vec4 sigmas{0.0f}, guide_sigmas{0.0f};
    bool blur = false;  // a separable Gaussian (σ = guide_sigmas.w) instead of à-trous
  };
  std::vector<gpu::vec4> filter(int width, int height, const std::vector<gpu::vec4>& color,
                                const std::vector<float>& var, const Features& f, const Pass& pass);
  // `inv`: the radiance scale run() filters at (a power of two, Denoiser.cpp radiance_scale).
  std::vector<gpu::vec4> run_guided(const Image& noisy, const std::vector<float>& var, const Features& f, float inv);

  vk::Context& ctx_;
  vk::ComputePipeline pipeline_;
};

}  // namespace pyrolume
