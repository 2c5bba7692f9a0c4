#pragma once
// Lights in the GPU's layout (shaders/shared/light_types.h, shaders/lights.glsl):
// an emissive medium's clustered distribution (light/EmissionCdf.h) and the
// environment map (light/EnvironmentMap.h).
#include <cstdint>
#include <vector>

#include "light/EmissionCdf.h"
#include "light/EnvironmentMap.h"
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

gpu::GpuEnvironment pack_gpu_environment_header(const EnvironmentMap& env);
// W·H × (r, g, b, p_uv), row 0 = top, no scale. The CDFs go as env.cdf().
std::vector<float> pack_gpu_environment_texels(const EnvironmentMap& env);

}  // namespace pyrolume
