#include "render/vulkan/GpuScene.h"

#include <cmath>

#include "color/Blackbody.h"
#include "color/EmissionModel.h"
#include "light/AnalyticLights.h"
#include "scene/MediumVolume.h"
#include "util/Error.h"
#include "volume/MajorantGrid.h"

namespace pyrolume {

// The host's radiance limits are the shaders' (shaders/shared/gpu_types.h).
static_assert(kMaxSampleRadiance == gpu::MAX_SAMPLE_RADIANCE);
static_assert(kMaxEmittedRadiance == gpu::MAX_EMITTED_RADIANCE);
namespace {
gpu::vec3 v3(glm::dvec3 v) { return gpu::vec3(float(v.x), float(v.y), float(v.z)); }
double max3(glm::dvec3 v) { return std::max(v.x, std::max(v.y, v.z)); }

glm::dvec3 homogeneous_le(const Emission& e) {
  if (e.rgb) return *e.rgb * e.scale;
  if (e.temperature_k) return color::blackbody_rgb(*e.temperature_k, e.blackbody, e.observer, e.adapt_to_k) * e.scale;
  return glm::dvec3(0.0);
}

// Rows of the affine world -> texel map: u = index − origin + 0.5 (texel i's
// centre, OpenVDB's integer index point, sits at u = i + 0.5).
void texel_rows(const DenseGrid& g, gpu::vec4& r0, gpu::vec4& r1, gpu::vec4& r2) {
  glm::dmat4 shift(1.0);
  shift[3] = glm::dvec4(-glm::dvec3(g.origin) + 0.5, 1.0);
  glm::dmat4 m = shift * g.world_to_index;  // column-major: m[col][row]
  gpu::vec4* rows[3] = {&r0, &r1, &r2};
  for (int r = 0; r < 3; ++r) *rows[r] = gpu::vec4(float(m[0][r]), float(m[1][r]), float(m[2][r]), float(m[3][r]));
}
}  // namespace

namespace {
bool both_half(const StoredGrid& density, const StoredGrid& temperature) {
  return density.format == TextureFormat::R16F && temperature.format == TextureFormat::R16F;
}
}  // namespace

uint64_t density_temperature_bytes(const StoredGrid& density, const StoredGrid& temperature) {
  return uint64_t(dense_bytes(density.grid, both_half(density, temperature))) * 2;
}

bool temperature_fits_density_texture(const StoredGrid& density, const StoredGrid& temperature, uint64_t max_bytes) {
  if (density.grid.world_to_index != temperature.grid.world_to_index) return false;
  const double apart = double(dense_bytes(density.grid, density.format == TextureFormat::R16F)) +
                       double(dense_bytes(temperature.grid, temperature.format == TextureFormat::R16F));
  const double together = double(density_temperature_bytes(density, temperature));
  return together <= 1.25 * apart && together <= double(max_bytes);
}

DensityTemperatureTexels density_temperature_texels(const StoredGrid& density, const StoredGrid& temperature) {
  DensityTemperatureTexels out;
  out.half = both_half(density, temperature);
  const DenseGrid& d = density.grid;
  const DenseGrid& t = temperature.grid;
  const size_t n = d.texel_count();
  if (out.half) out.half_bits.assign(2 * n, 0);
  else out.values.assign(2 * n, 0.f);
  // Both grids share one index space: density texel (i,j,k) is index
  // d.origin + (i,j,k), temperature texel index − t.origin (0 outside its box).
  const glm::ivec3 shift = d.origin - t.origin;
  size_t at = 0;
  for (int k = 0; k < d.dims.z; ++k)
    for (int j = 0; j < d.dims.y; ++j)
      for (int i = 0; i < d.dims.x; ++i, ++at) {
        const glm::ivec3 ti = glm::ivec3(i, j, k) + shift;
        const bool inside = glm::all(glm::greaterThanEqual(ti, glm::ivec3(0))) && glm::all(glm::lessThan(ti, t.dims));
        const size_t t_at =
            inside ? (size_t(ti.z) * size_t(t.dims.y) + size_t(ti.y)) * size_t(t.dims.x) + size_t(ti.x) : 0;
        if (out.half) {
          out.half_bits[2 * at] = density.half_bits[at];
          out.half_bits[2 * at + 1] = inside ? temperature.half_bits[t_at] : uint16_t(0);
        } else {
          out.values[2 * at] = d.values[at];
          out.values[2 * at + 1] = inside ? t.values[t_at] : 0.f;
        }
      }
  return out;
}

GpuScene build_gpu_scene(const Scene& scene, const std::vector<std::optional<StoredVolume>>& volumes, bool with_luts,
                         uint64_t max_texture_bytes) {
  GpuScene out;
  for (size_t i = 0; i < scene.media.size(); ++i) {
    const Medium& m = scene.media[i];
    gpu::GpuMedium g{};
    g.sigma_s = v3(m.sigma_s);
    g.g = float(m.g);
    if (m.type == Medium::Type::Homogeneous) {
      bool sphere = m.bounds.kind == Bounds::Kind::Sphere;
      g.sigma_a = v3(m.sigma_a);
      g.shape = sphere ? gpu::SHAPE_SPHERE : gpu::SHAPE_BOX;
      out.has_analytic = true;
      // A medium emits sigma_a·Le per unit length (docs/scene-format.md "media").
      g.emission = v3(m.sigma_a * homogeneous_le(m.emission));
      if (sphere) {
        g.center = v3(m.bounds.center);
        g.radius = float(m.bounds.radius);
      } else {
        g.box_min = v3(m.bounds.min);
        g.box_max = v3(m.bounds.max);
      }
      out.has_emission = out.has_emission || max3(glm::dvec3(g.emission)) > 0.0;
    } else {
      const StoredVolume& v = *volumes.at(i);
      if (v.density.grid.empty()) continue;  // an empty grid renders as no medium
      if (out.grids.size() >= gpu::MAX_GRIDS)
        throw input_error(scene.file.string(), "media[" + std::to_string(i) + "]",
                          "at most " + std::to_string(gpu::MAX_GRIDS) + " vdb media per scene");
      const uint32_t slot = uint32_t(out.grids.size());
      g.sigma_a = v3(m.sigma_a);
      g.shape = gpu::SHAPE_GRID;
      g.grid_slot = slot;

      gpu::GpuGrid grid{};
      GpuGridSource src;
      src.medium = i;
      src.density = &v.density;
      texel_rows(v.density.grid, grid.density_row0, grid.density_row1, grid.density_row2);
      grid.density_dims = v3(glm::dvec3(v.density.grid.dims));
      grid.density_scale = float(m.density_scale);
      if (m.emission.rgb) {
        g.emission = v3(*m.emission.rgb * m.emission.scale);
        g.emission_mode = gpu::EMIT_CONSTANT;
      } else if (needs_temperature_grid(m) && v.temperature && !v.temperature->grid.empty()) {
        g.emission = v3(glm::dvec3(m.emission.scale));
        g.emission_mode = gpu::EMIT_TEMPERATURE;
        src.temperature = &*v.temperature;
        texel_rows(v.temperature->grid, grid.temperature_row0, grid.temperature_row1, grid.temperature_row2);
        grid.temperature_dims = v3(glm::dvec3(v.temperature->grid.dims));
        grid.temperature_offset = float(m.temperature.offset);
        grid.temperature_scale = float(m.temperature.scale);
        grid.cutoff_k = float(m.temperature.cutoff_k);
        if (with_luts) src.blackbody.emplace(m.emission.blackbody, m.emission.observer, m.emission.adapt_to_k);
        color::BlackbodyLutParams p = src.blackbody ? src.blackbody->params() : color::BlackbodyLutParams{};
        set_blackbody_lut(grid, p);
      } else {
        g.emission_mode = gpu::EMIT_NONE;
      }
      out.has_emission = out.has_emission || (g.emission_mode != gpu::EMIT_NONE && m.emission.scale > 0.0);

      // Majorant cells over the stored (rounded) density.
      glm::ivec3 res = scene.integrator.majorant == Majorant::Global
                           ? glm::ivec3(1)
                           : scene.integrator.majorant_grid.value_or(default_majorant_resolution(v.density.grid.dims));
      MajorantGrid mg = build_majorant_grid(v.density.grid, res);
      grid.majorant_res = gpu::uvec3(uint32_t(mg.res.x), uint32_t(mg.res.y), uint32_t(mg.res.z));
      grid.majorant_offset = uint32_t(out.majorants.size());
      grid.majorant_cell = v3(mg.cell_size);
      grid.majorant_scale = float(max3(m.sigma_a + m.sigma_s) * m.density_scale);
      out.majorants.insert(out.majorants.end(), mg.max_density.begin(), mg.max_density.end());
      out.grids.push_back(grid);
      out.grid_sources.push_back(std::move(src));
      out.has_grids = true;
    }
    out.has_scattering = out.has_scattering || max3(m.sigma_s) > 0.0;
    out.media.push_back(g);
  }
  // One texture per grid for density and temperature where every emitting
  // grid allows it: the shader variant reads the temperature one way for all.
  bool any_temperature = false, all_fit = true;
  for (const GpuGridSource& src : out.grid_sources)
    if (src.temperature) {
      any_temperature = true;
      all_fit = all_fit && temperature_fits_density_texture(*src.density, *src.temperature, max_texture_bytes);
    }
  out.temperature_in_density = any_temperature && all_fit;
  if (out.media.size() > gpu::MAX_MEDIA)
    throw input_error(scene.file.string(), "media", "at most " + std::to_string(gpu::MAX_MEDIA) + " media are supported");
  return out;
}

void set_blackbody_lut(gpu::GpuGrid& grid, const color::BlackbodyLutParams& p) {
  grid.lut_scale = p.log_scale;
  grid.lut_offset = p.log_bias;
  grid.t_min_k = p.t_min_k;
}

gpu::FrameConstants build_frame_constants(const Scene& scene, const RenderSettings& s, uint32_t medium_count) {
  const Camera& c = scene.camera;
  glm::dvec3 forward = glm::normalize(c.look_at - c.position);
  glm::dvec3 right = glm::normalize(glm::cross(forward, c.up));  // image x grows along cross(forward, up)
  glm::dvec3 up = glm::cross(right, forward);
  double tan_half = std::tan(glm::radians(c.fov_deg) * 0.5);
  gpu::FrameConstants f{};
  f.camera_position = v3(c.position);
  f.tan_half_fov = float(tan_half);
  f.camera_forward = v3(forward);
  f.aspect = float(double(s.width) / double(s.height));
  f.camera_right = v3(right);
  f.camera_up = v3(up);
  f.background = v3(scene.background);
  f.width = uint32_t(s.width);
  f.height = uint32_t(s.height);
  f.medium_count = medium_count;
  f.max_depth = uint32_t(scene.integrator.max_depth);
  f.seed = s.seed;
  f.frame_index = s.frame;
  return f;
}

}  // namespace pyrolume

namespace pyrolume {
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
