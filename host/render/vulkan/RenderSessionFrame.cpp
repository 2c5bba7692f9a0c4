// RenderSession: loading a frame (grids, textures, majorant cells, surfaces,
// environment, lights) and uploading its constants.
#include "render/vulkan/RenderSession.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "geometry/SceneSurfaces.h"
#include "light/EmissionCdf.h"
#include "light/EnvironmentMap.h"
#include "render/Limits.h"
#include "render/SceneChecks.h"
#include "render/vulkan/LightPacking.h"
#include "render/vulkan/RenderSessionParts.h"
#include "render/vulkan/Spirv.h"
#include "render/vulkan/SurfacePacking.h"
#include "scene/MediumVolume.h"
#include "util/Error.h"

namespace pyrolume {

using namespace session;

// The largest density texture that may take its temperature as a second
// channel: one allocation; 0 (never) when the test hook turns it off.
uint64_t RenderSession::shared_texture_bytes() const {
  return hooks_.temperature_in_density ? uint64_t(ctx_.max_allocation_size()) : 0;
}

DenseLimits RenderSession::dense_limits() const {
  return DenseLimits{ctx_.properties().limits.maxImageDimension3D, uint64_t(ctx_.max_allocation_size())};
}

bool RenderSession::load_frame(const Scene& scene, const RenderSettings& settings) {
  if (settings.width != settings_.width || settings.height != settings_.height || scene.media.size() != volumes_.size())
    return false;
  // Load into locals first: a bad frame (or a different variant) leaves the
  // session as it was.
  check_scene_ranges(scene);
  std::vector<std::optional<StoredVolume>> volumes(scene.media.size());
  for (size_t i = 0; i < scene.media.size(); ++i)
    if (scene.media[i].type == Medium::Type::Vdb) volumes[i] = load_stored_volume(scene.media[i], dense_limits());
  check_loaded_media(scene, volumes);
  // Each frame's blackbody LUTs are the process's baked copies
  // (BlackbodyLut::baked): a sequence bakes each mode once.
  GpuScene gpu_scene = build_gpu_scene(scene, volumes, /*with_luts=*/true, shared_texture_bytes());
  EmissionLights lights = build_emission_lights(scene, volumes, gpu_scene);
  if (spec_constants(scene, gpu_scene, settings, lights.selection) != spec_) return false;

  // The previous frame's textures live until the descriptors point at the new
  // ones (every pass was waited for, so none is in flight).
  auto old_3d = std::move(textures_3d_);
  auto old_1d = std::move(textures_1d_);
  auto old_texel_views = std::move(density_texel_views_);
  auto old_texels = std::move(density_texels_);
  textures_3d_.clear();
  textures_1d_.clear();
  volumes_ = std::move(volumes);
  gpu_scene_ = std::move(gpu_scene);
  settings_ = settings;
  warnings_.clear();
  for (const auto& v : volumes_)
    if (v)
      for (const auto& w : v->warnings) warnings_.push_back(w);
  create_majorant_buffer(scene);
  upload_emission_lights(lights);
  create_textures(scene);
  write_grid_descriptors();
  upload_constants(scene);
  return true;
}

// One 3D texture per grid, each over its own active bounding box with its own
// transform (no resampling), plus one blackbody LUT per emitting grid medium.
// With GpuScene::temperature_in_density the temperature is the density
// texture's second channel instead (RG16F, or RG32F where either grid is R32F).
void RenderSession::create_textures(const Scene& scene) {
  const VkPhysicalDeviceLimits& limits = ctx_.properties().limits;
  const uint16_t zero_half = 0;
  const float zero_rgba[4] = {0, 0, 0, 0};
  // temperature: a grid to put in the second channel (temperature_in_density).
  auto make_3d = [&](const StoredGrid* g, const std::string& what, const StoredGrid* temperature = nullptr) {
    if (!g) {
      vk::Image3D img(ctx_, 1, 1, 1, VK_FORMAT_R16_SFLOAT, "unused grid slot");
      img.upload(ctx_, &zero_half, sizeof zero_half);
      return img;
    }
    if (g->grid.is_sparse()) {  // read from the sparse buffer; the slot gets a placeholder
      vk::Image3D img(ctx_, 1, 1, 1, VK_FORMAT_R16_SFLOAT, "sparse grid slot");
      img.upload(ctx_, &zero_half, sizeof zero_half);
      return img;
    }
    const glm::ivec3 d = g->grid.dims;
    const uint32_t max_dim = limits.maxImageDimension3D;
    const uint32_t largest = uint32_t(std::max({d.x, d.y, d.z}));
    const bool half = g->format == TextureFormat::R16F;
    if (largest > max_dim)
      throw input_error(scene.file.string(), what,
                        std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z) +
                            " texels exceed this device's 3D texture limit of " + std::to_string(max_dim) +
                            " per axis; add \"downsample\": " + std::to_string((largest + max_dim - 1) / max_dim) +
                            " to the medium");
    const double bytes = temperature ? double(density_temperature_bytes(*g, *temperature))
                                     : double(dense_bytes(g->grid, half));
    if (bytes > double(ctx_.max_allocation_size()))
      throw input_error(scene.file.string(), what,
                        "the dense texture needs " + mib(bytes) + ", more than the device allows in one allocation (" +
                            mib(double(ctx_.max_allocation_size())) + "); add \"downsample\": 2 to the medium");
    // The texels to upload: the grid's own, or (density, temperature) pairs.
    DensityTemperatureTexels pairs;
    if (temperature) pairs = density_temperature_texels(*g, *temperature);
    const bool half_texels = temperature ? pairs.half : half;
    const VkFormat format = temperature ? (half_texels ? VK_FORMAT_R16G16_SFLOAT : VK_FORMAT_R32G32_SFLOAT)
                                        : (half_texels ? VK_FORMAT_R16_SFLOAT : VK_FORMAT_R32_SFLOAT);
    const std::vector<uint16_t>& half_bits = temperature ? pairs.half_bits : g->half_bits;
    const std::vector<float>& values = temperature ? pairs.values : g->grid.values;
    vk::Image3D img(ctx_, uint32_t(d.x), uint32_t(d.y), uint32_t(d.z), format, what.c_str());
    if (half_texels) img.upload(ctx_, half_bits.data(), half_bits.size() * sizeof(uint16_t));
    else img.upload(ctx_, values.data(), values.size() * sizeof(float));
    return img;
  };
  auto make_lut = [&](const color::BlackbodyLut* lut) {
    if (!lut) {
      vk::Image1D img(ctx_, 1, VK_FORMAT_R32G32B32A32_SFLOAT, "unused blackbody LUT");
      img.upload(ctx_, zero_rgba, sizeof zero_rgba);
      return img;
    }
    if (lut->size() > limits.maxImageDimension1D)
      throw vk::VulkanError("blackbody LUT of " + std::to_string(lut->size()) +
                            " texels exceeds this device's maxImageDimension1D (" +
                            std::to_string(limits.maxImageDimension1D) + ")");
    vk::Image1D img(ctx_, lut->size(), VK_FORMAT_R32G32B32A32_SFLOAT, "blackbody LUT");
    img.upload(ctx_, lut->rgba().data(), lut->rgba().size() * sizeof(float));
    return img;
  };
  create_sparse_buffer(scene);
  create_density_texels();
  // Slot layout: 3D [0] placeholder, then density 1 + 2·slot, temperature 2 + 2·slot;
  // 1D [0] placeholder, then the LUT of slot at 1 + slot.
  textures_3d_.push_back(make_3d(nullptr, ""));
  textures_1d_.push_back(make_lut(nullptr));
  for (const GpuGridSource& s : gpu_scene_.grid_sources) {
    const bool together = gpu_scene_.temperature_in_density && s.temperature;
    textures_3d_.push_back(
        make_3d(s.density, "grid \"" + s.density->grid.name + "\"", together ? s.temperature : nullptr));
    textures_3d_.push_back(make_3d(together ? nullptr : s.temperature,
                                   s.temperature ? "grid \"" + s.temperature->grid.name + "\"" : ""));
    textures_1d_.push_back(make_lut(s.blackbody ? &*s.blackbody : nullptr));
  }
}

