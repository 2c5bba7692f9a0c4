#pragma once
// Lights in the GPU's layout (shaders/shared/light_types.h, shaders/lights.glsl):
// an emissive medium's clustered distribution (light/EmissionCdf.h), the
// environment map (light/EnvironmentMap.h) and the analytic lights.
#include <cstdint>
#include <vector>

#include "light/EmissionCdf.h"
#include "light/EnvironmentMap.h"
#include "light/LightSelection.h"
#include "scene/Scene.h"
#include "shared/gpu_types.h"
#include "shared/light_types.h"

namespace pyrolume {

// The GPU samples only from a receiver: a clustered() distribution (or an
// empty one); pack_gpu_emission_header throws std::logic_error for any other.
// entry_offset / pmf_offset / cluster_offset: where this medium's arrays
// start when several media share the buffers (cluster_cdf(), entry_cells(),
// cluster_pmf(), pack_gpu_emission_clusters()).
gpu::GpuEmissionCdf pack_gpu_emission_header(const EmissionCdf& cdf, uint32_t entry_offset = 0,
                                             uint32_t pmf_offset = 0, uint32_t cluster_offset = 0);
// One per cluster, then the nonempty ones again.
std::vector<gpu::GpuEmissionCluster> pack_gpu_emission_clusters(const EmissionCdf& cdf);

// Several emissive grids' CDFs in shared buffers, one after another:
// by_slot[s] (null: none) at grid slot s, its header's pick_probability
// pick[s]; headers has MAX_GRIDS entries (zero for a slot without one).
struct GpuEmissionLights {
  std::vector<float> cdf, pmf;
  std::vector<uint32_t> cells;
  std::vector<gpu::GpuEmissionCluster> clusters;
  std::vector<gpu::GpuEmissionCdf> headers = std::vector<gpu::GpuEmissionCdf>(gpu::MAX_GRIDS);
};
GpuEmissionLights pack_gpu_emission_lights(const std::vector<const EmissionCdf*>& by_slot,
                                           const std::vector<double>& pick);

gpu::GpuEnvironment pack_gpu_environment_header(const EnvironmentMap& env);
// W·H × (r, g, b, p_uv), row 0 = top, no scale. The CDFs go as env.cdf().
std::vector<float> pack_gpu_environment_texels(const EnvironmentMap& env);

// The scene's analytic lights as GpuLight (docs/lights.md "Analytic lights"),
// with light selection's probabilities; one zero placeholder when there are
// none (a storage buffer cannot be empty).
std::vector<gpu::GpuLight> pack_gpu_lights(const Scene& scene, const LightSelection& selection);

}  // namespace pyrolume
