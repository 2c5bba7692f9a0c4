#pragma once
// Switches that only tests and benchmarks set, to compare a Vulkan render
// with a variant of the same shader: no scene key or CLI flag reaches them,
// and the backend-neutral RenderSettings does not carry them
// (VulkanRenderer::set_hooks).
#include <cstdint>

namespace pyrolume {

struct VulkanHooks {
  // 1 = camera rays return the ratio-tracking transmittance through the
  // media, 2 = the delta-tracking one (per channel); 0 = radiance.
  uint32_t debug_mode = 0;
  // false keeps every lane of a SIMD group in the free-flight loop until the
  // group's last event, as before the early exit (the image is the same bit
  // for bit either way).
  bool early_event_exit = true;
  // false reads the density by the sampler's trilinear filter in free
  // flights too, instead of one texel of its footprint (docs/rendering.md
  // "Stochastic density lookups").
  bool stochastic_density = true;
  // false keeps the temperature in a texture of its own even where it could
  // be the density texture's second channel (GpuScene::temperature_in_density).
  bool temperature_in_density = true;
  // Pixel corners per dispatch of the denoiser guide's march (film.aovs;
  // RenderSession::march_guide_points), in bands of whole rows; 0: the default.
  uint32_t guide_band_corners = 0;
};

}  // namespace pyrolume