bool RenderSession::stochastic_density(const GpuScene& g) const {
  if (!hooks_.stochastic_density || g.grid_sources.empty()) return false;
  for (const GpuGridSource& s : g.grid_sources) {
    if (s.density->grid.is_sparse() || s.density->grid.empty()) return false;
    const uint64_t texels = s.density->grid.texel_count();
    const bool half = s.density->format == TextureFormat::R16F;
    if ((half ? s.density->half_bits.size() : s.density->grid.values.size()) != texels) return false;
    const uint64_t bytes = texels * (half ? 2u : 4u);
    // The copy is on top of the texture, which the dense-or-sparse choice
    // sized against the memory left: only small grids get it, where it costs
    // little (a 256 MiB copy is an R16F grid of 512³ texels).
    constexpr uint64_t kMaxCopyBytes = uint64_t(256) << 20;
    if (texels > ctx_.properties().limits.maxTexelBufferElements ||
        bytes > std::min<uint64_t>(kMaxCopyBytes, uint64_t(ctx_.max_allocation_size())))
      return false;
  }
  return true;
}

// [0] a one-texel placeholder for the slots that read none; where
// stochastic_density, the density's stored texels (r16f or r32f, as its
// texture) of grid slot s at 1 + s.
void RenderSession::create_density_texels() {
  density_texel_views_.clear();
  density_texels_.clear();
  auto add = [&](const void* data, size_t count, bool half, const char* name) {
    density_texels_.emplace_back();
    density_texel_views_.emplace_back();
    uniform_texel_buffer(ctx_, data, count, half ? VK_FORMAT_R16_SFLOAT : VK_FORMAT_R32_SFLOAT, half ? 2u : 4u, name,
                         density_texels_.back(), density_texel_views_.back());
  };
  const float zero = 0.0f;
  add(&zero, 1, false, "unused density texels");
  if (!stochastic_density(gpu_scene_)) return;
  for (const GpuGridSource& s : gpu_scene_.grid_sources) {
    const StoredGrid& g = *s.density;
    if (g.format == TextureFormat::R16F) add(g.half_bits.data(), g.half_bits.size(), true, "density texels");
    else add(g.grid.values.data(), g.grid.values.size(), false, "density texels");
  }
}

