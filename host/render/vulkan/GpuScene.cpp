#include "render/vulkan/GpuScene.h"

#include <cmath>
#include <cstring>
#include <map>

#include "color/Blackbody.h"
#include "color/EmissionModel.h"
#include "render/LineEstimator.h"
#include "scene/MediumVolume.h"
#include "util/Error.h"
#include "volume/MajorantGrid.h"
#include "util/Math.h"

namespace pyrolume {

// The host's radiance limits are the shaders' (shaders/shared/gpu_types.h).
static_assert(kMaxSampleRadiance == gpu::MAX_SAMPLE_RADIANCE);
static_assert(kMaxEmittedRadiance == gpu::MAX_EMITTED_RADIANCE);
namespace {
gpu::vec3 v3(glm::dvec3 v) { return gpu::vec3(float(v.x), float(v.y), float(v.z)); }

// Rows of the affine world -> texel map: u = index − origin + 0.5 (texel i's
// centre, OpenVDB's integer index point, sits at u = i + 0.5).
void texel_rows(const DenseGrid& g, gpu::vec4& r0, gpu::vec4& r1, gpu::vec4& r2) {
  glm::dmat4 shift(1.0);
  shift[3] = glm::dvec4(-glm::dvec3(g.origin) + 0.5, 1.0);
  glm::dmat4 m = shift * g.world_to_index;  // column-major: m[col][row]
  gpu::vec4* rows[3] = {&r0, &r1, &r2};
  for (int r = 0; r < 3; ++r) *rows[r] = gpu::vec4(float(m[0][r]), float(m[1][r]), float(m[2][r]), float(m[3][r]));
}

// A sparse grid's tree and leaf table, appended to the sparse buffer (the
// tree 32-byte aligned, as NanoVDB wants; offset 0 stays free so that 0 means
// "dense"), and where they sit into the GpuGrid's fields; a dense grid gets 0.
// The flat leaf table replaces the walk from the root (shaders/sparse.glsl);
// a box so large and empty that the table would outweigh the tree is refused.
// Without `with_tables` only the offsets are laid out (the same ones): a live
// edit re-packs the headers, and the tables it would rebuild visit every leaf.
void place_sparse(const std::string& file, const DenseGrid& g, bool with_tables, GpuScene& out, gpu::vec3& index_origin,
                  uint32_t& tree, gpu::ivec3& leaf_origin, uint32_t& leaf_table, gpu::uvec3& leaf_dims) {
  tree = 0;
  leaf_table = 0;
  index_origin = v3(glm::dvec3(g.origin) - 0.5);
  if (!g.is_sparse()) return;
  auto append = [&](uint64_t align, uint64_t bytes) {
    const uint64_t at = std::max<uint64_t>(out.sparse_bytes, gpu::SPARSE_ZERO_LEAF + 512 * 4);
    const uint64_t aligned = (at + align - 1) / align * align;
    if (aligned + bytes > uint64_t(UINT32_MAX))
      throw input_error(file, "grid \"" + g.name + "\"", "sparse grids of more than 4 GiB together are not supported");
    out.sparse_bytes = aligned + bytes;
    return uint32_t(aligned);
  };
  tree = append(32, g.sparse->bytes());
  if (with_tables) out.sparse_blocks.push_back({tree, g.sparse.get(), -1});
  const glm::ivec3 lo = g.origin >> 3, hi = (g.origin + g.dims - 1) >> 3, n = hi - lo + 1;
  const uint64_t entries = uint64_t(n.x) * uint64_t(n.y) * uint64_t(n.z);
  if (entries * 4 > std::max<uint64_t>(2 * g.sparse->bytes(), uint64_t(64) << 20))
    throw input_error(file, "grid \"" + g.name + "\"",
                      "its leaves are spread over a box of " + std::to_string(n.x) + " x " + std::to_string(n.y) + " x " +
                          std::to_string(n.z) + " leaf cells, whose table of leaf addresses would outweigh the tree; "
                          "crop the grid, or use \"texture_format\": \"r16f\" with a \"downsample\"");
  std::vector<uint32_t> table(with_tables ? entries : 0, gpu::SPARSE_ZERO_LEAF);
  if (with_tables) g.sparse->for_each_leaf([&](const glm::ivec3& o, uint64_t values) {
    const glm::ivec3 L = (o >> 3) - lo;
    if (glm::any(glm::lessThan(L, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(L, n))) return;  // all zero there
    table[(size_t(L.z) * size_t(n.y) + size_t(L.y)) * size_t(n.x) + size_t(L.x)] = uint32_t(tree + values);
  });
  // An active tile (a cube of one value) covers whole leaf cells: they point
  // at a leaf of 512 copies of its value, one per value.
  std::map<uint32_t, uint32_t> constant_leaves;
  g.sparse->for_each_tile([&](const glm::ivec3& o, int size, float v) {
    uint32_t bits;
    std::memcpy(&bits, &v, 4);
    auto it = constant_leaves.find(bits);
    if (it == constant_leaves.end()) {
      const uint32_t at = append(16, 512 * 4);
      if (with_tables) {
        out.sparse_blocks.push_back({at, nullptr, int(out.sparse_tables.size())});
        out.sparse_tables.emplace_back(512, bits);
      }
      it = constant_leaves.emplace(bits, at).first;
    }
    if (!with_tables) return;
    const glm::ivec3 a = glm::max((o >> 3) - lo, glm::ivec3(0)), b = glm::min(((o + size - 1) >> 3) - lo, n - 1);
    for (int z = a.z; z <= b.z; ++z)
      for (int y = a.y; y <= b.y; ++y)
        for (int x = a.x; x <= b.x; ++x) table[(size_t(z) * size_t(n.y) + size_t(y)) * size_t(n.x) + size_t(x)] = it->second;
  });
  leaf_table = append(16, entries * 4);
  leaf_origin = lo;
  leaf_dims = gpu::uvec3(n);
  if (!with_tables) return;
  out.sparse_blocks.push_back({leaf_table, nullptr, int(out.sparse_tables.size())});
  out.sparse_tables.push_back(std::move(table));
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
  if (density.grid.is_sparse() || temperature.grid.is_sparse()) return false;  // each tree is read on its own
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

namespace {
// The coefficients every medium has.
gpu::GpuMedium medium_coefficients(const Medium& m) {
  gpu::GpuMedium g{};
  g.sigma_a = v3(m.sigma_a);
  g.sigma_s = v3(m.sigma_s);
  g.g = float(m.g);
  return g;
}

// A sphere or box medium.
gpu::GpuMedium pack_analytic_medium(const Medium& m) {
  gpu::GpuMedium g = medium_coefficients(m);
  const bool sphere = m.bounds.kind == Bounds::Kind::Sphere;
  g.shape = sphere ? gpu::SHAPE_SPHERE : gpu::SHAPE_BOX;
  // A medium emits sigma_a·Le per unit length (docs/scene-format.md "media").
  g.emission = v3(m.sigma_a * homogeneous_le(m.emission));
  if (sphere) {
    g.center = v3(m.bounds.center);
    g.radius = float(m.bounds.radius);
  } else {
    g.box_min = v3(m.bounds.min);
    g.box_max = v3(m.bounds.max);
  }
  return g;
}

// How a grid medium emits: a constant Le, or the blackbody of its temperature
// grid (that grid's texel map, temperature mapping and LUT coordinates), or not.
void pack_grid_emission(const Medium& m, const StoredVolume& v, bool with_luts, bool with_tables, gpu::GpuMedium& g,
                        gpu::GpuGrid& grid, GpuGridSource& src, GpuScene& out) {
  if (m.emission.rgb) {
    g.emission = v3(*m.emission.rgb * m.emission.scale);
    g.emission_mode = gpu::EMIT_CONSTANT;
  } else if (needs_temperature_grid(m) && v.temperature && !v.temperature->grid.empty()) {
    g.emission = v3(glm::dvec3(m.emission.scale));
    g.emission_mode = gpu::EMIT_TEMPERATURE;
    src.temperature = &*v.temperature;
    texel_rows(v.temperature->grid, grid.temperature.row0, grid.temperature.row1, grid.temperature.row2);
    place_sparse(m.file.string(), v.temperature->grid, with_tables, out, grid.temperature.index_origin, grid.temperature.tree,
                 grid.temperature.leaf_origin, grid.temperature.leaf_table, grid.temperature.leaf_dims);
    grid.temperature.dims = v3(glm::dvec3(v.temperature->grid.dims));
    grid.temperature_offset = float(m.temperature.offset);
    grid.temperature_scale = float(m.temperature.scale);
    grid.cutoff_k = float(m.temperature.cutoff_k);
    if (with_luts)
      src.blackbody = color::BlackbodyLut::baked(m.emission.blackbody, m.emission.observer, m.emission.adapt_to_k);
    set_blackbody_lut(grid, src.blackbody ? src.blackbody->params() : color::BlackbodyLutParams{});
  } else {
    g.emission_mode = gpu::EMIT_NONE;
  }
}

// Medium i, a grid, in the next grid slot: its GpuMedium, GpuGrid (all but the
// majorant cells' geometry, add_majorant_cells') and source.
void pack_grid_medium(const Medium& m, size_t i, const StoredVolume& v, bool with_luts, bool with_tables,
                      GpuScene& out) {
  gpu::GpuMedium g = medium_coefficients(m);
  g.shape = gpu::SHAPE_GRID;
  g.grid_slot = uint32_t(out.grids.size());
  gpu::GpuGrid grid{};
  GpuGridSource src;
  src.medium = i;
  src.density = &v.density;
  texel_rows(v.density.grid, grid.density.row0, grid.density.row1, grid.density.row2);
  grid.density.dims = v3(glm::dvec3(v.density.grid.dims));
  place_sparse(m.file.string(), v.density.grid, with_tables, out, grid.density.index_origin, grid.density.tree, grid.density.leaf_origin,
               grid.density.leaf_table, grid.density.leaf_dims);
  grid.density_scale = float(m.density_scale);
  // Depends on the medium's coefficients, not on the cells: edits change it.
  grid.majorant_scale = float(max3(m.sigma_a + m.sigma_s) * m.density_scale);
  pack_grid_emission(m, v, with_luts, with_tables, g, grid, src, out);
  out.has_emission = out.has_emission || (g.emission_mode != gpu::EMIT_NONE && m.emission.scale > 0.0);
  out.media.push_back(g);
  out.grids.push_back(grid);
  out.grid_sources.push_back(std::move(src));
  out.has_grids = true;
}

// One texture per grid for density and temperature where every emitting grid
// allows it: the shader variant reads the temperature one way for all.
bool every_temperature_fits_density(const std::vector<GpuGridSource>& sources, uint64_t max_texture_bytes) {
  bool any_temperature = false, all_fit = true;
  for (const GpuGridSource& src : sources)
    if (src.temperature) {
      any_temperature = true;
      all_fit = all_fit && temperature_fits_density_texture(*src.density, *src.temperature, max_texture_bytes);
    }
  return any_temperature && all_fit;
}
}  // namespace

GpuScene pack_gpu_media(const Scene& scene, const std::vector<std::optional<StoredVolume>>& volumes, bool with_luts,
                        const std::vector<bool>& line, bool with_tables) {
  GpuScene out;
  out.line.line = line;
  out.line.line.resize(scene.media.size(), false);
  for (size_t i = 0; i < scene.media.size(); ++i) {
    const Medium& m = scene.media[i];
    if (m.type == Medium::Type::Homogeneous) {
      out.media.push_back(pack_analytic_medium(m));
      // Its line rate comes from each ray's chord (shaders/majorant_walk.glsl majorant_at).
      if (out.line.line[i]) out.media.back().line_points = float(kLinePointsPerCell);
      out.has_analytic = true;
      out.has_emission = out.has_emission || max3(glm::dvec3(out.media.back().emission)) > 0.0;
    } else {
      const StoredVolume& v = *volumes.at(i);
      if (v.density.grid.empty()) continue;  // an empty grid renders as no medium
      if (out.grids.size() >= gpu::MAX_GRIDS)
        throw input_error(scene.file.string(), "media[" + std::to_string(i) + "]",
                          "at most " + std::to_string(gpu::MAX_GRIDS) + " vdb media per scene");
      pack_grid_medium(m, i, v, with_luts, with_tables, out);
    }
    out.has_scattering = out.has_scattering || max3(m.sigma_s) > 0.0;
  }
  if (out.media.size() > gpu::MAX_MEDIA)
    throw input_error(scene.file.string(), "media", "at most " + std::to_string(gpu::MAX_MEDIA) + " media are supported");
  return out;
}

void add_majorant_cells(const Scene& scene, GpuScene& g) {
  g.majorants.clear();
  for (size_t slot = 0; slot < g.grids.size(); ++slot) {
    // Majorant cells over the stored (rounded) density.
    const GpuGridSource& src = g.grid_sources[slot];
    const DenseGrid& density = src.density->grid;
    const bool chosen = src.medium < g.line.majorant_res.size() && g.line.majorant_res[src.medium].x > 0;
    const glm::ivec3 res = chosen ? g.line.majorant_res[src.medium]
                                  : majorant_resolution(scene, scene.media[src.medium], density);
    const MajorantGrid mg = build_majorant_grid(density, res);
    gpu::GpuGrid& grid = g.grids[slot];
    grid.majorant_res = gpu::uvec3(uint32_t(mg.res.x), uint32_t(mg.res.y), uint32_t(mg.res.z));
    grid.majorant_offset = uint32_t(g.majorants.size());
    grid.majorant_cell = v3(mg.cell_size);
    g.majorants.insert(g.majorants.end(), mg.max_density.begin(), mg.max_density.end());
    // The line estimator's rates, for the grid media it collects (computed on
    // this same majorant grid by line_media).
    grid.line_rate_offset = 0;
    if (src.medium >= g.line.rates.size() || g.line.rates[src.medium].empty()) continue;
    const std::vector<float>& rates = g.line.rates[src.medium];
    grid.line_rate_offset = uint32_t(g.majorants.size());
    g.majorants.insert(g.majorants.end(), rates.begin(), rates.end());
  }
}

GpuScene build_gpu_scene(const Scene& scene, const std::vector<std::optional<StoredVolume>>& volumes, bool with_luts,
                         uint64_t max_texture_bytes) {
  std::vector<const StoredVolume*> by_medium(scene.media.size(), nullptr);
  for (size_t i = 0; i < volumes.size() && i < by_medium.size(); ++i)
    if (volumes[i]) by_medium[i] = &*volumes[i];
  LineMedia line = line_media(scene, by_medium);
  GpuScene out = pack_gpu_media(scene, volumes, with_luts, line.line);
  out.line.rates = std::move(line.rates);
  out.line.majorant_res = std::move(line.majorant_res);
  add_majorant_cells(scene, out);
  out.temperature_in_density = every_temperature_fits_density(out.grid_sources, max_texture_bytes);
  return out;
}

void keep_baked_grid_fields(const gpu::GpuGrid& baked, gpu::GpuGrid& grid) {
  grid.lut_scale = baked.lut_scale;
  grid.lut_offset = baked.lut_offset;
  grid.t_min_k = baked.t_min_k;
  grid.majorant_res = baked.majorant_res;
  grid.majorant_offset = baked.majorant_offset;
  grid.majorant_cell = baked.majorant_cell;
  grid.line_rate_offset = baked.line_rate_offset;
}

void set_blackbody_lut(gpu::GpuGrid& grid, const color::BlackbodyLutParams& p) {
  grid.lut_scale = p.log_scale;
  grid.lut_offset = p.log_bias;
  grid.t_min_k = p.t_min_k;
}

gpu::FrameConstants build_frame_constants(const Scene& scene, const RenderSettings& s, uint32_t medium_count,
                                          const LightSelection& lights) {
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
  f.transparent = scene.film.transparent ? 1u : 0u;
  f.p_env = float(lights.p_env);
  f.p_continue_own = float(lights.p_continue_own);
  f.surface_light_samples = uint32_t(lights.surface_light_samples);
  f.ratio_tracked_continuation = lights.ratio_tracked_continuation ? 1u : 0u;
  return f;
}

}  // namespace pyrolume
