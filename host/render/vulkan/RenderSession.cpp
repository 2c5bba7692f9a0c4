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
#include "render/vulkan/Spirv.h"
#include "render/vulkan/SurfacePacking.h"
#include "scene/MediumVolume.h"
#include "util/Error.h"

namespace pyrolume {
namespace {
constexpr VkBufferUsageFlags kUniform = VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
constexpr VkBufferUsageFlags kStorage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;

// A device-local storage buffer holding `values`; an empty vector gets one
// zeroed element (Vulkan has no empty buffers; the shader never reads it).
template <typename T>
vk::Buffer storage_buffer(vk::Context& ctx, const std::vector<T>& values, const char* name) {
  const std::vector<T> one(1);
  const std::vector<T>& v = values.empty() ? one : values;
  vk::Buffer b(ctx, v.size() * sizeof(T), kStorage, vk::MemoryKind::DeviceLocal, name);
  b.upload(ctx, v.data(), v.size() * sizeof(T));
  return b;
}

// A device-local uniform texel buffer holding `count` texels of `format` from
// `data`, and its view (majorant cells, density texels).
void uniform_texel_buffer(vk::Context& ctx, const void* data, size_t count, VkFormat format, size_t texel_bytes,
                          const char* name, vk::Buffer& buffer, vk::UniqueBufferView& view) {
  view = {};  // before its buffer goes
  buffer = vk::Buffer(ctx, count * texel_bytes, VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                      vk::MemoryKind::DeviceLocal, name);
  buffer.upload(ctx, data, count * texel_bytes);
  view = vk::texel_buffer_view(ctx, buffer, format);
}

// What every grid medium must satisfy once loaded (render/SceneChecks.h).
void check_loaded_media(const Scene& scene, const std::vector<std::optional<StoredVolume>>& volumes) {
  for (size_t i = 0; i < volumes.size(); ++i)
    if (volumes[i]) check_loaded_medium(scene, i, *volumes[i]);
}

// Printed as a number, not through int: a forged size past 2^31 MiB would wrap.
std::string mib(double bytes) {
  char text[64];
  std::snprintf(text, sizeof text, "%.0f MiB", bytes / (1024.0 * 1024.0));
  return text;
}
}  // namespace

RenderSession::RenderSession(vk::Context& ctx, const Scene& scene, const RenderSettings& settings,
                             const VulkanHooks& hooks)
    : ctx_(ctx), settings_(settings), hooks_(hooks) {
  // The accumulation buffer is one storage buffer: check it fits the device
  // (lavapipe allows 128 MiB, about 1448² pixels) and its host readback
  // (texels plus double sums) fits the machine, before loading anything.
  const VkDeviceSize range = ctx.properties().limits.maxStorageBufferRange;
  const bool range_binds = range <= ctx.max_allocation_size();
  check_accumulation_size(scene.file.string(), settings.width, settings.height, sizeof(gpu::AccumTexel),
                          range_binds ? range : ctx.max_allocation_size(),
                          range_binds ? "this device's maxStorageBufferRange" : "this device's maxMemoryAllocationSize");
  // The alpha texels follow the AccumTexels in the same buffer, as a binding of their own.
  // So do the AOV texels (settings.aovs), with the AOV sums' doubles on the host.
  const size_t aov_bytes = settings.aovs ? sizeof(gpu::AovLightTexel) + sizeof(gpu::AovFeatureTexel) : 0;
  const size_t aov_host_bytes = settings.aovs ? kAovValues * sizeof(double) : 0;
  check_accumulation_size(scene.file.string(), settings.width, settings.height,
                          sizeof(gpu::AccumTexel) + sizeof(gpu::AlphaTexel) + aov_bytes, ctx.max_allocation_size(),
                          "this device's maxMemoryAllocationSize");
  check_accumulation_fits_memory(scene.file.string(), settings.width, settings.height,
                                 sizeof(gpu::AccumTexel) + sizeof(gpu::AlphaTexel) + aov_bytes + 8 * sizeof(double) +
                                     aov_host_bytes);
  check_scene_ranges(scene);
  // Load only what the scene uses: the grids of its vdb media, each checked
  // against the device's texture limits before its dense array is allocated.
  volumes_.resize(scene.media.size());
  for (size_t i = 0; i < scene.media.size(); ++i) {
    if (scene.media[i].type != Medium::Type::Vdb) continue;
    volumes_[i] = load_stored_volume(scene.media[i], dense_limits());
    for (const auto& w : volumes_[i]->warnings) warnings_.push_back(w);
  }
  check_loaded_media(scene, volumes_);
  gpu_scene_ = build_gpu_scene(scene, volumes_, /*with_luts=*/true, shared_texture_bytes());

  // Storage buffers, not uniform ones: lavapipe would inline their values
  // where they decide a branch and compile a shader variant for every pass
  // (shaders/render_bindings.glsl).
  frame_buffer_ = vk::Buffer(ctx, sizeof(gpu::FrameConstants), kStorage, vk::MemoryKind::HostVisible, "frame constants");
  media_buffer_ = vk::Buffer(ctx, gpu::MAX_MEDIA * sizeof(gpu::GpuMedium), kStorage, vk::MemoryKind::HostVisible, "media");
  grid_buffer_ = vk::Buffer(ctx, gpu::MAX_GRIDS * sizeof(gpu::GpuGrid), kUniform, vk::MemoryKind::HostVisible, "grids");
  create_majorant_buffer(scene);
  const VkDeviceSize pixels = VkDeviceSize(settings.width) * VkDeviceSize(settings.height);
  const VkDeviceSize align = std::max<VkDeviceSize>(ctx.properties().limits.minStorageBufferOffsetAlignment, 1);
  auto aligned = [&](VkDeviceSize bytes) { return (bytes + align - 1) / align * align; };
  alpha_offset_ = aligned(pixels * sizeof(gpu::AccumTexel));
  VkDeviceSize accum_bytes = alpha_offset_ + pixels * sizeof(gpu::AlphaTexel);
  if (settings.aovs) {
    aov_lights_offset_ = aligned(accum_bytes);
    aov_features_offset_ = aligned(aov_lights_offset_ + pixels * sizeof(gpu::AovLightTexel));
    accum_bytes = aov_features_offset_ + pixels * sizeof(gpu::AovFeatureTexel);
  }
  accum_ = vk::Buffer(ctx, accum_bytes,
                      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                          VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                      vk::MemoryKind::DeviceLocal, "accumulation");
  accum_backup_ = vk::Buffer(ctx, accum_.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                             vk::MemoryKind::DeviceLocal, "accumulation before the pass");
  pass_constants_ = vk::ParameterBuffer(ctx, sizeof(gpu::PassConstants), "pass constants");
  pass_status_ = vk::Buffer(ctx, sizeof(gpu::PassStatus), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                            vk::MemoryKind::HostVisible, "pass status");
  create_textures(scene);
  create_surfaces(scene);
  create_environment(scene);
  emission_headers_ = vk::Buffer(ctx, gpu::MAX_GRIDS * sizeof(gpu::GpuEmissionCdf), kStorage,
                                 vk::MemoryKind::HostVisible, "emission light headers");
  upload_emission_lights(build_emission_lights(scene, volumes_, gpu_scene_));

  spec_ = spec_constants(scene, gpu_scene_, settings, light_selection_);
  const std::vector<uint32_t> code = vk::load_spirv("render.comp");
  pipeline_.emplace(ctx, code,
                    std::vector<vk::ComputePipeline::Binding>{
                        {gpu::BINDING_FRAME, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                        {gpu::BINDING_MEDIA, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                        {gpu::BINDING_ACCUM, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                        {gpu::BINDING_ALPHA, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                        {gpu::BINDING_AOV_LIGHTS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                        {gpu::BINDING_AOV_FEATURES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                        {gpu::BINDING_GRIDS, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER},
                        {gpu::BINDING_MAJORANTS, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER},
                        {gpu::BINDING_DENSITY, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, gpu::MAX_GRIDS},
                        {gpu::BINDING_TEMPERATURE, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, gpu::MAX_GRIDS},
                        {gpu::BINDING_BLACKBODY, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, gpu::MAX_GRIDS},
                        {gpu::BINDING_DENSITY_TEXELS, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, gpu::MAX_GRIDS},
                        {gpu::BINDING_BVH_NODES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                        {gpu::BINDING_BVH_TRIANGLES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                        {gpu::BINDING_BVH_ATTRIBUTES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                        {gpu::BINDING_SURFACE_SHAPES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                        {gpu::BINDING_MATERIALS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                        {gpu::BINDING_TEXTURES, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, gpu::MAX_TEXTURES},
                        {gpu::BINDING_ENV_TEXELS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                        {gpu::BINDING_ENV_CDF, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                        {gpu::BINDING_ENV_HEADER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                        {gpu::BINDING_EMISSION_CDF, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                        {gpu::BINDING_EMISSION_CELLS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                        {gpu::BINDING_EMISSION_PMF, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                        {gpu::BINDING_EMISSION_CLUSTERS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                        {gpu::BINDING_EMISSION_HEADERS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                        {gpu::BINDING_LIGHTS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                        {gpu::BINDING_PASS_STATUS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                        {gpu::BINDING_PATHS, VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER},
                        {gpu::BINDING_SPARSE, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER},
                        {gpu::BINDING_QUEUES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                        {gpu::BINDING_PASS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}},
                    /*push_constant_bytes=*/0, spec_, "render");
  set_.emplace(ctx, *pipeline_, "render set");
  create_wavefront(code);
  set_->write_buffer(gpu::BINDING_FRAME, frame_buffer_);
  set_->write_buffer(gpu::BINDING_MEDIA, media_buffer_);
  set_->write_buffer(gpu::BINDING_ACCUM, accum_, 0, accumulation_texel_bytes());
  const VkDeviceSize alpha_bytes = pixels * sizeof(gpu::AlphaTexel);
  set_->write_buffer(gpu::BINDING_ALPHA, accum_, alpha_offset_, alpha_bytes);
  if (settings.aovs) {
    set_->write_buffer(gpu::BINDING_AOV_LIGHTS, accum_, aov_lights_offset_, pixels * sizeof(gpu::AovLightTexel));
    set_->write_buffer(gpu::BINDING_AOV_FEATURES, accum_, aov_features_offset_, pixels * sizeof(gpu::AovFeatureTexel));
  } else {  // compiled out (AOVS false), but every binding needs a buffer
    set_->write_buffer(gpu::BINDING_AOV_LIGHTS, accum_, alpha_offset_, alpha_bytes);
    set_->write_buffer(gpu::BINDING_AOV_FEATURES, accum_, alpha_offset_, alpha_bytes);
  }
  set_->write_buffer(gpu::BINDING_PASS_STATUS, pass_status_);
  set_->write_buffer(gpu::BINDING_PASS, pass_constants_.buffer());
  set_->write_buffer(gpu::BINDING_GRIDS, grid_buffer_);
  write_grid_descriptors();
  set_->write_buffer(gpu::BINDING_BVH_NODES, bvh_nodes_);
  set_->write_buffer(gpu::BINDING_BVH_TRIANGLES, bvh_triangles_);
  set_->write_buffer(gpu::BINDING_BVH_ATTRIBUTES, bvh_attributes_);
  set_->write_buffer(gpu::BINDING_SURFACE_SHAPES, surface_shapes_);
  set_->write_buffer(gpu::BINDING_MATERIALS, materials_);
  set_->write_buffer(gpu::BINDING_ENV_TEXELS, env_texels_);
  set_->write_buffer(gpu::BINDING_ENV_CDF, env_cdf_);
  set_->write_buffer(gpu::BINDING_ENV_HEADER, env_header_);
  for (uint32_t slot = 0; slot < gpu::MAX_TEXTURES; ++slot)
    set_->write_image(gpu::BINDING_TEXTURES, textures_2d_[slot + 1 < textures_2d_.size() ? slot + 1 : 0], slot);
  upload_constants(scene);
  // A driver may compile a pipeline inside its first dispatch (~0.1–0.5 s;
  // lavapipe did while it inlined uniforms, docs/rendering.md): dispatch one
  // empty workgroup now so that cost counts as loading, not rendering
  // (docs/benchmarks.md: `seconds` starts at the first real pass).
  ctx.submit_and_wait([&](VkCommandBuffer cmd) {
    pass_constants_.record(cmd, gpu::PassConstants{0u, 0u, 0u, 0u});
    pipeline_->bind(cmd, set_->set());
    vkCmdDispatch(cmd, 1, 1, 1);
    // The wavefront's stages, on empty queues (the queues are zero).
    for (const vk::ComputePipeline& stage : wavefront_stages_) {
      stage.bind(cmd, set_->set());
      vkCmdDispatch(cmd, 1, 1, 1);
    }
  });
}

// The largest density texture that may take its temperature as a second
// channel: one allocation; 0 (never) when the test hook turns it off.
uint64_t RenderSession::shared_texture_bytes() const {
  return hooks_.temperature_in_density ? uint64_t(ctx_.max_allocation_size()) : 0;
}

DenseLimits RenderSession::dense_limits() const {
  return DenseLimits{ctx_.properties().limits.maxImageDimension3D, uint64_t(ctx_.max_allocation_size())};
}

// The shader variant: code for grids, scattering and emission only when used.
std::vector<std::pair<uint32_t, uint32_t>> RenderSession::spec_constants(const Scene& scene, const GpuScene& g,
                                                                        const RenderSettings& settings,
                                                                        const LightSelection& lights) const {
  auto flag = [](bool b) { return uint32_t(b ? 1 : 0); };
  return {{gpu::SPEC_HAS_GRIDS, flag(g.has_grids)},
          {gpu::SPEC_HAS_ANALYTIC_MEDIA, flag(g.has_analytic)},
          {gpu::SPEC_ALBEDO_TEXTURE_COUNT,
           uint32_t(std::min<size_t>(textures_2d_.empty() ? 0 : textures_2d_.size() - 1, gpu::MAX_TEXTURES))},
          {gpu::SPEC_HAS_SCATTERING, flag(g.has_scattering && scene.integrator.max_depth > 0)},
          {gpu::SPEC_HAS_EMISSION, flag(g.has_emission)},
          {gpu::SPEC_TEMPERATURE_IN_DENSITY, flag(g.temperature_in_density)},
          {gpu::SPEC_SPARSE_GRIDS, flag(g.has_sparse())},
          {gpu::SPEC_STOCHASTIC_DENSITY, flag(stochastic_density(g))},
          {gpu::SPEC_COLLISION_ESTIMATOR, flag(lights.estimator != EmissionEstimator::Absorption)},
          {gpu::SPEC_DEBUG_MODE, hooks_.debug_mode},
          {gpu::SPEC_MEDIUM_COUNT, uint32_t(g.media.size())},
          {gpu::SPEC_GRID_COUNT, uint32_t(g.grids.size())},
          {gpu::SPEC_HAS_SURFACES, flag(!scene.shapes.empty())},
          {gpu::SPEC_SURFACE_SHAPE_COUNT, gpu_surfaces_.shape_count},
          {gpu::SPEC_SURFACE_HAS_TRIANGLES, flag(gpu_surfaces_.triangle_count > 0)},
          {gpu::SPEC_HAS_ENVIRONMENT, flag(scene.environment.has_value())},
          {gpu::SPEC_LIGHT_COUNT, uint32_t(scene.lights.size())},
          {gpu::SPEC_AOVS, flag(settings.aovs)},
          {gpu::SPEC_LIGHT_STRATEGY, lights.strategy == LightStrategy::Mis         ? gpu::LIGHT_STRATEGY_MIS
                                     : lights.strategy == LightStrategy::LightOnly ? gpu::LIGHT_STRATEGY_LIGHT_ONLY
                                                                                   : gpu::LIGHT_STRATEGY_BSDF},
          {gpu::SPEC_GUIDED_CONTINUATION, flag(lights.p_continue_own < 1.0)},
          // Leaving the free-flight loop early pays where flights are long
          // and an event's code is short: media alone with BSDF/phase
          // sampling, 1.04–1.28×. With next-event estimation (0.8–0.95×) or
          // surfaces (0.96–0.98×) the extra pass through the event code
          // costs more than the wait (docs/benchmarks.md "Lanes in the
          // free-flight loop").
          {gpu::SPEC_EARLY_EVENT_EXIT,
           flag(hooks_.early_event_exit && lights.strategy == LightStrategy::Bsdf && scene.shapes.empty() &&
                ctx_.features().subgroup_ballot)}};
}

// The bindings that change with the media's grids.
void RenderSession::write_grid_descriptors() {
  set_->write_texel_buffer(gpu::BINDING_MAJORANTS, majorant_view_.get());
  set_->write_buffer(gpu::BINDING_EMISSION_CDF, emission_cdf_);
  set_->write_buffer(gpu::BINDING_EMISSION_CELLS, emission_cells_);
  set_->write_buffer(gpu::BINDING_EMISSION_PMF, emission_pmf_);
  set_->write_buffer(gpu::BINDING_EMISSION_CLUSTERS, emission_clusters_);
  set_->write_buffer(gpu::BINDING_EMISSION_HEADERS, emission_headers_);
  set_->write_buffer(gpu::BINDING_LIGHTS, analytic_lights_);
  // textures_3d_[0] / textures_1d_[0] are 1-texel placeholders for unused slots.
  for (uint32_t slot = 0; slot < gpu::MAX_GRIDS; ++slot) {
    const bool used = slot < gpu_scene_.grid_sources.size();
    const size_t d = used ? 1 + 2 * slot : 0, t = used ? 2 + 2 * slot : 0, b = used ? 1 + slot : 0;
    set_->write_image(gpu::BINDING_DENSITY, textures_3d_[d], slot);
    set_->write_image(gpu::BINDING_TEMPERATURE, textures_3d_[t], slot);
    set_->write_image(gpu::BINDING_BLACKBODY, textures_1d_[b], slot);
    const size_t texels = 1 + slot < density_texel_views_.size() ? 1 + slot : 0;
    set_->write_texel_buffer(gpu::BINDING_DENSITY_TEXELS, density_texel_views_[texels].get(), slot);
  }
  if (sparse_view_) {
    set_->write_texel_buffer(gpu::BINDING_SPARSE, sparse_view_.get());
  }
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
  // The blackbody LUTs depend only on the emission's mode, observer and
  // adaptation: bake them once per sequence and reuse them frame after frame.
  GpuScene gpu_scene = build_gpu_scene(scene, volumes, /*with_luts=*/false, shared_texture_bytes());
  for (size_t slot = 0; slot < gpu_scene.grid_sources.size(); ++slot) {
    GpuGridSource& src = gpu_scene.grid_sources[slot];
    if (!src.temperature) continue;
    const Emission& e = scene.media[src.medium].emission;
    for (const GpuGridSource& old : gpu_scene_.grid_sources)
      if (old.blackbody && old.blackbody->mode() == e.blackbody && old.blackbody->observer() == e.observer &&
          old.blackbody->adapt_to_k() == e.adapt_to_k) {
        src.blackbody = old.blackbody;
        break;
      }
    if (!src.blackbody) src.blackbody.emplace(e.blackbody, e.observer, e.adapt_to_k);
    const color::BlackbodyLutParams& p = src.blackbody->params();
    set_blackbody_lut(gpu_scene.grids[slot], p);
  }
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

void RenderSession::update(const Scene& scene) { upload_constants(scene); }

void RenderSession::reset() {
  spp_done_ = 0;
  needs_clear_ = true;
}

void RenderSession::record_pass(VkCommandBuffer cmd, int spp) {
  record_band(cmd, spp, 0, settings_.height);
  spp_done_ += spp;
}

void RenderSession::record_band(VkCommandBuffer cmd, int spp, int row_begin, int row_end, bool wavefront) {
  vkCmdFillBuffer(cmd, pass_status_.buffer(), 0, VK_WHOLE_SIZE, 0u);
  vk::memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                     VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
  if (needs_clear_) {
    vkCmdFillBuffer(cmd, accum_.buffer(), 0, VK_WHOLE_SIZE, 0u);
    vk::memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
    needs_clear_ = false;
  }
  const gpu::PassConstants pass{uint32_t(spp_done_), uint32_t(spp), uint32_t(row_begin), uint32_t(row_end)};
  pass_constants_.record(cmd, pass);
  if (wavefront) {
    record_wavefront_start(cmd, pass);
    return;
  }
  pipeline_->bind(cmd, set_->set());
  const uint32_t groups_x = (uint32_t(settings_.width) + gpu::WORKGROUP_SIZE_X - 1) / gpu::WORKGROUP_SIZE_X;
  const uint32_t groups_y = (uint32_t(row_end - row_begin) + gpu::WORKGROUP_SIZE_Y - 1) / gpu::WORKGROUP_SIZE_Y;
  vkCmdDispatch(cmd, groups_x, groups_y, 1);
  // The next pass, a readback copy or a display shader reads what this one wrote.
  vk::memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                     VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                     VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT);
}

// The wavefront integrator (shaders/wavefront.glsl), a benchmark and test
// hook (no scene key or flag): PYROLUME_WAVEFRONT=1 renders with its track
// and event stages, =2 with the event stage split in two (event, begin).
// It loses to the megakernel on lavapipe (docs/benchmarks.md "A wavefront
// prototype"), so nothing turns it on by default. One path slot per pixel:
// the whole image is one band, and the state must fit one texel buffer.
void RenderSession::create_wavefront(const std::vector<uint32_t>& code) {
  const char* env = std::getenv("PYROLUME_WAVEFRONT");
  const std::string mode = env ? env : "";
  // Not with analytic lights: the wavefront's path state does not carry a
  // delta light ray's target (PathState::delta_light).
  bool has_lights = false;
  for (const auto& [id, value] : spec_)
    if (id == gpu::SPEC_LIGHT_COUNT) has_lights = value > 0;
  // Nor with AOVs: its path state does not carry them.
  const bool on = (mode == "1" || mode == "2") && hooks_.debug_mode == 0 && !has_lights && !settings_.aovs;
  wavefront_split_ = on && mode == "2";
  const size_t slots = on ? size_t(settings_.width) * size_t(settings_.height) : 1;
  const size_t words = gpu::WAVEFRONT_PATH_WORDS + gpu::WAVEFRONT_PATH_WORDS_PER_MEDIUM *
                                                       std::max<size_t>(1, gpu_scene_.media.size());
  const double bytes = double(slots * words) * 16.0;
  if (slots * words > ctx_.properties().limits.maxTexelBufferElements || bytes > double(ctx_.max_allocation_size()))
    throw vk::VulkanError("PYROLUME_WAVEFRONT: " + std::to_string(settings_.width) + "x" +
                          std::to_string(settings_.height) + " pixels need " + mib(bytes) +
                          " of path state, more than this device's texel buffer holds; render a smaller image");
  wavefront_paths_ = vk::Buffer(ctx_, slots * words * 4 * sizeof(uint32_t),
                                VK_BUFFER_USAGE_STORAGE_TEXEL_BUFFER_BIT, vk::MemoryKind::DeviceLocal,
                                "wavefront paths");
  wavefront_paths_view_ = vk::texel_buffer_view(ctx_, wavefront_paths_, VK_FORMAT_R32G32B32A32_UINT);
  wavefront_queues_ = vk::Buffer(ctx_, sizeof(gpu::WavefrontQueues) + 4 * slots * sizeof(uint32_t),
                                 kStorage | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT, vk::MemoryKind::HostVisible,
                                 "wavefront queues");
  std::memset(wavefront_queues_.map(), 0, sizeof(gpu::WavefrontQueues));
  wavefront_queues_.flush();
  set_->write_texel_buffer(gpu::BINDING_PATHS, wavefront_paths_view_.get());
  set_->write_buffer(gpu::BINDING_QUEUES, wavefront_queues_);
  wavefront_capacity_ = uint32_t(slots);
  if (!on) return;
  for (uint32_t stage = gpu::WAVEFRONT_START; stage <= gpu::WAVEFRONT_SIZE_BEGIN; ++stage) {
    std::vector<std::pair<uint32_t, uint32_t>> spec = spec_;
    spec.push_back({gpu::SPEC_WAVEFRONT_STAGE, stage});
    spec.push_back({gpu::SPEC_WAVEFRONT_SPLIT, wavefront_split_ ? 1u : 0u});
    for (auto& [id, value] : spec)
      if (id == gpu::SPEC_EARLY_EVENT_EXIT)
        value = stage == gpu::WAVEFRONT_TRACK && ctx_.features().subgroup_ballot ? 1u : 0u;
    wavefront_stages_.emplace_back(ctx_, code, pipeline_->bindings(), /*push_constant_bytes=*/0, spec,
                                   "render wavefront stage");
  }
}

void RenderSession::record_wavefront_start(VkCommandBuffer cmd, const gpu::PassConstants& pass) {
  gpu::WavefrontQueues start{};
  start.capacity = wavefront_capacity_;
  vkCmdUpdateBuffer(cmd, wavefront_queues_.buffer(), 0, sizeof start, &start);
  vk::memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                     VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
  const vk::ComputePipeline& start_stage = wavefront_stages_[gpu::WAVEFRONT_START - 1];
  start_stage.bind(cmd, set_->set());
  const uint32_t groups_x = (uint32_t(settings_.width) + gpu::WORKGROUP_SIZE_X - 1) / gpu::WORKGROUP_SIZE_X;
  const uint32_t groups_y = (pass.row_end - pass.row_begin + gpu::WORKGROUP_SIZE_Y - 1) / gpu::WORKGROUP_SIZE_Y;
  vkCmdDispatch(cmd, groups_x, groups_y, 1);
  record_wavefront_iterations(cmd, kWavefrontIterations);
}

void RenderSession::record_wavefront_iterations(VkCommandBuffer cmd, int iterations) {
  auto barrier = [&] {
    vk::memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT,
                       VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_INDIRECT_COMMAND_READ_BIT);
  };
  auto stage = [&](uint32_t s) -> const vk::ComputePipeline& { return wavefront_stages_[s - 1]; };
  // The stages' layouts are identically defined, so the set stays bound
  // across their pipelines: bound once. The pass's constants stay in their
  // buffer (record_band wrote them).
  stage(gpu::WAVEFRONT_TRACK).bind(cmd, set_->set());
  // A queue stage: its one-lane sizing stage, then the stage itself, as large as its queue.
  auto run = [&](uint32_t sizing, uint32_t queued, VkDeviceSize dispatch_offset) {
    barrier();
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, stage(sizing).pipeline());
    vkCmdDispatch(cmd, 1, 1, 1);
    barrier();
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, stage(queued).pipeline());
    vkCmdDispatchIndirect(cmd, wavefront_queues_.buffer(), dispatch_offset);
  };
  for (int i = 0; i < iterations; ++i) {
    run(gpu::WAVEFRONT_SIZE_TRACK, gpu::WAVEFRONT_TRACK, offsetof(gpu::WavefrontQueues, track_dispatch));
    run(gpu::WAVEFRONT_SIZE_EVENT, gpu::WAVEFRONT_EVENT, offsetof(gpu::WavefrontQueues, event_dispatch));
    if (wavefront_split_)
      run(gpu::WAVEFRONT_SIZE_BEGIN, gpu::WAVEFRONT_BEGIN, offsetof(gpu::WavefrontQueues, begin_dispatch));
  }
  vk::memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                     VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_HOST_BIT,
                     VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
                         VK_ACCESS_HOST_READ_BIT);
}

// Paths still queued for the track stage after the last recorded iteration.
uint32_t RenderSession::wavefront_paths_left() const {
  wavefront_queues_.invalidate();
  const gpu::WavefrontQueues* q = wavefront_queues_.data<gpu::WavefrontQueues>();
  return (q->track_read ^ 1u) == 0u ? q->track_count0 : q->track_count1;
}

int RenderSession::first_band_rows(int spp) const {
  // About 2^14 paths: a few milliseconds for an ordinary scene, and bounded
  // for a pathological one (on llvmpipe each invocation stops after 65535
  // loop iterations, PassStatus); band_rows_ then adapts to what was measured.
  const int64_t rows = (int64_t(1) << 14) / std::max<int64_t>(1, int64_t(settings_.width) * spp);
  return int(std::clamp<int64_t>(rows, 1, settings_.height));
}

namespace {
// Test hook (no CLI flag): PYROLUME_TEST_FAIL_PASS=VK_ERROR_DEVICE_LOST:N (or
// VK_ERROR_OUT_OF_DEVICE_MEMORY:N; any other name means VK_ERROR_UNKNOWN)
// makes the N-th render pass of this process (1-based) fail as if
// vkQueueSubmit had returned that result. A device cannot be lost on
// lavapipe; this is how tests reach the recovery path.
VkResult injected_failure() {
  static const std::pair<VkResult, long> fault = [] {
    const char* v = std::getenv("PYROLUME_TEST_FAIL_PASS");
    if (!v) return std::pair<VkResult, long>{VK_SUCCESS, 0};
    const std::string s = v;
    const size_t colon = s.find(':');
    const std::string name = s.substr(0, colon);
    const long n = colon == std::string::npos ? 1 : std::atol(s.c_str() + colon + 1);
    VkResult r = name == "VK_ERROR_DEVICE_LOST"            ? VK_ERROR_DEVICE_LOST
                 : name == "VK_ERROR_OUT_OF_DEVICE_MEMORY" ? VK_ERROR_OUT_OF_DEVICE_MEMORY
                                                            : VK_ERROR_UNKNOWN;
    return std::pair<VkResult, long>{r, n};
  }();
  static long passes = 0;
  if (fault.first == VK_SUCCESS) return VK_SUCCESS;
  return ++passes == fault.second ? fault.first : VK_SUCCESS;
}
}  // namespace

bool RenderSession::run_pass(int spp, const std::atomic<bool>* cancel) {
  // What the accumulation holds after the last sub-pass that completed: a
  // failure restores it, so the counters never claim samples it lacks.
  int spp_ok = spp_done_;
  bool clear_ok = needs_clear_;
  const VkBufferCopy all{0, 0, accum_.size()};
  // The accumulation as it was before the pass in flight (a pass that cleared
  // it just needs clearing again).
  auto restore = [&](bool clears) {
    if (clears) {
      needs_clear_ = true;
      return;
    }
    ctx_.submit_and_wait([&](VkCommandBuffer cmd) {
      vkCmdCopyBuffer(cmd, accum_backup_.buffer(), accum_.buffer(), 1, &all);
      vk::memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                         VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT);
    });
  };
  try {
    if (VkResult r = injected_failure(); r != VK_SUCCESS)
      vk::throw_vk_error("vkQueueSubmit (PYROLUME_TEST_FAIL_PASS)", r, __FILE__, __LINE__);
    // A pass the device cannot finish (llvmpipe's loop budget, PassStatus) is
    // undone from the copy taken before it and redone in halves; the size that
    // works is kept for the passes after it. Each sample keeps its index, so
    // the result is the same as with passes that fit, and as with one dispatch
    // for the whole image: the bands below only split the pixels.
    const bool wavefront = !wavefront_stages_.empty();
    for (int remaining = spp; remaining > 0;) {
      const int n = std::min(remaining, max_pass_spp_);
      const bool clears = needs_clear_;
      if (band_rows_ == 0) band_rows_ = first_band_rows(n);
      uint32_t unfinished = 0;
      bool interrupted = false;
      for (int row = 0; row < settings_.height;) {
        // The wavefront keeps every pixel's path in flight at once: one band.
        const int rows = wavefront ? settings_.height - row : std::min(band_rows_, settings_.height - row);
        const bool first_band = row == 0;
        const auto t0 = std::chrono::steady_clock::now();
        ctx_.submit_and_wait([&](VkCommandBuffer cmd) {
          if (first_band && !clears) {
            vkCmdCopyBuffer(cmd, accum_.buffer(), accum_backup_.buffer(), 1, &all);
            vk::memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT,
                               VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
          }
          record_band(cmd, n, row, row + rows, wavefront);
        });
        // The wavefront: more rounds until no path is left in its queues (a
        // signal drops the pass; the next one starts on fresh queues).
        while (wavefront && wavefront_paths_left() > 0) {
          if (cancel && cancel->load()) {
            interrupted = true;
            break;
          }
          ctx_.submit_and_wait([&](VkCommandBuffer cmd) { record_wavefront_iterations(cmd, kWavefrontIterations); });
        }
        if (interrupted) break;
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        pass_status_.invalidate();
        unfinished += pass_status_.data<gpu::PassStatus>()->unfinished_samples;
        row += rows;
        // Dispatches long enough to hide their overhead, short enough that a
        // signal is answered at once and no GPU watchdog fires.
        if (seconds < kBandFastSeconds) band_rows_ = std::min(settings_.height, band_rows_ * 2);
        else if (seconds > kBandSlowSeconds) band_rows_ = std::max(1, band_rows_ / 2);
        if (row < settings_.height && cancel && cancel->load()) {
          interrupted = true;
          break;
        }
        if (unfinished > 0 && n > 1) break;  // redone in halves anyway: the other bands would be wasted
      }
      if (interrupted) {
        restore(clears);
        spp_ok = spp_done_;
        clear_ok = needs_clear_;
        return false;
      }
      if (unfinished == 0 || n == 1) {
        dropped_samples_ += unfinished;  // at 1 spp per pass there is nothing left to split
        spp_done_ += n;
        remaining -= n;
        spp_ok = spp_done_;
        clear_ok = needs_clear_;
        continue;
      }
      restore(clears);
      max_pass_spp_ = n / 2;
    }
  } catch (const vk::VulkanError&) {
    spp_done_ = spp_ok;
    needs_clear_ = clear_ok;
    throw;
  }
  return true;
}

AccumulationState RenderSession::save_state() {
  const size_t pixels = size_t(settings_.width) * size_t(settings_.height);
  AccumulationState st;
  st.backend = "vulkan";
  st.width = settings_.width;
  st.height = settings_.height;
  st.spp = spp_done_;
  // The AccumTexels, then the AlphaTexels (without the alignment gap between them on the device).
  const size_t texels = pixels * sizeof(gpu::AccumTexel);
  st.data.assign(texels + pixels * sizeof(gpu::AlphaTexel), 0);
  if (spp_done_ > 0 && !needs_clear_) {
    accum_.download(ctx_, st.data.data(), texels);
    accum_.download(ctx_, st.data.data() + texels, st.data.size() - texels, alpha_offset_);
  }
  return st;
}

void RenderSession::load_state(const AccumulationState& st) {
  const size_t texels = accumulation_texel_bytes(),
               bytes = texels + size_t(settings_.width) * size_t(settings_.height) * sizeof(gpu::AlphaTexel);
  if (st.backend != "vulkan" || st.width != settings_.width || st.height != settings_.height ||
      st.data.size() != bytes || st.spp < 0)
    throw std::invalid_argument("vulkan: the resumed accumulation is not a " + std::to_string(settings_.width) + "x" +
                                std::to_string(settings_.height) + " vulkan one");
  accum_.upload(ctx_, st.data.data(), texels);
  accum_.upload(ctx_, st.data.data() + texels, bytes - texels, alpha_offset_);
  spp_done_ = st.spp;
  needs_clear_ = st.spp == 0;
}

void RenderSession::read(RenderResult& result) {
  result_from_state(save_state(), result);
  read_aovs(result);
}

void RenderSession::read_aovs(RenderResult& result) {
  result.aov_sum.clear();
  if (!settings_.aovs) return;
  const size_t pixels = size_t(settings_.width) * size_t(settings_.height);
  result.aov_sum.assign(pixels * kAovValues, 0.0);
  if (spp_done_ <= 0 || needs_clear_) return;
  std::vector<gpu::AovLightTexel> lights(pixels);
  std::vector<gpu::AovFeatureTexel> features(pixels);
  accum_.download(ctx_, lights.data(), pixels * sizeof(gpu::AovLightTexel), aov_lights_offset_);
  accum_.download(ctx_, features.data(), pixels * sizeof(gpu::AovFeatureTexel), aov_features_offset_);
  for (size_t i = 0; i < pixels; ++i) {
    double* s = result.aov_sum.data() + i * kAovValues;
    const gpu::AovLightTexel& l = lights[i];
    const gpu::AovFeatureTexel& f = features[i];
    for (int c = 0; c < 3; ++c) {
      s[kAovEmission + c] = l.emission[c];
      s[kAovScatter + c] = l.scatter[c];
      s[kAovSurface + c] = l.surface[c];
      s[kAovBackground + c] = l.background[c];
      s[kAovAlbedo + c] = f.albedo[c];
      s[kAovNormal + c] = f.normal[c];
      s[kAovGuide + c] = f.guide[c];
    }
    s[kAovDepth] = f.depth;
    s[kAovHits] = f.hits;
    s[kAovGuideAlpha] = f.guide_alpha;
  }
}

void RenderSession::result_from_state(const AccumulationState& state, RenderResult& result) {
  const size_t pixels = size_t(state.width) * size_t(state.height);
  if (state.data.size() != pixels * (sizeof(gpu::AccumTexel) + sizeof(gpu::AlphaTexel)))
    throw std::logic_error("RenderSession::result_from_state: state size does not match its image");
  result.width = state.width;
  result.height = state.height;
  result.spp = state.spp;
  result.sum.assign(pixels * 3, 0.0);
  result.sum_sq.assign(pixels * 3, 0.0);
  result.alpha_sum.assign(pixels, 0.0);
  result.alpha_sum_sq.assign(pixels, 0.0);
  result.events = result.density_lookups = 0.0;
  result.nonfinite_samples = 0;
  for (size_t i = 0; i < pixels; ++i) {
    gpu::AccumTexel t;
    std::memcpy(&t, state.data.data() + i * sizeof t, sizeof t);
    for (int c = 0; c < 3; ++c) {
      // Kahan: the running sum minus its pending compensation.
      result.sum[i * 3 + c] = double(t.sum[c]) - double(t.sum_c[c]);
      result.sum_sq[i * 3 + c] = double(t.sum_sq[c]) - double(t.sum_sq_c[c]);
    }
    gpu::AlphaTexel a;
    std::memcpy(&a, state.data.data() + pixels * sizeof t + i * sizeof a, sizeof a);
    result.alpha_sum[i] = double(a.sum) - double(a.sum_c);
    result.alpha_sum_sq[i] = double(a.sq) - double(a.sq_c);
    result.events += double(t.events) - double(t.events_c);
    result.density_lookups += double(t.lookups);
    result.nonfinite_samples += uint64_t(t.nonfinite);
  }
}

}  // namespace pyrolume