// The majorant cells (a one-cell placeholder when there are none: every
// binding needs a buffer).
void RenderSession::create_majorant_buffer(const Scene& scene) {
  const std::vector<float> none(1, 0.0f);
  const std::vector<float>& cells = gpu_scene_.majorants.empty() ? none : gpu_scene_.majorants;
  if (cells.size() > ctx_.properties().limits.maxTexelBufferElements)
    throw input_error(scene.file.string(), "media",
                      "the majorant grids need " + std::to_string(cells.size()) +
                          " cells, more than this device's texel buffer holds (" +
                          std::to_string(ctx_.properties().limits.maxTexelBufferElements) +
                          "); set integrator.majorant to \"global\"");
  uniform_texel_buffer(ctx_, cells.data(), cells.size(), VK_FORMAT_R32_SFLOAT, sizeof(float), "majorant cells",
                       majorant_buffer_, majorant_view_);
}

// The sparse grids' trees, each at its offset (a 16-byte placeholder when
// there are none: every binding needs a buffer).
void RenderSession::create_sparse_buffer(const Scene& scene) {
  sparse_view_ = {};  // before its buffer goes
  const uint64_t bytes = std::max<uint64_t>(16, (gpu_scene_.sparse_bytes + 15) / 16 * 16);
  const uint64_t texels = bytes / 16;
  if (texels > ctx_.properties().limits.maxTexelBufferElements || bytes > uint64_t(ctx_.max_allocation_size()))
    throw input_error(scene.file.string(), "media",
                      "the sparse grids need " + mib(double(bytes)) + ", more than this device's texel buffer holds (" +
                          mib(16.0 * double(ctx_.properties().limits.maxTexelBufferElements)) + ")");
  sparse_buffer_ = vk::Buffer(ctx_, bytes, VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                              vk::MemoryKind::DeviceLocal, "sparse grids");
  if (gpu_scene_.has_sparse()) {
    const std::vector<float> zero_leaf(512, 0.0f);
    sparse_buffer_.upload(ctx_, zero_leaf.data(), zero_leaf.size() * sizeof(float), gpu::SPARSE_ZERO_LEAF);
  }
  // Where the buffer is mapped (the device's memory is host memory, as on
  // lavapipe) the trees move into it, smallest first, each freeing its host
  // copy as it goes: at most the largest tree is held twice, for a moment
  // (docs/volumes.md "Sparse grids"). Elsewhere they are copied up.
  std::vector<const GpuScene::SparseBlock*> trees;
  for (const GpuScene::SparseBlock& b : gpu_scene_.sparse_blocks)
    if (b.tree) trees.push_back(&b);
  std::sort(trees.begin(), trees.end(), [](auto* a, auto* b) { return a->tree->bytes() < b->tree->bytes(); });
  for (const GpuScene::SparseBlock* b : trees) {
    if (sparse_buffer_.host_visible()) {
      b->tree->move_to(static_cast<char*>(sparse_buffer_.map()) + b->offset);
      sparse_buffer_.flush(b->offset, b->tree->bytes());
    } else {
      sparse_buffer_.upload(ctx_, b->tree->handle.data(), b->tree->bytes(), b->offset);
    }
  }
  for (const GpuScene::SparseBlock& b : gpu_scene_.sparse_blocks) {
    if (b.tree) continue;
    const std::vector<uint32_t>& t = gpu_scene_.sparse_tables[size_t(b.table)];
    sparse_buffer_.upload(ctx_, t.data(), t.size() * sizeof(uint32_t), b.offset);
  }
  sparse_view_ = vk::texel_buffer_view(ctx_, sparse_buffer_, VK_FORMAT_R32G32B32A32_UINT);
}

