#pragma once
// The denoiser, in GLSL (shaders/denoise.comp) on the Vulkan device the
// renderer uses (docs/compositing.md "Denoiser"). Two filters:
//   guided, for renders with the AOVs and their guide (the ray-marched
//     expected emission + background): the ratio estimator (Heitz et al.
//     2018) for those layers, albedo-demodulated à-trous for the surfaces,
//     guide-weighted à-trous for the rest;
//   plain: an edge-avoiding à-trous wavelet filter (Dammertz et al. 2010)
//     with SVGF's variance-guided edge-stopping (Schied et al. 2017) on the
//     beauty, its variance of the mean and optionally the albedo, normal and
//     depth AOVs.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "image/Image.h"
#include "render/vulkan/Context.h"
#include "render/vulkan/Pipeline.h"
#include "shared/denoise_types.h"

namespace pyrolume {

struct DenoiseOptions {
  // The plain filter's settings (the guided filter has its own, below).
  // À-trous iterations; iteration i spaces its 5×5 taps 2^i pixels apart, so
  // n reach ±(2^(n+1) − 2) pixels. 1 measured best on the 16-spp fires
  // without AOVs (relMSE; more iterations blur the fire's and the terrain's
  // texture, which the noisy luminance cannot tell from noise: docs/compositing.md
  // "Denoiser").
  int iterations = 1;
  // Edge-stopping parameters, SVGF's names and defaults (σ_a is ours: the
  // albedo, which SVGF demodulates instead).
  float sigma_l = 1.5f;    // luminance, in standard deviations of the noise of l_p − l_q
  float sigma_n = 128.0f;  // normal: exponent of max(0, n_p·n_q)
  float sigma_z = 1.0f;    // depth, in units of the depth's gradient times the tap distance
  float sigma_a = 0.2f;    // albedo: Euclidean distance in RGB
  // Use the albedo/normal/depth AOVs when the image has them. Off: with
  // these weights they measured worse on the 16-spp fires (relMSE 0.00245
  // against 0.00181 on fire_ground, 0.00133 against 0.00109 on
  // terrain_explosion; docs/compositing.md "Denoiser"), as they stop the
  // filter where the beauty needs no stopping.
  bool use_features = false;
  // With the AOVs and their guide (renders with --aovs): the guided filter,
  // whatever the settings above (docs/compositing.md "Denoiser").
  bool use_guide = true;
  int device_index = -1;     // denoise(): the Vulkan device (-1: as the renderer chooses)
};

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

// A Denoiser on a context of its own, opened at the first run() on that
// run's options.device_index and kept: a frame sequence (render --denoise
// --frames) starts the Vulkan device and builds the pipeline once, not once
// per frame.
class DenoiserSession {
 public:
  Image run(const Image& noisy, const DenoiseOptions& options, const std::string& name = "image");
  // Opens the device (as run() would, on `device_index`) and checks that a
  // width×height image fits it (Denoiser::check_size): render --denoise calls
  // it before rendering.
  void check_size(int width, int height, int device_index, const std::string& name);

 private:
  Denoiser& open(int device_index);

  std::unique_ptr<vk::Context> ctx_;
  std::unique_ptr<Denoiser> denoiser_;
};

// One image, on a DenoiserSession of its own.
Image denoise(const Image& noisy, const DenoiseOptions& options = {}, const std::string& name = "image");

// Which filter `options` runs on `noisy`: the guided one when use_guide and
// the image has every AOV and the guide; else the plain à-trous, with the
// albedo, normal and depth when use_features and the image has them.
bool denoise_uses_guide(const Image& noisy, const DenoiseOptions& options);
bool denoise_uses_features(const Image& noisy, const DenoiseOptions& options);
// What that filter reads, in words, for the CLI's summary line.
std::string denoise_inputs(const Image& noisy, const DenoiseOptions& options);

}  // namespace pyrolume
