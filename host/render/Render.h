#pragma once
// What every backend returns: per-pixel sums and sums of squares of the sample
// radiance (so each render carries its own per-pixel variance), plus counters.
#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "scene/Scene.h"  // kMaxSpp

namespace pyrolume {

// A sample whose radiance exceeds this in any channel (or is NaN or infinite)
// is counted as non-finite and adds nothing: beyond it float sums of 2^24
// samples could overflow (shaders/shared/gpu_types.h MAX_SAMPLE_RADIANCE, the
// GPU's copy, asserted equal in render/vulkan/GpuScene.cpp).
inline constexpr float kMaxSampleRadiance = 1e15f;

// Camera samples of a width×height render at spp samples per pixel, in 64-bit
// (int products overflow at 2^31: 4096² pixels × 128 spp already does).
inline uint64_t total_samples(int width, int height, int spp) {
  return uint64_t(uint32_t(width)) * uint64_t(uint32_t(height)) * uint64_t(uint32_t(spp));
}

// A backend's accumulation in its own layout and precision (the CPU's double
// sums and integer counters, the GPU's Kahan-compensated float texels), opaque
// to everyone else: a checkpoint stores it byte for byte and a resumed render
// continues from it exactly where it stopped (render/Checkpoint.h).
struct AccumulationState {
  std::string backend;  // whose layout `data` is in: "cpu" | "vulkan"
  int width = 0, height = 0;
  int spp = 0;  // samples per pixel accumulated in `data`
  std::vector<uint8_t> data;
};

struct RenderSettings {
  int width = 0, height = 0;  // already resolved (CLI overrides scene film)
  int spp = 0;
  uint32_t seed = 1;
  uint32_t frame = 0;        // animation frame; feeds the RNG key
  double time_limit = 0.0;   // seconds, 0 = none; stops after the pass that crosses it
  // film.aovs or --aovs (docs/compositing.md "AOVs"): also accumulate the
  // light layers and first-hit features (RenderResult::aov_sum).
  bool aovs = false;
};

// RenderResult::aov_sum's layout: per pixel, kAovValues sums over its samples,
// at these offsets: the light layers (RGB; they sum to RenderResult::sum),
// then the first-event features (albedo RGB, normal XYZ, depth) summed over
// the samples that have a first event, and their number (kAovHits); then the
// denoiser's guide (RGB) and its alpha: the pixel's own values, not sums (a
// fixed quadrature of the pixel, computed once; docs/compositing.md "The guide").
constexpr int kAovEmission = 0, kAovScatter = 3, kAovSurface = 6, kAovBackground = 9;
constexpr int kAovAlbedo = 12, kAovNormal = 15, kAovDepth = 18, kAovHits = 19;
constexpr int kAovGuide = 20, kAovGuideAlpha = 23, kAovValues = 24;

// Called after each progressive pass: samples per pixel done so far, target.
using ProgressFn = std::function<void(int spp_done, int spp_target)>;

struct RenderControl {
  ProgressFn progress;
  // Set by SIGINT/SIGTERM: stop within the pass in flight (polled inside it;
  // that pass is dropped) and return what the finished passes hold.
  const std::atomic<bool>* cancel = nullptr;
  // Continue from this state (same backend and image size, checked by the
  // caller's checkpoint) instead of from 0 spp: the passes go on with sample
  // index `resume->spp`, so the result equals an uninterrupted render's.
  const AccumulationState* resume = nullptr;
  // Called with the accumulation after the first pass that ends at least
  // checkpoint_seconds after the previous call (or the start); 0 = never.
  double checkpoint_seconds = 0.0;
  std::function<void(const AccumulationState&)> checkpoint;
};

struct RenderResult {
  int width = 0, height = 0;
  int spp = 0;  // samples per pixel actually taken (including resumed ones)
  int spp_target = 0;   // samples per pixel asked for (RenderSettings::spp)
  int resumed_spp = 0;  // of `spp`, those that came from RenderControl::resume
  // Interleaved RGB, width*height*3, row 0 = top.
  std::vector<double> sum, sum_sq;
  // Per pixel (width*height): Σα and Σα² of the samples' alpha (docs/compositing.md).
  std::vector<double> alpha_sum, alpha_sum_sq;
  // RenderSettings::aovs: width*height*kAovValues sums (layout above); else empty.
  std::vector<double> aov_sum;
  std::string backend, device;
  // What the render resolved from integrator.mis / emission_estimator
  // (host/light/LightSelection.h): "bsdf" | "mis" | "light_only" and
  // "absorption" | "collision". Both backends fill them the same way.
  std::string light_strategy, emission_estimator;
  // Each grid medium's majorant grid, cells per axis (the GPU's: chosen per
  // grid, host/volume/MajorantGrid.h; empty on the CPU, which uses global majorants).
  std::vector<std::array<int, 3>> majorant_grids;
  double seconds = 0.0;       // first dispatch to finished readback
  double load_seconds = 0.0;  // device/pipeline creation, uploads, bakes
  // Of `seconds`, the denoiser guide's marches (settings.aovs; the Vulkan
  // backend's guide dispatch; 0 on the CPU, which marches within its passes).
  double guide_seconds = 0.0;
  // Counters summed over all camera samples.
  double density_lookups = 0.0;  // trilinear density samples
  double events = 0.0;           // real collisions (absorption + scattering)
  uint64_t nonfinite_samples = 0;
  // Samples the device could not finish even one per pass (llvmpipe's loop
  // budget, gpu_types.h PassStatus): counted in spp, contributing nothing.
  uint64_t dropped_samples = 0;
  bool cancelled = false;
  std::vector<std::string> warnings;  // one line each (e.g. NaN voxels), printed by the CLI
  // When the render ended short of spp_target (cancelled, time limit): the
  // accumulation, so the caller can checkpoint it. Empty otherwise.
  AccumulationState state;
};

// The device failed mid-render (VK_ERROR_DEVICE_LOST, out of device memory):
// what() says which; `partial` holds the accumulation saved before the failure
// (its spp may be 0), state included, so the caller can still write it.
struct RenderFailed : std::runtime_error {
  RenderFailed(const std::string& what, RenderResult partial)
      : std::runtime_error(what), partial(std::move(partial)) {}
  RenderResult partial;
};

}  // namespace pyrolume
