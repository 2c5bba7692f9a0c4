#pragma once
// What every backend returns: per-pixel sums and sums of squares of the sample
// radiance (so each render carries its own per-pixel variance), plus counters.
#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace pyrolume {

struct Scene;

struct RenderSettings {
  int width = 0, height = 0;  // already resolved (CLI overrides scene film)
  int spp = 0;
  uint32_t seed = 1;
  uint32_t frame = 0;        // animation frame; feeds the RNG key
  double time_limit = 0.0;   // seconds, 0 = none; stops after the pass that crosses it
  // Test hook (no scene key): 1 = camera rays return the ratio-tracking
  // transmittance through the media, 2 = the delta-tracking one (per channel).
  uint32_t debug_mode = 0;
};

// Called after each progressive pass: samples per pixel done so far, target.
using ProgressFn = std::function<void(int spp_done, int spp_target)>;

struct RenderControl {
  ProgressFn progress;
  const std::atomic<bool>* cancel = nullptr;  // set by SIGINT/SIGTERM: stop after the current pass
};

struct RenderResult {
  int width = 0, height = 0;
  int spp = 0;  // samples per pixel actually taken
  // Interleaved RGB, width*height*3, row 0 = top.
  std::vector<double> sum, sum_sq;
  std::string backend, device;
  double seconds = 0.0;       // first dispatch to finished readback
  double load_seconds = 0.0;  // device/pipeline creation, uploads, bakes
  // Counters summed over all camera samples.
  double density_lookups = 0.0;  // trilinear density samples
  double events = 0.0;           // real collisions (absorption + scattering)
  uint64_t nonfinite_samples = 0;
  bool cancelled = false;
  std::vector<std::string> warnings;  // one line each (e.g. NaN voxels), printed by the CLI
};

}  // namespace pyrolume