// The BVH over every mesh triangle, the analytic shapes, one material per
// shape and the albedo textures (8-bit sources as SRGB8 so the sampler decodes
// before filtering, float sources as RGBA32F). Empty scenes get 1-element
// placeholders (Vulkan has no empty buffers); the spec constants keep the shader
// from reading them.
void RenderSession::create_surfaces(const Scene& scene) {
  geometry::Surfaces surfaces;
  if (!scene.shapes.empty()) surfaces = geometry::build_surfaces(scene);
  if (surfaces.textures.size() > gpu::MAX_TEXTURES)
    throw input_error(scene.file.string(), "shapes",
                      "at most " + std::to_string(gpu::MAX_TEXTURES) + " different albedo textures per scene");
  gpu_surfaces_ = geometry::pack_gpu_surfaces(surfaces);
  const auto& g = gpu_surfaces_;
  bvh_nodes_ = storage_buffer(ctx_, g.nodes, "bvh nodes");
  bvh_triangles_ = storage_buffer(ctx_, g.triangles, "bvh triangles");
  bvh_attributes_ = storage_buffer(ctx_, g.attributes, "bvh attributes");
  surface_shapes_ = storage_buffer(ctx_, g.shapes, "surface shapes");
  materials_ = storage_buffer(ctx_, g.materials, "materials");

  const uint8_t white[4] = {255, 255, 255, 255};
  textures_2d_.emplace_back(ctx_, 1, 1, VK_FORMAT_R8G8B8A8_SRGB, VK_SAMPLER_ADDRESS_MODE_REPEAT,
                            VK_SAMPLER_ADDRESS_MODE_REPEAT, "unused texture slot");
  textures_2d_.back().upload(ctx_, white, sizeof white);
  for (const geometry::Texture& t : surfaces.textures) {
    const uint32_t max_side = ctx_.properties().limits.maxImageDimension2D;
    if (uint32_t(t.width()) > max_side || uint32_t(t.height()) > max_side)
      throw input_error(t.file().string(), "",
                        std::to_string(t.width()) + " x " + std::to_string(t.height()) +
                            " texels exceed this device's 2D texture limit of " + std::to_string(max_side) +
                            " per side; resize the texture (the CPU reference, --backend cpu, has no such limit)");
    if (t.srgb_source()) {
      std::vector<uint8_t> texels = t.rgba8_srgb();
      textures_2d_.emplace_back(ctx_, uint32_t(t.width()), uint32_t(t.height()), VK_FORMAT_R8G8B8A8_SRGB,
                                VK_SAMPLER_ADDRESS_MODE_REPEAT, VK_SAMPLER_ADDRESS_MODE_REPEAT, "albedo texture");
      textures_2d_.back().upload(ctx_, texels.data(), texels.size());
    } else {
      std::vector<float> texels = t.rgba32f();
      textures_2d_.emplace_back(ctx_, uint32_t(t.width()), uint32_t(t.height()), VK_FORMAT_R32G32B32A32_SFLOAT,
                                VK_SAMPLER_ADDRESS_MODE_REPEAT, VK_SAMPLER_ADDRESS_MODE_REPEAT, "albedo texture");
      textures_2d_.back().upload(ctx_, texels.data(), texels.size() * sizeof(float));
    }
  }
}

// The lat-long environment map as a texel buffer plus its sampling CDF
// (bilinear lookups in the shader, exactly like host/light/EnvironmentMap);
// 1-element placeholders when the scene has none.
void RenderSession::create_environment(const Scene& scene) {
  std::vector<float> texels(4, 0.0f), cdf;  // texels are vec4s: the placeholder is one
  gpu::GpuEnvironment header{};
  if (scene.environment) {
    EnvironmentMap env = EnvironmentMap::load(scene.environment->file, scene.environment->scale,
                                              scene.environment->rotation_deg,
                                              scene.up_axis.value_or(UpAxis::Z) == UpAxis::Y);
    texels = pack_gpu_environment_texels(env);
    cdf = env.cdf();
    header = pack_gpu_environment_header(env);
    environment_ = std::move(env);
  }
  env_texels_ = storage_buffer(ctx_, texels, "environment");
  env_cdf_ = storage_buffer(ctx_, cdf, "environment cdf");
  env_header_ = vk::Buffer(ctx_, sizeof header, kStorage, vk::MemoryKind::HostVisible, "environment header");
  env_header_.upload(ctx_, &header, sizeof header);
}

