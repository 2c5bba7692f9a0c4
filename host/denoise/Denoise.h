#pragma once
// The denoiser as the command line sees it: options, a session that keeps
// one device for a sequence of frames, and which filter an image gets. No
// Vulkan type appears here, so host/cli compiles without the Vulkan headers
// (docs/architecture.md). The filters themselves are denoise/Denoiser.h
// (docs/compositing.md "Denoiser").
#include <memory>
#include <string>

#include "image/Image.h"

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

// A Denoiser on a context of its own, opened at the first run() on that
// run's options.device_index and kept: a frame sequence (render --denoise
// --frames) starts the Vulkan device and builds the pipeline once, not once
// per frame.
class DenoiserSession {
 public:
  DenoiserSession();
  ~DenoiserSession();
  DenoiserSession(const DenoiserSession&) = delete;
  DenoiserSession& operator=(const DenoiserSession&) = delete;

  Image run(const Image& noisy, const DenoiseOptions& options, const std::string& name = "image");
  // Opens the device (as run() would, on `device_index`) and checks that a
  // width×height image fits it (Denoiser::check_size): render --denoise calls
  // it before rendering.
  void check_size(int width, int height, int device_index, const std::string& name);

 private:
  struct Device;  // the Vulkan context and its Denoiser (denoise/Denoiser.h)
  std::unique_ptr<Device> device_;
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
