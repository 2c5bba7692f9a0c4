#include "render/vulkan/LightPacking.h"

#include <cmath>
#include <stdexcept>

#include "light/AnalyticLights.h"

namespace pyrolume {

std::vector<gpu::GpuEmissionCluster> pack_gpu_emission_clusters(const EmissionCdf& cdf) {
  auto to_gpu = [](const EmissionCdf::Cluster& c) {
    gpu::GpuEmissionCluster g{};
    g.center = gpu::vec3(float(c.centre.x), float(c.centre.y), float(c.centre.z));
    g.radius_sq = float(c.radius2);
    g.power = float(c.power);
    g.first_entry = c.first;
    g.entry_count = c.count;
    return g;
  };
  // The grid of clusters (looked up by cell), then copies of the nonempty
  // ones (the loops over clusters skip the empty ones without reading them).
  std::vector<gpu::GpuEmissionCluster> out;
  out.reserve(cdf.clusters().size() + cdf.nonempty_clusters());
  for (const EmissionCdf::Cluster& c : cdf.clusters()) out.push_back(to_gpu(c));
  for (const EmissionCdf::Cluster& c : cdf.clusters())
    if (c.count > 0) out.push_back(to_gpu(c));
  return out;
}

gpu::GpuEmissionCdf pack_gpu_emission_header(const EmissionCdf& cdf, uint32_t entry_offset, uint32_t pmf_offset,
                                             uint32_t cluster_offset) {
  if (!cdf.empty() && !cdf.is_clustered())
    throw std::logic_error("pack_gpu_emission_header: the GPU needs a clustered() distribution");
  gpu::GpuEmissionCdf g{};
  auto row = [](const glm::dmat4& m, int r) {
    return gpu::vec4(float(m[0][r]), float(m[1][r]), float(m[2][r]), float(m[3][r]));
  };
  const glm::dmat4& world_to_cell = cdf.world_to_cell_matrix();
  const glm::dmat4& cell_to_world = cdf.cell_to_world_matrix();
  g.world_to_cell_row0 = row(world_to_cell, 0);
  g.world_to_cell_row1 = row(world_to_cell, 1);
  g.world_to_cell_row2 = row(world_to_cell, 2);
  g.cell_to_world_row0 = row(cell_to_world, 0);
  g.cell_to_world_row1 = row(cell_to_world, 1);
  g.cell_to_world_row2 = row(cell_to_world, 2);
  const glm::ivec3 cells = cdf.cells(), dims = cdf.cluster_dims();
  g.cells = gpu::uvec3(uint32_t(cells.x), uint32_t(cells.y), uint32_t(cells.z));
  g.entry_count = uint32_t(cdf.entry_count());
  g.first_entry = entry_offset;
  g.first_cell = pmf_offset;
  g.first_cluster = cluster_offset;
  g.nonempty_clusters = uint32_t(cdf.nonempty_clusters());
  g.clusters = gpu::uvec3(uint32_t(dims.x), uint32_t(dims.y), uint32_t(dims.z));
  g.cluster_k = uint32_t(cdf.cluster_cells_per_axis());
  const double volume = cdf.cell_volume();
  g.cell_volume = float(volume);
  g.inv_cell_volume = volume > 0.0 ? float(1.0 / volume) : 0.0f;
  g.power = float(cdf.power());
  return g;
}

GpuEmissionLights pack_gpu_emission_lights(const std::vector<const EmissionCdf*>& by_slot,
                                           const std::vector<double>& pick) {
  GpuEmissionLights out;
  for (size_t slot = 0; slot < by_slot.size(); ++slot) {
    if (!by_slot[slot]) continue;
    const EmissionCdf& c = *by_slot[slot];
    gpu::GpuEmissionCdf h = pack_gpu_emission_header(c, uint32_t(out.cdf.size()), uint32_t(out.pmf.size()),
                                                     uint32_t(out.clusters.size()));
    h.pick_probability = float(pick[slot]);
    out.headers.at(slot) = h;
    out.cdf.insert(out.cdf.end(), c.cluster_cdf().begin(), c.cluster_cdf().end());
    out.cells.insert(out.cells.end(), c.entry_cells().begin(), c.entry_cells().end());
    out.pmf.insert(out.pmf.end(), c.cluster_pmf().begin(), c.cluster_pmf().end());
    const std::vector<gpu::GpuEmissionCluster> clusters = pack_gpu_emission_clusters(c);
    out.clusters.insert(out.clusters.end(), clusters.begin(), clusters.end());
  }
  return out;
}

gpu::GpuEnvironment pack_gpu_environment_header(const EnvironmentMap& env) {
  gpu::GpuEnvironment g{};
  g.cos_rotation = float(env.cos_rotation());
  g.sin_rotation = float(env.sin_rotation());
  g.scale = float(env.scale());
  g.power = float(env.power());
  g.width = uint32_t(env.width());
  g.height = uint32_t(env.height());
  g.can_sample = env.has_distribution() ? 1u : 0u;
  g.zenith_y = env.zenith_y() ? 1u : 0u;
  return g;
}

std::vector<float> pack_gpu_environment_texels(const EnvironmentMap& env) {
  std::vector<float> t(size_t(env.width()) * env.height() * 4);
  size_t k = 0;
  for (int j = 0; j < env.height(); ++j)
    for (int i = 0; i < env.width(); ++i, ++k) {
      const glm::dvec3 rgb = env.texel(i, j);
      t[k * 4 + 0] = float(rgb.x);
      t[k * 4 + 1] = float(rgb.y);
      t[k * 4 + 2] = float(rgb.z);
      t[k * 4 + 3] = float(env.pdf_uv_texel(i, j));
    }
  return t;
}

std::vector<gpu::GpuLight> pack_gpu_lights(const Scene& scene, const LightSelection& selection) {
  std::vector<gpu::GpuLight> out;
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& l = scene.lights[i];
    gpu::GpuLight g{};
    const glm::dvec3 value = l.type == Light::Type::Distant && !l.is_delta() ? disc_radiance(l) : light_value(l);
    g.value = gpu::vec3(value);
    g.pick_probability = float(i < selection.p_light.size() ? selection.p_light[i] : 0.0);
    g.direction = gpu::vec3(l.direction);
    switch (l.type) {
      case Light::Type::Point:
        g.kind = gpu::LIGHT_POINT;
        g.position = gpu::vec3(l.position);
        break;
      case Light::Type::Spot: {
        g.kind = gpu::LIGHT_SPOT;
        g.position = gpu::vec3(l.position);
        const SpotCone c = spot_cone(l);
        g.cos_cone = float(c.cos_end);
        g.cos_falloff = float(c.cos_start);
        break;
      }
      case Light::Type::Distant: {
        g.kind = l.is_delta() ? gpu::LIGHT_DISTANT : gpu::LIGHT_DISC;
        const double s = std::sin(disc_half_angle(l));
        g.one_minus_cos = float(disc_one_minus_cos(l));
        g.sin2 = float(s * s);
        break;
      }
      case Light::Type::Sphere:
        g.kind = gpu::LIGHT_SPHERE;
        g.position = gpu::vec3(l.center);
        g.radius = float(l.radius);
        break;
    }
    out.push_back(g);
  }
  if (out.empty()) out.push_back(gpu::GpuLight{});
  return out;
}

}  // namespace pyrolume