// Each emissive grid medium as a light: its emission CDF over the grid as
// stored (host/light/EmissionCdf), packed one after another. Built only when
// next-event estimation may sample the grids (light_candidates). The preview's live edits of the
// emission (update) keep these CDFs: a stale distribution is still a valid
// light sampler, because MIS evaluates the same tables it samples from.
RenderSession::EmissionLights RenderSession::build_emission_lights(
    const Scene& scene, const std::vector<std::optional<StoredVolume>>& volumes, const GpuScene& g) const {
  EmissionLights out;
  std::vector<std::optional<EmissionCdf>> cdfs(scene.media.size());
  std::vector<const EmissionCdf*> by_medium(scene.media.size(), nullptr);
  if (light_candidates(scene).media)
    for (const GpuGridSource& src : g.grid_sources) {
      const Medium& m = scene.media[src.medium];
      if (!m.emission.emits() || !volumes[src.medium]) continue;
      cdfs[src.medium] = EmissionCdf::build_light(m, *volumes[src.medium]);
      if (!cdfs[src.medium]->empty()) by_medium[src.medium] = &*cdfs[src.medium];
    }
  out.selection = select_lights(scene, environment_ ? &*environment_ : nullptr, by_medium, g.line.any());
  out.analytic = pack_gpu_lights(scene, out.selection);
  if (out.selection.strategy == LightStrategy::Bsdf) return out;
  // By grid slot: the CDFs next-event estimation may pick.
  std::vector<const EmissionCdf*> by_slot(g.grid_sources.size(), nullptr);
  std::vector<double> pick(g.grid_sources.size(), 0.0);
  for (size_t slot = 0; slot < g.grid_sources.size(); ++slot) {
    const size_t i = g.grid_sources[slot].medium;
    if (!by_medium[i] || !(out.selection.p_medium[i] > 0.0)) continue;
    by_slot[slot] = by_medium[i];
    pick[slot] = out.selection.p_medium[i];
  }
  out.emission = pack_gpu_emission_lights(by_slot, pick);
  return out;
}

void RenderSession::upload_emission_lights(const EmissionLights& lights) {
  light_selection_ = lights.selection;
  const GpuEmissionLights& e = lights.emission;
  emission_cdf_ = storage_buffer(ctx_, e.cdf, "emission cdf");
  emission_cells_ = storage_buffer(ctx_, e.cells, "emission cells");
  emission_pmf_ = storage_buffer(ctx_, e.pmf, "emission pmf");
  emission_clusters_ = storage_buffer(ctx_, e.clusters, "emission clusters");
  analytic_lights_ = storage_buffer(ctx_, lights.analytic, "analytic lights");
  emission_headers_.upload(ctx_, e.headers.data(), e.headers.size() * sizeof(gpu::GpuEmissionCdf));
}

void RenderSession::upload_constants(const Scene& scene) {
  // Only the headers: the blackbody LUTs and majorant cells stay as baked (an
  // edit changes neither the emission's mode nor the grids), so they are not
  // rebuilt; the majorant scale, which follows the coefficients, is.
  GpuScene now = pack_gpu_media(scene, volumes_, /*with_luts=*/false, gpu_scene_.line.line, /*with_tables=*/false);
  for (size_t i = 0; i < now.grids.size() && i < gpu_scene_.grids.size(); ++i)
    keep_baked_grid_fields(gpu_scene_.grids[i], now.grids[i]);
  const gpu::FrameConstants frame = build_frame_constants(scene, settings_, uint32_t(now.media.size()), light_selection_);
  frame_buffer_.upload(ctx_, &frame, sizeof frame);
  if (!now.media.empty()) media_buffer_.upload(ctx_, now.media.data(), now.media.size() * sizeof(gpu::GpuMedium));
  if (!now.grids.empty()) grid_buffer_.upload(ctx_, now.grids.data(), now.grids.size() * sizeof(gpu::GpuGrid));
  reset();
}

}  // namespace pyrolume
